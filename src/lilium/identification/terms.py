"""The identification terms of an SFO result (docs/method/identification.md): how likely the
observations
are under "this skull is this person", given the camera(s) the SFO found.

The model (docs/method/identification.md, "Identification"), for every landmark pair ``i`` (cranial
point
``C_i``, soft-tissue axis ``a_i``, population depth mean ``mu_i`` and SD ``s_i``):

- **the soft tissue is a random vector**, not a free parameter: the facial point is
  ``F_i = C_i + mu_i a_i + delta_i`` with ``delta_i ~ N(0, Sigma_i)``,
  ``Sigma_i = s_i^2 a a^T + (mu_i tan(tau))^2 (I - a a^T) + sigma_bone^2 I``: the depth's
  population SD along the axis, an angular spread ``tau`` about it, and the cranial landmark's
  own placement error;
- **each 2D landmark is observed with an isotropic error** ``sigma_i`` (pixels per
  coordinate): a fraction of the eye-corner distance that depends on who placed it (by hand,
  automatic tracked, automatic template), with a floor;
- linearising the projection at the mean facial point (Jacobian ``J_i``, 2 x 3), the residual
  ``r_i = uv_i - P(C_i + mu_i a_i)`` is Gaussian with covariance
  ``S_i = J_i Sigma_i J_i^T + sigma_i^2 I``: the soft tissue is integrated out in closed form
  (a marginal likelihood; no freedom left to fit a wrong skull). With several photos of one
  person the soft tissue is the same in all of them, so the residuals of landmark ``i`` in
  every photo are stacked and share ``Sigma_i``: their dependence is modelled, not ignored.

The terms (all "lower is better", dimensionless):

- ``landmark_chi2``: ``sum_i r_i^T S_i^{-1} r_i / (2 N)``, the mean squared Mahalanobis
  residual per observed coordinate (1 expected for the true skull);
- ``soft_tissue_z2``: the SFO's own soft tissue against the population, the mean over
  landmarks of ``z_depth^2 + (angle / tau)^2`` (0 for POSEST-SFO, whose soft tissue is the
  mean one);
- ``outside_fraction``: the share of the projected skull's pixels outside the head mask;
- ``pll_face``: P_pll divided by the eye-corner distance in pixels (face-size units);
- ``prior_excess``: how far the camera lies outside its priors, relative to each prior
  (focal and distance as a fraction of the bound, the head angle in units of its tolerance),
  squared and summed.
- ``cohort_mean``, ``cohort_sd``: not about the skull but about the photo(s): the mean and SD
  of ``ln landmark_chi2`` of a cohort of other people's skulls, each under its own best
  camera (:mod:`lilium.identification.cohort`); they let the calibration read a
  ``landmark_chi2`` against what this photo gives any skull.
- ``skull_mean``, ``skull_sd``: the converse, about the skull: the mean and SD of the
  candidate's ``ln landmark_chi2`` against the cohort's faces, each a noise-free photo with
  the real photo's landmarks under the SFO's camera (:func:`lilium.identification.cohort.
  skull_cohort_terms`); a skull that fits anyone's landmarks weighs its own fit less.
- ``landmark_refit``: ``landmark_chi2`` of the candidate skull with each camera refitted to
  its photo's landmarks alone (:func:`lilium.identification.cohort.refit_views`), the best the
  landmarks allow whatever the outlines say. Not evidence by itself: the calibration reads
  its gap to ``landmark_chi2`` (:func:`landmark_tension`), what the outlines cost the landmark
  fit.
- ``outside_refit``: ``outside_fraction`` under those refitted cameras: where the landmarks
  alone would put this skull's outline. The true skull's lies inside its own face; a wrong
  skull that fits the landmarks often pokes out of the head.
- ``landmark_worst``: the largest landmark's ``r_i^T S_i^{-1} r_i`` per coordinate
  (:func:`landmark_worst`): whether the misfit that ``landmark_chi2`` averages is spread over
  the landmarks (noise) or sits in one (a skull that differs there).
- ``centred_mean``, ``centred_sd``: the mean and SD of ``ln landmark_chi2`` of the cohort's
  variation put on the candidate skull (each cohort member's difference from the cohort's mean
  shape added to the candidate's landmarks, its camera refitted:
  :func:`lilium.identification.cohort.centred_cohort_terms`): how much another person's
  differences cost this skull's fit to this photo. Unlike the cohort terms they do not compare
  the photo with the generated population's mean face, so they read a real photo as they read
  a generated one (docs/method/identification.md, "The realism gap").

A term whose input is missing (no mask, no curve, no prior) is None; the calibration
(:mod:`lilium.identification.calibration`) reads a None as the term's typical value and says so.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import DIRECTION_SD_DEG
from ..geometry.rotations import geodesic_angle_deg
from ..softtissue.depths import depth_stats

#: Mean adult eye-corner (exocanthion to exocanthion) distance, mm: the face-size unit.
EYE_CORNER_MM = 90.0

#: 2D landmark error per coordinate, as a fraction of the eye-corner distance, by source:
#: hand-placed (``manual``, also a reviewed automatic point), automatic on image evidence
#: (``tracked``) and automatic from the face template (``template``).
SIGMA_FRACTION = {"manual": 0.02, "tracked": 0.03, "template": 0.08}

#: Floor of the 2D landmark error (pixels per coordinate): a landmark is never placed better
#: than this, however small the face.
SIGMA_FLOOR_PX = 1.5

#: Placement error (mm per coordinate) of a cranial landmark on the skull.
BONE_SD_MM = 1.0

#: Order of the terms.
TERM_NAMES = (
    "landmark_chi2",
    "soft_tissue_z2",
    "outside_fraction",
    "pll_face",
    "prior_excess",
    "cohort_mean",
    "cohort_sd",
    "skull_mean",
    "skull_sd",
    "landmark_refit",
    "outside_refit",
    "landmark_worst",
    "centred_mean",
    "centred_sd",
)

#: The cohort terms: the photo(s) against other people's skulls, the skull against other
#: people's faces. Not evidence by themselves (left out of the unweighted score): they tell
#: the calibration how to read ``landmark_chi2``.
COHORT_TERMS = ("cohort_mean", "cohort_sd", "skull_mean", "skull_sd")

#: The terms that say how to read ``landmark_chi2`` and are not evidence apart from it: the
#: cohort terms, the landmarks' own best fit and the worst landmark (a second reading of the
#: same residuals); left out of the unweighted score.
REFERENCE_TERMS = (*COHORT_TERMS, "landmark_refit", "landmark_worst", "centred_mean",
                   "centred_sd")

#: The terms the calibration uses. ``soft_tissue_z2`` is reported but left out: measured on 20
#: generated subjects (docs/decisions/0012-identification-marginal-likelihood.md, Identification) it
#: lowered Lilium's frontal per-photo
#: AUC from 0.963 to 0.939; the soft tissue's plausibility is already in the marginal
#: landmark term. ``landmark_refit`` enters through its gap to ``landmark_chi2``
#: (``landmark_tension``, docs/decisions/0016-identification-features.md: "The landmarks' own fit").
#:
#: The cohort terms and ``landmark_snorm`` are left out since 2026-12-06
#: (docs/method/identification.md,
#: "The realism gap"): they read a photo or a skull against the generated population, and a real
#: head lies outside it (headsq's photos: ``cohort_mean`` 1.7-2.0 against the generated photos'
#: -0.5-0.5; its skull: ``skull_mean`` 1.1-1.9 against -0.5-0.2), so every real skull, the wrong
#: one included, got the largest LR. They are still computed and reported.
CALIBRATED_TERMS = (
    "landmark_chi2",
    "outside_fraction",
    "pll_face",
    "prior_excess",
    "landmark_tension",
    "outside_refit",
    "landmark_worst",
    "centred_mean",
    "centred_sd",
    "landmark_cnorm",
)

#: The terms calibrated before 2026-12-06, with the cohort's (for the comparison of
#: ``benchmarks/bench_identification.py``).
COHORT_CALIBRATED_TERMS = (
    *CALIBRATED_TERMS[:4], *COHORT_TERMS, "landmark_snorm", *CALIBRATED_TERMS[4:7]
)


def landmark_snorm(terms):
    """The landmark term normalised by both cohorts (S-norm): ``(ln chi2 - cohort_mean) /
    cohort_sd + (ln chi2 - skull_mean) / skull_sd``, how unusual the candidate's fit is for
    this photo and for this skull at once; None when a part is missing. Derived from stored
    terms (:data:`DERIVED_TERMS`), so it needs nothing computed again."""
    parts = [terms.get(n) for n in ("landmark_chi2", *COHORT_TERMS)]
    if any(v is None or not np.isfinite(v) for v in parts) or min(parts[2], parts[4]) <= 0:
        return None
    chi2, c_mean, c_sd, s_mean, s_sd = parts
    log_chi2 = np.log(max(chi2, 1e-6))
    return float((log_chi2 - c_mean) / c_sd + (log_chi2 - s_mean) / s_sd)


def landmark_cnorm(terms):
    """The landmark term in the units of the cohort's variation on the candidate skull:
    ``(ln chi2 - centred_mean) / centred_sd``; None when a part is missing. Derived from stored
    terms (:data:`DERIVED_TERMS`)."""
    parts = [terms.get(n) for n in ("landmark_chi2", "centred_mean", "centred_sd")]
    if any(v is None or not np.isfinite(v) for v in parts) or parts[2] <= 0:
        return None
    chi2, mean, sd = parts
    return float((np.log(max(chi2, 1e-6)) - mean) / sd)


def landmark_tension(terms):
    """What the outlines cost the landmark fit: ``ln landmark_chi2 - ln landmark_refit``, the
    candidate's landmark term under the SFO's camera(s) against the same skull's under cameras
    refitted to the landmarks alone; None when either is missing or not finite.

    For the true skull the camera that fits the outlines (P_skof, P_pll) also fits the
    landmarks, so the two terms are close; a wrong skull whose landmarks could be fitted
    only by a camera that puts its outline off the face pays for it here. Derived from
    stored terms (:data:`DERIVED_TERMS`)."""
    chi2, refit = terms.get("landmark_chi2"), terms.get("landmark_refit")
    if chi2 is None or refit is None or not (np.isfinite(chi2) and np.isfinite(refit)):
        return None
    return float(np.log(max(chi2, 1e-6)) - np.log(max(refit, 1e-6)))


#: Calibration features computed from the terms rather than stored with them:
#: ``{name: function(terms dict) -> float or None}``.
DERIVED_TERMS = {"landmark_snorm": landmark_snorm, "landmark_tension": landmark_tension,
                 "landmark_cnorm": landmark_cnorm}


@dataclass(frozen=True)
class View:
    """One photo's share of an identification: its correspondences under the SFO's camera.

    Attributes
    ----------
    camera : Camera
    cranial_mm : ndarray of shape (N, 3)
    axes : ndarray of shape (N, 3)
        Unit soft-tissue axes.
    depth_mean_mm, depth_sd_mm : ndarray of shape (N,)
    uv_px : ndarray of shape (N, 2)
        The observed facial landmarks.
    sources : tuple of str, length N
        Keys of :data:`SIGMA_FRACTION`.
    names : tuple of str, length N
        Cranial names (the key that ties a landmark across photos).
    """

    camera: object
    cranial_mm: np.ndarray
    axes: np.ndarray
    depth_mean_mm: np.ndarray
    depth_sd_mm: np.ndarray
    uv_px: np.ndarray
    sources: tuple
    names: tuple


def make_view(camera, corr, sources=None, depth_table=None):
    """A :class:`View` from an SFO's camera and its :class:`lilium.methods.pairs.Correspondences`.

    Parameters
    ----------
    camera : Camera
    corr : Correspondences
    sources : dict of str -> str, optional
        Facial name -> ``manual`` / ``tracked`` / ``template``; absent = ``manual``.
    depth_table : dict, optional
        A user's depth table (:func:`lilium.softtissue.depths.depth_stats`).
    """
    sources = sources or {}
    stats = [depth_stats(c, depth_table) for c in corr.cranial_names]
    return View(
        camera,
        np.asarray(corr.cranial_mm, float),
        np.asarray(corr.axes, float),
        np.array([s.mean_mm for s in stats]),
        np.array([s.sd_mm for s in stats]),
        np.asarray(corr.uv_px, float),
        tuple(sources.get(f, "manual") for f in corr.facial_names),
        tuple(corr.cranial_names),
    )


def soft_tissue_covariance(axes, depth_mean_mm, depth_sd_mm):
    """``Sigma_i`` of the model, ``(N, 3, 3)`` mm^2, for unit axes ``(N, 3)``."""
    a = np.asarray(axes, float)
    along = a[:, :, None] * a[:, None, :]
    lateral_sd = np.asarray(depth_mean_mm) * np.tan(np.radians(DIRECTION_SD_DEG))
    eye = np.eye(3)[None]
    return (
        np.asarray(depth_sd_mm)[:, None, None] ** 2 * along
        + lateral_sd[:, None, None] ** 2 * (eye - along)
        + BONE_SD_MM**2 * eye
    )


def eye_corner_px(camera, points_mm):
    """The eye-corner distance in pixels at the depth of ``points_mm`` ``(N, 3)`` (their
    centroid): ``EYE_CORNER_MM * focal / depth``; the face-size unit of a photo."""
    depth = camera.to_camera_frame(np.mean(points_mm, axis=0, keepdims=True))[0, 2]
    return EYE_CORNER_MM * camera.focal_px / depth if depth > 0 else np.nan


def _mean_points_and_jacobians(view):
    """Mean facial points' residuals ``(N, 2)`` and projection Jacobians ``(N, 2, 3)``."""
    mean_mm = view.cranial_mm + view.depth_mean_mm[:, None] * view.axes
    cam = view.camera
    X = cam.to_camera_frame(mean_mm)
    jac = projection_jacobians(X[None], cam.R[None], np.array([cam.focal_px]))[0]
    residual = view.uv_px - cam.project(mean_mm)
    return residual, jac, X[:, 2]


