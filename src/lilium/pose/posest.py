"""POSEST: pose and focal length from n >= 4 2D-3D correspondences (PnP+f).

As in Lourakis & Terzakis' POSEST: MSAC over P4Pf samples, then Levenberg-Marquardt over the
seven parameters on the inliers. A failure (fewer than four points, no real sample, focal length
out of range, a point behind the camera) is a falsy :class:`PoseResult` carrying a message, not an
exception.
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import FOCAL_MAX_PX, MIN_CORRESPONDENCES, RANSAC_THRESHOLD_PX
from .ransac import RansacOptions, msac
from .refine import RefineOptions, refine_batch


@dataclass(frozen=True)
class PosestOptions:
    """Options of :func:`posest`.

    Attributes
    ----------
    ransac : RansacOptions
    refine : RefineOptions
    refine_on : {"inliers", "all"}
        Points the Levenberg-Marquardt stage fits: MSAC's inliers (POSEST) or all points.
    focal_max_px : float
        Largest acceptable focal length; larger is a failure.
    """

    ransac: RansacOptions = field(default_factory=lambda: RansacOptions(RANSAC_THRESHOLD_PX))
    refine: RefineOptions = field(default_factory=RefineOptions)
    refine_on: str = "inliers"
    focal_max_px: float = FOCAL_MAX_PX


@dataclass(frozen=True)
class PoseResult:
    """A camera estimated by POSEST; falsy when it failed.

    Attributes
    ----------
    skull2cam : ndarray of shape (4, 4) or None
        World (skull) to camera rigid transform, mm.
    focal_px : float
    principal_point_px : ndarray of shape (2,)
    errors_px : ndarray of shape (N,)
        Reprojection error of every input point (pixels); ``inf`` behind the camera.
    inliers : ndarray of shape (N,), bool
    message : str
        Why it failed, or "" on success.
    """

    skull2cam: np.ndarray | None
    focal_px: float
    principal_point_px: np.ndarray
    errors_px: np.ndarray | None = None
    inliers: np.ndarray | None = None
    message: str = ""

    def __bool__(self):
        return self.skull2cam is not None

    @property
    def rms_px(self):
        """Root-mean-square reprojection error over all points (pixels)."""
        return float(np.sqrt(np.mean(self.errors_px**2)))

    @property
    def mean_error_px(self):
        """Mean reprojection error over all points (pixels), POSEST-SFO's score."""
        return float(np.mean(self.errors_px))


def failure(message, principal_point_px):
    """A falsy :class:`PoseResult` with ``message``."""
    return PoseResult(None, np.nan, np.asarray(principal_point_px, float), message=message)


def check_camera(R, t, focal_px, sq_err_px2, focal_max_px=FOCAL_MAX_PX):
    """Why a camera is unacceptable, or "" if it is fine (SPEC section 4 failures)."""
    if not np.isfinite(focal_px) or focal_px <= 0:
        return f"focal length {focal_px:.4g} px is not positive"
    if focal_px > focal_max_px:
        return f"focal length {focal_px:.4g} px exceeds the {focal_max_px:.0f} px limit"
    if not np.all(np.isfinite(sq_err_px2)):
        return "a point lies behind the camera"
    return ""


def posest(uv_px, points_mm, principal_point_px, options=PosestOptions(), rng=0):
    """Estimate rotation, translation and focal length from 2D-3D correspondences.

    Parameters
    ----------
    uv_px : array_like of shape (N, 2)
        Image points (u = column, v = row), pixels.
    points_mm : array_like of shape (N, 3)
        Matching 3D points (mm), ``N >= 4``.
    principal_point_px : array_like of shape (2,)
        Fixed principal point (the image centre in SFO).
    options : PosestOptions
    rng : seed or numpy Generator
        RANSAC sampling; the default seed makes POSEST deterministic.

    Returns
    -------
    PoseResult
        Falsy, with a message, on failure.

    Examples
    --------
    >>> import numpy as np
    >>> from lilium.geometry import project
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(scale=60.0, size=(12, 3))
    >>> skull2cam = np.eye(4); skull2cam[2, 3] = 1000.0
    >>> uv = project(X, skull2cam, 2500.0, [320.0, 240.0])
    >>> result = posest(uv, X, [320.0, 240.0])
    >>> round(result.focal_px, 6)
    2500.0
    """
    uv = np.asarray(uv_px, dtype=float)
    X = np.asarray(points_mm, dtype=float)
    c = np.asarray(principal_point_px, dtype=float)
    if len(uv) < MIN_CORRESPONDENCES:
        return failure(f"{len(uv)} correspondences, POSEST needs at least 4", c)
    uv_c = uv - c
    hyp = msac(uv_c, X, options.ransac, rng)
    if not hyp:
        return failure(hyp.message, c)
    weights = hyp.inliers.astype(float) if options.refine_on == "inliers" else np.ones(len(X))
    if weights.sum() < MIN_CORRESPONDENCES:
        weights = np.ones(len(X))
    ref = refine_batch(
        uv_c, X, hyp.R[None], hyp.t[None], [hyp.focal_px], weights[None], options.refine
    )
    R, t, f, sq = ref.R[0], ref.t[0], float(ref.focal_px[0]), ref.sq_err_px2[0]
    why = check_camera(R, t, f, sq, options.focal_max_px)
    if why:
        return failure(why, c)
    skull2cam = np.eye(4)
    skull2cam[:3, :3], skull2cam[:3, 3] = R, t
    errors = np.sqrt(sq)
    return PoseResult(skull2cam, f, c, errors, errors < options.ransac.threshold_px)
