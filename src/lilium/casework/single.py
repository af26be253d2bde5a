"""One SFO of a request, without a report (``lilium sfo``): read, check, run, write
``result.json``, the overlays and the workbench pages; one photo (:func:`single_sfo`) or a
joint SFO of two or more photos of one person (:func:`joint_sfo`).
"""

from ..methods.registry import check_joint_method, run_joint_sfo, run_sfo
from .folders import write_joint_result, write_sfo
from .identify import with_identification
from .read import read_case


def single_sfo(request, log=None):
    """One SFO: read the skull and the photo, check them, run the method, write ``request.out``.

    The photo's priors come from the request, ``photo.json``, or its focal prior from the
    image's EXIF (:func:`~lilium.casework.inputs.with_priors`), those of a ``lilium photo``
    folder with ``"source": "automatic"`` and its head orientation converted through the skull's
    frame (:func:`~lilium.casework.prepared.with_automatic_priors`); the left/right checks run
    before the SFO (:func:`~lilium.methods.checks.check_inputs`).

    Parameters
    ----------
    request : CaseRequest
        One photo and one method (``request.methods[0]``); its axes, priors, depth table
        (replaces ``options.depth_table``), calibration (default: the shipped one,
        :mod:`lilium.casework.identify`) and ``overlay`` (write ``overlay.png`` too). A photo
        with a ``camera`` file has that camera scored instead of searched
        (:func:`~lilium.methods.registry.run_sfo`; ``"camera_source": "examiner"``).
    log : callable, optional
        Receives one line per sidecar file found beside a mesh or an image.

    Returns
    -------
    SfoResult
        With its ``warnings`` (print them) and ``extra["identification"]``.

    Raises
    ------
    ValueError
        An invalid input (naming the file), including mirrored skull or photo labels.
    """
    (method,) = request.methods
    inputs = read_case(request, log=log)
    skull, (record,) = inputs.skull, inputs.records
    photo = record.photo
    result = run_sfo(method, skull, photo, inputs.options, request.seed, record.camera)
    result = with_identification(result, skull, [photo], inputs.calibrations)
    write_sfo(request.out, result, skull, photo, overlay=request.overlay)
    return result


def joint_sfo(request, log=None):
    """One joint SFO of the request's two or more photos of the same person (one soft tissue
    shared by the photos, one camera each): read, check, run, write ``request.out``.

    As :func:`single_sfo`; writes ``result.json`` with ``"joint": true`` and
    ``overlay_<photo id>.png`` per photo (:func:`write_joint_result`).

    Returns
    -------
    JointSfoResult

    Raises
    ------
    ValueError
        An invalid input (naming the file), a method without a joint form, fewer than two
        photos, or a photo given twice.
    """
    (method,) = request.methods
    check_joint_method(method, request.options.variant)
    if len(request.photos) < 2:
        raise ValueError("a joint SFO needs two or more --photo folders")
    if any(source.camera is not None for source in request.photos):
        raise ValueError(
            "--camera scores one photo's camera: give one --photo with it (lilium sfo), or "
            "use lilium case, which scores each photo's --camera beside its SFO"
        )
    inputs = read_case(request, log=log)
    skull, photos = inputs.skull, inputs.photos
    result = run_joint_sfo(method, skull, photos, inputs.options, request.seed)
    result = with_identification(result, skull, photos, inputs.calibrations)
    write_joint_result(request.out, result, skull, photos, overlay=request.overlay)
    return result
