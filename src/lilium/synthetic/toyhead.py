"""A tiny stand-in subject: an ellipsoidal head with a nose, a chin and a neck.

Used by the photo, dataset and metric tests (and while developing them) so that they do not
need to run the full procedural subject generator. It is a
``lilium.synthetic.subjects.SyntheticSubject``: skull and skin meshes (mm), cranial and facial
landmarks (dicts name -> (3,)) and soft-tissue axes (dict cranial name -> unit (3,)).

Skull frame: mm, x = the subject's left, y = up, z = anterior.
"""

import numpy as np

from ..io.mesh import import_trimesh
from ..softtissue.landmarks import CORRESPONDENCES, EXTRA_CRANIAL, EXTRA_FACIAL
from .subjects import MANDIBLE_LANDMARKS, SyntheticSubject, axes_on_skull

#: Facial landmark directions from the head centre: (azimuth towards the subject's left from
#: anterior, elevation), degrees. Bilateral ones are given for the left side and mirrored.
_FACIAL_DIRECTIONS_DEG = {
    "glabella": (0, 24),
    "nasion": (0, 17),
    "metopion": (0, 48),
    "bregma": (0, 84),
    "subnasale": (0, -12),
    "labiale_superius": (0, -20),
    "pogonion": (0, -44),
    "gnathion": (0, -52),
    "exocanthion_l": (38, 12),
    "endocanthion_l": (14, 12),
    "zygion_l": (68, 2),
    "gonion_l": (62, -40),
    "alare_l": (11, -6),
    "frontotemporale_l": (30, 36),
    "cheilion_l": (20, -28),
}
_EXTRA_CRANIAL_DIRECTIONS_DEG = {
    "infradentale": (0, -34),
    "mental_foramen_l": (25, -40),
    "porion_l": (95, 5),
    "orbitale_l": (34, 4),
}

_SKIN_SEMI_AXES_MM = np.array([74.0, 108.0, 96.0])
_SOFT_TISSUE_MM = 7.0


def _direction(az_deg, el_deg):
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.array([np.sin(az) * np.cos(el), np.sin(el), np.cos(az) * np.cos(el)])


def _mirror(name, value):
    if name.endswith("_l"):
        return {name: value, name[:-2] + "_r": (-value[0], value[1])}
    return {name: value}


def _radius(directions, scale, nose_mm, chin_mm):
    """Radial distance of the skin (or skull) surface along unit ``directions`` (N, 3)."""
    d = directions
    r = 1.0 / np.sqrt(np.sum((d / (_SKIN_SEMI_AXES_MM * scale)) ** 2, axis=1))
    az = np.degrees(np.arctan2(d[:, 0], d[:, 2]))
    el = np.degrees(np.arcsin(np.clip(d[:, 1], -1, 1)))
    r = r + nose_mm * np.exp(-((az / 9.0) ** 2) - ((el - 2.0) / 11.0) ** 2)
    r = r + chin_mm * np.exp(-((az / 22.0) ** 2) - ((el + 46.0) / 10.0) ** 2)
    return r


