"""The photo folder ``lilium photo`` writes, and owns (issue 28, docs/contract.md and
docs/method/photo.md).

Rules (docs/method/photo.md):

- ``lilium photo`` writes only :data:`OWN_FILES` and marks its ``photo.json`` with
  ``"prepared_by": "lilium photo"`` (a folder of an older version is recognised by its automatic
  ``landmark_sources`` and ``priors``).
- Rerun into its own folder, it first removes its previous files (so ``image.png`` of an earlier
  photo never stays beside this photo's ``image.jpg``: the SFO would read the old picture with
  the new landmarks); files of other names (the review page's ``landmarks.json``, notes) stay.
- A folder holding any of those names that ``lilium photo`` did not write (a hand-made photo
  folder) is refused: nothing of the user's is replaced.
- The image may be the folder's own (``lilium photo D/image.jpg --out D``, the user's or an
  earlier run's): it is read first and kept in place. Any other file this command writes there
  (``D/face_mask.png``, or ``D/image.png`` when the folder's image will be ``image.jpg`` or the
  turned copy) is refused as the photo: writing the folder would replace it.
"""

from pathlib import Path

from ..io.paths import same_file
from ..io.prepared import PREPARED_BY, written_by_lilium_photo

__all__ = [
    "IMAGE_FILES",
    "OWN_FILES",
    "PREPARED_BY",
    "check_image_path",
    "check_photo_not_output",
    "claim_folder",
]

#: The files ``lilium photo`` writes in its folder.
IMAGE_FILES = ("image.png", "image.jpg", "image.jpeg")
OWN_FILES = (*IMAGE_FILES, "photo.json", "face_mask.png", "face_curve.json", "review.html")


def claim_folder(out, image_path):
    """Check that ``lilium photo`` may write ``out``; return its previous files to remove.

    Parameters
    ----------
    out : Path
        ``--out``.
    image_path : Path
        The photograph (never removed, even when it is the folder's own image).

    Returns
    -------
    list of Path
        This command's files from an earlier run, to remove before writing.

    Raises
    ------
    ValueError
        ``out`` is a file, or it holds files of :data:`OWN_FILES` that ``lilium photo`` did not
        write; the message names them and the fix.
    """
    from ..io.jsonio import read_json

    if out.exists() and not out.is_dir():
        raise ValueError(f"{out}: exists and is not a folder; give a folder for --out")
    present = [out / name for name in OWN_FILES if (out / name).exists()]
    present = [p for p in present if not same_file(p, image_path)]  # the photo: read, kept
    if not present:
        return []
    meta_path = out / "photo.json"
    ours = False
    if meta_path.is_file():
        try:
            ours = written_by_lilium_photo(read_json(meta_path))
        except ValueError:
            ours = False
    if not ours:
        names = ", ".join(p.name for p in present)
        raise ValueError(
            f"{out}: holds {names}, not written by lilium photo; give a new or empty folder with "
            "--out (lilium photo replaces only its own files)"
        )
    return present


def check_photo_not_output(out, image_path, kept_name=None):
    """Refuse a photograph that is one of the files ``lilium photo`` writes in ``out``.

    Parameters
    ----------
    out : Path
        ``--out``.
    image_path : Path
        The photograph.
    kept_name : str, optional
        The folder's image when it is the photo copied unchanged (``image.png``, ``image.jpg``
        or ``image.jpeg``): the photo may be that file, kept in place. None when the folder's
        image is a converted or turned copy.

    Raises
    ------
    ValueError
        The photo is (the same file as) one of :data:`OWN_FILES` in ``out`` other than
        ``kept_name``: the message names the photo and the fix.
    """
    for name in OWN_FILES:
        if name != kept_name and same_file(out / name, image_path):
            raise ValueError(
                f"{image_path}: the photo is {out / name}, a file lilium photo writes in --out "
                f"{out}, so preparing it would replace it; give another --out or rename the photo"
            )


def check_image_path(image_path):
    """The photograph's path, checked: a file (not a folder) that exists."""
    image_path = Path(image_path)
    if image_path.is_dir():
        raise ValueError(
            f"{image_path}: is a folder, not an image; give the photograph's file (PNG or JPEG)"
        )
    if not image_path.is_file():
        raise ValueError(f"{image_path}: file not found; check the photo's path")
    return image_path
