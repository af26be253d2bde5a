"""The output folders of a case (docs/contract.md): what lets ``lilium case`` and ``lilium
lineup`` resume (each stored result's input fingerprint, :func:`sfo_fingerprint`; the test that
a stored result is this SFO's, :func:`stored_result`), the joint SFO's files and the lock that
keeps a second run off an output folder (:func:`output_lock`); a photo given twice is refused
by :func:`lilium.io.case.check_distinct_files`.
"""

import hashlib
import json
from contextlib import contextmanager
from dataclasses import asdict, is_dataclass, replace
from pathlib import Path

import numpy as np

from .. import __version__
from ..io.jsonio import write_json
from ..io.locks import RunLock
from ..io.paths import printable, safe_id
from ..io.provenance import input_files
from ..io.results import png_readable, read_result, remove_overlays, write_png, write_result
from ..methods.overlay import result_overlay
from ..methods.registry import (
    method_tag,
    run_sfo,
)
from .identify import with_identification

#: Name of one SFO's workbench page in its folder (:func:`write_sfo`).
WORKBENCH = "workbench.html"


def joint_workbench_name(photo_id):
    """File name of a photo's workbench page in a joint SFO's folder."""
    return f"workbench_{safe_id(photo_id)}.html"


def write_sfo(folder, result, skull, photo, overlay=True):
    """Write one SFO's files in ``folder``: ``workbench.html`` (the overlay workbench,
    :mod:`lilium.report.workbench`; none for a failed SFO, whose folder then holds no earlier
    one), ``overlay.png`` (with ``overlay``) and ``result.json``, last
    (:func:`~lilium.io.results.write_result`)."""
    _workbench(Path(folder) / WORKBENCH, skull, photo, result)
    write_result(folder, result, result_overlay(result, skull, photo) if overlay else None)


def _workbench(page, skull, photo, result):
    """(Re)write one result's workbench page ``page``; a failed SFO has none."""
    from ..report.workbench import write_workbench  # the report layer, loaded when used

    page.unlink(missing_ok=True)
    if result:
        write_workbench(page, skull, photo, result)


def joint_overlay_name(photo_id):
    """File name of a photo's overlay in a joint SFO's folder: ``overlay_<photo id>.png``."""
    return f"overlay_{safe_id(photo_id)}.png"


def write_joint_result(out_dir, result, skull, photos, overlay=True):
    """Write a joint SFO's files per photo, as :func:`write_sfo` writes a single one's: its
    workbench page, then ``overlay_<photo id>.png`` (the photo's plain image when its camera
    failed); then its ``result.json`` (docs/method/joint.md).

    As :func:`~lilium.io.results.write_result`: an earlier ``result.json`` and the overlays of
    an earlier SFO (:func:`~lilium.io.results.remove_overlays`, a single one's too) are removed
    first and the new ``result.json`` written last, so it is only ever there with its whole
    overlays.

    Each photo with a camera gets its workbench page, ``workbench_<photo id>.html``
    (:mod:`lilium.report.workbench`).

    Returns
    -------
    dict of str -> Path
        ``result.json`` and each photo id's overlay path (when written).
    """
    out_dir = Path(out_dir)
    written = {"result.json": out_dir / "result.json"}
    written["result.json"].unlink(missing_ok=True)
    remove_overlays(out_dir)
    for single, photo in zip(result.photos, photos, strict=True):  # as write_sfo's
        _workbench(out_dir / joint_workbench_name(photo.id), skull, photo, single)
        if overlay:
            path = out_dir / joint_overlay_name(photo.id)
            write_png(path, result_overlay(single, skull, photo))
            written[photo.id] = path
    write_json(written["result.json"], result.to_dict())
    return written


#: ``result.json`` key of the SFO's input fingerprint (:func:`sfo_fingerprint`).
FINGERPRINT_KEY = "inputs_sha256"


