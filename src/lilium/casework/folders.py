"""One SFO on case folders (SPEC section 8): read, check, run, write ``result.json``."""

from dataclasses import replace
from pathlib import Path

from ..io.case import read_depth_table, read_photo, read_skull
from ..io.results import write_result
from ..methods.checks import check_inputs
from ..methods.options import SfoOptions
from ..methods.overlay import result_overlay
from ..methods.registry import check_method, run_sfo
from .inputs import load_photos, load_skull


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

    Returns
    -------
    SfoResult
        With its ``warnings`` (print them).

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
    result = run_sfo(method, skull, photo, options, seed)
    write_result(out_dir, result, result_overlay(result, skull, photo) if overlay else None)
    return result
