"""The ground truth of a generated photo (docs/method/evaluation.md and docs/contract.md), read in
one place.

A generated photo's ``photo.json`` carries ``ground_truth`` (``subject``, ``skull2cam``,
``focal_px``, ``scd_mm``, ``noise``, ``landmarks_noise_free``, and from the generator also
``principal_point_px``, ``image_size``, ``visible_landmarks``); its subject folder carries the
true 3D facial landmarks in ``facial_landmarks.json``. The methods never read either.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..geometry.camera import Camera, principal_point_of
from .formats import points_from_object
from .jsonio import read_json

FACIAL_LANDMARKS_FILE = "facial_landmarks.json"


@dataclass(frozen=True)
class GroundTruth:
    """What is known about a generated photo, for scoring an SFO (docs/method/evaluation.md).

    Attributes
    ----------
    photo : str
        Photo id (the photo folder's name).
    subject : str
        Id of the subject photographed (the true skull).
    camera : Camera
        The true camera (principal point: the image centre unless ``photo.json`` gives one).
    scd_mm : float
        True subject-to-camera distance (mm).
    noise : str
        Experiment whose noise the given landmarks carry (``"A"``, ``"B"`` or ``"C"``).
    landmarks_noise_free : dict of str -> ndarray of shape (2,)
        Every facial landmark's true image point (pixels, ``u`` = column), visible or not;
        NaN for one that has none (behind the camera).
    image_size_wh : tuple of int
        (width, height), pixels.
    visible : tuple of str or None
        Landmarks visible in the photo, when the generator recorded them.
    facial_landmarks_mm : dict of str -> ndarray of shape (3,) or None
        The subject's true 3D facial landmarks (skull frame); None when no subject folder was
        given or it has no ``facial_landmarks.json``.
    """

    photo: str
    subject: str
    camera: Camera
    scd_mm: float
    noise: str
    landmarks_noise_free: dict
    image_size_wh: tuple
    visible: tuple | None = None
    facial_landmarks_mm: dict | None = None


def read_facial_landmarks(subject_dir):
    """The true 3D facial landmarks of a subject folder, or None when it has none.

    Returns
    -------
    dict of str -> ndarray of shape (3,) or None
        From ``facial_landmarks.json`` (``{"landmarks": {name: [x, y, z]}}``, skull frame).

    Raises
    ------
    ValueError
        A malformed file, naming it.
    """
    path = Path(subject_dir) / FACIAL_LANDMARKS_FILE
    if not path.is_file():
        return None
    data = read_json(path)
    if not isinstance(data, dict) or "landmarks" not in data:
        raise ValueError(f"{path}: missing field 'landmarks'")
    return points_from_object(path, "landmarks", data["landmarks"], "facial", dim=3)


def _number(path, gt, key, positive=True):
    value = gt.get(key)
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
    if not ok or (positive and value <= 0):
        raise ValueError(
            f"{path}: ground_truth.{key} must be a {'positive ' if positive else ''}number, "
            f"got {value!r}"
        )
    return float(value)


def _image_size(path, gt):
    size = gt.get("image_size")
    if size is not None:
        if not (
            isinstance(size, list)
            and len(size) == 2
            and all(isinstance(x, int) and not isinstance(x, bool) and x > 0 for x in size)
        ):
            raise ValueError(
                f"{path}: ground_truth.image_size must be [width, height] pixels, got {size!r}"
            )
        return int(size[0]), int(size[1])
    from .case import IMAGE_NAMES, read_image

    for name in IMAGE_NAMES:
        if (path.parent / name).is_file():
            image = read_image(path.parent / name)
            return image.shape[1], image.shape[0]
    raise ValueError(
        f"{path}: ground_truth has no image_size and the folder no image; give one of them"
    )


def read_ground_truth(photo_dir, subject_dir=None):
    """Read the ground truth of a generated photo folder.

    Parameters
    ----------
    photo_dir : str or Path
        Holds ``photo.json`` with a ``ground_truth`` object (docs/contract.md).
    subject_dir : str or Path, optional
        The subject's folder, for its true 3D facial landmarks (``facial_landmarks.json``).

    Returns
    -------
    GroundTruth

    Raises
    ------
    ValueError
        A missing or malformed ground truth (no ``ground_truth``, a bad camera, a landmark name
        unknown ...), naming the file and the field.
    """
    photo_dir = Path(photo_dir)
    path = photo_dir / "photo.json"
    data = read_json(path)
    gt = data.get("ground_truth") if isinstance(data, dict) else None
    if not isinstance(gt, dict):
        raise ValueError(
            f"{path}: no ground_truth object; only generated (synthetic) photos carry one"
        )
    subject = gt.get("subject")
    if not isinstance(subject, str) or not subject:
        raise ValueError(f"{path}: ground_truth.subject must be the subject's id, got {subject!r}")
    noise = gt.get("noise")
    if not isinstance(noise, str):
        raise ValueError(f"{path}: ground_truth.noise must be the experiment letter, got {noise!r}")
    size_wh = _image_size(path, gt)
    principal_point = gt.get("principal_point_px")
    if principal_point is None:
        principal_point = principal_point_of(size_wh)
    camera = Camera.from_dict(
        {
            "skull2cam": gt.get("skull2cam"),
            "focal_px": gt.get("focal_px"),
            "principal_point_px": principal_point,
        },
        name=f"{path}: ground_truth",
    )
    landmarks = points_from_object(
        path,
        "ground_truth.landmarks_noise_free",
        gt.get("landmarks_noise_free"),
        "facial",
        finite=False,
    )
    visible = gt.get("visible_landmarks")
    if visible is not None:
        if not (isinstance(visible, list) and all(n in landmarks for n in visible)):
            raise ValueError(
                f"{path}: ground_truth.visible_landmarks must list names of landmarks_noise_free"
            )
        visible = tuple(visible)
    return GroundTruth(
        photo=photo_dir.name,
        subject=subject,
        camera=camera,
        scd_mm=_number(path, gt, "scd_mm"),
        noise=noise,
        landmarks_noise_free=landmarks,
        image_size_wh=size_wh,
        visible=visible,
        facial_landmarks_mm=None if subject_dir is None else read_facial_landmarks(subject_dir),
    )
