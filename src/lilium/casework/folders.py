"""One SFO on case folders (SPEC section 8): read, run, write ``result.json`` and the overlay."""

from ..io.case import read_depth_table, read_photo, read_skull
from ..io.results import write_result
from ..methods.options import SfoOptions
from ..methods.overlay import result_overlay
from ..methods.registry import check_method, run_sfo


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
    """Read a subject and a photo folder, run the method, write ``out_dir``.

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
    """
    check_method(method, options.variant)
    skull = read_skull(skull_dir, axes_path=axes)
    photo = read_photo(photo_dir, load_image=overlay)
    if depth_table is not None:
        from dataclasses import replace

        options = replace(options, depth_table=read_depth_table(depth_table))
    result = run_sfo(method, skull, photo, options, seed)
    write_result(out_dir, result, result_overlay(result, skull, photo) if overlay else None)
    return result
