"""The four MediaPipe models shipped in ``lilium/photo/models`` run with LiteRT (one core).

Face detection (BlazeFace, short range) -> a square, eye-aligned crop -> the 468-point face
mesh -> one crop per eye -> iris landmarks; selfie segmentation on the whole frame gives the
person mask. The pre- and post-processing follows MediaPipe's legacy CPU graphs
(``face_detection_short_range``, ``face_landmark_front``, ``iris_landmark_left_and_right``,
``selfie_segmentation``); nothing is downloaded, the optional dependency is
``ai-edge-litert`` (``pip install 'lilium[photo]'``).

Image coordinates are ``uv`` (column, row) pixels of the original image, the centre of the
top-left pixel at (0, 0) (docs/contract.md).
"""

import contextlib
import os
import sys
from dataclasses import dataclass
from functools import cache
from importlib import resources

import cv2
import numpy as np

#: Minimum BlazeFace score for a face (MediaPipe's default ``min_detection_confidence``).
MIN_DETECTION_SCORE = 0.5
#: Minimum face-presence score of the mesh model on its crop.
MIN_PRESENCE_SCORE = 0.5
#: Face crop side over the detection box's long side (MediaPipe's ROI scale).
FACE_CROP_SCALE = 1.5
#: Eye crop side over the eye-corner distance (MediaPipe's iris ROI scale).
EYE_CROP_SCALE = 2.3
#: MediaPipe mesh indices of the eye corners (outer, inner) for the subject's right / left eye.
RIGHT_EYE_CORNERS = (33, 133)
LEFT_EYE_CORNERS = (263, 362)

MODEL_FILES = {
    "detector": "face_detection_short_range.tflite",
    "mesh": "face_landmark.tflite",
    "iris": "iris_landmark.tflite",
    "segmentation": "selfie_segmentation.tflite",
}


def _interpreter_class():
    try:
        from ai_edge_litert.interpreter import Interpreter
    except ImportError:
        raise ValueError(
            "automatic photo preparation needs the LiteRT runtime; install it with "
            "pip install 'lilium[photo]' (ai-edge-litert)"
        ) from None
    return Interpreter


def check_runtime():
    """Raise the one-line ``ValueError`` naming ``pip install 'lilium[photo]'`` when LiteRT
    (``ai-edge-litert``) is not installed; nothing is loaded."""
    _interpreter_class()


