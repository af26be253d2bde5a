"""P_cam, the camera-plausibility term of docs/method/lilium.md, over a whole population at once.

``P_cam = C_INF * [no solution or f <= 0 or f > focal cap]
+ max(0, fmin - f)^2 + max(0, f - fmax)^2
+ max(0, SCDmin - SCD)^2 + max(0, SCD - SCDmax)^2
+ max(0, dbeta - beta_tol)^2``

with f in pixels, SCD in mm and dbeta in degrees. The focal cap is
:data:`~lilium.constants.FOCAL_MAX_PX` unless the focal prior reaches above it
(:func:`~lilium.constants.focal_cap_px`). A prior that is ``None`` switches its terms
off. A quantity that is NaN while its prior is on (a camera that could not be measured) counts
as a failure; the terms of a failed camera that are finite are still added, as the formula says,
so failures stay ordered among themselves.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import C_INF, FOCAL_MAX_PX, FOCAL_MIN_PX, focal_cap_px
from ..geometry.rotations import geodesic_angle_deg
from ..validation import check_interval, check_prior


def _interval(value, name):
    return None if value is None else check_interval(value, name)


@dataclass(frozen=True)
class CameraPriors:
    """A priori camera information of one photo (docs/contract.md); every field is optional.

    Attributes
    ----------
    focal_px : (float, float) or None
        Admissible focal length interval (pixels).
    scd_mm : (float, float) or None
        Admissible subject-to-camera distance interval (mm).
    head_rotation_skull2cam : ndarray of shape (3, 3) or None
        A priori head orientation (the rotation part of ``skull2cam``).
    head_tolerance_deg : float or None
        Largest deviation from it that costs nothing (degrees). The head term is on only when
        both the rotation and the tolerance are given.
    """

    focal_px: tuple | None = None
    scd_mm: tuple | None = None
    head_rotation_skull2cam: np.ndarray | None = None
    head_tolerance_deg: float | None = None

    def __post_init__(self):
        for key in ("focal_px", "scd_mm"):
            value = getattr(self, key)
            object.__setattr__(self, key, None if value is None else check_prior(value, key, key))
        if self.head_rotation_skull2cam is not None:
            R = np.asarray(self.head_rotation_skull2cam, dtype=float)
            if R.shape != (3, 3):
                raise ValueError(
                    f"head_rotation_skull2cam must be a 3x3 matrix, got shape {R.shape}"
                )
            object.__setattr__(self, "head_rotation_skull2cam", R)
        if self.head_tolerance_deg is not None:
            tol = float(self.head_tolerance_deg)
            if not np.isfinite(tol) or tol < 0:
                raise ValueError(f"head_tolerance_deg must be >= 0, got {tol}")
            object.__setattr__(self, "head_tolerance_deg", tol)

    @property
    def uses_head(self):
        return self.head_rotation_skull2cam is not None and self.head_tolerance_deg is not None


def head_deviation_deg(R, R_prior):
    """dbeta of docs/method/lilium.md: geodesic angle (degrees) of ``R @ R_prior.T``.

    Parameters
    ----------
    R : array_like of shape (S, 3, 3)
        Estimated head orientations (rotation of ``skull2cam``).
    R_prior : array_like of shape (3, 3)

    Returns
    -------
    dbeta_deg : ndarray of shape (S,)
    """
    return geodesic_angle_deg(np.asarray(R, dtype=float), np.asarray(R_prior, dtype=float))


def _excess2(x, lo, hi):
    return np.maximum(0.0, lo - x) ** 2 + np.maximum(0.0, x - hi) ** 2


def camera_penalty(
    focal_px,
    scd_mm=None,
    dbeta_deg=None,
    success=None,
    *,
    focal_interval_px=None,
    scd_interval_mm=None,
    tolerance_deg=None,
    focal_max_px=FOCAL_MAX_PX,
):
    """P_cam of a population of cameras.

    Parameters
    ----------
    focal_px : array_like of shape (S,)
        Estimated focal lengths (pixels); NaN for a camera that does not exist.
    scd_mm : array_like of shape (S,), optional
        Subject-to-camera distances (mm); needed when ``scd_interval_mm`` is given.
    dbeta_deg : array_like of shape (S,), optional
        Head orientation deviations (degrees, :func:`head_deviation_deg`); needed when
        ``tolerance_deg`` is given.
    success : array_like of shape (S,) of bool, optional
        False where POSEST returned no solution. Default: all True.
    focal_interval_px, scd_interval_mm : (float, float), optional
        Admissible intervals; None switches the term off.
    tolerance_deg : float, optional
        Head orientation tolerance; None switches the head term off.
    focal_max_px : float, optional
        The focal cap: a larger focal length is a failure (default
        :data:`~lilium.constants.FOCAL_MAX_PX`; see :func:`~lilium.constants.focal_cap_px`).

    Returns
    -------
    p_cam : ndarray of shape (S,)

    Examples
    --------
    >>> camera_penalty([1000.0, 1300.0, 0.0], focal_interval_px=(800, 1200)).tolist()
    [0.0, 10000.0, 1000000640000.0]
    """
    f, ok = _focal_and_success(focal_px, success)
    focal_lo_hi = _interval(focal_interval_px, "focal_interval_px")
    scd_lo_hi = _interval(scd_interval_mm, "scd_interval_mm")
    tol = None if tolerance_deg is None else float(tolerance_deg)
    for x, name, on in ((scd_mm, "scd_mm", scd_lo_hi), (dbeta_deg, "dbeta_deg", tol)):
        if on is not None and x is None:
            raise ValueError(f"{name} is needed when its prior is given")
    return _penalty(f, scd_mm, dbeta_deg, ok, focal_lo_hi, scd_lo_hi, tol, focal_max_px)


def _focal_and_success(focal_px, success):
    """``focal_px`` and ``success`` (all True when None) as arrays of one shape ``(S,)``."""
    f = np.atleast_1d(np.asarray(focal_px, dtype=float))
    ok = np.ones(f.shape, bool) if success is None else np.asarray(success, dtype=bool)
    if ok.shape != f.shape:
        raise ValueError(f"success has shape {ok.shape}, focal_px has shape {f.shape}")
    return f, ok


def _penalty(f, scd_mm, dbeta_deg, ok, focal_lo_hi, scd_lo_hi, tolerance_deg, focal_max_px):
    """:func:`camera_penalty` of checked arguments (``f``, ``ok``: arrays of shape (S,); an
    interval or tolerance that is None switches its term off)."""
    fail = ~ok | ~np.isfinite(f) | (f < FOCAL_MIN_PX) | (f > focal_max_px)
    terms = np.zeros(f.shape)
    parts = ((f, focal_lo_hi, False), (scd_mm, scd_lo_hi, False), (dbeta_deg, tolerance_deg, True))
    for x, prior, one_sided in parts:
        if prior is None:
            continue
        x = np.asarray(x, dtype=float)
        if x.shape != f.shape:
            x = np.broadcast_to(x, f.shape)
        value = np.maximum(0.0, x - prior) ** 2 if one_sided else _excess2(x, *prior)
        fail = fail | ~np.isfinite(x)
        terms = terms + np.where(np.isfinite(value), value, 0.0)
    return np.where(fail, C_INF, 0.0) + terms


def prior_arrays(priors):
    """:class:`CameraPriors` as the arguments of the compiled camera terms
    (:func:`lilium.fitness._camera_kernels.camera_terms_kernel`): ``(focal (2,), scd (2,),
    head (3, 3), tol, cap)``, a prior that is off as NaN."""
    off = np.full(2, np.nan)
    focal = off if priors.focal_px is None else np.array(priors.focal_px, float)
    scd = off if priors.scd_mm is None else np.array(priors.scd_mm, float)
    head, tol = np.eye(3), np.nan
    if priors.uses_head:
        head = np.ascontiguousarray(priors.head_rotation_skull2cam, float)
        tol = float(priors.head_tolerance_deg)
    return focal, scd, head, tol, float(focal_cap_px(priors.focal_px))


def camera_penalty_from_priors(focal_px, scd_mm, R, success, priors):
    """P_cam of a population given :class:`CameraPriors`.

    Parameters
    ----------
    focal_px, scd_mm : array_like of shape (S,)
    R : array_like of shape (S, 3, 3)
        Head orientations (rotation of each ``skull2cam``); NaN where none.
    success : array_like of shape (S,) of bool
    priors : CameraPriors
        Its focal interval also sets the focal cap (:func:`~lilium.constants.focal_cap_px`).

    Returns
    -------
    p_cam : ndarray of shape (S,)
    """
    f, ok = _focal_and_success(focal_px, success)
    if priors.scd_mm is not None and scd_mm is None:
        raise ValueError("scd_mm is needed when its prior is given")
    # The priors' intervals were checked when they were made (CameraPriors).
    head = priors.uses_head
    dbeta = head_deviation_deg(R, priors.head_rotation_skull2cam) if head else None
    tolerance = priors.head_tolerance_deg if head else None
    cap = focal_cap_px(priors.focal_px)
    return _penalty(f, scd_mm, dbeta, ok, priors.focal_px, priors.scd_mm, tolerance, cap)
