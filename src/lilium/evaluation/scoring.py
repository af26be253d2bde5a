"""Score one SFO result against the ground truth of its photo (docs/method/evaluation.md)."""

import math
from dataclasses import dataclass

from .metrics import ImplausibleSFO, back_projection_error_from_dicts, outside_face


@dataclass(frozen=True)
class Score:
    """How one SFO compares with the truth.

    Attributes
    ----------
    bpe_mm : float
        Back-projection error (mm) of the estimated camera; NaN when the SFO failed or the
        truth has no 3D facial landmarks (a negative pair, or a photo without its subject).
    implausible : ImplausibleSFO or None
        Skull pixels outside the face mask (None without a mask or a camera).
    """

    bpe_mm: float
    implausible: ImplausibleSFO | None = None


def score(result, truth=None, skull=None, face_mask=None, topology=None):
    """Score an SFO result: BPE against the ground truth, skull pixels outside the face mask.

    Parameters
    ----------
    result : SfoResult, Camera or None
        The estimate: an SFO result (falsy when it failed), or its camera (None = failed).
    truth : GroundTruth, optional
        Of the photo, read with the subject folder of the skull tested for a positive pair
        (``facial_landmarks_mm``); without it, or without its 3D landmarks, no BPE is defined.
    skull : Skull, optional
        With ``face_mask``: count the skull pixels outside the mask (:func:`outside_face`, the
        exact skull raster behind P_skof).
    face_mask : ndarray of shape (H, W), bool, optional
    topology : EdgeTopology, optional
        Of the skull mesh (cached by a caller).

    Returns
    -------
    Score
    """
    camera = getattr(result, "camera", result) if result else None
    bpe = math.nan
    if camera is not None and truth is not None and truth.facial_landmarks_mm:
        bpe = back_projection_error_from_dicts(
            truth.facial_landmarks_mm, truth.landmarks_noise_free, camera
        )
    implausible = None
    if camera is not None and skull is not None and face_mask is not None:
        implausible = outside_face(
            camera, skull.vertices_mm, skull.faces, face_mask, topology=topology
        )
    return Score(bpe, implausible)
