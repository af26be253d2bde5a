"""POSEST: pose and focal length from n >= 4 2D-3D correspondences (PnP+f).

As in Lourakis & Terzakis' POSEST: MSAC over P4Pf samples, then Levenberg-Marquardt over the
seven parameters on the inliers. The few best MSAC hypotheses are refined together (one batched
call), each re-fitted to its own inlier set until that set settles (local optimisation, as in
LO-RANSAC), and the refined camera with the most inliers wins (ties: the lowest MSAC cost;
``PosestOptions.select``). A failure (fewer than four
points, no real sample, focal length out of range, a point behind the camera, a camera the
caller's ``camera_check`` rejects) is a falsy :class:`PoseResult` carrying a message and a
code, not an exception.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ..constants import FOCAL_MAX_PX, FOCAL_MIN_PX, MIN_CORRESPONDENCES, RANSAC_THRESHOLD_PX
from ..geometry.camera import Camera
from .ransac import RansacOptions, msac
from .refine import RefineOptions, refine_batch
from .residuals import reprojection_sq_errors


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
        Largest acceptable focal length; larger is a failure (the SFO methods set it from the
        photo's focal prior, :func:`lilium.constants.focal_cap_px`).
    local_rounds : int
        Refinements at most per hypothesis; after each, its inliers are re-classified with the
        refined camera and, if they changed, it is refined again on the new set.
    threshold_spread_fraction : float or None
        When set, the inlier threshold is ``max(threshold_floor_px, fraction x spread)``, the
        spread being the RMS distance (pixels) of the image points from their centroid, instead
        of ``ransac.threshold_px``: a fixed 12 px is loose for a small face and tight for a
        large one.
    threshold_floor_px : float
    select : {"inliers", "msac"}
        How the refined hypothesis is chosen: ``"inliers"`` the one with the most inliers, ties
        broken by the lowest MSAC cost (the support COLMAP's RANSAC ranks by); ``"msac"`` the
        lowest MSAC cost (truncated squared error). See the notes below.

    Defaults chosen by measurement on SFO problems (``benchmarks/bench_posest.py --sfo``:
    generated Exp. C positive pairs, 12 subjects x 8 photos, seeds 0 and 1, against pycolmap's
    LO-RANSAC P4Pf with focal refinement): a threshold of max(6 px, 0.1 x spread), 16 refined
    hypotheses and one refinement each gave 0.62-0.85 x pycolmap's mean BPE with no more
    failures, where the fixed 12 px, 4 hypotheses and 4 rounds gave 0.76-1.12 x.

    ``select="inliers"`` (issue 27, docs/decisions/0001-posest-hypothesis-selection.md): on
    near-planar landmark sets (frontal
    photos of a skull without the mandible) the focal length is barely determined, and the
    lowest truncated cost often belongs to a camera far too close to the face (a focal length
    0.1-0.2 x the truth) that fits a few landmarks tightly and leaves the others outside the
    threshold; the camera that keeps the most landmarks within it is nearer the truth. On 48
    generated mandible-less frontal photos the mean BPE fell from 4.79 to 4.05 mm and on the
    headsq CT's mandible-less frontal photos from 8.59 to 5.49 mm.
    """

    ransac: RansacOptions = field(
        default_factory=lambda: RansacOptions(RANSAC_THRESHOLD_PX, n_candidates=16)
    )
    refine: RefineOptions = field(default_factory=RefineOptions)
    refine_on: str = "inliers"
    focal_max_px: float = FOCAL_MAX_PX
    local_rounds: int = 1
    threshold_spread_fraction: float | None = 0.1
    threshold_floor_px: float = 6.0
    select: str = "inliers"

    def ransac_for(self, uv_px):
        """:attr:`ransac` with the inlier threshold for these image points ``(N, 2)``."""
        if self.threshold_spread_fraction is None:
            return self.ransac
        d = uv_px - uv_px.mean(axis=0)
        spread = float(np.sqrt(np.mean(np.sum(d**2, axis=1))))
        tau = max(self.threshold_floor_px, self.threshold_spread_fraction * spread)
        return replace(self.ransac, threshold_px=tau)