@contextlib.contextmanager
def _quiet_stderr():
    """Silence file descriptor 2 (the runtime's own C++ logging, e.g. "INFO: Created TensorFlow
    Lite XNNPACK delegate for CPU.") for the block; Python's ``sys.stderr`` is flushed first."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):  # no real fd 2 (embedded): nothing to silence
        yield
        return
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


@cache
def _model(kind):
    path = resources.files("lilium.photo") / "models" / MODEL_FILES[kind]
    interpreter_class = _interpreter_class()
    with _quiet_stderr():
        interpreter = interpreter_class(model_content=path.read_bytes(), num_threads=1)
        interpreter.allocate_tensors()
    return interpreter


def _run(kind, tensor):
    it = _model(kind)
    it.set_tensor(it.get_input_details()[0]["index"], tensor[None].astype(np.float32))
    it.invoke()
    return [it.get_tensor(d["index"])[0] for d in it.get_output_details()]


@cache
def _anchors():
    """BlazeFace short-range SSD anchors, ``(896, 2)`` centres in the unit square."""
    rows = []
    for stride, per_cell in ((8, 2), (16, 6)):
        n = 128 // stride
        y, x = np.mgrid[0:n, 0:n]
        centres = np.stack([(x.ravel() + 0.5) / n, (y.ravel() + 0.5) / n], axis=1)
        rows.append(np.repeat(centres, per_cell, axis=0))
    return np.concatenate(rows)


@dataclass(frozen=True)
class Crop:
    """A square, rotated crop: ``uv = centre + R(angle) @ (crop_px / size * side - side / 2)``.

    Attributes
    ----------
    centre_uv : ndarray of shape (2,)
    side_px : float
        Side of the crop in image pixels.
    angle_rad : float
        Rotation of the crop's axes in the image (counter-clockwise on screen is negative).
    """

    centre_uv: np.ndarray
    side_px: float
    angle_rad: float

    def matrix(self, size):
        """The ``2 x 3`` affine map crop pixels (0..size) -> image ``uv``."""
        c, s = np.cos(self.angle_rad), np.sin(self.angle_rad)
        scale = self.side_px / size
        rot = scale * np.array([[c, -s], [s, c]])
        offset = self.centre_uv - rot @ np.array([size / 2, size / 2])
        return np.hstack([rot, offset[:, None]])

    def sample(self, image, size, flip=False):
        """The crop resampled to ``(size, size, 3)`` float in [0, 1] (optionally mirrored)."""
        forward = self.matrix(size)
        patch = cv2.warpAffine(
            image,
            forward,
            (size, size),
            flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
            borderMode=cv2.BORDER_CONSTANT,
        )
        patch = patch[:, ::-1] if flip else patch
        return patch.astype(np.float32) / 255.0

    def to_image(self, points, size, flip=False):
        """Crop points ``(N, 2+)`` -> image ``uv``; a third column (depth) is scaled alike."""
        points = np.array(points, dtype=float)
        if flip:
            points[:, 0] = size - points[:, 0]
        out = points.copy()
        out[:, :2] = points[:, :2] @ self.matrix(size)[:, :2].T + self.matrix(size)[:, 2]
        if points.shape[1] > 2:
            out[:, 2] = points[:, 2] * self.side_px / size
        return out


def detect_faces(image):
    """Every face the detector finds, most confident first.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB

    Returns
    -------
    list of tuple (score, box_uv (4,) as [u_min, v_min, u_max, v_max], keypoints_uv (6, 2))
        Keypoints: subject's right eye, left eye, nose tip, mouth, right ear, left ear. The
        overlapping boxes of one face are averaged (MediaPipe's weighted suppression).
    """
    h, w = image.shape[:2]
    side = max(h, w)
    pad_v, pad_u = (side - h) // 2, (side - w) // 2
    square = np.zeros((side, side, 3), np.uint8)
    square[pad_v : pad_v + h, pad_u : pad_u + w] = image
    tensor = cv2.resize(square, (128, 128), interpolation=cv2.INTER_AREA) / 127.5 - 1.0
    raw, logits = _run("detector", tensor)
    scores = 1.0 / (1.0 + np.exp(-np.clip(logits[:, 0].astype(float), -100, 100)))
    anchors = _anchors()
    centres = raw[:, :2] / 128 + anchors
    left = scores >= MIN_DETECTION_SCORE
    faces = []
    while left.any():
        best = int(np.argmax(np.where(left, scores, -1.0)))
        keep = left & (np.linalg.norm(centres - centres[best], axis=1) < 0.5 * raw[best, 2] / 128)
        keep[best] = True
        left &= ~keep
        weights = scores[keep] / scores[keep].sum()
        decoded = raw[keep].copy()
        decoded[:, 0:2] = centres[keep]
        decoded[:, 2:4] /= 128
        decoded[:, 4:] = decoded[:, 4:] / 128 + np.tile(anchors[keep], 6)
        mean = weights @ decoded
        offset = np.array([pad_u, pad_v])
        centre = mean[0:2] * side - offset
        half = mean[2:4] * side / 2
        box = np.concatenate([centre - half, centre + half])
        keypoints = mean[4:].reshape(6, 2) * side - offset
        faces.append((float(scores[best]), box, keypoints))
    return faces


def detect_face(image):
    """The most confident face of :func:`detect_faces`, or ``None``."""
    faces = detect_faces(image)
    return faces[0] if faces else None


def face_crop(box_uv, keypoints_uv):
    """The eye-aligned square crop the mesh model expects, from a detection."""
    right_eye, left_eye = keypoints_uv[0], keypoints_uv[1]
    d = left_eye - right_eye
    angle = float(np.arctan2(d[1], d[0]))
    centre = (box_uv[:2] + box_uv[2:]) / 2
    side = FACE_CROP_SCALE * float(np.max(box_uv[2:] - box_uv[:2]))
    return Crop(centre, side, angle)


def face_mesh(image, crop):
    """The 468 mesh points ``(468, 3)`` (u, v, depth in pixels) and the presence score."""
    raw, presence = _run("mesh", crop.sample(image, 192))
    points = crop.to_image(raw.reshape(468, 3), 192)
    score = float(1.0 / (1.0 + np.exp(-presence.ravel()[0])))
    return points, score


def mesh_crop(points_uv):
    """The crop of the next frame from a mesh (MediaPipe's landmarks-to-ROI, eye-aligned)."""
    right_eye, left_eye = points_uv[33, :2], points_uv[263, :2]
    d = left_eye - right_eye
    lo, hi = points_uv[:, :2].min(axis=0), points_uv[:, :2].max(axis=0)
    return Crop(
        (lo + hi) / 2, FACE_CROP_SCALE * float(np.max(hi - lo)), float(np.arctan2(d[1], d[0]))
    )


def iris(image, points_uv):
    """Iris centre and radius (pixels) of each eye, from the iris model on eye crops.

    Returns
    -------
    dict
        ``{"right": (centre_uv (2,), radius_px), "left": (...)}``, the subject's sides.
    """
    out = {}
    for side, (outer, inner), flip in (
        ("right", RIGHT_EYE_CORNERS, False),
        ("left", LEFT_EYE_CORNERS, True),
    ):
        a, b = points_uv[outer, :2], points_uv[inner, :2]
        d = b - a if side == "right" else a - b
        crop = Crop(
            (a + b) / 2, EYE_CROP_SCALE * float(np.linalg.norm(d)), float(np.arctan2(d[1], d[0]))
        )
        _, raw = _run("iris", crop.sample(image, 64, flip=flip))
        pts = crop.to_image(raw.reshape(5, 3)[:, :2], 64, flip=flip)
        radius = float(np.mean(np.linalg.norm(pts[1:] - pts[0], axis=1)))
        out[side] = (pts[0], radius)
    return out


def person_mask(image):
    """Selfie-segmentation person probability, ``(H, W)`` float in [0, 1]."""
    h, w = image.shape[:2]
    tensor = cv2.resize(image, (256, 256), interpolation=cv2.INTER_AREA) / 255.0
    (prob,) = _run("segmentation", tensor)
    return cv2.resize(prob[:, :, 0], (w, h), interpolation=cv2.INTER_LINEAR)