def make_toy_subject(subject_id="toy", rng=None, subdivisions=4, mandible=True):
    """A stand-in head; ``rng`` varies its proportions by a few per cent.

    Parameters
    ----------
    subject_id : str
    rng : anything ``np.random.default_rng`` accepts
    subdivisions : int
        Icosphere subdivisions of the skin and skull meshes (4 -> 5,120 faces each).
    mandible : bool
        False: the skull loses its "mandible" (the triangles below the infradentale in front
        of the ear canals) and the :data:`~lilium.softtissue.landmarks.MANDIBLE_LANDMARKS`; the
        head is the same.

    Returns
    -------
    SyntheticSubject
        With the fields the photo renderer needs (no ``shape``, depths or bone normals).
    """
    trimesh = import_trimesh()

    rng = np.random.default_rng(rng)
    scale = 1.0 + rng.uniform(-0.05, 0.05, size=3)
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    dirs = np.asarray(sphere.vertices, dtype=float)
    faces = np.asarray(sphere.faces, dtype=np.int64)
    skin = dirs * _radius(dirs, scale, 22.0, 8.0)[:, None]
    skull_scale = scale * (1.0 - _SOFT_TISSUE_MM / _SKIN_SEMI_AXES_MM)
    skull = dirs * _radius(dirs, skull_scale, 4.0, 3.0)[:, None]

    # A neck: a cylinder below the jaw, joined to the head mesh only visually.
    neck_v, neck_f = _neck(radius_mm=48.0 * scale[0], top_mm=-60.0, bottom_mm=-190.0, z_mm=-20.0)
    skin_faces = np.vstack([faces, neck_f + len(skin)])
    skin = np.vstack([skin, neck_v])

    facial_dirs = {}
    for name, value in _FACIAL_DIRECTIONS_DEG.items():
        facial_dirs.update(_mirror(name, value))
    cranial_dirs = {}
    for cranial, facial in CORRESPONDENCES:
        cranial_dirs[cranial] = facial_dirs[facial]
    for name, value in _EXTRA_CRANIAL_DIRECTIONS_DEG.items():
        cranial_dirs.update(_mirror(name, value))
    assert set(cranial_dirs) >= set(EXTRA_CRANIAL)
    assert set(facial_dirs) >= set(EXTRA_FACIAL)

    facial, cranial, axes = {}, {}, {}
    for name, (az, el) in facial_dirs.items():
        d = _direction(az, el)[None]
        facial[name] = (d * _radius(d, scale, 22.0, 8.0)[:, None])[0]
    for name, (az, el) in cranial_dirs.items():
        d = _direction(az, el)[None]
        cranial[name] = (d * _radius(d, skull_scale, 4.0, 3.0)[:, None])[0]
    for cranial_name, facial_name in CORRESPONDENCES:
        v = facial[facial_name] - cranial[cranial_name]
        axes[cranial_name] = v / np.linalg.norm(v)
    skull_faces, removed, head_skull = faces.copy(), {}, None
    if not mandible:
        jaw = np.all((skull[faces, 1] < cranial["infradentale"][1]) & (skull[faces, 2] > 0), axis=1)
        skull_faces, head_skull = faces[~jaw], skull
        removed = {n: cranial.pop(n) for n in MANDIBLE_LANDMARKS}
    return SyntheticSubject(
        subject_id=str(subject_id),
        skull_vertices_mm=skull,
        skull_faces=skull_faces,
        skin_vertices_mm=skin,
        skin_faces=skin_faces,
        cranial_landmarks=cranial,
        facial_landmarks=facial,
        soft_tissue_axes=axes,
        mandible=bool(mandible),
        removed_landmarks=removed,
        head_skull_vertices_mm=head_skull,
    )


def _neck(radius_mm, top_mm, bottom_mm, z_mm, n=32):
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.column_stack([radius_mm * np.sin(angles), np.zeros(n), radius_mm * np.cos(angles)])
    ring[:, 2] += z_mm
    top = ring + [0, top_mm, 0]
    bottom = ring + [0, bottom_mm, 0]
    vertices = np.vstack([top, bottom])
    i = np.arange(n)
    j = (i + 1) % n
    faces = np.vstack([np.column_stack([i, j, i + n]), np.column_stack([j, j + n, i + n])])
    return vertices, faces


def write_toy_subject(folder, subject):
    """Write a stand-in subject folder (docs/contract.md) with trimesh PLY meshes."""
    from pathlib import Path

    from ..io.jsonio import write_json

    trimesh = import_trimesh()

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    trimesh.Trimesh(subject.skull_vertices_mm, subject.skull_faces, process=False).export(
        folder / "skull.ply"
    )
    trimesh.Trimesh(subject.skin_vertices_mm, subject.skin_faces, process=False).export(
        folder / "face.ply"
    )
    write_json(folder / "cranial_landmarks.json", {"landmarks": subject.cranial_landmarks})
    write_json(folder / "facial_landmarks.json", {"landmarks": subject.facial_landmarks})
    write_json(folder / "soft_tissue_axes.json", {"axes": axes_on_skull(subject)})
