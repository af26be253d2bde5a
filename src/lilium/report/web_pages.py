"""The self-contained WebGL pages (``workbench.html``, a skull's ``review.html``): their shared
scripts and templates (``lilium/report/web/``) inlined, and arrays as base64 blocks.

A page fetches nothing: :func:`web_page` fills a template with the page's values and inlines
``page.js`` (shared page helpers), ``meshgl.js`` (the mesh drawn through the project's camera)
and the page's own script.
"""

import base64
from importlib import resources

import numpy as np

from ..photo.review import fill_template


def web_file(name):
    """The text of ``lilium/report/web/<name>``."""
    return resources.files("lilium.report").joinpath("web", name).read_text(encoding="utf-8")


def base64_array(array, dtype):
    """``array`` as ``dtype`` (e.g. ``"<f4"``, little-endian), base64 text."""
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def web_page(template, script, values):
    """The page ``template`` (``web/<template>``) with ``values`` filled and its scripts inline.

    Parameters
    ----------
    template : str
        The page's HTML template in ``web/``; it holds ``__PAGE_JS__``, ``__MESHGL_JS__`` and
        ``__SCRIPT_JS__`` where the scripts go.
    script : str
        The page's own script in ``web/``.
    values : dict of str -> str
        The template's other placeholders (already escaped).

    Returns
    -------
    str
    """
    values = dict(values)
    scripts = {"__PAGE_JS__": "page.js", "__MESHGL_JS__": "meshgl.js", "__SCRIPT_JS__": script}
    for key, name in scripts.items():
        source = web_file(name)
        if "</script" in source.lower():
            raise ValueError(f"lilium/report/web/{name} must not contain '</script'")
        values[key] = source
    return fill_template(web_file(template), values)
