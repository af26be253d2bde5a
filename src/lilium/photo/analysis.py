"""One photograph in, the automatic face analysis out (no files: see :mod:`.prepare`)."""

from dataclasses import dataclass, field

import numpy as np

from . import runtime
from .headpose import euler_deg, face_rotation_face2cam
from .landmarks import mesh_to_landmarks
from .mask import head_mask, segmentation_input

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
    face_boxes: tuple = ()
    face_index: int = 0

    @property
    def several_faces(self):
        """One line naming the face taken, by its box, and how to take another ("" for one)."""
        n = len(self.face_boxes)
        if n < 2:
            return ""
        boxes = [_box_text(b) for b in self.face_boxes]
        others = ", ".join(
            f"--face {k + 1} for {boxes[k]}" for k in range(n) if k != self.face_index
        )
        return (
            f"{n} faces in the photo (numbered from the left): took face {self.face_index + 1} "
            f"at {boxes[self.face_index]}; give {others}"
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


def _box_text(box):
    u0, v0, u1, v1 = (int(round(x)) for x in box)
    return f"box u {u0}-{u1}, v {v0}-{v1} px"


def upright_turns(image):
    """How many quarter turns (counter-clockwise, ``np.rot90``) put the face upright: 0 unless a
    turned copy's best face scores :data:`TURN_SCORE_MARGIN` above the photo's own, and at least
    :data:`TURN_MIN_SCORE`."""
    found = runtime.detect_face(image)
    own = found[0] if found else 0.0
    best_k, best = 0, max(own + TURN_SCORE_MARGIN, TURN_MIN_SCORE)
    for k in (1, 2, 3):
        turned = runtime.detect_face(np.ascontiguousarray(np.rot90(image, k)))
        if turned is not None and turned[0] > best:
            best_k, best = k, turned[0]
    return best_k


def _not_found(why):
    return FaceAnalysis(
        message=f"no face found ({why}); the folder is written without automatic landmarks: "
        "mark them by hand (review.html) and pass the file with --landmarks"
    )


def analyse_face(image, face=None):
    """Run detection, mesh, iris and segmentation on one image.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
        Upright (EXIF orientation applied).
    face : int, optional
        Which face (1 = the leftmost) of a photo with several; default the most confident.

    Returns
    -------
    FaceAnalysis
        Falsy with a message when the detector finds no face (a profile beyond about 60
        degrees of yaw, a tiny or occluded face) or the mesh model rejects the crop.
    """
    faces = runtime.detect_faces(image)
    if not faces:
        return _not_found("the detector saw none: a profile, a tiny or an occluded face")
    by_u = sorted(range(len(faces)), key=lambda k: faces[k][1][0] + faces[k][1][2])
    if face is None:
        index = by_u.index(0)
    elif 1 <= face <= len(faces):
        index = face - 1
    else:
        raise ValueError(
            f"--face {face}: the photo has {len(faces)} face(s); give a number from 1 to "
            f"{len(faces)} (numbered from the left)"
        )
    score, box, keypoints = faces[by_u[index]]
    boxes = tuple(faces[k][1] for k in by_u)
    if np.max(box[2:] - box[:2]) < MIN_FACE_PX:
        return _not_found(f"the face is under {MIN_FACE_PX} px; use a larger photo or a crop")
    mesh, presence = runtime.face_mesh(image, runtime.face_crop(box, keypoints))
    if presence < runtime.MIN_PRESENCE_SCORE:
        return _not_found("the face-mesh model rejected the detected face")
    # A second pass on the crop the first mesh gives (MediaPipe's tracking ROI) is steadier.
    refined, presence = runtime.face_mesh(image, runtime.mesh_crop(mesh))
    if presence >= runtime.MIN_PRESENCE_SCORE:
        mesh = refined
    landmarks, sources = mesh_to_landmarks(mesh)
    face2cam = face_rotation_face2cam(mesh)
    yaw, pitch, roll = euler_deg(face2cam)
    irises = runtime.iris(image, mesh)
    iris_px = float(np.mean([2 * r for _, r in irises.values()]))
    mask = head_mask(runtime.person_mask(segmentation_input(image)), mesh)
    return FaceAnalysis(
        mesh_xyz=mesh,
        landmarks=landmarks,
        sources=sources,
        face2cam=face2cam,
        angles_deg={"yaw": yaw, "pitch": pitch, "roll": roll},
        iris_diameter_px=iris_px,
        mask=mask,
        detection_score=score,
        face_boxes=boxes,
        face_index=index,
    )
