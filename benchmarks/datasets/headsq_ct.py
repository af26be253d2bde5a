"""The headsq CT (issue 27): its volume edits, its meshes and its two subjects in the skull frame.

:func:`headsq_subjects` gives the subjects ``hq`` and ``hq_nm`` of
``benchmarks/datasets/headsq_case.py`` (which renders their photos and writes the dataset);
:func:`data_dir` finds the CT.

Data: ``../shared/data/headsq`` beside the repository (override with ``--data`` or the
environment variable ``LILIUM_HEADSQ``): VTK's quarter-resolution head CT, 64 x 64 x 93 int16
slices of 3.2 x 3.2 x 1.5 mm, from the eyebrows to the neck (the vault is cut off above the
orbits), skin at 500, bone at 1150.

What is built here, all through the project's own code:

1. Volume edits before meshing (the only hand-made step, voxel index boxes written below):
   the cervical spine is cut away (bone at rows >= 34 and slices >= 33 lowered to soft tissue:
   it is attached to the skull base at this resolution, ``import_ct`` warns so); the plastic
   tube hanging from the mouth in front of the chin is removed from the skin (what a 2D opening
   of radius 2 voxels takes off the skin mask below slice 64, in front of row 22, columns 20-43);
   for the mandible-less variant the mandible's bone is lowered to soft tissue (the bone
   component that holds the chin after a one-voxel erosion, grown back to every bone voxel
   nearer to it than to another component).
2. ``lilium.ct.import_ct`` (skull at 1150, skin at 500, LPS) into the subject folder, then the
   meshes and landmarks turned into the generator's skull frame (x = the subject's left, y = up,
   z = anterior; ``lilium.synthetic.subjects``): ``(x, y, z) = (L, S, -P)`` minus the centre of
   the complete skull's bounding box (a proper rotation, no mirroring).
3. Landmarks placed on the meshes by :func:`headsq_landmarks.place_landmarks` (its rules in that
   module's docstring; each one a vertex of its mesh); the true soft tissue of each pair is
   ``F - C``: ``soft_tissue_axes.json`` holds its direction (like the generator's true axes),
   ``subject.json`` its depth.
4. The head continued above the cut: the skin's lid (its vertices within :data:`LID_BAND_MM` of
   its top, the flat cap marching cubes closes the cut with) raised into a dome, each vertex by
   ``DOME_MM * sqrt(1 - r^2)`` with ``r`` its place in the lid's ellipse (0 at the centre, 1 on
   the rim; the half-widths of the lid in x and z): a photo shows the whole head, and a skull
   cut above the orbits lies well inside its outline. Cut flat at the skull's own cut (0.4 mm
   above it), the outline had no margin there: a camera refitted to a lateral photo's 5-9
   landmarks put the skull's cut rim 8-15 % of its pixels above the head (``outside_refit``,
   2026-12-07), which no photo of a person shows. :data:`DOME_MM` is the head's height above
   the cut, about: the vault rises 70-90 mm above the brows' level.
"""

import os
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from headsq_landmarks import place_landmarks

#: The CT beside the repository (``../shared/data/headsq``); ``LILIUM_HEADSQ`` overrides it.
DEFAULT_DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "headsq"
HEADER = "quarter.nhdr"
BONE_ISO = 1150.0
SKIN_ISO = 500.0
SOFT_TISSUE_VALUE = 1000  # between skin and bone: what removed bone becomes
AIR_VALUE = 100

#: Voxel boxes of the volume edits (slice k, row j, column i; see the module notes).
SPINE_ROWS_FROM = 34
SPINE_SLICES_FROM = 33
SPINE_COLUMNS = (21, 44)
CHIN_SLICES_FROM = 75  # the vertebrae, medial of the mandible's rami
TUBE_SLICES_FROM = 64
TUBE_ROWS_BEFORE = 22
TUBE_COLUMNS = (20, 44)

#: The skin's lid: its vertices this close to its top (mm); the dome's height over its centre.
LID_BAND_MM = 0.6
DOME_MM = 70.0

