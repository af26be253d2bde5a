"""MSAC: RANSAC with truncated-quadratic scoring, over P4Pf samples."""

from dataclasses import dataclass

import numpy as np

from .minimal import p4pf
from .residuals import reprojection_sq_errors


@dataclass(frozen=True)
class RansacOptions:
    """Options of :func:`msac`.

    Attributes
    ----------
    threshold_px : float
        Inlier threshold on the reprojection error (pixels); also the MSAC truncation.
    max_iterations, min_iterations : int
        Bounds on the number of 4-point samples.
    success_prob : float
        Wanted probability of drawing one all-inlier sample (adaptive stopping).
    chunk : int
        Samples drawn and scored together (vectorised scoring).
    """

    threshold_px: float = 12.0
    max_iterations: int = 500
    min_iterations: int = 16
    success_prob: float = 0.9999
    chunk: int = 16


@dataclass(frozen=True)
class RansacResult:
    """Best MSAC hypothesis. Falsy when no sample gave a camera."""

    R: np.ndarray | None
    t: np.ndarray | None
    focal_px: float
    inliers: np.ndarray | None
    cost: float
    n_samples: int
    message: str = ""

    def __bool__(self):
        return self.R is not None


def _needed_iterations(inlier_ratio, success_prob, sample_size=4):
    w = inlier_ratio**sample_size
    if w >= 1.0 - 1e-12:
        return 0
    if w <= 0.0:
        return np.inf
    return np.log(1.0 - success_prob) / np.log(1.0 - w)


def msac(uv_centred_px, points_mm, options=RansacOptions(), rng=None):
    """Robustly estimate pose and focal length with P4Pf samples and MSAC scoring.

    Parameters
    ----------
    uv_centred_px : ndarray of shape (N, 2)
        Image points minus the principal point (pixels), ``N >= 4``.
    points_mm : ndarray of shape (N, 3)
    options : RansacOptions
    rng : seed or numpy Generator
        Sampling randomness; the same seed gives the same result.

    Returns
    -------
    RansacResult
    """
    rng = np.random.default_rng(rng)
    n = len(points_mm)
    tau_sq = options.threshold_px**2
    best_cost, best = np.inf, None
    needed, drawn = options.max_iterations, 0
    while drawn < min(max(needed, options.min_iterations), options.max_iterations):
        Rs, ts, fs = [], [], []
        for _ in range(options.chunk):
            idx = rng.choice(n, size=4, replace=False)
            R, t, f = p4pf(uv_centred_px[idx], points_mm[idx])
            Rs.append(R)
            ts.append(t)
            fs.append(f)
        drawn += options.chunk
        R, t, f = np.concatenate(Rs), np.concatenate(ts), np.concatenate(fs)
        if len(f) == 0:
            continue
        sq = reprojection_sq_errors(uv_centred_px, points_mm, R, t, f)
        cost = np.minimum(sq, tau_sq).sum(axis=1)
        k = int(np.argmin(cost))
        if cost[k] < best_cost:
            best_cost = float(cost[k])
            inliers = sq[k] < tau_sq
            best = (R[k], t[k], float(f[k]), inliers)
            needed = _needed_iterations(inliers.mean(), options.success_prob)
    if best is None:
        return RansacResult(
            None, None, np.nan, None, np.inf, drawn, "no 4-point sample gave a real camera"
        )
    return RansacResult(*best, cost=best_cost, n_samples=drawn)
