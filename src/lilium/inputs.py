"""In-memory SFO inputs: a skull, a photo and the a-priori camera information.

These are plain validated arrays; :mod:`lilium.io.case` parses case folders and
:mod:`lilium.casework.build` builds these from what it parses. Types only: the pairing of a
skull's landmarks with a photo's is :func:`lilium.methods.pairs.correspondences`.
"""

from dataclasses import dataclass, field

import numpy as np

from .fitness.camera_penalty import CameraPriors

#: A-priori camera information of a photo (focal and SCD intervals, head orientation and
#: tolerance; each optional): the same object P_cam takes.
Priors = CameraPriors

#: Where a prior came from (docs/checks.md, ``result.json``'s ``"priors"``).
PRIOR_SOURCES = ("command line", "photo.json", "exif", "automatic", "none")


@dataclass(frozen=True)
class CaseWarning:
    """A warning about an input or a result (docs/checks.md): a stable code and a sentence.

    Attributes
    ----------
    code : str
        ``view_mismatch``, ``no_focal_prior``, ``no_scd_prior``, ``outside_prior``,
        ``exif_focal_unusable``, ``implausible_prior``, ``focal_cap``, ``chin_unconstrained``
        (no chin pair and no chin-jaw curve), ``unknown_key`` (a key of ``photo.json`` that
        Lilium does not read), ``mesh_part_left_out`` (parts of the skull mesh apart from the
        skull, left out), ``normal_axes`` (the eye corners' or the alae's cone axes left to
        the bone normal); docs/checks.md lists them all.
    message : str
        What is wrong and what fixes it.
    """

    code: str
    message: str

    def to_dict(self):
        return {"code": self.code, "message": self.message}


@dataclass(frozen=True)
class Skull:
    """A skull: mesh, cranial landmarks and the soft-tissue axes given for them.

    Attributes
    ----------
    id : str
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    landmarks_mm : dict of str -> ndarray of shape (3,)
        Cranial landmarks, skull frame.
    axes : dict of str -> ndarray of shape (3,)
        Unit soft-tissue directions (cone axes); every correspondence landmark has one (given,
        or the skull-surface normal by default).
    landmarks_file : str or None
        The cranial landmark file, named in the messages about its labels (None: unknown, the
        messages then name the skull).
    warnings : tuple of CaseWarning
        Found while reading the skull (``mesh_part_left_out``, ``normal_axes``); every result
        on it repeats them.
    landmark_sources : dict of str -> str
        Who placed each cranial landmark: ``"located"`` or ``"template"`` for an automatic,
        unreviewed point (``lilium skull``), else ``"manual"`` (missing = manual).
    """

    id: str
    vertices_mm: np.ndarray
    faces: np.ndarray
    landmarks_mm: dict
    axes: dict
    landmarks_file: str | None = None
    warnings: tuple = ()
    landmark_sources: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Photo:
    """A photograph with its 2D facial landmarks and optional mask, curve and priors.

    Attributes
    ----------
    id : str
    image_size_wh : tuple (width, height), pixels
    view : {"frontal", "lateral_left", "lateral_right"}
    landmarks_uv : dict of str -> ndarray of shape (2,)
        Facial landmarks, (u = column, v = row) pixels.
    face_mask : ndarray of shape (H, W), bool, or None
    face_curve_uv : ndarray of shape (K, 2) or None
        Chin-jaw (frontal) or forehead (lateral) curve.
    priors : Priors
    image : ndarray of shape (H, W, 3), uint8, or None
        The picture itself, for overlays.
    landmarks_file : str or None
        The facial landmark file (``photo.json`` or the user's file), named in the messages
        about its labels.
    prior_sources : dict of str -> str
        Where each prior came from, keyed ``focal_px``, ``scd_mm``, ``head_rotation``, values
        among :data:`PRIOR_SOURCES`. A prior given without a source is taken as from
        ``photo.json`` (what :func:`lilium.casework.build.read_photo` reads).
    warnings : tuple of CaseWarning
        Found while reading the photo (e.g. ``exif_focal_unusable``); every result of the photo
        carries them.
    landmark_sources : dict of str -> str
        Who placed each facial landmark: ``manual`` (by hand, or an automatic point the user
        reviewed), ``tracked`` or ``template`` (automatic, unreviewed; docs/method/photo.md). A
        landmark not listed is ``manual``. Sets its 2D uncertainty in the identification
        (:mod:`lilium.identification`).
    """

    id: str
    image_size_wh: tuple
    view: str
    landmarks_uv: dict
    face_mask: np.ndarray | None = None
    face_curve_uv: np.ndarray | None = None
    priors: Priors = field(default_factory=Priors)
    image: np.ndarray | None = None
    landmarks_file: str | None = None
    prior_sources: dict = field(default_factory=dict)
    warnings: tuple = ()
    landmark_sources: dict = field(default_factory=dict)
    mask_file: str | None = None


@dataclass(frozen=True)
class GivenCamera:
    """A camera given to score without search (an examiner's, ``--camera``).

    Attributes
    ----------
    camera : lilium.geometry.camera.Camera
    facial_landmarks_mm : dict of str -> ndarray of shape (3,), or None
        The soft tissue the camera was chosen with (the facial landmarks of the result the
        workbench showed, or of a ``result.json``), skull frame; None for a bare camera.
    source : str
        Where it came from (a file), for messages.
    """

    camera: object
    facial_landmarks_mm: dict | None = None
    source: str = "camera"