#: LPS -> generator skull frame (x = left, y = up, z = anterior): a proper rotation.
LPS_TO_SKULL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def data_dir(path=None):
    """The headsq folder (argument, ``LILIUM_HEADSQ``, or the default), or None if absent."""
    path = Path(path or os.environ.get("LILIUM_HEADSQ") or DEFAULT_DATA)
    return path if (path / HEADER).is_file() else None


# -- volume -----------------------------------------------------------------------------------
def _with_data(volume, data):
    return replace(volume, data=data)


def edited_volumes(path=None):
    """The CT with the spine and the tube removed, and the same without the mandible.

    Returns
    -------
    complete, no_mandible : lilium.ct.Volume
    """
    from scipy import ndimage as ndi

    from lilium.ct import read_volume

    folder = data_dir(path)
    if folder is None:
        raise FileNotFoundError(f"no headsq CT at {path or DEFAULT_DATA}")
    volume = read_volume(folder / HEADER)
    data = volume.data.copy()
    spine = data[SPINE_SLICES_FROM:, SPINE_ROWS_FROM:, SPINE_COLUMNS[0] : SPINE_COLUMNS[1]]
    spine[spine >= BONE_ISO] = SOFT_TISSUE_VALUE
    skin = data >= SKIN_ISO
    disk = np.zeros((1, 5, 5), bool)
    disk[0] = np.hypot(*np.mgrid[-2:3, -2:3]) <= 2.1
    thin = skin & ~ndi.binary_opening(skin, structure=disk)
    region = np.zeros_like(skin)
    region[TUBE_SLICES_FROM:, :TUBE_ROWS_BEFORE, TUBE_COLUMNS[0] : TUBE_COLUMNS[1]] = True
    data[thin & region] = AIR_VALUE
    bone = data >= BONE_ISO
    apart = bone.copy()  # for the labels only: the whole width behind the rami cut away
    apart[SPINE_SLICES_FROM:, SPINE_ROWS_FROM:, :] = False
    labels, _ = ndi.label(ndi.binary_erosion(apart))
    k, j, i = np.nonzero(labels[CHIN_SLICES_FROM:])
    front = np.argmin(j)  # the chin: the most anterior bone of the lowest slices
    mandible_label = labels[CHIN_SLICES_FROM + k[front], j[front], i[front]]
    _, nearest = ndi.distance_transform_edt(labels == 0, return_indices=True)
    mandible = bone & (labels[tuple(nearest)] == mandible_label)
    no_mandible = data.copy()
    no_mandible[mandible] = SOFT_TISSUE_VALUE
    return _with_data(volume, data), _with_data(volume, no_mandible)


def _import(volume, folder):
    """``import_ct`` into ``folder``; skull and skin in LPS."""
    from lilium.ct import import_ct

    result = import_ct(volume, folder, bone_iso=BONE_ISO, skin_iso=SKIN_ISO)
    return result["skull"], result["skin"], result["record"]


# -- subjects ---------------------------------------------------------------------------------
def true_soft_tissue(skull, skull_f, cranial, facial):
    """A CT subject's true soft tissue from its placed landmarks (skull frame, the midline at
    x = 0, checked): per correspondence the direction ``F - C`` (unit) and the depth
    ``|F - C|`` (mm), and the bone normal at every cranial landmark.

    Returns
    -------
    axes, depths, normals : dict
    """
    from lilium.softtissue.landmarks import CORRESPONDENCES, MIDLINE_CRANIAL
    from lilium.softtissue.normals import landmark_normals

    for name in MIDLINE_CRANIAL:
        if name in cranial:
            assert abs(cranial[name][0]) < 3.0, name
    pairs = [(c, f) for c, f in CORRESPONDENCES if c in cranial and f in facial]
    axes = {c: (facial[f] - cranial[c]) / np.linalg.norm(facial[f] - cranial[c]) for c, f in pairs}
    depths = {c: float(np.linalg.norm(facial[f] - cranial[c])) for c, f in pairs}
    return axes, depths, landmark_normals(skull, skull_f, cranial)