@dataclass(frozen=True)
class PoseResult:
    """A camera estimated by POSEST; falsy when it failed.

    Attributes
    ----------
    camera : Camera or None
        Skull-to-camera transform, focal length and principal point; None on failure.
    errors_px : ndarray of shape (N,)
        Reprojection error of every input point (pixels); ``inf`` behind the camera.
    inliers : ndarray of shape (N,), bool
    message : str
        Why it failed, or "" on success.
    code : str
        Why it failed, for callers: ``"focal_cap"`` (focal length above ``focal_max_px``),
        ``"rejected"`` (``camera_check`` refused every camera that was otherwise valid),
        ``"no_sample"`` (no minimal sample gave a real camera: too few or near-planar
        points), ``"other"``; "" on success.
    capped_focal_px : float or None
        On success: the focal length of a camera that fitted better than the one returned but
        was refused for exceeding ``focal_max_px`` (the cap was hit; None when not). On a
        ``"focal_cap"`` failure: the focal length refused.
    """

    camera: Camera | None
    errors_px: np.ndarray | None = None
    inliers: np.ndarray | None = None
    message: str = ""
    code: str = ""
    capped_focal_px: float | None = None

    def __bool__(self):
        return self.camera is not None

    @property
    def rms_px(self):
        """Root-mean-square reprojection error over all points (pixels)."""
        return float(np.sqrt(np.mean(self.errors_px**2)))

    @property
    def mean_error_px(self):
        """Mean reprojection error over all points (pixels), POSEST-SFO's score."""
        return float(np.mean(self.errors_px))


def failure(message, code="other", capped_focal_px=None):
    """A falsy :class:`PoseResult` with ``message`` (and a ``code``)."""
    return PoseResult(None, message=message, code=code, capped_focal_px=capped_focal_px)


#: Message of a camera refused by the caller's ``camera_check``.
REJECTED_MESSAGE = "the camera was rejected by the caller's check"


def check_camera(R, t, focal_px, sq_err_px2, focal_max_px=FOCAL_MAX_PX):
    """Why a camera is unacceptable, or "" if it is fine (docs/method/pose.md failures)."""
    if not np.isfinite(focal_px) or focal_px < FOCAL_MIN_PX:
        return f"focal length {focal_px:.4g} px is not positive (below {FOCAL_MIN_PX:g} px)"
    if focal_px > focal_max_px:
        return f"focal length {focal_px:.4g} px exceeds the {focal_max_px:.0f} px limit"
    if not np.all(np.isfinite(sq_err_px2)):
        return "a point lies behind the camera"
    return ""


