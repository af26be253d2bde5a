"""One photograph in, the automatic face analysis out (no files: see :mod:`.prepare`)."""

from dataclasses import dataclass, field

import cv2
import numpy as np

from . import runtime
from .headpose import euler_deg, face_rotation_face2cam
from .landmarks import mesh_to_landmarks
from .mask import head_crop_box, head_mask, segmentation_input

#: Smallest face (detection box side, pixels) the mesh model is trusted on.
MIN_FACE_PX = 40
#: Beyond this yaw (degrees) the face is called lateral when no view is given.
LATERAL_YAW_DEG = 30.0
#: A copy of the photo turned by 90, 180 or 270 degrees is taken as the upright one only when
#: its best face scores this much more than the photo as it is (the mesh model fits an upright
#: template whatever it is given: an upside-down face gets upright landmarks, roll 0).
TURN_SCORE_MARGIN = 0.1
#: ... and at least this score: on photos without a face the detector's false alarms (a cup, a
#: cat: 0.5-0.6) would otherwise turn them (measured on scikit-image's sample pictures).
TURN_MIN_SCORE = 0.75
#: A detection is listed as a face when the mesh model, run on its crop, says a face is there
#: (presence >= ``runtime.MIN_PRESENCE_SCORE``) and either the detector is sure of it (this
#: score) or the mesh model is (:data:`SURE_PRESENCE`). Measured on scikit-image's pictures
#: without a face enlarged to 12 MP, where the multi-scale search raises 0.5-0.75 false alarms
#: (galaxies, a cat, a rocket): their presence is under 0.1 but one at 0.68 (score 0.59); real
#: faces of 40-500 px scored 0.58-0.97 with presence 1.00.
SURE_DETECTION_SCORE = 0.75
SURE_PRESENCE = 0.9
#: MEPROCS's minimum resolution for a craniofacial superimposition: the pupils this far apart
#: (iris centres, px) ...
MIN_INTERPUPILLARY_PX = 90.0
#: ... and the head this wide (px; here the face mesh's width, ear to ear at the cheeks).
MIN_HEAD_WIDTH_PX = 180.0


@dataclass(frozen=True)
class Face:
    """One face found in the photo.

    Attributes
    ----------
    number : int
        1 = the leftmost (box centre), as ``--face`` counts.
    box_uv : ndarray of shape (4,)
        ``[u_min, v_min, u_max, v_max]`` pixels.
    score : float
        The detector's.
    keypoints_uv : ndarray of shape (6, 2)
        The detector's eyes, nose tip, mouth and ears.
    """

    number: int
    box_uv: np.ndarray
    score: float
    keypoints_uv: np.ndarray

    @property
    def width_px(self):
        return float(self.box_uv[2] - self.box_uv[0])

    def to_json(self):
        """``photo.json``'s entry: ``number``, ``box_px``, ``width_px``, ``score``."""
        return {
            "number": self.number,
            "box_px": [round(float(x), 1) for x in self.box_uv],
            "width_px": round(self.width_px, 1),
            "score": round(self.score, 3),
        }

    def text(self):
        u0, v0, u1, v1 = (int(round(x)) for x in self.box_uv)
        return f"box u {u0}-{u1}, v {v0}-{v1} px, {self.width_px:.0f} px wide"


