"""The typed inputs (:class:`~lilium.inputs.Skull`, :class:`~lilium.inputs.Photo`) built and
checked from what :mod:`lilium.io` parses, in one pass per skull and per photo.

:mod:`lilium.io` turns each file into plain arrays and dicts (a mesh's vertices and faces, a
landmark file's points); here they are cleaned and checked against each other (landmarks on the
mesh and spread, landmarks inside the image, the mesh's parts apart from the skull) and put
together. Every problem found is a ``ValueError`` whose message names the file, the field and
the fix.
"""

from pathlib import Path

import numpy as np

from ..constants import (
    MIN_CRANIAL_EXTENT_FRACTION,
    MIN_LANDMARK_EXTENT_FRACTION,
    MIN_LANDMARK_EXTENT_PX,
    MIN_LANDMARK_SPREAD_RATIO,
    MIN_PHOTO_SIDE_PX,
    PART_APART_MM,
    VIEWS,
)
from ..geometry.mesh import check_landmarks_on_mesh, clean_mesh, compact, parts_apart
from ..inputs import CaseWarning, Photo, Priors, Skull
from ..io.case import (
    check_axes_file,
    check_folder,
    find_photo_image,
    parse_facial_landmarks,
    parse_skull_files,
    read_image_or_size,
    read_photo_meta,
    required_field,
    subject_files,
)
from ..io.curves import read_face_curve
from ..io.formats import read_landmarks
from ..io.images import read_mask
from ..io.keys import unknown_key_warnings
from ..io.paths import path_id, safe_id
from ..io.prepared import face_only_mask, written_by_lilium_photo
from ..softtissue.landmarks import CRANIAL_TO_FACIAL, base_name
from ..softtissue.normals import LATERAL_OFFSET_MM, landmark_normals
from ..validation import check_prior, is_real

__all__ = [
    "check_in_image",
    "build_skull",
    "check_landmark_layout",
    "parse_priors",
    "photo_from_files",
    "read_photo",
    "read_skull",
    "skull_from_files",
]


def read_skull(folder, axes_path=None, landmarks_path=None):
    """Read a subject (skull) folder.

    Parameters
    ----------
    folder : str or Path
        Holds ``skull.ply`` (or ``.obj``/``.stl``), ``cranial_landmarks.json`` and optionally
        ``soft_tissue_axes.json``.
    axes_path : str or Path, optional
        Soft-tissue axes file to use instead of the folder's own (e.g. a perturbed set); it
        must exist (a missing file is an error, never a silent fall-back to the normals).
    landmarks_path : str or Path, optional
        Cranial landmark file to use instead of the folder's own (any supported format).

    Returns
    -------
    Skull
        Axes missing from the file default to the outward skull-surface normal. Its id is the
        folder's name (:func:`lilium.io.paths.path_id`).
    """
    folder = check_folder(folder, "subject")
    mesh_path, lm_path = subject_files(folder)
    if landmarks_path is not None:
        lm_path = Path(landmarks_path)
    if axes_path is not None:
        check_axes_file(axes_path)
    else:
        axes_path = folder / "soft_tissue_axes.json"
    return skull_from_files(mesh_path, lm_path, axes_path, skull_id=path_id(folder, "skull"))


def skull_from_files(mesh_path, landmarks_path, axes_path=None, skull_id=None):
    """A :class:`Skull` from a mesh file and a landmark file of any supported format: the files
    parsed (:func:`~lilium.io.case.parse_skull_files`), then built (:func:`build_skull`).

    Parameters
    ----------
    mesh_path : str or Path
        PLY, OBJ or STL (millimetres).
    landmarks_path : str or Path
        ``cranial_landmarks.json`` (docs/contract.md), or any file
        :func:`lilium.io.formats.read_landmarks` reads (3D Slicer, MeshLab, CSV, JSON; aliases).
    axes_path : str or Path, optional
        ``soft_tissue_axes.json``; absent axes default to the outward skull-surface normal.
    skull_id : str, optional
        Defaults to the mesh's folder name for ``skull.*`` and to the mesh's stem otherwise;
        made a safe folder name either way (:func:`lilium.io.paths.safe_id`).
    """
    parsed = parse_skull_files(mesh_path, landmarks_path, axes_path, skull_id)
    return build_skull(parsed)


