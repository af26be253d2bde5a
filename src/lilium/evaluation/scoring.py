"""Score one SFO result against the ground truth of its photo (SPEC section 7)."""

import math
from dataclasses import dataclass

from .metrics import ImplausibleSFO, back_projection_error_from_dicts


@dataclass(frozen=True)
class Score:
    """How one SFO compares with the truth.

    Attributes
    ----------
    bpe_mm : float
        Back-projection error (mm) of the estimated camera; NaN when the SFO failed or the
        truth has no 3D facial landmarks (a negative pair, or a photo without its subject).
    implausible : ImplausibleSFO or None
        Skull pixels outside the face mask, when the caller computed them.
    """

    bpe_mm: float
    implausible: ImplausibleSFO | None = None


def score(result, truth, implausible=None):
    """Score an SFO result against a :class:`~lilium.io.truth.GroundTruth`.

    Parameters
    ----------
    result : SfoResult, Camera or None
        The estimate: an SFO result (falsy when it failed), or its camera (None = failed).
    truth : GroundTruth
        Of the photo, read with the subject folder of the skull tested for a positive pair
        (``facial_landmarks_mm``); without 3D landmarks no BPE is defined.
    implausible : ImplausibleSFO, optional
        Passed through (the outside-the-mask count is computed where the skull raster is).

    Returns
    -------
    Score
    """
    camera = getattr(result, "camera", result) if result else None
    bpe = math.nan
    if camera is not None and truth.facial_landmarks_mm:
        bpe = back_projection_error_from_dicts(
            truth.facial_landmarks_mm, truth.landmarks_noise_free, camera
        )
    return Score(bpe, implausible)