@dataclass(frozen=True)
class FaceAnalysis:
    """What the models found on one photo; falsy (with a ``message``) when no face was found.

    Attributes
    ----------
    message : str
        Empty on success; otherwise why no face was found and what to do.
    mesh_xyz : ndarray of shape (468, 3) or None
        Mesh points (u, v, depth) pixels.
    landmarks : dict of str -> ndarray of shape (2,)
    sources : dict of str -> dict
        ``landmark_sources`` of docs/method/photo.md.
    face2cam : ndarray of shape (3, 3) or None
        Face-frame orientation (:mod:`.headpose`).
    angles_deg : dict
        ``yaw``, ``pitch``, ``roll``.
    iris_diameter_px : float or None
        Mean of both eyes.
    mask : ndarray of shape (H, W), bool, or None
    detection_score : float
    faces : tuple of Face
        Every face found (:func:`find_faces`), also when the one taken could not be analysed.
    face_number : int
        The face taken (``Face.number``); 0 when none was.
    interpupillary_px : float or None
        Distance between the iris centres.
    head_width_px : float or None
        The face mesh's width (:func:`mesh_width_px`).
    """

    message: str = ""
    mesh_xyz: np.ndarray | None = None
    landmarks: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    face2cam: np.ndarray | None = None
    angles_deg: dict = field(default_factory=dict)
    iris_diameter_px: float | None = None
    mask: np.ndarray | None = None
    detection_score: float = 0.0
    faces: tuple = ()
    face_number: int = 0
    interpupillary_px: float | None = None
    head_width_px: float | None = None

    @property
    def several_faces(self):
        """One line naming the face taken, by its box and size, and how to take each other
        ("" for one face)."""
        if len(self.faces) < 2:
            return ""
        others = ", ".join(
            f"--face {f.number} for {f.text()}" for f in self.faces if f.number != self.face_number
        )
        taken = self.faces[self.face_number - 1].text() if self.face_number else "none"
        return (
            f"{len(self.faces)} faces in the photo (numbered from the left): took face "
            f"{self.face_number} at {taken}; give {others}"
        )

    @property
    def resolution(self):
        """``photo.json``'s ``resolution``: ``interpupillary_px`` (iris centres) and
        ``head_width_px`` (the face mesh's width); empty without a face."""
        if self.interpupillary_px is None:
            return {}
        return {
            "interpupillary_px": round(self.interpupillary_px, 1),
            "head_width_px": round(self.head_width_px, 1),
            "head_width_from": "face mesh (ear to ear at the cheeks)",
        }

    @property
    def low_resolution(self):
        """One line naming the figures under MEPROCS's minimum ("" when both reach it)."""
        if self.interpupillary_px is None:
            return ""
        low = []
        if self.interpupillary_px < MIN_INTERPUPILLARY_PX:
            low.append(
                f"{self.interpupillary_px:.0f} px between the pupils (minimum "
                f"{MIN_INTERPUPILLARY_PX:.0f})"
            )
        if self.head_width_px < MIN_HEAD_WIDTH_PX:
            low.append(
                f"{self.head_width_px:.0f} px across the head (minimum {MIN_HEAD_WIDTH_PX:.0f})"
            )
        if not low:
            return ""
        return (
            f"the face is below MEPROCS's minimum resolution for a superimposition: "
            f"{' and '.join(low)}; use the original photograph or a larger scan"
        )

    def __bool__(self):
        return not self.message

    @property
    def view(self):
        """``frontal`` or the lateral view the yaw suggests (docs/contract.md: lateral_left faces
        -u)."""
        yaw = self.angles_deg.get("yaw", 0.0)
        if abs(yaw) < LATERAL_YAW_DEG:
            return "frontal"
        return "lateral_left" if yaw > 0 else "lateral_right"


def find_faces(image):
    """The faces in a photo, numbered from the left.

    Every detection of :func:`lilium.photo.runtime.detect_faces` (all sizes from about 60 px,
    :data:`lilium.photo.runtime.SMALL_FACE_PX`, whatever the photo's size) that the mesh model
    confirms on its crop (:data:`SURE_DETECTION_SCORE`, :data:`SURE_PRESENCE`).

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB

    Returns
    -------
    tuple of Face
        Sorted by the box centre's u; ``number`` 1 = the leftmost.
    """
    kept = []
    for score, box, keypoints in runtime.detect_faces(image):
        _, presence = runtime.face_mesh(image, runtime.face_crop(box, keypoints))
        if presence >= runtime.MIN_PRESENCE_SCORE and (
            score >= SURE_DETECTION_SCORE or presence >= SURE_PRESENCE
        ):
            kept.append((score, box, keypoints))
    kept.sort(key=lambda f: f[1][0] + f[1][2])
    return tuple(Face(k + 1, box, score, kp) for k, (score, box, kp) in enumerate(kept))


