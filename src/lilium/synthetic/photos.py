"""Synthetic photographs of a subject's skin mesh with known cameras (docs/method/evaluation.md and
docs/contract.md).

A photo is a render of the skin mesh under a random camera, with the projected facial landmarks
(the visible ones; all of them noise-free in the ground truth), the face mask and the facial
contour curve (chin-jaw in frontal views, forehead in lateral views).

Cameras (defaults of :class:`CameraRanges`, every draw uniform in its interval):

- head orientation ``skull2cam[:3, :3] = R0 @ Ry(yaw) @ Rx(pitch) @ Rz(roll)`` with the axes of the
  skull frame (x = subject's left, y = up, z = anterior) and ``R0 = diag(1, -1, -1)`` (frontal,
  upright: the face looks at the camera, the subject's left on the image's right). Yaw turns the
  head about its vertical axis, pitch nods it, roll tilts it;
- frontal: yaw in [-15, 15] deg; lateral_left (the face points towards the image's left edge,
  -u; the camera sees the subject's left side): yaw in [-95, -75] deg; lateral_right: yaw in
  [75, 95] deg; every view: pitch in [-10, 10] deg, roll in [-5, 5] deg;
- subject-to-camera distance (SCD, camera centre to the facial nasion) in [500, 3000] mm;
- focal length in [1000, 6000] px, principal point at the image centre;
- image size drawn from :data:`IMAGE_SIZES` (640 x 480 to 4000 x 3000, landscape, or portrait
  with probability 1/4);
- the nasion is placed at a pixel drawn uniformly within +-20 % of the image size around its
  centre;
- accepted only when the whole head (the skin above the neck cut, see
  :func:`~.head.head_faces_of`) lies inside the image, at least 8 px from its borders (more
  than the 5 px landmark noise), and is at least 180 px wide; otherwise every parameter is
  drawn again (so the accepted ones are uniform on the feasible set).

Landmark visibility: a landmark is kept in ``photo.json`` when it is at most
``render.VISIBILITY_TOLERANCE_MM`` behind the skin surface seen at its pixel (z-buffer test), so
e.g. the far-side zygion and gonion in a lateral view are dropped. A photo with fewer than
:data:`MIN_VISIBLE_LANDMARKS` visible landmarks usable for pose estimation (lateral views turned
away from the camera hide the midline ones) is drawn again, camera and all.

The head model (the skin above the neck and the jaw-line cuts, the face mask's outline) is
:mod:`lilium.synthetic.head`'s; a photo renders it.
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import VIEWS
from ..fitness import curves as _curves
from ..fitness.curves import check_view
from ..geometry.camera import Camera, principal_point_of
from ..geometry.rotations import rotvec_to_matrix
from ..softtissue.landmarks import FACIAL_TO_CRANIAL
from . import render as _render

#: Common camera image sizes (width, height), landscape.
IMAGE_SIZES = (
    (640, 480),
    (800, 600),
    (1024, 768),
    (1280, 960),
    (1600, 1200),
    (2048, 1536),
    (2592, 1944),
    (3264, 2448),
    (4000, 3000),
)

#: A photo is drawn again until at least this many landmarks with a cranial counterpart are
#: visible (lateral views turned away from the camera can hide all midline landmarks).
MIN_VISIBLE_LANDMARKS = 6
MAX_VISIBILITY_TRIES = 20

#: Frontal head orientation: skull x (left) -> camera x (right), y (up) -> -y, z (anterior) -> -z.
R_FRONTAL = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class CameraRanges:
    """Intervals (degrees, mm, px) the random photo cameras are drawn from."""

    frontal_yaw_deg: tuple = (-15.0, 15.0)
    # Magnitude (lateral_left uses the negative). At most 95 so that, with the pitch, a true
    # camera stays within docs/checks.md's 110 deg of the skull's anterior direction.
    lateral_yaw_deg: tuple = (75.0, 95.0)
    pitch_deg: tuple = (-10.0, 10.0)
    roll_deg: tuple = (-5.0, 5.0)
    scd_mm: tuple = (500.0, 3000.0)
    focal_px: tuple = (1000.0, 6000.0)
    image_sizes: tuple = IMAGE_SIZES
    portrait_probability: float = 0.25
    nasion_offset_fraction: float = 0.2
    min_head_width_px: float = 180.0
    border_px: float = 8.0
    max_tries: int = 5000

    def yaw_range_deg(self, view):
        check_view(view)
        if view == "frontal":
            return self.frontal_yaw_deg
        lo, hi = self.lateral_yaw_deg
        return (-hi, -lo) if view == "lateral_left" else (lo, hi)

    def as_dict(self):
        return {
            "yaw_deg": {v: list(self.yaw_range_deg(v)) for v in VIEWS},
            "pitch_deg": list(self.pitch_deg),
            "roll_deg": list(self.roll_deg),
            "scd_mm": list(self.scd_mm),
            "focal_px": list(self.focal_px),
            "image_sizes_wh": [list(s) for s in self.image_sizes],
            "portrait_probability": self.portrait_probability,
            "nasion_offset_fraction": self.nasion_offset_fraction,
            "min_head_width_px": self.min_head_width_px,
            "border_px": self.border_px,
            "rotation": "R0 @ Ry(yaw) @ Rx(pitch) @ Rz(roll), R0 = diag(1, -1, -1)",
        }


#: Priors of the paper's protocol, centred on the truth: focal +-5 %, SCD +-10 %, head orientation
#: = the true rotation with a 10 degree tolerance.
PRIOR_FOCAL_FRACTION = 0.05
PRIOR_SCD_FRACTION = 0.10
PRIOR_HEAD_TOLERANCE_DEG = 10.0


@dataclass(frozen=True)
class PhotoCamera:
    """A ground-truth photo camera.

    Attributes
    ----------
    view : str
    camera : Camera
        Skull-to-camera transform, focal length, principal point (the image centre).
    image_size_wh : (int, int)
    scd_mm : float
        Camera centre to the facial nasion.
    yaw_deg, pitch_deg, roll_deg : float
    """

    view: str
    camera: Camera
    image_size_wh: tuple
    scd_mm: float
    yaw_deg: float
    pitch_deg: float
    roll_deg: float


@dataclass(frozen=True)
class SyntheticPhoto:
    """One rendered photo with its ground truth.

    Attributes
    ----------
    camera : PhotoCamera
    image : ndarray of shape (H, W, 3), uint8 RGB
    face_mask : ndarray of shape (H, W), bool
    landmarks_uv : dict
        All facial landmarks, noise-free pixel positions ``(2,)``.
    visible : tuple of str
        Names of the landmarks that are visible (kept in ``photo.json``).
    face_curve : dict
        ``{"chin_jaw": (N, 2)}`` or ``{"forehead": (N, 2)}`` pixel curve; empty when the
        landmarks that bound it are missing.
    """

    camera: PhotoCamera
    image: np.ndarray
    face_mask: np.ndarray
    landmarks_uv: dict
    visible: tuple
    face_curve: dict = field(default_factory=dict)


def head_rotation(yaw_deg, pitch_deg, roll_deg):
    """``R0 @ Ry(yaw) @ Rx(pitch) @ Rz(roll)`` (skull-frame axes), see the module notes."""
    y, p, r = np.radians([yaw_deg, pitch_deg, roll_deg])
    return (
        R_FRONTAL
        @ rotvec_to_matrix([0.0, y, 0.0])
        @ rotvec_to_matrix([p, 0.0, 0.0])
        @ rotvec_to_matrix([0.0, 0.0, r])
    )


def sample_camera(head, view, rng, ranges=CameraRanges()):
    """Draw a random camera that sees the whole head, large enough (rejection sampling).

    Parameters
    ----------
    head : lilium.synthetic.head.HeadModel
    view : {"frontal", "lateral_left", "lateral_right"}
    rng : anything ``np.random.default_rng`` accepts
    ranges : CameraRanges

    Returns
    -------
    PhotoCamera

    Raises
    ------
    ValueError
        When no camera in ``ranges`` fits the head after ``ranges.max_tries`` draws.
    """
    check_view(view)
    rng = np.random.default_rng(rng)
    yaw_range = ranges.yaw_range_deg(view)
    for _ in range(ranges.max_tries):
        yaw = rng.uniform(*yaw_range)
        pitch = rng.uniform(*ranges.pitch_deg)
        roll = rng.uniform(*ranges.roll_deg)
        width, height = ranges.image_sizes[rng.integers(len(ranges.image_sizes))]
        if rng.random() < ranges.portrait_probability:
            width, height = height, width
        focal = rng.uniform(*ranges.focal_px)
        scd = rng.uniform(*ranges.scd_mm)
        offset = rng.uniform(-1.0, 1.0, size=2) * ranges.nasion_offset_fraction
        R = head_rotation(yaw, pitch, roll)
        ray = np.array([offset[0] * width / focal, offset[1] * height / focal, 1.0])
        t = scd * ray / np.linalg.norm(ray) - R @ head.nasion_mm
        camera = Camera.from_rt(R, t, focal, principal_point_of((width, height)))
        if np.any(camera.to_camera_frame(head.hull_points_mm)[:, 2] <= 1.0):
            continue
        uv = camera.project(head.hull_points_mm)
        lo, hi = uv.min(axis=0), uv.max(axis=0)
        b = ranges.border_px
        if hi[0] - lo[0] < ranges.min_head_width_px:
            continue
        if lo[0] < b or lo[1] < b or hi[0] > width - 1 - b or hi[1] > height - 1 - b:
            continue
        return PhotoCamera(
            view=view,
            camera=camera,
            image_size_wh=(int(width), int(height)),
            scd_mm=float(camera.distance_mm(head.nasion_mm)),
            yaw_deg=float(yaw),
            pitch_deg=float(pitch),
            roll_deg=float(roll),
        )
    raise ValueError(
        f"no {view} camera within the ranges fits the head after {ranges.max_tries} draws; "
        "widen the focal/SCD/image-size ranges or lower min_head_width_px"
    )


def face_curve_from_mask(mask, view, landmarks_uv):
    """The photo's facial contour curve from its face mask, for ``face_curve.json``.

    The rule of docs/method/lilium.md (:func:`lilium.fitness.curves.face_curve_from_mask`) on the
    mask
    with its holes filled: the chin-jaw between the cheilion u-coordinates (frontal) or the
    forehead between the glabella and metopion v-coordinates (lateral).

    Returns
    -------
    dict
        ``{"chin_jaw": ndarray (N, 2)}`` or ``{"forehead": ndarray (N, 2)}``; ``{}`` when a
        bounding landmark is missing.
    """
    check_view(view)
    if _curves.missing_curve_bounds(view, landmarks_uv):
        return {}
    from scipy import ndimage

    # Holes filled: the jaw-line cut left a few isolated neck triangles under the mouth corners.
    mask = ndimage.binary_fill_holes(mask)
    key = "chin_jaw" if view == "frontal" else "forehead"
    return {key: _curves.face_curve_from_mask(mask, view, landmarks_uv)}


def render_photo(head, camera):
    """Render the head under ``camera``: image, mask, landmarks, visibility, face curve.

    Parameters
    ----------
    head : lilium.synthetic.head.HeadModel
    camera : PhotoCamera

    Returns
    -------
    SyntheticPhoto
    """
    r = _render.render_mesh(
        head.skin_vertices_mm,
        head.skin_faces,
        camera.camera,
        camera.image_size_wh,
        cull_back_faces=head.outward_wound,
    )
    image = _render.shade(r)
    lut = np.append(head.head_faces, False)
    mask = lut[r.face_index]
    visible, uv = _render.visible_points(r, head.facial_points_mm, camera.camera)
    landmarks_uv = {n: uv[i] for i, n in enumerate(head.facial_names)}
    visible_names = tuple(n for i, n in enumerate(head.facial_names) if visible[i])
    jaw_lut = lut if head.jaw_faces is None else np.append(head.jaw_faces, False)
    curve = face_curve_from_mask(jaw_lut[r.face_index], camera.view, landmarks_uv)
    return SyntheticPhoto(camera, image, mask, landmarks_uv, visible_names, curve)


def n_usable_landmarks(photo):
    """Visible facial landmarks that have a cranial counterpart (usable for pose estimation)."""
    return sum(1 for n in photo.visible if n in FACIAL_TO_CRANIAL)


def make_photo(head, view, rng, ranges=CameraRanges(), min_landmarks=MIN_VISIBLE_LANDMARKS):
    """Draw a camera (:func:`sample_camera`) and render the head (:func:`render_photo`).

    The camera is drawn again while fewer than ``min_landmarks`` usable landmarks are visible
    (at most ``MAX_VISIBILITY_TRIES`` renders, then the last one is returned).
    """
    rng = np.random.default_rng(rng)
    for _ in range(MAX_VISIBILITY_TRIES):
        photo = render_photo(head, sample_camera(head, view, rng, ranges))
        if n_usable_landmarks(photo) >= min_landmarks:
            break
    return photo


def photo_views(n_photos, rng=None):
    """Views of a subject's photos: ``n_photos`` frontal then ``n_photos`` lateral, the lateral
    ones alternating left and right (first left), so they split evenly."""
    del rng
    lateral = ["lateral_left" if k % 2 == 0 else "lateral_right" for k in range(n_photos)]
    return ["frontal"] * n_photos + lateral


def priors_of(camera):
    """Priors of the paper's protocol from the true camera (module constants ``PRIOR_*``)."""
    f, d = camera.camera.focal_px, camera.scd_mm
    return {
        "focal_px": [f * (1 - PRIOR_FOCAL_FRACTION), f * (1 + PRIOR_FOCAL_FRACTION)],
        "scd_mm": [d * (1 - PRIOR_SCD_FRACTION), d * (1 + PRIOR_SCD_FRACTION)],
        "head_rotation_skull2cam": camera.camera.R,
        "head_tolerance_deg": PRIOR_HEAD_TOLERANCE_DEG,
    }


