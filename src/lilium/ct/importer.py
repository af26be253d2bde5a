"""CT volume -> subject folder (docs/contract.md): skull and skin meshes, optional landmarks.

Everything is written in one right-handed patient frame, LPS (:mod:`lilium.ct.frame`), whatever
the file's own frame; ``ct_import.json`` names it, gives the map from the file's coordinates,
the units and levels used and every warning (:mod:`lilium.ct.checks`).
"""

import re
from pathlib import Path

import numpy as np

from .checks import (
    DEFAULT_LEVELS,
    border_cuts,
    cut_warnings,
    detect_units,
    spine_check,
    spine_warning,
    voxel_warnings,
)
from .frame import PATIENT_FRAME, PATIENT_FRAME_TEXT, index_orientation_to_lps, space_to_lps
from .mesh import _parse_crop, volume_to_mesh
from .readers import read_volume
from .volume import Volume

#: Landmarks further than this fraction of the skull's size from its mesh are reported (the
#: distance at which ``lilium case`` refuses them).
LANDMARK_OFF_MESH_FRACTION = 0.10


def _is_slicer(path):
    """Whether a landmark file is a 3D Slicer markup (it states its own LPS/RAS frame)."""
    from ..io.formats import landmark_format

    fmt = landmark_format(path)
    if fmt in ("mrk.json", "fcsv"):
        return True
    if fmt == "json":
        try:
            head = Path(path).read_text(encoding="utf-8-sig", errors="replace")
        except OSError:
            return False
        return '"markups"' in head
    return False


#: What 3D Slicer writes as a markup's coordinate system (``0`` = RAS, ``1`` = LPS in old files).
SLICER_SYSTEMS = {"LPS": "LPS", "RAS": "RAS", "1": "LPS", "0": "RAS"}

_SYSTEM_FIELD = re.compile(r'coordinate\s*system"?\s*[=:]\s*"?([^",}\s]*)', re.IGNORECASE)


def _slicer_systems(path):
    """The coordinate systems a Slicer markup states (LPS when it states none).

    Raises
    ------
    ValueError
        A system Slicer does not write (e.g. ``CoordinateSystem = XYZ``): the points would be
        read in a frame nobody stated.
    """
    text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    found = [m.group(1) for m in _SYSTEM_FIELD.finditer(text)]
    unknown = [v for v in found if v.strip().upper() not in SLICER_SYSTEMS]
    if unknown:
        raise ValueError(
            f"{path}: coordinate system {unknown[0]!r} is not one 3D Slicer writes; state LPS or "
            "RAS (the frame the points were placed in), e.g. '# CoordinateSystem = LPS'"
        )
    systems = sorted({SLICER_SYSTEMS[v.strip().upper()] for v in found})
    return systems or ["LPS"]


def read_landmark_file(path):
    """Cranial landmarks of a CT, from any file :func:`lilium.io.formats.read_landmarks` reads
    (the formats ``lilium case`` accepts): JSON (``{"landmarks": {name: [x, y, z]}}`` or a bare
    mapping), CSV (rows ``name,x,y,z``; a header row is allowed), 3D Slicer (``.mrk.json``,
    ``.fcsv``; returned in LPS) or MeshLab ``.pp``; the usual aliases accepted.

    Returns
    -------
    dict of str -> ndarray of shape (3,)

    Raises
    ------
    ValueError
        Unreadable file, unknown landmark name, or a point that is not 3 finite numbers.
    """
    from ..io.formats import read_landmarks

    return read_landmarks(path, "cranial")


def _landmarks_to_lps(landmarks, to_lps):
    """Landmarks (file or mapping) in LPS, and where they came from.

    Plain files and mappings are in the volume file's coordinates and take the mesh's map;
    Slicer markups carry their own patient frame and are read into LPS directly.
    """
    if landmarks is None:
        return {}, None
    if isinstance(landmarks, (str, Path)):
        points = read_landmark_file(landmarks)
        if _is_slicer(landmarks):
            systems = _slicer_systems(landmarks)
            return points, f"3D Slicer markup: patient {'/'.join(systems)} as stated in the file"
    else:
        points = {k: np.asarray(v, dtype=float).reshape(3) for k, v in dict(landmarks).items()}
    return {k: to_lps @ v for k, v in points.items()}, "the volume file's coordinates"


def _extract(volume, level, crop, to_lps):
    """A surface in LPS and its vertices as (i, j, k) indices of the cropped volume."""
    vertices, faces = volume_to_mesh(volume, level, crop=crop)
    start = np.array([s.start or 0 for s in _parse_crop(crop, volume.data.shape, "")[::-1]])
    index = (np.linalg.solve(volume.direction, (vertices - volume.origin_mm).T).T) / (
        volume.spacing_mm
    ) - start
    lps = vertices @ to_lps.T
    if np.linalg.det(to_lps) < 0:  # a reflection turns the winding inside out
        faces = faces[:, ::-1]
    return lps, faces, index


