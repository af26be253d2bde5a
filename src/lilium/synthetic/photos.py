"""Synthetic photographs of a subject's skin mesh with known cameras (SPEC sections 7 and 8).

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
- accepted only when the whole head (the skin above the neck cut, see :func:`head_faces_of`) lies
  inside the image, at least 8 px from its borders (more than the 5 px landmark noise), and is
  at least 180 px wide; otherwise every parameter is drawn again (so the accepted ones are
  uniform on the feasible set).

Landmark visibility: a landmark is kept in ``photo.json`` when it is at most
``render.VISIBILITY_TOLERANCE_MM`` behind the skin surface seen at its pixel (z-buffer test), so
e.g. the far-side zygion and gonion in a lateral view are dropped. A photo with fewer than
:data:`MIN_VISIBLE_LANDMARKS` visible landmarks usable for pose estimation (lateral views turned
away from the camera hide the midline ones) is drawn again, camera and all.

Two cuts of the skin (see :func:`head_faces_of`): in front of the gonia a plane through the facial
gnathion and both facial gonia (the lower border of the jaw), behind them the horizontal plane
through the gonia. The *jaw-line cut* lowers them by :data:`NECK_CUT_MARGIN_MM`, and under the chin
(in front of the gonia, more than :data:`JAW_BELOW_MOUTH_MM` below the mouth corners, at most
:data:`JAW_BEYOND_MOUTH_MM` beyond them sideways) it follows the mandible instead of the plane: skin
hanging below the bone farther than the subject's chin depth + :data:`JAW_CUT_MARGIN_MM` is neck
(:data:`JAW_BELOW_ANGLE_DEG`).
The skin above it is the face's own outline, from which the chin-jaw curve of ``face_curve.json`` is
taken (SPEC 5's mask rule applied to that outline). A plane there would be seen nearly edge-on from
the front, so the facial chin-jaw curve would be a flat line whatever the jaw's shape, while the
bony chin's outline is a U: the true skull's own P_pll was then large (issue 20, measured in
docs/method.md); following the bone keeps the skin's chin outline as curved as the real one
(``benchmarks/chin_profile.py``).

The *face mask* keeps the upper neck too: its cut lies :data:`NECK_SKULL_CLEARANCE_MM` below the
whole skull, so that, as in a real photo of a head, the true skull projects inside the mask from
every camera of the ranges (P_skof 0 at the truth). Both cuts are properties of the subject, the
same in every photo.
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import VIEWS
from ..fitness import curves as _curves
from ..fitness.curves import check_view
from ..geometry.camera import Camera, principal_point_of
from ..geometry.rotations import rotvec_to_matrix
from ..io.mesh import import_trimesh
from ..softtissue.depths import BUILTIN_DEPTHS
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

#: How far (mm) the jaw-line cut is lowered below the jaw border / the gonia (the face outline).
NECK_CUT_MARGIN_MM = 4.0

#: Under the chin the jaw-line cut follows the mandible: a skin point more than
#: ``JAW_BELOW_MOUTH_MM`` below the mouth corners and at most ``JAW_BEYOND_MOUTH_MM`` beyond them
#: sideways (the chin, where the facial curve is taken) is neck when it lies below its nearest bone
#: vertex (within ``JAW_BELOW_ANGLE_DEG`` of straight down) and farther from it than the
#: subject's own chin depth (facial gnathion to the nearest bone vertex, ``JAW_DEPTH_FALLBACK_MM``
#: without a facial gnathion) plus ``JAW_CUT_MARGIN_MM``: the outline then follows the bone, as
#: in a real head (``benchmarks/chin_profile.py``), one chin depth below it under the midline and
#: up to the margin deeper at the sides.
#: The 4 mm margin: closer, the cut runs through the chin's own skin and its triangles leave a
#: ragged outline (at 2 mm the true skull had P_int > 0 at its true camera on 3 of 8 frontal
#: photos of seed 0, at 1 mm on 2; none at 4 mm).
JAW_BELOW_ANGLE_DEG = 60.0
JAW_BELOW_MOUTH_MM = 10.0
JAW_BEYOND_MOUTH_MM = 5.0
JAW_CUT_MARGIN_MM = 4.0
JAW_DEPTH_FALLBACK_MM = BUILTIN_DEPTHS["gnathion"].mean_mm

#: How far (mm) below the skull the face mask's neck cut lies: with pitch, the skin under the
#: jaw covers the mandible's lower border in the image, so a cut just under the bone would drop
#: pixels the true skull projects onto.
NECK_SKULL_CLEARANCE_MM = 20.0

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
    # camera stays within SPEC 10's 110 deg of the skull's anterior direction.
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
class HeadModel:
    """A subject's skin mesh prepared for photographing.

    Attributes
    ----------
    skin_vertices_mm : ndarray of shape (V, 3)
    skin_faces : ndarray of shape (F, 3)
    head_faces : ndarray of shape (F,), bool
        Triangles above the neck cut (they make the face mask).
    jaw_faces : ndarray of shape (F,), bool or None
        Triangles above the jaw-line cut (the face's own outline, for the chin-jaw curve);
        None = ``head_faces``.
    hull_points_mm : ndarray of shape (K, 3)
        Convex-hull vertices of the head part (their projection bounds the head's).
    facial_names : tuple of str
    facial_points_mm : ndarray of shape (L, 3)
    nasion_mm : ndarray of shape (3,)
        Facial nasion (centroid of the facial landmarks when absent): the SCD reference.
    outward_wound : bool
        The skin faces are consistently wound with outward normals (flipped here if they were
        inward), so back faces can be culled when rendering.
    """

    skin_vertices_mm: np.ndarray
    skin_faces: np.ndarray
    head_faces: np.ndarray
    hull_points_mm: np.ndarray
    facial_names: tuple
    facial_points_mm: np.ndarray
    nasion_mm: np.ndarray
    outward_wound: bool = False
    jaw_faces: np.ndarray | None = None


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


def _neck_planes(facial_landmarks):
    """Signed heights (mm) above the jaw plane and above the gonion plane, as functions."""
    gl = np.asarray(facial_landmarks["gonion_l"], dtype=float)
    gr = np.asarray(facial_landmarks["gonion_r"], dtype=float)
    gonion_y = 0.5 * (gl[1] + gr[1])
    gonion_z = 0.5 * (gl[2] + gr[2])
    if "gnathion" in facial_landmarks:
        gn = np.asarray(facial_landmarks["gnathion"], dtype=float)
        normal = np.cross(gl - gn, gr - gn)
        if normal[1] < 0:
            normal = -normal
        normal /= np.linalg.norm(normal)
    else:
        gn, normal = np.array([0.0, gonion_y, 0.0]), np.array([0.0, 1.0, 0.0])

    def heights(points):
        points = np.asarray(points, dtype=float)
        anterior = points[:, 2] > gonion_z
        return anterior, (points - gn) @ normal, points[:, 1] - gonion_y

    return heights


def head_faces_of(
    skin_vertices_mm,
    skin_faces,
    facial_landmarks,
    margin_mm=NECK_CUT_MARGIN_MM,
    skull_vertices_mm=None,
    jaw_bone_mm=None,
):
    """Which skin triangles belong to the head (above the neck cut, see the module notes).

    Parameters
    ----------
    skin_vertices_mm : array_like of shape (V, 3)
    skin_faces : array_like of shape (F, 3), int
    facial_landmarks : dict
        Needs ``gonion_l``, ``gonion_r`` (and ``gnathion`` for the jaw plane); without the gonia
        every triangle counts as head.
    margin_mm : float
        How far the cut planes are lowered at least.
    skull_vertices_mm : array_like of shape (K, 3), optional
        When given, each plane is lowered further where needed so that the whole skull lies
        at least ``margin_mm`` above it.
    jaw_bone_mm : array_like of shape (K, 3), optional
        The complete skull's vertices: under the chin the cut follows this bone (the jaw-line
        cut, see the module notes; needs both cheilions).

    Returns
    -------
    head : ndarray of shape (F,), bool
    """
    vertices = np.asarray(skin_vertices_mm, dtype=float)
    faces = np.asarray(skin_faces, dtype=np.int64)
    centroids = vertices[faces].mean(axis=1)
    if "gonion_l" not in facial_landmarks or "gonion_r" not in facial_landmarks:
        return np.ones(len(faces), dtype=bool)
    heights = _neck_planes(facial_landmarks)
    margin_jaw = margin_gonia = margin_mm
    if skull_vertices_mm is not None:
        anterior, jaw, gonia = heights(skull_vertices_mm)
        if anterior.any():
            margin_jaw = max(margin_mm, margin_mm - jaw[anterior].min())
        if (~anterior).any():
            margin_gonia = max(margin_mm, margin_mm - gonia[~anterior].min())
    anterior, jaw, gonia = heights(centroids)
    neck = np.where(anterior, jaw < -margin_jaw, gonia < -margin_gonia)
    has_bone = jaw_bone_mm is not None and len(jaw_bone_mm) > 0
    if has_bone and {"cheilion_l", "cheilion_r"} <= set(facial_landmarks):
        left, right = (np.asarray(facial_landmarks[n], float) for n in ("cheilion_l", "cheilion_r"))
        half_width_mm = 0.5 * abs(left[0] - right[0]) + JAW_BEYOND_MOUTH_MM
        chin = (
            anterior
            & (centroids[:, 1] < min(left[1], right[1]) - JAW_BELOW_MOUTH_MM)
            & (np.abs(centroids[:, 0] - 0.5 * (left[0] + right[0])) < half_width_mm)
        )
        neck[chin] = _below_jaw_bone(centroids[chin], jaw_bone_mm, facial_landmarks)
    return ~neck


def _below_jaw_bone(points_mm, bone_vertices_mm, facial_landmarks):
    """Which points hang below the bone deeper than the chin's soft tissue (the jaw-line cut
    under the chin, see :data:`JAW_BELOW_ANGLE_DEG`).

    Parameters
    ----------
    points_mm : ndarray of shape (N, 3)
    bone_vertices_mm : array_like of shape (K, 3), K >= 1
    facial_landmarks : dict
        Its ``gnathion`` sets the chin depth (distance to the nearest bone vertex).

    Returns
    -------
    ndarray of shape (N,), bool
    """
    from scipy.spatial import cKDTree

    bone = np.asarray(bone_vertices_mm, dtype=float)
    tree = cKDTree(bone)
    depth_mm = JAW_DEPTH_FALLBACK_MM
    if "gnathion" in facial_landmarks:
        depth_mm = float(tree.query(np.asarray(facial_landmarks["gnathion"], dtype=float))[0])
    distance_mm, index = tree.query(points_mm)
    offset_mm = points_mm - bone[index]
    below = -offset_mm[:, 1] > np.cos(np.radians(JAW_BELOW_ANGLE_DEG)) * distance_mm
    return below & (distance_mm > depth_mm + JAW_CUT_MARGIN_MM)


def prepare_head(subject):
    """A :class:`HeadModel` from a subject (``skin_vertices_mm``, ``skin_faces``,
    ``facial_landmarks``; the mask's neck cut clears ``head_skull_vertices_mm``, the complete
    skull of a subject whose skull lacks the mandible, or else ``skull_vertices_mm``)."""
    from scipy.spatial import ConvexHull

    trimesh = import_trimesh()

    vertices = np.asarray(subject.skin_vertices_mm, dtype=float)
    faces = np.asarray(subject.skin_faces, dtype=np.int64)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    outward = bool(mesh.is_winding_consistent)
    if outward and mesh.volume < 0:
        faces = faces[:, ::-1].copy()
    facial = {k: np.asarray(v, dtype=float) for k, v in subject.facial_landmarks.items()}
    if not facial:
        raise ValueError("the subject has no facial landmarks; a photo needs them")
    skull = getattr(subject, "head_skull_vertices_mm", None)  # the complete skull, if not given
    skull = getattr(subject, "skull_vertices_mm", None) if skull is None else skull
    jaw = head_faces_of(vertices, faces, facial, jaw_bone_mm=skull)
    head = jaw
    if skull is not None:
        head = head_faces_of(vertices, faces, facial, NECK_SKULL_CLEARANCE_MM, skull)
        jaw = jaw & head  # the facial curve's skin lies inside the face mask
    head_points = vertices[np.unique(faces[head])]
    hull = head_points[ConvexHull(head_points).vertices]
    names = tuple(facial)
    points = np.array([facial[n] for n in names])
    nasion = facial["nasion"] if "nasion" in facial else points.mean(axis=0)
    return HeadModel(vertices, faces, head, hull, names, points, nasion, outward, jaw)


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
    head : HeadModel
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

    The rule of SPEC section 5 (:func:`lilium.fitness.curves.face_curve_from_mask`) on the mask
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
    head : HeadModel
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
    """The ``photo.json`` content of SPEC section 8.

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