def photo_record(photo, subject_id, noise="A", landmarks_uv=None, extra=None, unmarked=()):
    """The ``photo.json`` content of docs/contract.md.

    Parameters
    ----------
    photo : SyntheticPhoto
    subject_id : str
    noise : {"A", "B", "C"}
    landmarks_uv : dict, optional
        The 2D landmarks to give the methods (noisy ones in B/C); defaults to the noise-free
        positions. Only the visible landmarks are written either way.
    extra : dict, optional
        More top-level fields.
    unmarked : sequence of str
        Visible landmarks left out of ``landmarks`` (listed in the ground truth as
        ``"unmarked_landmarks"``; :mod:`lilium.synthetic.incomplete`).

    Returns
    -------
    dict
    """
    given = photo.landmarks_uv if landmarks_uv is None else landmarks_uv
    cam = photo.camera
    marked = [n for n in photo.visible if n not in set(unmarked)]
    record = {
        "view": cam.view,
        "landmarks": {n: np.asarray(given[n], dtype=float) for n in marked},
        "priors": priors_of(cam),
        "ground_truth": {
            "subject": subject_id,
            "skull2cam": cam.camera.skull2cam,
            "focal_px": cam.camera.focal_px,
            "principal_point_px": cam.camera.principal_point_px,
            "scd_mm": cam.scd_mm,
            "noise": noise,
            "landmarks_noise_free": photo.landmarks_uv,
            "visible_landmarks": list(photo.visible),
            "image_size": list(cam.image_size_wh),
            "head_angles_deg": {
                "yaw": cam.yaw_deg,
                "pitch": cam.pitch_deg,
                "roll": cam.roll_deg,
            },
        },
    }
    if unmarked:
        record["ground_truth"]["unmarked_landmarks"] = list(unmarked)
    if extra:
        record.update(extra)
    return record
