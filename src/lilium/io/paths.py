"""Ids that become file and folder names: always one safe path component.

A photo's or skull's id is its folder's name (or its file's stem); the case writes each photo's
results to ``OUT/<photo id>/``. A name taken from the command line can be anything (``..``,
``.``, ``/``, ``javascript:alert(1)``, a name with a slash from a JSON field), so every id goes
through :func:`safe_id` before it names a folder: the result is a single path component that
stays inside its parent on every common file system and reads as a relative link in HTML.
"""

import os
import re
from pathlib import Path

#: Characters replaced by ``_``: path separators, characters Windows forbids, and ``%``/``#``
#: (which would change the meaning of a relative link); control characters too.
_UNSAFE = re.compile(r'[\x00-\x1f\x7f/\\:*?"<>|%#]')

#: Names Windows reserves whatever the extension.
_RESERVED = {"con", "prn", "aux", "nul"} | {f"{p}{i}" for p in ("com", "lpt") for i in range(10)}

#: Longest id (characters); longer names are cut (file systems allow 255 bytes).
MAX_ID_CHARS = 100


def safe_id(name, default="photo"):
    """``name`` as a safe folder name: one path component, never ``.``/``..``, not hidden.

    Parameters
    ----------
    name : str
    default : str
        Used when nothing is left of ``name`` (empty, only dots or spaces).

    Returns
    -------
    str
        ``name`` unchanged when it is already safe (letters, digits, spaces, ``-_.+()`` ...).

    Examples
    --------
    >>> safe_id("front_view")
    'front_view'
    >>> safe_id("..")
    'photo'
    >>> safe_id("javascript:alert(1)")
    'javascript_alert(1)'
    >>> safe_id("a/b\\\\c")
    'a_b_c'
    """
    text = _UNSAFE.sub("_", str(name)).strip(" .")
    text = text[:MAX_ID_CHARS].rstrip(" .")
    if not text:
        return default
    if text.split(".")[0].lower() in _RESERVED:
        text = "_" + text
    return text


def path_id(path, default="photo"):
    """The id of a folder or file given on the command line: its name as written, made safe.

    ``some/dir/..`` is ``some`` (the path is normalised first, without following links), and
    ``.`` is the current folder's name.
    """
    name = Path(os.path.normpath(os.path.abspath(path))).name
    return safe_id(name, default)