def projection_jacobians(X_cam_mm, R, focal_px):
    """Jacobians ``(S, N, 2, 3)`` of the pinhole projection with respect to skull-frame points,
    at points ``X_cam_mm`` ``(S, N, 3)`` already in the frames of S cameras (rotations ``R``
    ``(S, 3, 3)``, ``focal_px`` ``(S,)``)."""
    z = X_cam_mm[..., 2]
    fz = np.asarray(focal_px, float)[:, None] / z
    jac = np.zeros(X_cam_mm.shape[:2] + (2, 3))
    jac[..., 0, 0] = jac[..., 1, 1] = fz
    jac[..., 0, 2] = -fz * X_cam_mm[..., 0] / z
    jac[..., 1, 2] = -fz * X_cam_mm[..., 1] / z
    return jac @ np.asarray(R, float)[:, None]


def landmark_sigma_px(view):
    """The 2D error ``(N,)`` (pixels per coordinate) of each landmark of a view: its source's
    fraction of the eye-corner distance, never below :data:`SIGMA_FLOOR_PX`."""
    fraction = [SIGMA_FRACTION.get(s, SIGMA_FRACTION["manual"]) for s in view.sources]
    return np.maximum(
        SIGMA_FLOOR_PX, np.array(fraction) * eye_corner_px(view.camera, view.cranial_mm)
    )


