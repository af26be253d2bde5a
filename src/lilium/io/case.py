"""Case folders of SPEC section 8: subject (skull) folders and photo folders.

Every problem found is a ``ValueError`` whose message names the file, the field and the fix.
"""

import csv
from pathlib import Path

import numpy as np

from ..constants import VIEWS
from ..inputs import Photo, Priors, Skull
from ..softtissue.depths import DepthStats, check_depth_table
from ..softtissue.landmarks import CRANIAL_TO_FACIAL
from ..softtissue.normals import surface_normals_at
from ..validation import check_interval
from .curves import read_face_curve
from .formats import find_landmark_file, points_from_object, read_landmarks
from .jsonio import read_json
from .mesh import MESH_SUFFIXES, read_mesh

IMAGE_NAMES = ("image.png", "image.jpg", "image.jpeg")


def _find(folder, stems_or_names, what, fix):
    for name in stems_or_names:
        if (folder / name).is_file():
            return folder / name
    raise ValueError(f"{folder}: no {what} ({' or '.join(stems_or_names)}); {fix}")


def _check_folder(folder, kind):
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder}: {kind} folder not found")
    return folder


def _field(path, data, key):
    if not isinstance(data, dict) or key not in data:
        raise ValueError(f"{path}: missing field {key!r}")
    return data[key]


def read_skull(folder, axes_path=None):
    """Read a subject (skull) folder.

    Parameters
    ----------
    folder : str or Path
        Holds ``skull.ply`` (or ``.obj``/``.stl``), ``cranial_landmarks.json`` and optionally
        ``soft_tissue_axes.json``.
    axes_path : str or Path, optional
        Soft-tissue axes file to use instead of the folder's own (e.g. a perturbed set).

    Returns
    -------
    Skull
        Axes missing from the file default to the outward skull-surface normal.
    """
    folder = _check_folder(folder, "subject")
    mesh_path = _find(
        folder,
        [f"skull{s}" for s in MESH_SUFFIXES],
        "skull mesh",
        "put the skull mesh (millimetres) there",
    )
    lm_path = folder / "cranial_landmarks.json"
    if not lm_path.is_file():
        # A Slicer / MeshLab / CSV file instead (cranial_landmarks.csv, skull.mrk.json, ...).
        lm_path = find_landmark_file(folder, ["cranial_landmarks", "skull"]) or lm_path
    axes_path = axes_path or folder / "soft_tissue_axes.json"
    return skull_from_files(mesh_path, lm_path, axes_path, skull_id=folder.name)


def skull_from_files(mesh_path, landmarks_path, axes_path=None, skull_id=None):
    """A :class:`Skull` from a mesh file and a landmark file of any supported format.

    Parameters
    ----------
    mesh_path : str or Path
        PLY, OBJ or STL (millimetres).
    landmarks_path : str or Path
        ``cranial_landmarks.json`` (SPEC section 8), or any file
        :func:`lilium.io.formats.read_landmarks` reads (3D Slicer, MeshLab, CSV, JSON; aliases).
    axes_path : str or Path, optional
        ``soft_tissue_axes.json``; absent axes default to the outward skull-surface normal.
    skull_id : str, optional
        Defaults to the mesh's folder name for ``skull.*`` and to the mesh's stem otherwise.
    """
    mesh_path, lm_path = Path(mesh_path), Path(landmarks_path)
    if skull_id is None:
        skull_id = mesh_path.parent.name if mesh_path.stem == "skull" else mesh_path.stem
    vertices, faces = read_mesh(mesh_path)
    if lm_path.name == "cranial_landmarks.json" or not lm_path.is_file():
        raw = _field(lm_path, read_json(lm_path), "landmarks")
        landmarks = points_from_object(lm_path, "landmarks", raw, "cranial")
    else:
        landmarks = read_landmarks(lm_path, "cranial")
    extent = np.ptp(vertices, axis=0).max()
    for name, p in landmarks.items():
        gap = np.min(np.linalg.norm(vertices - p, axis=1))
        if gap > 0.1 * extent:
            raise ValueError(
                f"{lm_path}: landmarks.{name} lies {gap:.0f} mm from the skull mesh; landmarks "
                "must be in the mesh's frame and units"
            )
    axes = {}
    axes_path = Path(axes_path) if axes_path else None
    if axes_path is not None and axes_path.is_file():
        raw = _field(axes_path, read_json(axes_path), "axes")
        axes_raw = points_from_object(axes_path, "axes", raw, "cranial", allow_empty=True)
        for name, a in axes_raw.items():
            norm = np.linalg.norm(a)
            if norm == 0:
                raise ValueError(f"{axes_path}: axes.{name} is the zero vector; give a direction")
            axes[name] = a / norm
    missing = [n for n in landmarks if n not in axes and n in CRANIAL_TO_FACIAL]
    if missing:
        normals = surface_normals_at(vertices, faces, np.array([landmarks[n] for n in missing]))
        axes.update(zip(missing, normals, strict=True))
    return Skull(skull_id, vertices, faces, landmarks, axes)


