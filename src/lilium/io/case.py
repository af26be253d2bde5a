"""Case folders of docs/contract.md: subject (skull) folders and photo folders, parsed.

Each function here reads one file (or finds one in a folder) into plain arrays and dicts; the
typed :class:`~lilium.inputs.Skull` and :class:`~lilium.inputs.Photo` are built and checked
across files by :mod:`lilium.casework.build`. A request's photos are compared as files here too
(:func:`check_distinct_files`: the same path, or the same image byte for byte). Every problem
found is a ``ValueError`` whose message names the file, the field and the fix.
"""

import csv
import filecmp
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..softtissue.depths import DepthStats, check_depth_table
from .curves import read_face_curve
from .formats import find_landmark_file, points_from_object, read_landmarks
from .images import image_size_wh, read_image, read_mask
from .jsonio import read_json
from .keys import json_type
from .mesh import MESH_SUFFIXES, parse_mesh
from .paths import path_id, safe_id
from .prepared import (
    _without_unconfirmed_templates,
    landmark_qualities,
)

__all__ = [
    "IMAGE_NAMES",
    "check_axes_file",
    "check_distinct_files",
    "check_folder",
    "find_photo_image",
    "first_file",
    "parse_axes",
    "cranial_landmark_file",
    "parse_cranial_landmarks",
    "parse_facial_landmarks",
    "parse_depth_table",
    "read_depth_table",
    "read_face_curve",
    "read_image",
    "read_image_or_size",
    "read_mask",
    "read_photo_meta",
    "repeated_photo",
    "required_field",
]

IMAGE_NAMES = ("image.png", "image.jpg", "image.jpeg")


def first_file(folder, names):
    """The first of ``names`` that is a file in ``folder``; None when none is."""
    return next((folder / n for n in names if (folder / n).is_file()), None)


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


def required_field(path, data, key):
    """``data[key]``; a ``ValueError`` naming ``path`` when it is missing."""
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
    """The cranial landmarks of a landmark file, as parsed (:func:`cranial_landmark_file`'s
    first part): dict of str -> ndarray (3,), mm."""
    return cranial_landmark_file(landmarks_path)[0]


def cranial_landmark_file(landmarks_path):
    """The cranial landmarks of a ``cranial_landmarks.json`` or of any file
    :func:`lilium.io.formats.read_landmarks` reads, as parsed, and who placed each.

    A ``cranial_landmarks.json`` written by ``lilium skull`` (or saved by its review page) tags
    each point in ``landmark_sources``; as on photos, a ``"quality": "template"`` point is left
    out unless its entry says ``"confirmed": true`` (docs/method/skull.md).

    Returns
    -------
    landmarks : dict of str -> ndarray of shape (3,)
        mm.
    sources : dict of str -> str
        Each landmark's quality (:func:`~lilium.io.prepared.landmark_qualities`: ``"located"``
        or ``"template"`` for an automatic, unreviewed point, else ``"manual"``).
    """
    from .prepared import _without_unconfirmed_templates, landmark_qualities

    lm_path = Path(landmarks_path)
    if lm_path.name == "cranial_landmarks.json" or not lm_path.is_file():
        data = read_json(lm_path)
        raw = required_field(lm_path, data, "landmarks")
        points = points_from_object(lm_path, "landmarks", raw, "cranial")
        sources = data.get("landmark_sources")
        points = _without_unconfirmed_templates(points, sources)
        return points, landmark_qualities(sources, points)
    points = read_landmarks(lm_path, "cranial")
    return points, dict.fromkeys(points, "manual")


class ParsedSkull(NamedTuple):
    """A skull's files parsed to arrays (:func:`parse_skull_files`), before anything is built
    or checked across them (:func:`lilium.casework.build.build_skull`).

    Attributes
    ----------
    skull_id : str
        The skull's id, a safe folder name (:func:`~lilium.io.paths.safe_id`).
    mesh_path, landmarks_path : Path
        The files, for the messages.
    mesh : tuple
        ``(vertices, faces, shared)`` as :func:`~lilium.io.mesh.parse_mesh` parsed it:
        ndarray of shape (V, 3), millimetres, ndarray of shape (F, 3), and the flag it returns.
    landmarks : dict of str -> ndarray of shape (3,)
        The cranial landmarks, mm (:func:`cranial_landmark_file`).
    sources : dict of str -> str
        Who placed each landmark.
    axes : dict of str -> ndarray of shape (3,)
        The soft-tissue axes given, unit directions (:func:`parse_axes`; empty without a file).
    """

    skull_id: str
    mesh_path: Path
    landmarks_path: Path
    mesh: tuple
    landmarks: dict
    sources: dict
    axes: dict


