"""POSEST-SFO, the state-of-the-art baseline (Valsecchi et al. 2018).

Facial 3D landmarks are the cranial landmarks pushed along the given soft-tissue directions by the
population's mean depth; POSEST then finds the camera from those 3D points and the photo's 2D
landmarks. The score (used for ranking skulls) is the mean reprojection error in pixels over the
landmarks visible in the photo. Deterministic: RANSAC runs with a fixed seed.
"""

import time

import numpy as np

from ..geometry.camera import principal_point_of
from ..inputs import correspondences
from ..pose.posest import posest
from ..softtissue.depths import depth_stats
from .options import SfoOptions
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
    pose = posest(corr.uv_px, facial_mm, centre, options.posest, rng=seed)
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
            error=f"POSEST failed: {pose.message}",
            **common,
        )
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
        **common,
    )