def landmark_blocks(views):
    """Each landmark's share of the marginal landmark term over one or several photos of one
    person: its stacked residual's squared Mahalanobis norm, log-determinant and number of
    coordinates.

    Landmarks with the same cranial name in several views share their soft tissue: their
    residuals are stacked into one Gaussian whose covariance couples them through
    ``Sigma_i``.

    Parameters
    ----------
    views : sequence of View

    Returns
    -------
    names : list of str, length L
        The cranial names, in order of first appearance.
    quad, logdet, coords : ndarray of shape (L,)
        Per landmark name: ``r^T S^-1 r``, ``log det(2 pi S)`` and the length of ``r`` (2 per
        photo it is seen in).

    None when a landmark lies behind a camera, or the face's centroid does, or a covariance
    is not finite or singular (a degenerate camera, such as a cohort member's diverged refit:
    no face size, no 2D error).
    """
    by_name = {}
    for view in views:
        residual, jac, z = _mean_points_and_jacobians(view)
        if not np.all(z > 0) or not np.all(np.isfinite(residual)):
            return None
        sigma_px = landmark_sigma_px(view)
        if not np.all(np.isfinite(sigma_px)):  # the face's centroid at or behind the camera
            return None
        cov = soft_tissue_covariance(view.axes, view.depth_mean_mm, view.depth_sd_mm)
        for k, name in enumerate(view.names):
            by_name.setdefault(name, []).append((residual[k], jac[k], sigma_px[k], cov[k]))
    quad, logdet, coords = [], [], []
    for entries in by_name.values():
        r = np.concatenate([e[0] for e in entries])
        J = np.concatenate([e[1] for e in entries])
        noise = np.repeat([e[2] ** 2 for e in entries], 2)
        S = J @ entries[0][3] @ J.T + np.diag(noise)
        if not np.all(np.isfinite(S)):
            return None
        try:
            quad.append(float(r @ np.linalg.solve(S, r)))
        except np.linalg.LinAlgError:  # a diverged refit's camera: no usable covariance
            return None
        logdet.append(float(np.linalg.slogdet(2 * np.pi * S)[1]))
        coords.append(len(r))
    return list(by_name), np.array(quad), np.array(logdet), np.array(coords)


