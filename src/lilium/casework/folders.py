"""One SFO on case folders (SPEC section 8): read, check, run, write ``result.json``."""

import filecmp
from dataclasses import replace
from pathlib import Path

from ..io.case import IMAGE_NAMES, read_depth_table, read_photo, read_skull
from ..io.jsonio import write_json
from ..io.paths import safe_id
from ..io.results import write_png, write_result
from ..methods.checks import check_inputs
from ..methods.options import SfoOptions
from ..methods.overlay import result_overlay
from ..methods.registry import check_joint_method, check_method, run_joint_sfo, run_sfo
from .identify import Calibrations, with_identification
from .inputs import first_file, load_photos, load_skull


def labelled_skull(skull, inputs):
    """The skull with its cranial landmark file named (for the left/right messages)."""
    path = inputs.get("cranial landmarks")
    return skull if path is None else replace(skull, landmarks_file=str(path))


def sfo_on_folders(
    skull_dir,
    photo_dir,
    out_dir,
    method="posest-sfo",
    options=SfoOptions(),
    seed=0,
    axes=None,
    depth_table=None,
    overlay=True,
    calibration=None,
):
    """Read a subject and a photo folder, check them, run the method, write ``out_dir``.

    The photo's priors come from ``photo.json``, or its focal prior from the image's EXIF
    (:func:`~lilium.casework.inputs.with_priors`), those of a ``lilium photo`` folder with
    ``"source": "automatic"`` and its head orientation converted through the skull's frame
    (:func:`~lilium.casework.prepared.with_automatic_priors`); the left/right checks of SPEC
    section 10 run before the SFO (:func:`~lilium.methods.checks.check_inputs`).

    Parameters
    ----------
    skull_dir, photo_dir, out_dir : path
    method : str
        A key of :data:`lilium.methods.METHODS`.
    options : SfoOptions
    seed : int
    axes : path, optional
        Soft-tissue axes file to use instead of the subject's own.
    depth_table : path, optional
        CSV depth table (replaces ``options.depth_table``).
    overlay : bool
        Write ``overlay.png`` too.
    calibration : path, optional
        Identification calibration file (default: the shipped one;
        :mod:`lilium.casework.identify`).

    Returns
    -------
    SfoResult
        With its ``warnings`` (print them) and ``extra["identification"]``.

    Raises
    ------
    ValueError
        An invalid input (naming the file), including mirrored skull or photo labels.
    """
    check_method(method, options.variant)
    for folder, read in ((skull_dir, read_skull), (photo_dir, read_photo)):
        if not Path(folder).is_dir():
            read(folder)  # raises its "not a folder" message
    skull, skull_inputs = load_skull(skull_dir, axes=axes)
    skull = labelled_skull(skull, skull_inputs)
    # A lilium photo folder's automatic head orientation is paired with this skull's frame.
    (record,) = load_photos([photo_dir], skull=skull)
    photo = record.photo
    check_inputs(skull, photo)
    if depth_table is not None:
        options = replace(options, depth_table=read_depth_table(depth_table))
    calibrations = Calibrations(calibration)
    result = run_sfo(method, skull, photo, options, seed)
    result = with_identification(result, skull, [photo], calibrations)
    write_result(out_dir, result, result_overlay(result, skull, photo) if overlay else None)
    return result


def joint_overlay_name(photo_id):
    """File name of a photo's overlay in a joint SFO's folder: ``overlay_<photo id>.png``."""
    return f"overlay_{safe_id(photo_id)}.png"


def write_joint_result(out_dir, result, skull, photos, overlay=True):
    """Write a joint SFO's ``result.json`` (SPEC section 9) and ``overlay_<photo id>.png`` per
    photo (the photo's plain image when its camera failed).

    Without overlays, an ``overlay_<photo id>.png`` of these photos left in ``out_dir`` by an
    earlier run is removed (it would show another camera than the ``result.json`` beside it).

    Returns
    -------
    dict of str -> Path
        ``result.json`` and each photo id's overlay path (when written).
    """
    out_dir = Path(out_dir)
    written = {"result.json": out_dir / "result.json"}
    write_json(written["result.json"], result.to_dict())
    for single, photo in zip(result.photos, photos, strict=True):
        path = out_dir / joint_overlay_name(photo.id)
        if overlay:
            write_png(path, result_overlay(single, skull, photo))
            written[photo.id] = path
        elif path.is_file() or path.is_symlink():
            path.unlink()
    return written