def _domed(skin):
    """The skin (V, 3) with its flat lid raised into a dome (module notes, 4)."""
    lid = skin[:, 1] > skin[:, 1].max() - LID_BAND_MM
    xz = skin[lid][:, [0, 2]]
    centre = 0.5 * (xz.min(axis=0) + xz.max(axis=0))
    half = 0.5 * (xz.max(axis=0) - xz.min(axis=0))
    r2 = np.clip((((xz - centre) / half) ** 2).sum(axis=1), 0.0, 1.0)
    out = skin.copy()
    out[lid, 1] += DOME_MM * np.sqrt(1.0 - r2)
    return out


_CACHE = {}


def mandible_vertices(skull, cranium):
    """Which vertices of the complete ``skull`` (V, 3) are the mandible's, ``(V,)`` bool: those
    with no vertex of the mandible-less ``cranium`` (V', 3) within 2 mm, in the skull's lower
    60 %."""
    from scipy.spatial import cKDTree

    mask = cKDTree(cranium).query(skull)[0] > 2.0
    return mask & (skull[:, 1] < np.percentile(skull[:, 1], 60))


def headsq_subjects(path=None, work_dir=None):
    """The two headsq subjects (``lilium.synthetic.subjects.SyntheticSubject``), keyed by id.

    Meshes come from ``import_ct`` (written under ``work_dir``, a temporary folder by default)
    and are turned into the skull frame; see the module notes.
    """
    from scipy.spatial import cKDTree

    from lilium.synthetic.subjects import MANDIBLE_LANDMARKS, SyntheticSubject

    key = str(data_dir(path))
    if key in _CACHE:
        return _CACHE[key]
    complete, cranium = edited_volumes(path)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(work_dir or tmp)
        (skull, skull_f), (skin, skin_f), record = _import(complete, base / "ct_complete")
        (nm, nm_f), _, _ = _import(cranium, base / "ct_no_mandible")
    origin = 0.5 * (skull.min(axis=0) + skull.max(axis=0)) @ LPS_TO_SKULL.T

    def frame(v):
        return v @ LPS_TO_SKULL.T - origin

    skull, skin, nm = frame(skull), frame(skin), frame(nm)
    skin = _domed(skin)  # the head goes on above the cut (module notes, 4)
    mandible_mask = mandible_vertices(skull, nm)
    cranial, facial, x_mid = place_landmarks(skull, skull_f, skin, skin_f, mandible_mask)
    shift = np.array([x_mid, 0.0, 0.0])  # x = 0 on the midline (between the orbits)
    skull, skin, nm = skull - shift, skin - shift, nm - shift
    cranial = {k: v - shift for k, v in cranial.items()}
    facial = {k: v - shift for k, v in facial.items()}
    origin = origin + shift
    axes, depths, normals = true_soft_tissue(skull, skull_f, cranial, facial)
    out = {
        "hq": SyntheticSubject(
            "hq", skull, skull_f, skin, skin_f, cranial, facial, axes, depths, normals
        )
    }
    kept = {n: v for n, v in cranial.items() if n not in MANDIBLE_LANDMARKS}
    removed = {n: v for n, v in cranial.items() if n in MANDIBLE_LANDMARKS}
    off = cKDTree(nm).query(np.array(list(kept.values())))[0]
    # cranium landmarks are vertices of the complete skull; snap to the mandible-less mesh
    kept = {n: nm[cKDTree(nm).query(v)[1]].copy() for n, v in kept.items()}
    assert off.max() < 1.0, off
    out["hq_nm"] = SyntheticSubject(
        "hq_nm",
        nm,
        nm_f,
        skin,
        skin_f,
        kept,
        facial,
        {c: a for c, a in axes.items() if c in kept},
        depths,
        {n: v for n, v in normals.items() if n in kept},
        mandible=False,
        removed_landmarks=removed,
        head_skull_vertices_mm=skull,
    )
    out["_record"] = record
    out["_origin_lps"] = origin @ LPS_TO_SKULL
    _CACHE[key] = out
    return out