def _check_finite(volume, crop):
    """Refuse NaN or infinite voxels: they would read as air, a hole through the bone."""
    data = volume.data[_parse_crop(crop, volume.data.shape, volume.source)]
    if data.dtype.kind != "f":
        return
    bad = ~np.isfinite(data)
    if bad.any():
        k, j, i = (int(x) for x in np.argwhere(bad)[0])
        raise ValueError(
            f"{volume.source}: {int(bad.sum())} voxels are NaN or infinite (the first at column "
            f"{i}, row {j}, slice {k}); they would read as air and cut holes through the bone: "
            "export the volume again with numbers there, or leave them out with --crop "
            "i0:i1,j0:j1,k0:k1"
        )


def _oriented(volume, orientation):
    """``volume`` with the index axes of ``--orientation`` (a file naming no anatomy only)."""
    import dataclasses

    to_lps, _ = space_to_lps(volume.space, volume.source)
    if volume.space_known:
        raise ValueError(
            f"{volume.source}: the file states its orientation (space {volume.space}); "
            "--orientation is for files that name none (raw data, NRRD without an anatomical "
            "space, NIfTI without qform/sform): leave it out"
        )
    direction = index_orientation_to_lps(orientation)
    return dataclasses.replace(
        volume, direction=direction, origin_mm=to_lps @ volume.origin_mm, space="lps",
        space_known=True,
    )  # fmt: skip


def _prepare_out(out_dir):
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out}: is a file; give a folder to write the subject into")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot create the folder ({exc.strerror or exc})") from exc
    return out