def _image_of(path):
    """The image file of a photo folder or an image path; None when there is none (yet)."""
    path = Path(path)
    if path.is_dir():
        return first_file(path, IMAGE_NAMES)
    return path if path.is_file() else None


def repeated_photo(paths):
    """The first photo of ``paths`` that repeats an earlier one: the same path, or the same
    image byte for byte (a copied photo folder, the image under another name).

    Returns
    -------
    (int, int, str) or None
        The later index, the earlier one and how they are the same (``"the same photo as"``
        or ``"the same image (byte for byte) as"``); None when every photo differs.
    """
    seen, by_size = {}, {}
    for k, path in enumerate(paths):
        key = Path(path).resolve()
        if key in seen:
            return k, seen[key], "the same photo as"
        seen[key] = k
        image = _image_of(path)
        if image is None:
            continue
        size = image.stat().st_size
        for j in by_size.get(size, []):
            if filecmp.cmp(image, _image_of(paths[j]), shallow=False):
                return k, j, "the same image (byte for byte) as"
        by_size.setdefault(size, []).append(k)
    return None


def check_distinct_photos(paths):
    """Refuse a photo given twice to a case or a joint SFO, by path or as a copy of its image
    (a joint SFO would count its landmarks twice, and the identification of several photos
    would count it as a second view and lift the single-photo cap).

    Raises
    ------
    ValueError
        Naming the repeated path.
    """
    repeat = repeated_photo(paths)
    if repeat is not None:
        k, j, how = repeat
        raise ValueError(
            f"--photo {paths[k]}: {how} --photo {paths[j]}; give each photo of the person once "
            "(a repeated photo is no second view)"
        )


def joint_sfo_on_folders(
    skull_dir,
    photo_dirs,
    out_dir,
    method="lilium",
    options=SfoOptions(),
    seed=0,
    axes=None,
    depth_table=None,
    overlay=True,
    calibration=None,
):
    """One joint SFO (SPEC section 9) of a subject folder and two or more photo folders of the
    same person: read, check, run, write ``out_dir``.

    As :func:`sfo_on_folders`, with ``photo_dirs`` a list; writes ``result.json`` with
    ``"joint": true`` and ``overlay_<photo id>.png`` per photo (:func:`write_joint_result`).

    Returns
    -------
    JointSfoResult

    Raises
    ------
    ValueError
        An invalid input (naming the file), a method without a joint form, fewer than two
        photos, or a photo given twice.
    """
    check_joint_method(method, options.variant)
    photo_dirs = [Path(d) for d in photo_dirs]
    if len(photo_dirs) < 2:
        raise ValueError("a joint SFO needs two or more --photo folders")
    check_distinct_photos(photo_dirs)
    for folder, read in ((skull_dir, read_skull), *((d, read_photo) for d in photo_dirs)):
        if not Path(folder).is_dir():
            read(folder)  # raises its "not a folder" message
    skull, skull_inputs = load_skull(skull_dir, axes=axes)
    skull = labelled_skull(skull, skull_inputs)
    photos = [record.photo for record in load_photos(photo_dirs, skull=skull)]
    for photo in photos:
        check_inputs(skull, photo)
    if depth_table is not None:
        options = replace(options, depth_table=read_depth_table(depth_table))
    calibrations = Calibrations(calibration)
    result = run_joint_sfo(method, skull, photos, options, seed)
    result = with_identification(result, skull, photos, calibrations)
    write_joint_result(out_dir, result, skull, photos, overlay=overlay)
    return result
