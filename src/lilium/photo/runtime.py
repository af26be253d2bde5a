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
from functools import cache, lru_cache
from importlib import resources

import cv2
import numpy as np

#: Minimum BlazeFace score for a face (MediaPipe's default ``min_detection_confidence``).
MIN_DETECTION_SCORE = 0.5
#: The detector's own input side (px). It finds faces whose box is about 15-60 % of it
#: (measured on the astronaut: 12 % scores 0.6-0.7, 15-50 % 0.9 or more, 70 % nothing).
DETECTOR_INPUT_PX = 128
#: Smallest face (box width, photo px) searched for in a photo of any size ...
SMALL_FACE_PX = 60
#: ... by scaling the photo so that such a face is this wide (px of the detector's input).
SMALL_FACE_INPUT_PX = 20
#: Scale step between the pyramid's levels: each level finds faces of 20-60 px of its input.
LEVEL_STEP = 3
#: At most this many pixels on the finest level (about 4 s of detector on one core): above
#: about 110 MP the smallest face searched for grows with the photo's side.
MAX_LEVEL_PIXELS = 12e6
#: Largest detector input (px a side) run at once, and the overlap of neighbouring windows (more
#: than the largest face a level finds, about 77 px, so each face lies whole in one window).
WINDOW_PX = 1024
WINDOW_OVERLAP_PX = 128
#: A detection within this many px of a window's inner edge is cut: left to the neighbour.
WINDOW_EDGE_PX = 2
#: Detections of one face from several windows and levels overlap at least this much (IoU).
MERGE_IOU = 0.3
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
def _anchors(height=DETECTOR_INPUT_PX, width=DETECTOR_INPUT_PX):
    """BlazeFace short-range SSD anchor centres, ``(N, 2)`` uv in pixels of a detector input of
    ``height x width`` (multiples of 16; pixel edges at 0 and the side): two anchors per cell of
    8 px, then six per cell of 16 px, row by row (the order of the model's outputs)."""
    rows = []
    for stride, per_cell in ((8, 2), (16, 6)):
        v, u = np.mgrid[0 : height // stride, 0 : width // stride]
        centres = (np.stack([u.ravel(), v.ravel()], axis=1) + 0.5) * stride
        rows.append(np.repeat(centres, per_cell, axis=0))
    return np.concatenate(rows)


@lru_cache(maxsize=4)  # a 1024-px input holds about 200 MB
def _detector(height, width):
    """The face detector with its input resized to ``height x width`` (multiples of 16): the
    network is fully convolutional, so a large input is many 128-px tiles at once."""
    path = resources.files("lilium.photo") / "models" / MODEL_FILES["detector"]
    interpreter_class = _interpreter_class()
    with _quiet_stderr():
        interpreter = interpreter_class(model_content=path.read_bytes(), num_threads=1)
        interpreter.resize_tensor_input(0, [1, height, width, 3])
        interpreter.allocate_tensors()
    return interpreter


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


def _detect_window(window):
    """Faces on one detector input, MediaPipe's weighted suppression.

    Parameters
    ----------
    window : ndarray of shape (h, w, 3), uint8 RGB
        ``h`` and ``w`` multiples of 16.

    Returns
    -------
    list of tuple (score, box (4,), keypoints (6, 2))
        In the window's pixel-edge coordinates (its top-left corner at 0).
    """
    h, w = window.shape[:2]
    it = _detector(h, w)
    tensor = (window.astype(np.float32) / 127.5 - 1.0)[None]
    it.set_tensor(it.get_input_details()[0]["index"], tensor)
    it.invoke()
    raw, logits = (it.get_tensor(d["index"])[0] for d in it.get_output_details())
    scores = 1.0 / (1.0 + np.exp(-np.clip(logits[:, 0].astype(float), -100, 100)))
    candidates = np.flatnonzero(scores >= MIN_DETECTION_SCORE)
    anchors = _anchors(h, w)[candidates]
    scores = scores[candidates]
    decoded = raw[candidates].astype(float)
    decoded[:, 0:2] += anchors
    decoded[:, 4:] += np.tile(anchors, 6)
    left = np.ones(len(candidates), bool)
    faces = []
    while left.any():
        best = int(np.argmax(np.where(left, scores, -1.0)))
        near = np.linalg.norm(decoded[:, :2] - decoded[best, :2], axis=1) < 0.5 * decoded[best, 2]
        keep = left & near
        keep[best] = True
        left &= ~keep
        mean = (scores[keep] / scores[keep].sum()) @ decoded[keep]
        half = mean[2:4] / 2
        box = np.concatenate([mean[0:2] - half, mean[0:2] + half])
        faces.append((float(scores[best]), box, mean[4:].reshape(6, 2)))
    return faces


def _ceil16(n):
    return int(16 * np.ceil(n / 16))


def _windows(n):
    """Starts of the windows that cover ``n`` level pixels along one axis, and their common
    size: as few as :data:`WINDOW_PX` allows, overlapping by at least
    :data:`WINDOW_OVERLAP_PX`, at least the detector's own input."""
    if n <= WINDOW_PX:
        return [0], max(DETECTOR_INPUT_PX, _ceil16(n))
    k = int(np.ceil((n - WINDOW_OVERLAP_PX) / (WINDOW_PX - WINDOW_OVERLAP_PX)))
    size = _ceil16((n + (k - 1) * WINDOW_OVERLAP_PX) / k)
    return [int(x) for x in np.linspace(0, n - size, k).round()], size


def _shrink(image, factor):
    """``image`` reduced ``factor`` times (an integer: pixel blocks averaged, OpenCV's fast
    path); the last rows and columns that do not fill a block are left out."""
    h, w = image.shape[:2]
    lh, lw = h // factor, w // factor
    block = image[: lh * factor, : lw * factor]
    return cv2.resize(block, (lw, lh), interpolation=cv2.INTER_AREA)


def image_pyramid(image, levels=True):
    """The images the detector searches, finest first, each with its photo px per level px.

    The finest is the photo reduced :data:`SMALL_FACE_PX` / :data:`SMALL_FACE_INPUT_PX` (3)
    times, so that a small face is 20 px wide for the detector (or more, to hold at most
    :data:`MAX_LEVEL_PIXELS`); each next one is :data:`LEVEL_STEP` times smaller, while it is
    larger than the detector's input; the last shows the whole photo in one 128-px input (the
    only one with ``levels=False``, and for photos up to about 400 px).

    Yields
    ------
    level : ndarray of shape (h, w, 3), uint8
    to_photo : ndarray of shape (2,)
        Photo pixels per level pixel along u and v.
    """
    h, w = image.shape[:2]
    factor = int(round(SMALL_FACE_PX / SMALL_FACE_INPUT_PX))
    factor = max(factor, int(np.ceil(np.sqrt(h * w / MAX_LEVEL_PIXELS))))
    source, total = image, 1
    while (
        levels
        and max(h, w) // (total * factor) > DETECTOR_INPUT_PX
        and min(h, w) // (total * factor) >= 1
    ):
        source, total = _shrink(source, factor), total * factor
        factor = LEVEL_STEP
        yield source, np.array([total, total], float)
    whole = DETECTOR_INPUT_PX / max(h, w)
    lw, lh = max(1, round(w * whole)), max(1, round(h * whole))
    shrinking = source.shape[0] > lh
    interpolation = cv2.INTER_AREA if shrinking else cv2.INTER_LINEAR
    yield cv2.resize(source, (lw, lh), interpolation=interpolation), np.array([w / lw, h / lh])


def _detect_level(level, to_photo):
    """Faces on one level of :func:`image_pyramid`, window by window, in photo ``uv``; a face
    that a window's inner edge cuts is left to the neighbour that holds it whole."""
    lh, lw = level.shape[:2]
    (u_starts, u_size), (v_starts, v_size) = _windows(lw), _windows(lh)
    found = []
    for v0 in v_starts:
        for u0 in u_starts:
            window = np.zeros((v_size, u_size, 3), np.uint8)
            patch = level[v0 : v0 + v_size, u0 : u0 + u_size]
            window[: patch.shape[0], : patch.shape[1]] = patch
            inner_lo = np.array([u0 > 0, v0 > 0])
            inner_hi = np.array([u0 + u_size < lw, v0 + v_size < lh])
            size = np.array([u_size, v_size])
            for score, box, keypoints in _detect_window(window):
                cut_lo = inner_lo & (box[:2] < WINDOW_EDGE_PX)
                cut_hi = inner_hi & (box[2:] > size - WINDOW_EDGE_PX)
                if cut_lo.any() or cut_hi.any():
                    continue
                offset = np.array([u0, v0])
                box = np.concatenate([box[:2] + offset, box[2:] + offset]) * np.tile(to_photo, 2)
                keypoints = (keypoints + offset) * to_photo
                found.append((score, box - 0.5, keypoints - 0.5))  # pixel centres (docs)
    return found


def box_iou(box, boxes):
    """Intersection over union of ``box`` (4,) with each of ``boxes`` (N, 4), [u0, v0, u1, v1]."""
    lo = np.maximum(box[:2], boxes[:, :2])
    hi = np.minimum(box[2:], boxes[:, 2:])
    inter = np.prod(np.clip(hi - lo, 0, None), axis=1)
    area = np.prod(box[2:] - box[:2])
    areas = np.prod(boxes[:, 2:] - boxes[:, :2], axis=1)
    return inter / np.maximum(area + areas - inter, 1e-9)


def _merge(found):
    """One detection per face across windows and levels: the boxes overlapping the most
    confident one by :data:`MERGE_IOU` or more are averaged with it, weighted by score."""
    if not found:
        return []
    scores = np.array([f[0] for f in found])
    boxes = np.array([f[1] for f in found])
    keypoints = np.array([f[2] for f in found])
    left = np.ones(len(found), bool)
    faces = []
    while left.any():
        best = int(np.argmax(np.where(left, scores, -1.0)))
        keep = left & (box_iou(boxes[best], boxes) >= MERGE_IOU)
        keep[best] = True
        left &= ~keep
        weights = scores[keep] / scores[keep].sum()
        faces.append(
            (float(scores[best]), weights @ boxes[keep], np.tensordot(weights, keypoints[keep], 1))
        )
    return faces


def detect_faces(image, pyramid=True):
    """Every face the detector finds, most confident first.

    The short-range detector sees a 128-px input and finds faces of about 15-60 % of it, so the
    photo is searched on a pyramid (:func:`image_pyramid`): from a scale where a
    :data:`SMALL_FACE_PX` face is :data:`SMALL_FACE_INPUT_PX` px wide, in windows of up to
    :data:`WINDOW_PX` px, to the whole photo in one input; the detections of one face in
    several windows and levels are merged (:func:`box_iou` >= :data:`MERGE_IOU`).

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
    pyramid : bool
        False: the whole photo in one input only (faces of about 15 % of its long side and up).

    Returns
    -------
    list of tuple (score, box_uv (4,) as [u_min, v_min, u_max, v_max], keypoints_uv (6, 2))
        Keypoints: subject's right eye, left eye, nose tip, mouth, right ear, left ear.
    """
    found = []
    for level, to_photo in image_pyramid(image, levels=pyramid):
        found += _detect_level(level, to_photo)
    return _merge(found)


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