def import_ct(
    volume,
    out_dir,
    bone_iso=None,
    skin_iso=None,
    landmarks=None,
    target_faces=None,
    crop=None,
    face=True,
    units=None,
    orientation=None,
    **reader_options,
):
    """Extract skull and skin from a CT volume and write a subject folder, in LPS.

    Parameters
    ----------
    volume : Volume, str or Path
        A volume, or anything :func:`~lilium.ct.readers.read_volume` reads (``reader_options``
        are passed to it: ``raw_shape``, ``raw_dtype``, ``spacing``, ...).
    out_dir : str or Path
    bone_iso, skin_iso : float, optional
        Levels of bone and skin (volume units; any sign). None: the default of the volume's
        units (:data:`~lilium.ct.checks.DEFAULT_LEVELS`: 300 / -400 HU, 1150 / 500 scanner).
    landmarks : str, Path or dict, optional
        Cranial landmarks in the volume file's coordinates (mm; a 3D Slicer markup in its own
        patient frame), any format of :func:`read_landmark_file`, or a mapping; they take the
        mesh's map to LPS and are written to ``cranial_landmarks.json``.
    target_faces : int, optional
        Decimate each mesh to about this many faces.
    crop : ((i0, i1), (j0, j1), (k0, k1)), optional
        Voxel index ranges to keep (see :func:`~lilium.ct.mesh.volume_to_mesh`).
    face : bool
        Write ``face.ply`` (the skin surface).
    units : {"auto", "hu", "scanner"}, optional
        Intensity units; default: detected (:func:`~lilium.ct.checks.detect_units`).
    orientation : str, optional
        For a file that names no anatomical orientation (raw data, NRRD without an anatomical
        space, NIfTI without qform/sform): the side each index axis (column, row, slice) points
        to, e.g. ``"LPI"`` (:func:`~lilium.ct.frame.index_orientation_to_lps`). It replaces the
        file's direction; ``ct_import.json`` says ``"orientation": "given (--orientation
        LPI)"``. A file that states its orientation is an error with it.

    Returns
    -------
    dict
        ``skull`` and ``skin`` (``(vertices_lps_mm (V, 3), faces (F, 3))``; skin None without
        a face), ``landmarks`` (name -> LPS mm), ``folder``, ``warnings`` (list of
        ``{"code", "message"}``) and ``record`` (what ``ct_import.json`` holds).
    """
    from ..io.jsonio import write_json
    from ..io.mesh import write_mesh

    if not isinstance(volume, Volume):
        volume = read_volume(volume, **reader_options)
    if orientation is not None:
        volume = _oriented(volume, orientation)
    unit, unit_how = detect_units(volume, units)
    default_bone, default_skin = DEFAULT_LEVELS[unit]
    bone_iso = default_bone if bone_iso is None else float(bone_iso)
    skin_iso = (default_skin if skin_iso is None else float(skin_iso)) if face else None
    if skin_iso is not None and bone_iso <= skin_iso:
        raise ValueError(
            f"bone level ({bone_iso:g}) must be above the skin level ({skin_iso:g}): bone is "
            "denser than soft tissue (--bone-iso, --skin-iso)"
        )
    _check_finite(volume, crop)
    to_lps, anatomy_known = space_to_lps(volume.space, volume.source)
    lm_lps, lm_frame = _landmarks_to_lps(landmarks, to_lps)
    out = _prepare_out(out_dir)

    warnings = [("header", note) for note in volume.notes]
    if not anatomy_known:
        warnings.append(
            (
                "orientation_assumed",
                f"the file names no anatomical orientation (space {volume.space or 'none'}): "
                "its axes are taken as LPS"
                + (" with z negated (a left-handed space)" if np.linalg.det(to_lps) < 0 else "")
                + "; the mesh is not mirrored, but check which way is up and front, and state "
                "the side each index axis points to with --orientation (e.g. LPI when the first "
                "slice is the top of the head)",
            )
        )
    warnings += voxel_warnings(volume.spacing_mm)
    skull_lps, skull_faces, skull_index = _extract(volume, bone_iso, crop, to_lps)
    cropped_shape = volume.data[_parse_crop(crop, volume.data.shape, volume.source)].shape
    index_dirs_lps = to_lps @ volume.direction
    cuts = border_cuts(skull_index, skull_faces, skull_lps, cropped_shape, index_dirs_lps)
    warnings += cut_warnings(cuts)
    attached, spine = spine_check(skull_lps)
    if attached:
        warnings.append(spine_warning(spine))
    skin = None
    if skin_iso is not None:
        skin_lps, skin_faces, _ = _extract(volume, skin_iso, crop, to_lps)
        skin = (skin_lps, skin_faces)
    if target_faces is not None:
        from ..geometry.mesh import decimate

        skull_lps, skull_faces = decimate(skull_lps, skull_faces, target_faces)
        if skin is not None:
            skin = decimate(*skin, target_faces)
    skull = (skull_lps, skull_faces)
    if lm_lps:
        warnings += _landmark_warnings(lm_lps, skull_lps)

    try:
        write_mesh(out / "skull.ply", *skull)
        if skin is not None:
            write_mesh(out / "face.ply", *skin)
        elif (out / "face.ply").exists():
            (out / "face.ply").unlink()  # no stale skin from an earlier import
        if lm_lps:
            write_json(out / "cranial_landmarks.json", {"landmarks": lm_lps})
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write the subject ({exc})") from exc
    index_to_lps = np.eye(4)
    index_to_lps[:3, :3] = to_lps @ volume.direction @ np.diag(volume.spacing_mm)
    index_to_lps[:3, 3] = to_lps @ volume.origin_mm
    file_to_lps = np.eye(4)
    file_to_lps[:3, :3] = to_lps
    record = {
        "source": volume.source,
        "frame": PATIENT_FRAME,
        "frame_description": PATIENT_FRAME_TEXT,
        "source_space": volume.space,
        "orientation": (
            f"given (--orientation {orientation.strip().upper()})"
            if orientation is not None
            else ("from the file" if anatomy_known else "assumed")
        ),
        "file_to_frame": file_to_lps,
        "index_to_frame": index_to_lps,
        "landmarks_frame_in": lm_frame,
        "shape_zyx": list(volume.data.shape),
        "spacing_mm": volume.spacing_mm,
        "origin_mm": volume.origin_mm,
        "direction": volume.direction,
        "units": unit,
        "units_how": unit_how,
        "bone_iso": bone_iso,
        "skin_iso": skin_iso,
        "crop": crop,
        "skull_faces": len(skull[1]),
        "skin_faces": None if skin is None else len(skin[1]),
        "skull_extent_mm": _extent(skull[0]),
        "border_cuts": cuts,
        "spine_check": {"attached": attached, **spine},
        "warnings": [{"code": c, "message": m} for c, m in warnings],
    }
    try:
        write_json(out / "ct_import.json", record)
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write ct_import.json ({exc})") from exc
    return {
        "skull": skull,
        "skin": skin,
        "landmarks": lm_lps,
        "folder": out,
        "warnings": record["warnings"],
        "record": record,
    }


def _extent(vertices):
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return {"min": lo.round(2), "max": hi.round(2), "size": (hi - lo).round(2)}


def _landmark_warnings(landmarks_lps, skull_lps):
    """Landmarks far from the skull mesh: a frame or file mistake, said at import."""
    from scipy.spatial import cKDTree

    names = sorted(landmarks_lps)
    points = np.array([landmarks_lps[n] for n in names])
    distance, _ = cKDTree(skull_lps).query(points)
    size = float(np.linalg.norm(np.ptp(skull_lps, axis=0)))
    far = [f"{n} ({d:.0f} mm)" for n, d in zip(names, distance, strict=True)]
    far = [f for f, d in zip(far, distance, strict=True) if d > LANDMARK_OFF_MESH_FRACTION * size]
    if not far:
        return []
    return [
        (
            "landmark_off_mesh",
            f"landmarks far from the skull mesh: {', '.join(far)} (more than "
            f"{100 * LANDMARK_OFF_MESH_FRACTION:.0f} % of its size, {size:.0f} mm): the landmark "
            "file is not in the volume's coordinates, or in another frame",
        )
    ]
