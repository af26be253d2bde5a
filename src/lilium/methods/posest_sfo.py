"""POSEST-SFO, the state-of-the-art baseline (Valsecchi et al. 2018).

Facial 3D landmarks are the cranial landmarks pushed along the given soft-tissue directions by the
population's mean depth; POSEST then finds the camera from those 3D points and the photo's 2D
landmarks. The score (used for ranking skulls) is the mean reprojection error in pixels over the
landmarks visible in the photo. Deterministic: RANSAC runs with a fixed seed.

A camera that sees the back of the skull (docs/checks.md) is treated like no solution; when the
landmarks fit only from behind, the SFO fails with a message that asks whether left and right
are swapped in the skull's (or the photo's) landmark file. A camera refused for its focal
length above the cap says how to lift the cap (docs/method/pose.md).
"""

import time

import numpy as np

from ..constants import FOCAL_MAX_PX, focal_cap_px
from ..geometry.camera import principal_point_of
from ..inputs import CaseWarning
from ..pose.posest import posest
from ..softtissue.depths import depth_stats
from ..validation import fmt_number, fmt_range
from .checks import facing_check, facing_failure
from .options import SfoOptions, with_cap_px, with_focal_cap
from .pairs import correspondences
from .result import SfoResult


def mean_depth_landmarks(corr, depth_table=None):
    """Facial 3D landmarks ``C_i + mean_depth_i * axis_i``.

    Parameters
    ----------
    corr : Correspondences
    depth_table : dict, optional
        A user's depth table (see :func:`lilium.softtissue.check_depth_table`).

    Returns
    -------
    facial_mm : ndarray of shape (N, 3)
    """
    depth = np.array([depth_stats(c, depth_table).mean_mm for c in corr.cranial_names])
    return corr.cranial_mm + depth[:, None] * corr.axes


def posest_sfo(skull, photo, options=SfoOptions(), seed=0):
    """Run POSEST-SFO on one skull and one photo.

    Parameters
    ----------
    skull : lilium.inputs.Skull
    photo : lilium.inputs.Photo
    options : SfoOptions
        Uses ``posest`` and ``depth_table``.
    seed : int
        RANSAC seed (fixed: the method is deterministic).

    Returns
    -------
    SfoResult
        ``fitness`` = mean pixel error; ``terms["mse_pix"]`` = mean squared pixel error; falsy
        with an ``error`` message when POSEST fails.

    Raises
    ------
    ValueError
        Fewer than 4 landmarks usable on both skull and photo.
    """
    start = time.perf_counter()
    corr = correspondences(skull, photo)
    facial_mm = mean_depth_landmarks(corr, options.depth_table)
    centre = principal_point_of(photo.image_size_wh)
    options = with_focal_cap(options, photo.priors.focal_px)
    pose = posest(
        corr.uv_px, facial_mm, centre, options.posest, rng=seed, camera_check=facing_check(skull)
    )
    landmarks = dict(zip(corr.facial_names, facial_mm, strict=True))
    common = dict(
        method="posest-sfo",
        variant=None,
        seed=None,
        skull_id=skull.id,
        photo_id=photo.id,
        facial_landmarks_mm=landmarks,
    )
    if not pose:
        return SfoResult(
            camera=None,
            fitness=np.inf,
            terms={"mse_pix": None, "p_cam": None, "p_skof": None, "p_pll": None},
            seconds=time.perf_counter() - start,
            error=_failure_message(pose, skull, photo),
            **common,
        )
    warnings = ()
    capped = pose.capped_focal_px
    if capped is not None and photo.priors.focal_px is None:
        if capped <= RUN_OFF_FACTOR * focal_cap_px(None):
            warnings = (focal_cap_warning(capped, photo),)
    return SfoResult(
        camera=pose.camera,
        fitness=pose.mean_error_px,
        terms={
            "mse_pix": float(np.mean(pose.errors_px**2)),
            "p_cam": None,
            "p_skof": None,
            "p_pll": None,
        },
        seconds=time.perf_counter() - start,
        warnings=warnings,
        **common,
    )


