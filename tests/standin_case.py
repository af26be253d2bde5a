"""A stand-in case for fast tests of case folders, POSEST-SFO and Lilium.

An ellipsoidal "skull" with every correspondence landmark at a fixed direction on it, soft tissue
along the exact surface normals (mean depth +- 0.5 mm), and one frontal photo of it with a known
camera. Deliberately simple and quick to build (about 1 s); the realistic subjects of
:mod:`lilium.synthetic` serve the demo and the benchmarks.
"""

import json
from pathlib import Path

import numpy as np

from lilium.geometry.camera import Camera, principal_point_of
from lilium.geometry.rotations import rotvec_to_matrix
from lilium.imaging.overlay import render_mesh_shaded
from lilium.io.jsonio import write_json
from lilium.io.mesh import write_mesh
from lilium.io.results import write_png
from lilium.softtissue.depths import depth_stats
from lilium.softtissue.landmarks import CRANIAL_TO_FACIAL

#: Semi-axes (mm) of the stand-in skull: half breadth, half height, half length.
SKULL_RADII_MM = np.array([70.0, 85.0, 92.0])

#: Landmark directions on the stand-in (azimuth from the front towards the subject's left,
#: elevation), degrees. Skull frame: x = subject's left, y = up, z = anterior.
_DIRECTIONS_DEG = {
    "glabella": (0, 12),
    "nasion": (0, 5),
    "metopion": (0, 35),
    "bregma": (0, 80),
    "subspinale": (0, -22),
    "prosthion": (0, -30),
    "pogonion": (0, -50),
    "gnathion": (0, -56),
    "ectoconchion": (38, 0),
    "dacryon": (12, 2),
    "zygion": (62, -12),
    "gonion": (58, -45),
    "alare": (9, -14),
    "frontotemporale": (30, 28),
}


def _direction(azimuth_deg, elevation_deg):
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    return np.array([np.sin(az) * np.cos(el), np.sin(el), np.cos(az) * np.cos(el)])


def _ellipsoid(radii_mm, subdivisions=4):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.asarray(sphere.vertices) * radii_mm, np.asarray(sphere.faces)


def _surface_point(direction, radii_mm):
    """Where the ray from the centre along ``direction`` meets the ellipsoid, and the normal."""
    s = 1.0 / np.sqrt(np.sum((direction / radii_mm) ** 2))
    p = s * direction
    n = p / radii_mm**2
    return p, n / np.linalg.norm(n)


def make_standin_case(folder, seed=0):
    """Write a stand-in subject and one frontal photo of it.

    Returns
    -------
    subject_dir, photo_dir : Path
    """
    rng = np.random.default_rng(seed)
    folder = Path(folder)
    subject_dir, photo_dir = folder / "subjects" / "standin", folder / "photos" / "standin_frontal"
    cranial, facial, axes = {}, {}, {}
    for base, (az, el) in _DIRECTIONS_DEG.items():
        sides = [("_l", 1), ("_r", -1)] if az else [("", 1)]
        for suffix, sign in sides:
            p, n = _surface_point(_direction(sign * az, el), SKULL_RADII_MM)
            name = base + suffix
            depth = depth_stats(name).mean_mm + rng.normal(0, 0.5)
            cranial[name], axes[name] = p, n
            facial[CRANIAL_TO_FACIAL[name]] = p + depth * n
    skull_v, skull_f = _ellipsoid(SKULL_RADII_MM)
    skin_v, skin_f = _ellipsoid(SKULL_RADII_MM + 8.0)
    write_mesh(subject_dir / "skull.ply", skull_v, skull_f)
    write_mesh(subject_dir / "face.ply", skin_v, skin_f)
    write_json(subject_dir / "cranial_landmarks.json", {"landmarks": cranial})
    write_json(subject_dir / "soft_tissue_axes.json", {"axes": axes})
    write_json(subject_dir / "facial_landmarks.json", {"landmarks": facial})

    # Frontal camera: looks along the skull's -z, x right = subject's right, y down.
    size_wh, focal_px, scd_mm = (1200, 900), 2600.0, 900.0
    # Facing the camera the subject's left is on the image's right: cam x = skull x,
    # cam y (down) = -skull y, cam z (forward, into the face) = -skull z.
    R = np.diag([1.0, -1.0, -1.0])
    R = rotvec_to_matrix(np.radians([4.0, -9.0, 2.0])) @ R
    skull2cam = np.eye(4)
    skull2cam[:3, :3] = R
    skull2cam[:3, 3] = np.array([0.0, 0.0, scd_mm]) - R @ facial["nasion"]
    camera = Camera(skull2cam, focal_px, principal_point_of(size_wh))
    shade, covered = render_mesh_shaded(skin_v, skin_f, camera, size_wh)
    image = np.full(size_wh[::-1] + (3,), 40, dtype=np.uint8)
    skin_rgb = np.array([224, 172, 140])
    image[covered] = (shade[covered, None] * skin_rgb).astype(np.uint8)
    names = list(facial)
    uv = camera.project(np.array([facial[n] for n in names]))
    write_png(photo_dir / "image.png", image)
    write_png(photo_dir / "face_mask.png", np.repeat(covered[..., None] * 255, 3, axis=2))
    write_json(
        photo_dir / "photo.json",
        {
            "view": "frontal",
            "landmarks": dict(zip(names, uv, strict=True)),
            "priors": {
                "focal_px": [0.95 * focal_px, 1.05 * focal_px],
                "scd_mm": [0.9 * scd_mm, 1.1 * scd_mm],
                "head_rotation_skull2cam": R,
                "head_tolerance_deg": 10,
            },
            "ground_truth": {
                "subject": "standin",
                "skull2cam": skull2cam,
                "focal_px": focal_px,
                "scd_mm": scd_mm,
                "noise": "A",
                "landmarks_noise_free": dict(zip(names, uv, strict=True)),
            },
        },
    )
    return subject_dir, photo_dir