def parse_skull_files(mesh_path, landmarks_path, axes_path=None, skull_id=None):
    """Parse a skull's mesh, cranial landmark file and soft-tissue axes file, in that order,
    and name the skull.

    Parameters
    ----------
    mesh_path : str or Path
        PLY, OBJ or STL (millimetres).
    landmarks_path : str or Path
        Any file :func:`cranial_landmark_file` reads.
    axes_path : str or Path, optional
        ``soft_tissue_axes.json`` (absent or None: no axes given).
    skull_id : str, optional
        Defaults to the mesh's folder name for ``skull.*`` and to the mesh's stem otherwise;
        made a safe folder name either way (:func:`lilium.io.paths.safe_id`).

    Returns
    -------
    ParsedSkull

    Raises
    ------
    ValueError
        A file that cannot be parsed, naming it.
    """
    mesh_path, landmarks_path = Path(mesh_path), Path(landmarks_path)
    if skull_id is None:
        skull_id = (
            path_id(mesh_path.parent, "skull") if mesh_path.stem == "skull" else mesh_path.stem
        )
    skull_id = safe_id(skull_id, "skull")
    mesh = parse_mesh(mesh_path)
    landmarks, sources = cranial_landmark_file(landmarks_path)
    axes = parse_axes(axes_path)
    return ParsedSkull(skull_id, mesh_path, landmarks_path, mesh, landmarks, sources, axes)


def parse_axes(axes_path):
    """The soft-tissue axes of ``soft_tissue_axes.json``, made unit directions: dict of str ->
    ndarray (3,); empty when ``axes_path`` is None or not a file.

    Raises
    ------
    ValueError
        Naming the file: a malformed file, or an axis that is the zero vector.
    """
    axes_path = Path(axes_path) if axes_path else None
    if axes_path is None or not axes_path.is_file():
        return {}
    raw = required_field(axes_path, read_json(axes_path), "axes")
    axes = {}
    for name, a in points_from_object(axes_path, "axes", raw, "cranial", allow_empty=True).items():
        norm = np.linalg.norm(a)
        if norm == 0:
            raise ValueError(f"{axes_path}: axes.{name} is the zero vector; give a direction")
        axes[name] = a / norm
    return axes


def find_photo_image(folder):
    """The photograph of a photo folder (``image.png``/``.jpg``/``.jpeg``); a ``ValueError``
    when there is none or more than one (which one the landmarks belong to is unknown)."""
    image_path = _find(folder, IMAGE_NAMES, "photo image", "put the photograph there")
    images = [name for name in IMAGE_NAMES if (folder / name).is_file()]
    if len(images) > 1:  # which one the landmarks belong to is unknown
        raise ValueError(
            f"{folder}: holds {' and '.join(images)}; keep only the photograph its landmarks, "
            "mask and curve were made on"
        )
    return image_path


def read_image_or_size(image_path, load_image=True):
    """The image's pixels (or None without ``load_image``) and its ``(width, height)``; without
    the pixels only the file's header is read."""
    image = read_image(image_path) if load_image else None
    size_wh = (image.shape[1], image.shape[0]) if load_image else image_size_wh(image_path)
    return image, size_wh


def read_photo_meta(meta_path):
    """A ``photo.json`` as parsed: a dict (a ``ValueError`` for any other JSON value)."""
    meta = read_json(meta_path)
    if not isinstance(meta, dict):
        raise ValueError(
            f'{meta_path}: must be a JSON object {{"view": ..., "landmarks": {{...}}}}, '
            f"got a JSON {json_type(meta)}; see docs/contract.md for the photo folder"
        )
    return meta


def parse_facial_landmarks(folder, meta_path, meta):
    """A photo folder's facial landmarks as parsed: from ``photo.json``'s ``landmarks`` (without
    unconfirmed template points) or, when it has none, from a file of their own
    (``facial_landmarks.csv``, ``landmarks.json``, ...).

    Returns
    -------
    landmarks_path : Path
        The file they were read from.
    landmarks_uv : dict of str -> ndarray of shape (2,), px
    sources : dict of str -> str
        Each landmark's quality from ``photo.json``'s ``landmark_sources`` (empty for a file of
        their own).
    """
    lm_path = meta_path
    if "landmarks" not in meta:
        # Facial landmarks in a file of their own (facial_landmarks.csv, landmarks.json, ...).
        lm_path = find_landmark_file(folder, ["facial_landmarks", "landmarks"]) or meta_path
    if lm_path == meta_path:
        raw = required_field(meta_path, meta, "landmarks")
        landmarks = points_from_object(meta_path, "landmarks", raw, "facial")
        landmarks = _without_unconfirmed_templates(landmarks, meta.get("landmark_sources"))
        return lm_path, landmarks, landmark_qualities(meta.get("landmark_sources"), landmarks)
    return lm_path, read_landmarks(lm_path, "facial"), {}


def read_depth_table(path):
    """Read a user's soft-tissue depth table (CSV with ``landmark,mean,sd,min,max``, mm) and
    check it (:func:`~lilium.softtissue.depths.check_depth_table`).

    Returns
    -------
    dict of str -> DepthStats
        Keyed by cranial base name; see :func:`lilium.softtissue.check_depth_table`.
    """
    return check_depth_table(parse_depth_table(path), source=str(path))


def parse_depth_table(path):
    """Parse a user's soft-tissue depth table (CSV with ``landmark,mean,sd,min,max``, mm), its
    values not yet checked (:func:`read_depth_table` checks them).

    Returns
    -------
    dict of str -> DepthStats
        Keyed by the landmark column, stripped.

    Raises
    ------
    ValueError
        No such file, a header without those columns, a value that is not a number.
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
    return table


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


def check_distinct_files(paths):
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
