"""Case folders of docs/contract.md: subject (skull) folders and photo folders.

Every problem found is a ``ValueError`` whose message names the file, the field and the fix.
"""

import csv
from pathlib import Path

import numpy as np

from ..constants import (
    MIN_LANDMARK_EXTENT_FRACTION,
    MIN_LANDMARK_EXTENT_PX,
    MIN_LANDMARK_SPREAD_RATIO,
    MIN_PHOTO_SIDE_PX,
    VIEWS,
)
from ..inputs import Photo, Priors
from ..softtissue.depths import DepthStats, check_depth_table
from ..validation import check_prior, is_real
from .curves import read_face_curve
from .formats import find_landmark_file, points_from_object, read_landmarks
from .images import image_size_wh, read_image, read_mask
from .jsonio import read_json
from .keys import json_type, unknown_key_warnings
from .mesh import MESH_SUFFIXES
from .paths import path_id, safe_id
from .prepared import (
    _without_unconfirmed_templates,
    face_only_mask,
    landmark_qualities,
    written_by_lilium_photo,
)

__all__ = [
    "IMAGE_NAMES",
    "check_axes_file",
    "check_folder",
    "check_in_image",
    "check_landmark_layout",
    "parse_priors",
    "photo_from_files",
    "read_depth_table",
    "read_face_curve",
    "read_image",
    "read_mask",
    "read_photo",
    "parse_axes",
    "parse_cranial_landmarks",
]

IMAGE_NAMES = ("image.png", "image.jpg", "image.jpeg")


def _find(folder, stems_or_names, what, fix):
    for name in stems_or_names:
        if (folder / name).is_file():
            return folder / name
    raise ValueError(f"{folder}: no {what} ({' or '.join(stems_or_names)}); {fix}")