def scaled_photo(photo_dir, folder, factor, moved=0.015):
    """Another photo of the stand-in: its image and mask resized by ``factor``, its landmarks
    and focal prior scaled with them (no ground truth), and each landmark moved at random by
    about ``moved`` of the landmarks' extent, as another photo's pose, expression and hand move
    them (``moved=0``: a resized copy, which a case refuses as the same photo given twice).

    Returns
    -------
    Path
        ``folder``.
    """
    from PIL import Image

    photo_dir, folder = Path(photo_dir), Path(folder)
    folder.mkdir(parents=True)
    for name in ("image.png", "face_mask.png"):
        image = Image.open(photo_dir / name)
        size = (round(image.width * factor), round(image.height * factor))
        image.resize(size).save(folder / name)
    data = json.loads((photo_dir / "photo.json").read_text())
    uv = np.array(list(data["landmarks"].values()), float)
    rng = np.random.default_rng(round(1000 * factor))
    uv = uv + rng.normal(0.0, moved * np.ptp(uv, axis=0).max(), uv.shape)
    data["landmarks"] = {
        k: [(u + 0.5) * factor - 0.5, (v + 0.5) * factor - 0.5]
        for k, (u, v) in zip(data["landmarks"], uv.tolist(), strict=True)
    }
    data["priors"]["focal_px"] = [f * factor for f in data["priors"]["focal_px"]]
    data.pop("ground_truth", None)
    write_json(folder / "photo.json", data)
    return folder


def terms_database(path, n_subjects=3, result=None, seed=0):
    """A results database (``lilium experiment``'s) of frontal POSEST-SFO SFOs of
    ``n_subjects`` people, every photo against every skull, each with a camera and stored
    identification terms, the same person's landmark term lower (so ``lilium calibrate`` can
    fit a model on 10+ subjects); ``result(k, data)`` returns row ``k``'s ``result`` text
    instead of ``data`` as JSON. Returns ``path``.
    """
    from lilium.experiments.store import ResultStore
    from lilium.identification.terms import TERM_NAMES

    rng = np.random.default_rng(seed)
    camera = {
        "focal_px": 2600.0,
        "principal_point_px": [600.0, 450.0],
        "skull2cam": [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 900], [0, 0, 0, 1]],
    }
    subjects = [f"s{k:02d}" for k in range(n_subjects)]
    with ResultStore(path) as store:
        for k, (person, skull) in enumerate((p, s) for p in subjects for s in subjects):
            same = skull == person
            terms = {t: float(rng.normal(0, 1)) for t in TERM_NAMES}
            terms["landmark_chi2"] = float(rng.gamma(2.0, 0.3 if same else 1.0))
            data = {"camera": camera, "identification_terms": terms}
            store.insert(
                dict(experiment="A", method="posest-sfo", variant="", axes_set=0, repetition=0,
                     seed=0, photo=f"{person}_f", subject=skull, view="frontal",
                     true_subject=person, positive=int(same), success=1,
                     score=terms["landmark_chi2"], seconds=0.01, skull_px=100, outside_px=0,
                     percent_outside=0.0,
                     result=json.dumps(data) if result is None else result(k, data))
            )  # fmt: skip
    return path


def toy_dataset(out, seed=3, n_photos=1, image_sizes=((640, 480),), **kwargs):
    """A small generated dataset of two toy-head subjects (fast to make and to run).

    ``n_photos`` frontal (and as many lateral) photos per subject, at ``image_sizes``; other
    keywords go to :func:`lilium.synthetic.dataset.generate_dataset` (``experiments``,
    ``subject_writer``, ``no_mandible_share``, ...). Returns its index.
    """
    from lilium.synthetic.dataset import generate_dataset
    from lilium.synthetic.photos import CameraRanges
    from lilium.synthetic.toyhead import make_toy_subject, write_toy_subject

    kwargs.setdefault("subject_writer", write_toy_subject)
    return generate_dataset(
        out,
        2,
        n_photos,
        seed=seed,
        workers=1,
        ranges=CameraRanges(image_sizes=tuple(image_sizes)),
        subject_factory=make_toy_subject,
        **kwargs,
    )