def _plain(value):
    """``value`` as JSON can hold it, for :func:`sfo_fingerprint` (dataclasses as dicts)."""
    if is_dataclass(value) and not isinstance(value, type):
        return asdict(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return repr(value)


def sfo_fingerprint(method, options, seed, skull, skull_inputs, photos, photo_inputs, cache=None):
    """The input fingerprint of one SFO: SHA-256 over the bytes of its input files and every
    setting that changes its result.

    A stored result is reused on resume only under the same fingerprint
    (:func:`stored_result`): another file content, option, seed, prior or Lilium version
    runs the SFO again. The files are hashed by content under their labels, not by path, so a
    case folder may move.

    Parameters
    ----------
    method : str
    options : SfoOptions
        Whole (variant, DE budget: population, generations, max_seconds; depth table, ...).
    seed : int
    skull : Skull
        Its id.
    skull_inputs : dict of str -> path
        The skull's labelled files (:func:`~lilium.casework.inputs.load_skull`: mesh,
        cranial landmarks, soft-tissue axes).
    photos : sequence of Photo
        Their ids, views and priors (the command line's ``--focal-px``/``--scd-mm`` and the
        EXIF's land there).
    photo_inputs : sequence of dict of str -> path
        Each photo's labelled files (:func:`~lilium.casework.inputs.load_photos`: image,
        ``photo.json``, landmark file, mask, face curve), in the order of ``photos``.
    cache : dict, optional
        File digests by resolved path, filled in (:func:`~lilium.io.provenance.input_files`).

    Returns
    -------
    str
        64 hex digits.
    """
    cache = {} if cache is None else cache
    files = [input_files(skull_inputs, cache)] + [input_files(i, cache) for i in photo_inputs]
    settings = {
        "lilium": __version__,
        "method": method,
        "seed": seed,
        "options": options,
        "skull": skull.id,
        "photos": [{"id": p.id, "view": p.view, "priors": p.priors} for p in photos],
        "files": [[(f.label, f.sha256) for f in group] for group in files],
    }
    text = json.dumps(settings, sort_keys=True, default=_plain)
    return hashlib.sha256(text.encode()).hexdigest()


def with_fingerprint(result, fingerprint):
    """``result`` with its input fingerprint in ``extra`` (so in ``result.json``)."""
    return replace(result, extra={**result.extra, FINGERPRINT_KEY: fingerprint})


def stored_result(folder, fingerprint, overlays=("overlay.png",), read=read_result):
    """The SFO stored in ``folder`` when it is this one and complete, else why not.

    Parameters
    ----------
    folder : Path
        The SFO's output folder (``result.json`` and its overlays).
    fingerprint : str
        This SFO's :func:`sfo_fingerprint`.
    overlays : sequence of str
        The overlay PNGs that must be there, whole, beside ``result.json``.
    read : callable
        ``read(path) -> result`` (:func:`~lilium.io.results.read_result`, or the joint one).

    Returns
    -------
    result : SfoResult, JointSfoResult or None
        None when the SFO must run (again).
    why : str
        Why it runs again ("" when there is nothing stored, or the result is reused).
    """
    path = Path(folder) / "result.json"
    if not path.is_file():
        return None, ""
    try:
        result = read(path)
    except ValueError:
        return None, f"{path} is unreadable"
    stored = result.extra.get(FINGERPRINT_KEY)
    if stored is None:
        return None, f"{path} has no {FINGERPRINT_KEY} (written by an older Lilium)"
    if stored != fingerprint:
        return None, f"{path} is of other inputs or options"
    for name in overlays:
        if not png_readable(Path(folder) / name):
            return None, f"{Path(folder) / name} is missing or incomplete"
    if "identification" not in result.extra:
        return None, f"{path} has no identification"
    return result, ""


def resumed_sfo(
    folder, method, skull, photo, options, seed, fingerprint, calibrations, log, run=None
):
    """One SFO of ``photo`` in ``folder``: the one stored there when it is this SFO
    (:func:`stored_result`), else run and written (``result.json`` with ``fingerprint``,
    ``overlay.png``); either way identified with this run's ``calibrations``.

    ``log`` gets one line saying why when a stored result is not reused (other inputs or
    options, an overlay missing or cut) and the SFO runs again; the caller says what it reused.
    ``run`` is the SFO runner (default :func:`~lilium.methods.registry.run_sfo`; the caller's
    own name of it, so a test can replace it there).

    Returns
    -------
    result : SfoResult
    reused : bool
    """
    tag = method_tag(method, options.variant)
    result, why = stored_result(folder, fingerprint)
    if result is not None:
        result = with_identification(result, skull, [photo], calibrations)
        write_json(Path(folder) / "result.json", result.to_dict())  # this run's calibration
        if not (Path(folder) / WORKBENCH).is_file():  # stored by an older Lilium
            _workbench(Path(folder) / WORKBENCH, skull, photo, result)
        return result, True
    if why:
        log(f"{printable(photo.id)}: {tag}: running the SFO again: {why}")
    result = (run or run_sfo)(method, skull, photo, options, seed)
    result = with_identification(result, skull, [photo], calibrations)
    result = with_fingerprint(result, fingerprint)
    write_sfo(folder, result, skull, photo)
    return result, False


def sfo_outputs(folder, out):
    """The report's links to one SFO's files in ``folder``: ``result.json`` and, when they
    were written, ``overlay.png`` and ``workbench.html``, as POSIX paths relative to the output
    folder ``out``."""
    rel = Path(folder).relative_to(out).as_posix()
    outputs = {"result.json": f"{rel}/result.json"}
    for name in ("overlay.png", WORKBENCH):
        if (Path(folder) / name).is_file():
            outputs[name] = f"{rel}/{name}"
    return outputs


@contextmanager
def output_lock(out):
    """Hold the output folder ``out`` for one run (``lilium case`` or ``lilium lineup``).

    The lock is :class:`~lilium.io.locks.RunLock`'s (``out/.lilium-run.lock``, held by the
    kernel, so a killed run leaves no stale lock). ``out`` is made when missing, and removed
    again at the end when the run left it empty (a refused run).

    Raises
    ------
    ValueError
        Another run holds ``out`` (naming it and its owner), or ``out`` cannot hold the lock.
    """
    out = Path(out)
    made = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    try:
        with RunLock(out, "lilium run", "--out"):
            yield out
    finally:
        if made and not any(out.iterdir()):
            out.rmdir()