def check_folder(folder, kind):
    """``folder`` as a Path; a ``ValueError`` when it is not a folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder}: {kind} folder not found")
    return folder


def _field(path, data, key):
    if not isinstance(data, dict) or key not in data:
        raise ValueError(f"{path}: missing field {key!r}")
    return data[key]


def subject_files(folder):
    """The skull mesh and the cranial landmark file of a subject folder.

    The landmarks are ``cranial_landmarks.json`` or, failing that, a Slicer / MeshLab / CSV file
    (``cranial_landmarks.csv``, ``skull.mrk.json``, ...); when neither is there, the path of the
    missing ``cranial_landmarks.json`` (reading it then names it).

    Returns
    -------
    mesh_path, landmarks_path : Path

    Raises
    ------
    ValueError
        No ``skull.ply`` / ``.obj`` / ``.stl`` in the folder.
    """
    folder = Path(folder)
    mesh_path = _find(
        folder,
        [f"skull{s}" for s in MESH_SUFFIXES],
        "skull mesh",
        "put the skull mesh (millimetres) there",
    )
    lm_path = folder / "cranial_landmarks.json"
    if not lm_path.is_file():
        lm_path = find_landmark_file(folder, ["cranial_landmarks", "skull"]) or lm_path
    return mesh_path, lm_path


def check_axes_file(axes_path, option="soft-tissue axes file"):
    """Raise a ``ValueError`` naming ``axes_path`` when an explicitly given axes file is not a file.

    The subject folder's own ``soft_tissue_axes.json`` is optional; a file the user names
    (``--axes``, an experiment's axis set) is not: ignoring it would silently run the SFO with
    other directions.
    """
    if not Path(axes_path).is_file():
        raise ValueError(
            f"{axes_path}: {option} not found; check the path (or leave it out to use the "
            "subject's soft_tissue_axes.json, or the skull-surface normals)"
        )


def parse_cranial_landmarks(landmarks_path):
    """The cranial landmarks of a ``cranial_landmarks.json`` or of any file
    :func:`lilium.io.formats.read_landmarks` reads, as parsed: dict of str -> ndarray (3,), mm."""
    lm_path = Path(landmarks_path)
    if lm_path.name == "cranial_landmarks.json" or not lm_path.is_file():
        raw = _field(lm_path, read_json(lm_path), "landmarks")
        return points_from_object(lm_path, "landmarks", raw, "cranial")
    return read_landmarks(lm_path, "cranial")


def parse_axes(axes_path):
    """The soft-tissue axes of ``soft_tissue_axes.json`` as given (not normalised): dict of
    str -> ndarray (3,); empty when ``axes_path`` is None or not a file."""
    axes_path = Path(axes_path) if axes_path else None
    if axes_path is None or not axes_path.is_file():
        return {}
    raw = _field(axes_path, read_json(axes_path), "axes")
    return points_from_object(axes_path, "axes", raw, "cranial", allow_empty=True)


def _interval(path, priors, key):
    value = priors.get(key)
    return None if value is None else check_prior(value, key, f"{path}: priors.{key}")


def parse_priors(path, priors):
    """Validate the ``priors`` object of ``photo.json``."""
    from ..geometry.rotations import check_rotation

    if priors is None:
        return Priors()
    if not isinstance(priors, dict):
        raise ValueError(f"{path}: priors must be an object")
    rotation = priors.get("head_rotation_skull2cam")
    if rotation is not None:
        try:
            rotation = check_rotation(rotation, name="priors.head_rotation_skull2cam")
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
    tolerance = priors.get("head_tolerance_deg")
    if tolerance is not None:
        if not (is_real(tolerance) and 0 < tolerance <= 180):
            raise ValueError(f"{path}: priors.head_tolerance_deg must be in (0, 180] degrees")
        tolerance = float(tolerance)
    if (rotation is None) != (tolerance is None):
        raise ValueError(
            f"{path}: priors.head_rotation_skull2cam and priors.head_tolerance_deg go together; "
            "give both or neither"
        )
    return Priors(
        _interval(path, priors, "focal_px"), _interval(path, priors, "scd_mm"), rotation, tolerance
    )


def _photo_pixels(image_path, load_image):
    """The photo's pixels (or None) and its ``(width, height)``, checking the smallest size."""
    image = read_image(image_path) if load_image else None
    size_wh = (image.shape[1], image.shape[0]) if load_image else image_size_wh(image_path)
    if min(size_wh) < MIN_PHOTO_SIDE_PX:
        raise ValueError(
            f"{image_path}: the photo is {size_wh[0]}x{size_wh[1]} px, too small to superimpose "
            f"a skull on (at least {MIN_PHOTO_SIDE_PX} px a side); use the original photograph"
        )
    return image, size_wh


def read_photo(folder, load_image=True):
    """Read a photo folder (``image.png``/``.jpg``, ``photo.json``, optional mask and curve).

    Parameters
    ----------
    folder : str or Path
    load_image : bool
        Keep the pixels (for overlays); without them only the image's header is read (its size).

    Returns
    -------
    Photo
        Its id is the folder's name (:func:`lilium.io.paths.path_id`).

    Raises
    ------
    ValueError
        Every problem of docs/checks.md, naming the file, the field and the fix.
    """
    folder = check_folder(folder, "photo")
    image_path = _find(folder, IMAGE_NAMES, "photo image", "put the photograph there")
    images = [name for name in IMAGE_NAMES if (folder / name).is_file()]
    if len(images) > 1:  # which one the landmarks belong to is unknown
        raise ValueError(
            f"{folder}: holds {' and '.join(images)}; keep only the photograph its landmarks, "
            "mask and curve were made on"
        )
    image, size_wh = _photo_pixels(image_path, load_image)
    meta_path = folder / "photo.json"
    meta = read_json(meta_path)
    if not isinstance(meta, dict):
        raise ValueError(
            f'{meta_path}: must be a JSON object {{"view": ..., "landmarks": {{...}}}}, '
            f"got a JSON {json_type(meta)}; see docs/contract.md for the photo folder"
        )
    view = _field(meta_path, meta, "view")
    if view not in VIEWS:
        raise ValueError(f"{meta_path}: view must be one of {', '.join(VIEWS)}, got {view!r}")
    lm_path = meta_path
    if isinstance(meta, dict) and "landmarks" not in meta:
        # Facial landmarks in a file of their own (facial_landmarks.csv, landmarks.json, ...).
        lm_path = find_landmark_file(folder, ["facial_landmarks", "landmarks"]) or meta_path
    if lm_path == meta_path:
        raw = _field(meta_path, meta, "landmarks")
        landmarks = points_from_object(meta_path, "landmarks", raw, "facial")
        landmarks = _without_unconfirmed_templates(landmarks, meta.get("landmark_sources"))
        sources = landmark_qualities(meta.get("landmark_sources"), landmarks)
    else:
        landmarks = read_landmarks(lm_path, "facial")
        sources = {}
    check_in_image(lm_path, landmarks, size_wh, image_path.name)
    check_landmark_layout(lm_path, landmarks, _min_extent_px(size_wh), "px")
    priors = parse_priors(meta_path, meta.get("priors"))
    mask_path = folder / "face_mask.png"
    mask = read_mask(mask_path, size_wh) if mask_path.is_file() else None
    warnings = unknown_key_warnings(meta_path, meta)
    if mask is not None and meta.get("face_mask_is_head") is False:  # docs/method/photo.md
        mask, warning = face_only_mask(mask, landmarks, folder)
        warnings = (*warnings, warning)
    curve_path = folder / "face_curve.json"
    curve = read_face_curve(curve_path, view, size_wh) if curve_path.is_file() else None
    if curve is None and mask is not None and written_by_lilium_photo(meta):
        # A head mask ends at the neck (often the collar): never a facial curve
        # (docs/method/photo.md).
        curve = np.empty((0, 2))
    return Photo(
        path_id(folder),
        size_wh,
        view,
        landmarks,
        mask,
        curve,
        priors,
        image,
        landmark_sources=sources,
        warnings=tuple(warnings),
        mask_file=str(mask_path) if mask is not None else None,
    )


def _min_extent_px(image_size_wh):
    return max(MIN_LANDMARK_EXTENT_PX, MIN_LANDMARK_EXTENT_FRACTION * max(image_size_wh))


def check_landmark_layout(path, landmarks, min_extent, unit):
    """Raise a ``ValueError`` naming ``path`` when landmarks are tiny, coincident or collinear.

    A camera (from 2D landmarks) or a pose (from 3D ones) needs landmarks spread in two
    directions: all of them at one place, or on one line, fit a camera at any distance with an
    excellent score. Checked only with at least :data:`~lilium.constants.MIN_CORRESPONDENCES`
    landmarks (fewer are reported as too few to pair).

    Parameters
    ----------
    path : path
        The landmark file, for the message.
    landmarks : dict of str -> ndarray of shape (2,) or (3,)
    min_extent : float
        Smallest allowed longest distance between two landmarks (the photo's: 1 % of its longer
        side, at least 16 px; the skull's: 5 % of the mesh's extent).
    unit : str
        ``"px"`` or ``"mm"``.
    """
    from ..constants import MIN_CORRESPONDENCES

    if len(landmarks) < MIN_CORRESPONDENCES:
        return
    points = np.array(list(landmarks.values()), dtype=float)
    extent = float(np.max(np.linalg.norm(points[:, None] - points[None], axis=-1)))
    if extent < min_extent:
        raise ValueError(
            f"{path}: the {len(points)} landmarks lie within {extent:.3g} {unit} of each other "
            f"(at least {min_extent:.3g} {unit} is needed); they are all at one place: check "
            "their coordinates and units"
        )
    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if spread[1] < MIN_LANDMARK_SPREAD_RATIO * spread[0]:
        raise ValueError(
            f"{path}: the {len(points)} landmarks lie on one line (spread across it "
            f"{spread[1] / spread[0]:.1%} of that along it, at least "
            f"{MIN_LANDMARK_SPREAD_RATIO:.0%} is needed), which fixes no camera; add landmarks "
            "off that line or check their coordinates"
        )


def check_in_image(path, landmarks_uv, image_size_wh, image_name):
    """Raise a ``ValueError`` naming ``path`` when a landmark lies outside the image."""
    w, h = image_size_wh
    for name, (u, v) in landmarks_uv.items():
        if not (-0.5 <= u <= w - 0.5 and -0.5 <= v <= h - 0.5):
            raise ValueError(
                f"{path}: landmarks.{name} = ({u:g}, {v:g}) lies outside the {w}x{h} image "
                f"{image_name}; u is the column and v the row, in pixels"
            )


def photo_from_files(
    image_path,
    landmarks_path,
    view="frontal",
    mask_path=None,
    priors=None,
    photo_id=None,
    load_image=True,
):
    """A :class:`Photo` from an image file and a facial landmark file of any supported format.

    Parameters
    ----------
    image_path : str or Path
        PNG or JPEG.
    landmarks_path : str or Path
        Facial landmarks (pixels, ``u`` = column, ``v`` = row): CSV ``name,u,v``, JSON
        ``{"landmarks": {name: [u, v]}}`` or ``{name: [u, v]}``; aliases accepted.
    view : {"frontal", "lateral_left", "lateral_right"}
    mask_path : str or Path, optional
        Face mask PNG (non-zero = face), the photo's size.
    priors : Priors, optional
    photo_id : str, optional
        Defaults to the image's stem; made a safe folder name either way
        (:func:`lilium.io.paths.safe_id`).
    """
    image_path = Path(image_path)
    if not image_path.is_file():
        raise ValueError(f"{image_path}: file not found; check the photo's path")
    if view not in VIEWS:
        raise ValueError(f"{image_path}: view must be one of {', '.join(VIEWS)}, got {view!r}")
    image, size_wh = _photo_pixels(image_path, load_image)
    landmarks = read_landmarks(landmarks_path, "facial")
    check_in_image(landmarks_path, landmarks, size_wh, image_path.name)
    check_landmark_layout(landmarks_path, landmarks, _min_extent_px(size_wh), "px")
    mask = None
    if mask_path is not None:
        if not Path(mask_path).is_file():
            raise ValueError(f"{mask_path}: file not found; check the face mask's path")
        mask = read_mask(mask_path, size_wh)
    return Photo(
        safe_id(photo_id or image_path.stem),
        size_wh,
        view,
        landmarks,
        mask,
        None,
        priors or Priors(),
        image,
        mask_file=None if mask_path is None else str(mask_path),
    )


def read_depth_table(path):
    """Read a user's soft-tissue depth table (CSV with ``landmark,mean,sd,min,max``, mm).

    Returns
    -------
    dict of str -> DepthStats
        Keyed by cranial base name; see :func:`lilium.softtissue.check_depth_table`.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    table = {}
    with path.open(newline="") as fh:
        reader = csv.DictReader(fh)
        need = {"landmark", "mean", "sd", "min", "max"}
        if not reader.fieldnames or not need <= set(reader.fieldnames):
            raise ValueError(f"{path}: the header must hold the columns {', '.join(sorted(need))}")
        for line, row in enumerate(reader, start=2):
            try:
                stats = DepthStats(*(float(row[k]) for k in ("mean", "sd", "min", "max")))
            except (TypeError, ValueError):
                raise ValueError(
                    f"{path}: line {line}: mean, sd, min and max must be numbers"
                ) from None
            table[(row["landmark"] or "").strip()] = stats
    return check_depth_table(table, source=str(path))
