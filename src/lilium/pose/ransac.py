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
    n_candidates : int
        Lowest-cost hypotheses kept for refinement (several starts guard the refinement
        against a poor best sample, common when a distant head makes P4Pf ill-conditioned).
    """

    threshold_px: float = 12.0
    max_iterations: int = 500
    min_iterations: int = 16
    success_prob: float = 0.9999
    chunk: int = 16
    n_candidates: int = 4


@dataclass(frozen=True)
class RansacResult:
    """Best MSAC hypothesis, and the runners-up. Falsy when no sample gave a camera.

    Attributes
    ----------
    R : ndarray of shape (3, 3) or None
    t : ndarray of shape (3,) or None
    focal_px : float
    inliers : ndarray of shape (N,), bool, or None
    cost : float
        MSAC cost (sum of squared errors truncated at the threshold) of the best hypothesis.
    n_samples : int
        4-point samples drawn.
    candidates : tuple (R, t, focal_px, cost) or None
        The ``K <= n_candidates`` lowest-cost hypotheses, best first: arrays of shapes
        (K, 3, 3), (K, 3), (K,), (K,).
    message : str
    """

    R: np.ndarray | None
    t: np.ndarray | None
    focal_px: float
    inliers: np.ndarray | None
    cost: float
    n_samples: int
    candidates: tuple | None = None
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
    best_cost = np.inf
    kept = []  # (R, t, f, cost) of every scored hypothesis
    needed, drawn = options.max_iterations, 0
    while drawn < min(max(needed, options.min_iterations), options.max_iterations):
        Rs, ts, fs = [], [], []
        # A chunk of 4-point samples without repetition, drawn in one call.
        samples = np.argsort(rng.random((options.chunk, n)), axis=1)[:, :4]
        # Gathered once per chunk: each sample is then a contiguous (4, 2) / (4, 3) view.
        uv_samples, X_samples = uv_centred_px[samples], points_mm[samples]
        for k in range(len(samples)):
            R, t, f = p4pf(uv_samples[k], X_samples[k])
            Rs.append(R)
            ts.append(t)
            fs.append(f)
        drawn += options.chunk
        R, t, f = np.concatenate(Rs), np.concatenate(ts), np.concatenate(fs)
        if len(f) == 0:
            continue
        sq = reprojection_sq_errors(uv_centred_px, points_mm, R, t, f)
        cost = np.minimum(sq, tau_sq).sum(axis=1)
        kept.append((R, t, f, cost))
        k = int(np.argmin(cost))
        if cost[k] < best_cost:
            best_cost = float(cost[k])
            needed = _needed_iterations((sq[k] < tau_sq).mean(), options.success_prob)
    if not kept:
        return RansacResult(
            None, None, np.nan, None, np.inf, drawn, message="no 4-point sample gave a real camera"
        )
    R, t, f, cost = (np.concatenate(a) for a in zip(*kept, strict=True))
    order = np.argsort(cost, kind="stable")[: max(options.n_candidates, 1)]
    R, t, f, cost = R[order], t[order], f[order], cost[order]
    sq = reprojection_sq_errors(uv_centred_px, points_mm, R[:1], t[:1], f[:1])[0]
    return RansacResult(
        R[0], t[0], float(f[0]), sq < tau_sq, float(cost[0]), drawn, candidates=(R, t, f, cost)
    )