def focal_cap_warning(focal_px, photo):
    """Warning ``focal_cap``: a better-fitting camera was refused for its focal length."""
    return CaseWarning(
        "focal_cap",
        f"a camera that fits the landmarks better, with a focal length of {focal_px:.0f} px, was "
        f"refused: {focal_cap_message(photo)}",
    )


#: A fit whose focal length runs this far past the cap fits no perspective camera.
RUN_OFF_FACTOR = 10.0


def focal_cap_message(photo, focal_px=None):
    """How to lift the focal cap a camera ran into (docs/method/pose.md), or what else is wrong.

    Parameters
    ----------
    photo : Photo
    focal_px : float, optional
        The focal length refused; beyond :data:`RUN_OFF_FACTOR` times the cap the fit ran off
        towards an orthographic camera, which no lens explains: the landmarks disagree.
    """
    prior = photo.priors.focal_px
    cap = focal_cap_px(prior)
    if focal_px is not None and focal_px > RUN_OFF_FACTOR * cap:
        return (
            "no perspective camera fits the landmarks (the fit runs off towards an infinite "
            "focal length): check that the skull's and the photo's landmarks match (left and "
            "right swapped? a landmark misplaced?)"
        )
    if prior is None:
        return (
            f"the focal length is capped at {cap:.0f} px without a focal prior; give the focal "
            "prior (a photo with EXIF, or --focal-px LO HI) to lift the cap for a long lens"
        )
    if prior[1] <= FOCAL_MAX_PX:
        return (
            f"the landmarks call for a focal length above {fmt_number(cap)} px, the most a "
            f"camera may have, far beyond the focal prior {fmt_range(*prior, 'px')}: check the "
            "prior and that the skull's and the photo's landmarks match"
        )
    return (
        f"the focal length is capped at {fmt_number(cap)} px (twice the focal prior's upper "
        f"bound, {fmt_range(*prior, 'px')}): check the prior and the landmarks"
    )


def _failure_message(pose, skull, photo):
    if pose.code == "no_sample":
        n = len(correspondences(skull, photo).facial_names)
        where = photo.landmarks_file or f"photo {photo.id!r}"
        if skull.landmarks_file:
            where = f"{where} and {skull.landmarks_file}"
        return (
            f"POSEST failed: {pose.message} from the {n} landmark pairs of {where}: too few "
            "(4 pairs fix a camera only when they are exact), or nearly on one plane (the "
            "midline alone); add landmarks off the midline (bilateral pairs: exocanthion, "
            "zygion, gonion, ...), or run --method lilium, which needs no minimal sample"
        )
    if pose.code == "rejected":
        return f"POSEST failed: {facing_failure(skull, photo)}"
    if pose.code == "focal_cap":
        return f"POSEST failed: {pose.message}; {focal_cap_message(photo, pose.capped_focal_px)}"
    return f"POSEST failed: {pose.message}"


def long_lens_focal_px(skull, photo, options=SfoOptions(), seed=0):
    """The focal length the landmarks fit above the cap, for a photo without a focal prior.

    POSEST on POSEST-SFO's mean-depth facial landmarks with the cap lifted to
    :data:`RUN_OFF_FACTOR` times :func:`~lilium.constants.focal_cap_px`: a long-lens photo
    (33,000 px) fits there, where a capped SFO settles on a shorter focal length and a farther
    or distorted soft tissue without a word.

    Returns
    -------
    float or None
        The focal length (pixels) when it lies above the cap, None otherwise.
    """
    cap = focal_cap_px(photo.priors.focal_px)
    corr = correspondences(skull, photo)
    facial_mm = mean_depth_landmarks(corr, options.depth_table)
    lifted = with_cap_px(options, RUN_OFF_FACTOR * cap)
    centre = principal_point_of(photo.image_size_wh)
    pose = posest(
        corr.uv_px, facial_mm, centre, lifted.posest, rng=seed, camera_check=facing_check(skull)
    )
    return float(pose.camera.focal_px) if pose and pose.camera.focal_px > cap else None