def landmark_chi2(views):
    """The marginal landmark term over one or several photos of one person
    (:func:`landmark_blocks`).

    Parameters
    ----------
    views : sequence of View

    Returns
    -------
    chi2 : float
        ``sum_i r_i^T S_i^-1 r_i`` over every landmark of every view divided by the number of
        observed coordinates; ``inf`` when a landmark lies behind a camera.
    nll : float
        The negative log-likelihood of the landmarks (nats): ``0.5 sum_i (r^T S^-1 r +
        log det(2 pi S_i))``.
    """
    blocks = landmark_blocks(views)
    if blocks is None:
        return np.inf, np.inf
    _, quad, logdet, coords = blocks
    return float(quad.sum() / coords.sum()), float(0.5 * (quad.sum() + logdet.sum()))


def worst_landmark(views):
    """The worst landmark: the cranial name and the misfit (``r_i^T S_i^-1 r_i`` per
    coordinate, :func:`landmark_blocks`) of the landmark that fits worst; ``(None, inf)`` when
    a landmark lies behind a camera (or none is seen).

    ``landmark_chi2`` averages the misfit over the landmarks; a wrong skull that fits most of
    them and misses one (a wider zygomatic arch, a longer chin) shows here, and so does one
    misplaced 2D landmark (which is why a case names it). Under the model a landmark's misfit
    is 1 on average; in one photo (two coordinates) it is exponential, so for the true skull
    the largest of ``N`` is about the harmonic number ``H_N`` (3.5 for 18 landmarks).
    """
    blocks = landmark_blocks(views)
    if blocks is None or not blocks[0]:
        return None, np.inf
    names, quad, _, coords = blocks
    misfit = quad / coords
    k = int(np.argmax(misfit))
    return names[k], float(misfit[k])