def upright_turns(image, faces=None):
    """How many quarter turns (counter-clockwise, ``np.rot90``) put the face upright: 0 unless a
    turned copy's best face scores :data:`TURN_SCORE_MARGIN` above the photo's own, and at least
    :data:`TURN_MIN_SCORE`.

    ``faces``: the photo's own (:func:`find_faces`), if already found. The turned copies are
    searched whole only (``pyramid=False``: faces of about 15 % of the long side and up), so a
    group photo stored on its side is turned only by its EXIF tag.
    """
    faces = find_faces(image) if faces is None else faces
    own = max((f.score for f in faces), default=0.0)
    best_k, best = 0, max(own + TURN_SCORE_MARGIN, TURN_MIN_SCORE)
    # The whole-photo search shows the photo 128 px long: turn that, not the full photo.
    h, w = image.shape[:2]
    scale = runtime.DETECTOR_INPUT_PX / max(h, w)
    if scale < 1:
        size = (max(1, round(w * scale)), max(1, round(h * scale)))
        step = max(1, max(h, w) // (4 * runtime.DETECTOR_INPUT_PX))  # every step-th pixel first
        image = cv2.resize(image[::step, ::step], size, interpolation=cv2.INTER_AREA)
    for k in (1, 2, 3):
        turned = runtime.detect_faces(np.ascontiguousarray(np.rot90(image, k)), pyramid=False)
        if turned and turned[0][0] > best:
            best_k, best = k, turned[0][0]
    return best_k


def _not_found(why, faces=(), number=0):
    return FaceAnalysis(
        message=f"no face found ({why}); the folder is written without automatic landmarks: "
        "mark them by hand (review.html) and pass the file with --landmarks",
        faces=tuple(faces),
        face_number=number,
    )


def analyse_face(image, face=None, faces=None):
    """Run detection, mesh, iris and segmentation on one image.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
        Upright (EXIF orientation applied).
    face : int, optional
        Which face (1 = the leftmost) of a photo with several; default the most confident of
        those :data:`MIN_FACE_PX` wide or more (of all, if none is).
    faces : tuple of Face, optional
        :func:`find_faces` of this image, if already found.

    Returns
    -------
    FaceAnalysis
        Falsy with a message when the detector finds no face (a profile beyond about 60
        degrees of yaw, a tiny or occluded face) or the mesh model rejects the crop.
    """
    faces = find_faces(image) if faces is None else tuple(faces)
    if not faces:
        return _not_found("the detector saw none: a profile, a tiny or an occluded face")
    if face is None:
        large = [f for f in faces if f.width_px >= MIN_FACE_PX] or faces
        chosen = max(large, key=lambda f: f.score)
    elif 1 <= face <= len(faces):
        chosen = faces[face - 1]
    else:
        raise ValueError(
            f"--face {face}: the photo has {len(faces)} face(s); give a number from 1 to "
            f"{len(faces)} (numbered from the left)"
        )
    box, keypoints = chosen.box_uv, chosen.keypoints_uv
    if np.max(box[2:] - box[:2]) < MIN_FACE_PX:
        return _not_found(
            f"the face is under {MIN_FACE_PX} px; use a larger photo or a crop",
            faces,
            chosen.number,
        )
    mesh, presence = runtime.face_mesh(image, runtime.face_crop(box, keypoints))
    if presence < runtime.MIN_PRESENCE_SCORE:
        return _not_found("the face-mesh model rejected the detected face", faces, chosen.number)
    # A second pass on the crop the first mesh gives (MediaPipe's tracking ROI) is steadier.
    refined, presence = runtime.face_mesh(image, runtime.mesh_crop(mesh))
    if presence >= runtime.MIN_PRESENCE_SCORE:
        mesh = refined
    landmarks, sources = mesh_to_landmarks(mesh)
    face2cam = face_rotation_face2cam(mesh)
    yaw, pitch, roll = euler_deg(face2cam)
    irises = runtime.iris(image, mesh)
    iris_px = float(np.mean([2 * r for _, r in irises.values()]))
    interpupillary = float(np.linalg.norm(irises["left"][0] - irises["right"][0]))
    mask = segmented_head_mask(image, mesh)
    return FaceAnalysis(
        mesh_xyz=mesh,
        landmarks=landmarks,
        sources=sources,
        face2cam=face2cam,
        angles_deg={"yaw": yaw, "pitch": pitch, "roll": roll},
        iris_diameter_px=iris_px,
        mask=mask,
        detection_score=chosen.score,
        faces=faces,
        face_number=chosen.number,
        interpupillary_px=interpupillary,
        head_width_px=mesh_width_px(mesh),
    )


def segmented_head_mask(image, mesh_xyz):
    """:func:`.mask.head_mask` from two person segmentations of :func:`.mask.segmentation_input`:
    the whole photo, and the crop around the head (:func:`.mask.head_crop_box`)."""
    seg = segmentation_input(image)
    u0, v0, u1, v1 = head_crop_box(mesh_xyz, image.shape[:2])
    crown = np.zeros(image.shape[:2], np.float32)
    if u1 > u0 and v1 > v0:
        crown[v0:v1, u0:u1] = runtime.person_mask(np.ascontiguousarray(seg[v0:v1, u0:u1]))
    return head_mask(runtime.person_mask(seg), mesh_xyz, crown_prob=crown)


def mesh_width_px(mesh_xyz):
    """The face mesh's width (px) along the line through the eyes' outer corners: ear to ear at
    the cheeks, the head's width without its hair."""
    axis = mesh_xyz[263, :2] - mesh_xyz[33, :2]
    axis = axis / np.linalg.norm(axis)
    along = mesh_xyz[:, :2] @ axis
    return float(along.max() - along.min())
