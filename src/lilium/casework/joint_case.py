"""The ``--joint`` path of a user's case (``lilium case --joint``, docs/method/joint.md).

Each method that has a joint form (Lilium) runs once for all the photos of the person: one soft
tissue shared by the photos, one camera each. Its outputs go to ``<out>/joint/<method tag>/``:
``result.json`` (``"joint": true``, a ``photos`` list) and ``overlay_<photo id>.png`` per photo.
Methods without a joint form (POSEST-SFO) run per photo as without ``--joint``.
"""

from pathlib import Path

from ..io.jsonio import write_json
from ..io.results import read_joint_result
from ..methods.pairs import correspondences
from ..methods.registry import METHODS, method_tag, run_joint_sfo
from .console import log_warnings, status_text
from .folders import (
    joint_overlay_name,
    joint_workbench_name,
    sfo_fingerprint,
    stored_result,
    with_fingerprint,
    write_joint_result,
)
from .identify import conclusion_line, with_identification
from .inputs import JOINT_FOLDER


def run_joint_methods(inputs, methods, seed, out, log=print):
    """Run every joint-capable method of ``methods`` once on all the photos; write each.

    A joint SFO already stored in its folder for the same input files, options, seed and
    priors (:func:`~lilium.casework.folders.stored_result`), with every overlay whole, is read
    back instead (its log line says ``(stored)``) and identified with ``calibrations``.

    Parameters
    ----------
    inputs : CaseInputs
        The case's skull, photo records, options (with its depth table) and calibrations
        (:func:`~lilium.casework.read.read_case`).
    methods : sequence of str
    seed : int
    out : Path
        The case's output folder.
    log : callable

    Returns
    -------
    dict of str -> (JointSfoResult, Path)
        Per joint method, its result and its output folder.

    A photo's id is never :data:`~lilium.casework.inputs.JOINT_FOLDER`
    (:func:`~lilium.casework.inputs.unique_id`).
    """
    skull, skull_inputs, records = inputs.skull, inputs.skull_inputs, inputs.records
    options, calibrations, photos = inputs.options, inputs.calibrations, inputs.photos
    done = {}
    for method in methods:
        if METHODS[method].run_joint is None:
            continue
        folder = Path(out) / JOINT_FOLDER / method_tag(method, options.variant)
        fingerprint = sfo_fingerprint(
            method, options, seed, skull, skull_inputs, photos, [r.inputs for r in records]
        )
        sfo = (method, skull, photos, options, seed)
        result, reused = _resumed_joint(folder, sfo, fingerprint, calibrations, log)
        name = f"{result.method}{f' {result.variant}' if result.variant else ''}"
        log(
            f"joint ({', '.join(p.id for p in photos)}): {name}: score {result.fitness:.4g}, "
            f"{result.seconds:.2f} s{' (stored)' if reused else ''} -> {folder}"
        )
        for single in result.photos:
            log(f"  {single.photo_id}: {status_text(single)}")
            log_warnings(single, log)
        log(f"  {conclusion_line(result.extra['identification'])}")
        done[method] = (result, folder)
    return done


def _resumed_joint(folder, sfo, fingerprint, calibrations, log):
    """The joint SFO ``sfo = (method, skull, photos, options, seed)`` stored in ``folder``
    when it is this one, else run and written (``result.json`` with ``fingerprint``, the
    overlays); either way identified with ``calibrations``.

    Returns
    -------
    result : JointSfoResult
    reused : bool
    """
    method, skull, photos, options, seed = sfo
    names = [correspondences(skull, photo).facial_names for photo in photos]
    overlays = [joint_overlay_name(photo.id) for photo in photos]
    result, why = stored_result(
        folder, fingerprint, overlays, lambda path: read_joint_result(path, names)
    )
    if result is not None:
        result = with_identification(result, skull, photos, calibrations)
        write_json(folder / "result.json", result.to_dict())  # this run's calibration
        return result, True
    if why:
        log(f"joint: {method_tag(method, options.variant)}: running the SFO again: {why}")
    result = run_joint_sfo(method, skull, photos, options, seed)
    result = with_identification(result, skull, photos, calibrations)
    result = with_fingerprint(result, fingerprint)
    write_joint_result(folder, result, skull, photos)
    return result, False


def joint_entry(joint_run, k, skull, photo, inputs, notes, out):
    """The report entry of photo ``k`` of a joint SFO ``joint_run = (result, folder)``."""
    from ..report.html import ReportEntry

    result, folder = joint_run
    rel = folder.relative_to(out).as_posix()
    outputs = {"result.json (joint)": f"{rel}/result.json"}
    if (folder / joint_overlay_name(photo.id)).is_file():
        outputs["overlay.png"] = f"{rel}/{joint_overlay_name(photo.id)}"
    if (folder / joint_workbench_name(photo.id)).is_file():
        outputs["workbench.html"] = f"{rel}/{joint_workbench_name(photo.id)}"
    return ReportEntry(skull, photo, result.photos[k], inputs, notes, outputs, joint=result)