def landmark_worst(views):
    """The term ``landmark_worst``: the misfit of :func:`worst_landmark`."""
    return worst_landmark(views)[1]


def soft_tissue_z2(facial_mm, cranial_mm, axes, depth_mean_mm, depth_sd_mm):
    """Mean over landmarks of ``z_depth^2 + (angle / tau)^2`` of an SFO's soft tissue.

    Parameters
    ----------
    facial_mm, cranial_mm, axes : ndarray of shape (N, 3)
    depth_mean_mm, depth_sd_mm : ndarray of shape (N,)
    """
    v = np.asarray(facial_mm, float) - np.asarray(cranial_mm, float)
    depth = np.linalg.norm(v, axis=1)
    cos = np.einsum("ij,ij->i", v, axes) / np.maximum(depth, 1e-12)
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    z = (depth - depth_mean_mm) / depth_sd_mm
    return float(np.mean(z**2 + (angle / DIRECTION_SD_DEG) ** 2))


def prior_excess(camera, priors, nasion_mm):
    """How far a camera lies outside its priors (0 inside every prior; None without any).

    Parameters
    ----------
    camera : Camera
    priors : lilium.inputs.Priors
    nasion_mm : ndarray of shape (3,)
        The point whose distance is the SCD (skull frame).
    """
    parts = []
    if priors.focal_px is not None:
        lo, hi = priors.focal_px
        parts.append(max(0.0, lo / camera.focal_px - 1.0, camera.focal_px / hi - 1.0))
    if priors.scd_mm is not None:
        lo, hi = priors.scd_mm
        scd = float(camera.distance_mm(nasion_mm))
        parts.append(max(0.0, lo / scd - 1.0, scd / hi - 1.0))
    if priors.uses_head:
        angle = geodesic_angle_deg(camera.R, priors.head_rotation_skull2cam)
        tol = max(priors.head_tolerance_deg, 1.0)
        parts.append(max(0.0, angle - priors.head_tolerance_deg) / tol)
    return float(np.sum(np.square(parts))) if parts else None