def posest(uv_px, points_mm, principal_point_px, options=PosestOptions(), rng=0, camera_check=None):
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
    camera_check : callable, optional
        ``camera_check(R (K, 3, 3), t (K, 3)) -> (K,) bool``: False refuses a camera like no
        solution (the SFO methods pass the skull-faces-camera rule).

    Returns
    -------
    PoseResult
        Falsy, with a message and a code, on failure.

    Examples
    --------
    >>> import numpy as np
    >>> from lilium.geometry import Camera
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(scale=60.0, size=(12, 3))
    >>> truth = Camera.from_rt(np.eye(3), [0.0, 0.0, 1000.0], 2500.0, [320.0, 240.0])
    >>> result = posest(truth.project(X), X, [320.0, 240.0])
    >>> round(result.camera.focal_px, 6)
    2500.0
    """
    uv = np.asarray(uv_px, dtype=float)
    X = np.asarray(points_mm, dtype=float)
    c = np.asarray(principal_point_px, dtype=float)
    if len(uv) < MIN_CORRESPONDENCES:
        return failure(f"{len(uv)} correspondences, POSEST needs at least 4")
    if options.refine_on not in ("inliers", "all"):
        raise ValueError(f"refine_on must be 'inliers' or 'all', got {options.refine_on!r}")
    if options.select not in ("inliers", "msac"):
        raise ValueError(f"select must be 'inliers' or 'msac', got {options.select!r}")
    uv_c = uv - c
    ransac = options.ransac_for(uv)
    hyp = msac(uv_c, X, ransac, rng)
    if not hyp:
        return failure(hyp.message, "no_sample")
    R, t, f, _ = hyp.candidates
    tau_sq = ransac.threshold_px**2
    sq = reprojection_sq_errors(uv_c, X, R, t, f)
    on_inliers = options.refine_on == "inliers"
    used = _used_points(sq, tau_sq) if on_inliers else np.ones(sq.shape, bool)
    cost = np.empty(len(f))
    todo = np.arange(len(f))  # hypotheses whose used points changed
    for _ in range(max(options.local_rounds, 1)):
        ref = refine_batch(
            uv_c, X, R[todo], t[todo], f[todo], used[todo].astype(float), options.refine
        )
        R[todo], t[todo], f[todo] = ref.R, ref.t, ref.focal_px
        sq[todo], cost[todo] = ref.sq_err_px2, ref.cost
        if not on_inliers:
            break
        new_used = _used_points(sq[todo], tau_sq)
        changed = np.any(new_used != used[todo], axis=1)
        used[todo] = new_used
        todo = todo[changed & (f[todo] <= options.focal_max_px)]
        if len(todo) == 0:
            break
    score = cost if not on_inliers else np.minimum(sq, tau_sq).sum(axis=1)
    if options.select == "inliers":
        # Most inliers first; among equal counts the MSAC cost (it is below tau_sq per point,
        # so the count dominates), COLMAP's InlierSupportMeasurer order.
        with np.errstate(invalid="ignore"):
            count = (sq < tau_sq).sum(axis=1)
        score = (len(uv) - count) * tau_sq * (len(uv) + 1) + np.minimum(score, tau_sq * len(uv))
    # check_camera's rules, vectorised; its messages are needed only when every camera fails.
    with np.errstate(invalid="ignore"):
        fine = np.isfinite(f) & (f >= FOCAL_MIN_PX) & (f <= options.focal_max_px)
    fine &= np.all(np.isfinite(sq), axis=1)
    accepted = (
        np.ones(len(f), bool) if camera_check is None else np.asarray(camera_check(R, t), bool)
    )
    valid = fine & accepted
    if not valid.any():
        why = [check_camera(R[k], t[k], f[k], sq[k], options.focal_max_px) for k in range(len(f))]
        why = [w or ("" if accepted[k] else REJECTED_MESSAGE) for k, w in enumerate(why)]
        k = int(np.argmin(score))
        if any(w == REJECTED_MESSAGE for w in why):  # would have fitted, but refused
            k = min((j for j, w in enumerate(why) if w == REJECTED_MESSAGE), key=score.__getitem__)
            return failure(why[k], "rejected")
        if f[k] > options.focal_max_px:
            return failure(why[k], "focal_cap", float(f[k]))
        return failure(why[k])
    k = int(np.argmin(np.where(valid, score, np.inf)))
    errors = np.sqrt(sq[k])
    camera = Camera.from_rt(R[k], t[k], f[k], c)
    capped = np.isfinite(f) & (f > options.focal_max_px) & (score < score[k])
    capped_focal = float(f[np.argmin(np.where(capped, score, np.inf))]) if capped.any() else None
    return PoseResult(camera, errors, errors < ransac.threshold_px, capped_focal_px=capped_focal)


def _used_points(sq_err_px2, tau_sq):
    """Inliers (K, N) of K cameras; a camera with fewer than four keeps all its points."""
    used = sq_err_px2 < tau_sq
    used[used.sum(axis=1) < MIN_CORRESPONDENCES] = True
    return used