def _interval(path, priors, key):
    value = priors.get(key)
    return None if value is None else check_interval(value, f"{path}: priors.{key}")


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
        if not (isinstance(tolerance, (int, float)) and 0 < tolerance <= 180):
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


def read_image(path):
    """Read an RGB image as ``(H, W, 3)`` uint8, upright; a corrupt file is a ``ValueError``.

    The EXIF Orientation tag is applied (as image viewers do), so landmarks marked on a
    phone photo stored sideways match the pixels read here.
    """
    from PIL import Image, ImageOps, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            return np.asarray(ImageOps.exif_transpose(im).convert("RGB"))
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        raise ValueError(f"{path}: cannot read the image ({exc}); save it as PNG or JPEG") from exc


def read_mask(path, image_size_wh):
    """Read a face mask (non-zero = face) as ``(H, W)`` bool, checking size and emptiness."""
    mask = read_image(path).max(axis=2) > 0
    w, h = image_size_wh
    if mask.shape != (h, w):
        raise ValueError(
            f"{path}: the mask is {mask.shape[1]}x{mask.shape[0]} px but the photo is {w}x{h}; "
            "make the mask the photo's size"
        )
    if not mask.any():
        raise ValueError(f"{path}: the face mask is empty; paint the face/head pixels non-zero")
    return mask


def read_photo(folder, load_image=True):
    """Read a photo folder (``image.png``/``.jpg``, ``photo.json``, optional mask and curve).

    Parameters
    ----------
    folder : str or Path
    load_image : bool
        Keep the pixels (for overlays); the size is always read.

    Returns
    -------
    Photo
    """
    folder = _check_folder(folder, "photo")
    image_path = _find(folder, IMAGE_NAMES, "photo image", "put the photograph there")
    image = read_image(image_path)
    size_wh = (image.shape[1], image.shape[0])
    meta_path = folder / "photo.json"
    meta = read_json(meta_path)
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
    else:
        landmarks = read_landmarks(lm_path, "facial")
    check_in_image(lm_path, landmarks, size_wh, image_path.name)
    priors = parse_priors(meta_path, meta.get("priors"))
    mask_path = folder / "face_mask.png"
    mask = read_mask(mask_path, size_wh) if mask_path.is_file() else None
    curve_path = folder / "face_curve.json"
    curve = read_face_curve(curve_path, view, size_wh) if curve_path.is_file() else None
    return Photo(
        folder.name,
        size_wh,
        view,
        landmarks,
        mask,
        curve,
        priors,
        image if load_image else None,
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
        Defaults to the image's stem.
    """
    image_path = Path(image_path)
    if not image_path.is_file():
        raise ValueError(f"{image_path}: file not found; check the photo's path")
    if view not in VIEWS:
        raise ValueError(f"{image_path}: view must be one of {', '.join(VIEWS)}, got {view!r}")
    image = read_image(image_path)
    size_wh = (image.shape[1], image.shape[0])
    landmarks = read_landmarks(landmarks_path, "facial")
    check_in_image(landmarks_path, landmarks, size_wh, image_path.name)
    mask = None
    if mask_path is not None:
        if not Path(mask_path).is_file():
            raise ValueError(f"{mask_path}: file not found; check the face mask's path")
        mask = read_mask(mask_path, size_wh)
    return Photo(
        photo_id or image_path.stem,
        size_wh,
        view,
        landmarks,
        mask,
        None,
        priors or Priors(),
        image if load_image else None,
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
            except ValueError:
                raise ValueError(
                    f"{path}: line {line}: mean, sd, min and max must be numbers"
                ) from None
            table[row["landmark"].strip()] = stats
    return check_depth_table(table, source=str(path))