def build_skull(parsed):
    """A :class:`Skull` built and checked from its parsed files.

    The surface cleaned (:func:`_skull_surface`), the axes missing from the file set to the
    outward skull-surface normal (with warning ``normal_axes`` where the facial landmark lies
    beside the bone's, :data:`~lilium.softtissue.normals.LATERAL_OFFSET_MM`: the eye corners and
    the alae), and the landmarks checked to lie on the mesh and to spread.

    Parameters
    ----------
    parsed : ParsedSkull
        :func:`~lilium.io.case.parse_skull_files`'s (its files, parsed, and the skull's id).

    Returns
    -------
    Skull

    Raises
    ------
    ValueError
        A landmark off the mesh, landmarks all at one place or on one line (naming the landmark
        file), or a mesh :func:`~lilium.geometry.mesh.clean_mesh` refuses.
    """
    mesh_path, lm_path = parsed.mesh_path, parsed.landmarks_path
    landmarks, axes = parsed.landmarks, dict(parsed.axes)
    vertices, faces, warnings = _skull_surface(mesh_path, parsed.mesh, landmarks)
    missing = [n for n in landmarks if n not in axes and n in CRANIAL_TO_FACIAL]
    if missing:
        axes.update(landmark_normals(vertices, faces, {n: landmarks[n] for n in missing}))
    beside = [n for n in missing if base_name(n) in LATERAL_OFFSET_MM]
    if beside:
        warnings.append(CaseWarning("normal_axes", (
            f"{mesh_path}: no soft-tissue axes for {', '.join(beside)}: their cone axes are the "
            "bone normals, but on a real face the eye corners and the alae lie beside them "
            "(on the real CT heads the true person's log10 LR came out 1.0 to 1.9 lower, "
            "docs/method/identification.md); give --axes: `lilium skull MESH --landmarks "
            "FILE --out DIR` keeps your landmarks and writes them to DIR/soft_tissue_axes.json"
        )))  # fmt: skip
    check_landmarks_on_mesh(landmarks, vertices, faces, lm_path)
    extent = np.ptp(vertices, axis=0).max()
    check_landmark_layout(lm_path, landmarks, extent * MIN_CRANIAL_EXTENT_FRACTION, "mm")
    return Skull(
        parsed.skull_id, vertices, faces, landmarks, axes, warnings=tuple(warnings),
        landmark_sources=parsed.sources,
    )


def _skull_surface(mesh_path, mesh, landmarks):
    """The skull's surface from a parsed mesh: cleaned (:func:`~lilium.geometry.mesh.clean_mesh`),
    without the parts apart from its cranial landmarks' part (:data:`PART_APART_MM`) and without
    unreferenced vertices; and the warning that names what was left out.

    Parameters
    ----------
    mesh_path : Path
        The mesh file, for the messages.
    mesh : tuple
        ``(vertices, faces, shared)`` as :func:`~lilium.io.mesh.parse_mesh` parsed it
        (millimetres).
    landmarks : dict of str -> ndarray of shape (3,), millimetres

    Returns
    -------
    vertices : ndarray of shape (V', 3)
    faces : ndarray of shape (F', 3)
    warnings : list of CaseWarning
        ``mesh_part_left_out`` when parts were left out.
    """
    vertices, faces = clean_mesh(*mesh, source=str(mesh_path))
    apart, parts = parts_apart(vertices, faces, np.array(list(landmarks.values())), PART_APART_MM)
    warnings = []
    if parts:
        faces = faces[~apart]
        sizes = "; ".join(f"{n} faces, {gap:.0f} mm away" for n, gap in parts[:3])
        more = f"; and {len(parts) - 3} more" if len(parts) > 3 else ""
        warnings.append(
            CaseWarning(
                "mesh_part_left_out",
                f"{mesh_path}: {len(parts)} fragment(s) of the mesh lie apart from the skull (the "
                f"part holding its cranial landmarks) and are left out ({sizes}{more}); delete "
                "them from the mesh if they are not this skull's bone",
            )
        )
    vertices, faces = compact(vertices, faces)
    return vertices, faces, warnings


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
    image_path = find_photo_image(folder)
    image, size_wh = _photo_pixels(image_path, load_image)
    meta_path = folder / "photo.json"
    meta = read_photo_meta(meta_path)
    view = required_field(meta_path, meta, "view")
    if view not in VIEWS:
        raise ValueError(f"{meta_path}: view must be one of {', '.join(VIEWS)}, got {view!r}")
    lm_path, landmarks, sources = parse_facial_landmarks(folder, meta_path, meta)
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


def photo_from_files(
    image_path,
    landmarks_path,
    view="frontal",
    mask_path=None,
    priors=None,
    photo_id=None,
    load_image=True,
    face_curve_path=None,
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
    load_image : bool
        Keep the pixels (for overlays); without them only the image's header is read.
    face_curve_path : str or Path, optional
        Facial curve (``face_curve.json`` format, :func:`lilium.io.curves.read_face_curve`).
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
    curve = None if face_curve_path is None else read_face_curve(face_curve_path, view, size_wh)
    return Photo(
        safe_id(photo_id or image_path.stem),
        size_wh,
        view,
        landmarks,
        mask,
        curve,
        priors or Priors(),
        image,
        mask_file=None if mask_path is None else str(mask_path),
    )


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


def _check_photo_size(image_path, size_wh):
    """Raise when the photo is smaller than :data:`~lilium.constants.MIN_PHOTO_SIDE_PX` a side."""
    if min(size_wh) < MIN_PHOTO_SIDE_PX:
        raise ValueError(
            f"{image_path}: the photo is {size_wh[0]}x{size_wh[1]} px, too small to superimpose "
            f"a skull on (at least {MIN_PHOTO_SIDE_PX} px a side); use the original photograph"
        )


def _photo_pixels(image_path, load_image):
    """The photo's pixels (or None) and its ``(width, height)``, checking the smallest size."""
    image, size_wh = read_image_or_size(image_path, load_image)
    _check_photo_size(image_path, size_wh)
    return image, size_wh


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
