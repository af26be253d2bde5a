"""CT volume -> subject folder (SPEC section 8): skull and skin meshes, optional landmarks."""

from pathlib import Path

from .mesh import volume_to_mesh
from .readers import read_volume
from .volume import Volume

#: Classic iso-values of CT in scanner units (VTK's head example): skin and bone.
DEFAULT_SKIN_ISO = 500.0
DEFAULT_BONE_ISO = 1150.0


def read_landmark_file(path):
    """Cranial landmarks of a CT, from any file :func:`lilium.io.formats.read_landmarks` reads:
    JSON (``{"landmarks": {name: [x, y, z]}}`` or a bare mapping), CSV (rows ``name,x,y,z``; a
    header row is allowed), 3D Slicer or MeshLab; the usual aliases accepted.

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


def import_ct(
    volume,
    out_dir,
    bone_iso=DEFAULT_BONE_ISO,
    skin_iso=DEFAULT_SKIN_ISO,
    landmarks=None,
    target_faces=None,
    crop=None,
    **reader_options,
):
    """Extract skull and skin from a CT volume and write a subject folder.

    Parameters
    ----------
    volume : Volume, str or Path
        A volume, or anything :func:`~lilium.ct.readers.read_volume` reads (``reader_options``
        are passed to it: ``raw_shape``, ``raw_dtype``, ``spacing``, ...).
    out_dir : str or Path
    bone_iso, skin_iso : float
        Iso-values of bone and skin (volume units). ``skin_iso=None`` writes no ``face.ply``.
    landmarks : str, Path or dict, optional
        Cranial landmarks (volume frame, mm): a JSON/CSV file (:func:`read_landmark_file`) or a
        mapping; written to ``cranial_landmarks.json``.
    target_faces : int, optional
        Decimate each mesh to about this many faces.
    crop : ((i0, i1), (j0, j1), (k0, k1)), optional
        Voxel index ranges to keep (see :func:`~lilium.ct.mesh.volume_to_mesh`).

    Returns
    -------
    dict
        ``{"skull": (vertices, faces), "skin": (vertices, faces) or None, "landmarks": dict,
        "folder": Path}``. Meshes are in the volume frame (mm).
    """
    from ..io.jsonio import write_json
    from ..io.mesh import write_mesh

    if not isinstance(volume, Volume):
        volume = read_volume(volume, **reader_options)
    if skin_iso is not None and bone_iso <= skin_iso:
        raise ValueError(
            f"bone iso-value ({bone_iso:g}) must be above the skin iso-value ({skin_iso:g}): "
            "bone is denser than soft tissue"
        )
    if isinstance(landmarks, (str, Path)):
        landmarks = read_landmark_file(landmarks)
    skull = volume_to_mesh(volume, bone_iso, crop=crop, target_faces=target_faces)
    skin = None
    if skin_iso is not None:
        skin = volume_to_mesh(volume, skin_iso, crop=crop, target_faces=target_faces)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_mesh(out / "skull.ply", *skull)
    if skin is not None:
        write_mesh(out / "face.ply", *skin)
    if landmarks:
        write_json(out / "cranial_landmarks.json", {"landmarks": dict(landmarks)})
    write_json(
        out / "ct_import.json",
        {
            "source": volume.source,
            "shape_zyx": list(volume.data.shape),
            "spacing_mm": volume.spacing_mm,
            "origin_mm": volume.origin_mm,
            "direction": volume.direction,
            "bone_iso": bone_iso,
            "skin_iso": skin_iso,
            "crop": crop,
            "skull_faces": len(skull[1]),
            "skin_faces": None if skin is None else len(skin[1]),
        },
    )
    return {"skull": skull, "skin": skin, "landmarks": dict(landmarks or {}), "folder": out}
