"""Cohort normalisation of the landmark term (docs/method/identification.md): how well does this
photo fit
*this* skull compared with how well it fits other people's skulls?

The marginal landmark term ``landmark_chi2`` (:mod:`lilium.identification.terms`) varies from
photo to photo for reasons that have nothing to do with the skull: the view, how many
landmarks are visible, how sharp they are. Measured on 40 generated subjects, that spread
across photos, not the ranking within a photo, is what kept the pooled calibration poor
(docs/method/identification.md, Identification). Speaker and face recognition meet the same problem
and
answer it with test normalisation ("T-norm"): score the same observation against a cohort of
impostor models and express the candidate's score in the cohort's units.

Here the cohort is a set of skulls, each a set of cranial landmarks and soft-tissue axes
(no mesh: the landmark term needs none). For each cohort skull:

1. it is moved onto the candidate skull (rigid Kabsch fit of their common landmarks), so the
   SFO's camera is a starting camera for it;
2. that camera is refitted to the photo's landmarks under the same marginal likelihood (a
   batched Levenberg-Marquardt over rotation, translation and log focal, all cohort skulls at
   once): the best any camera does for that skull;
3. its ``landmark_chi2`` is computed with the refitted camera(s) (several photos of one person
   still share their soft tissue).

The mean and the SD of ``ln chi2_j`` over the cohort are two terms of the identification
(``cohort_mean``, ``cohort_sd``): they change nothing in how the skulls of one photo rank, and
tell the calibration how far this photo's ``landmark_chi2`` values spread. Test normalisation
proper (dividing the candidate's term by them) was measured too and lost to letting the
calibration weigh them (docs/method/identification.md, Identification).

Maths only: the shipped cohort is read by :mod:`lilium.io.calibration`.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from .. import jit
from ..geometry.camera import Camera, project_points, to_camera_frame
from ..geometry.rotations import rotvec_to_matrix
from ._cohort_kernels import refit_whitened_kernel
from .terms import (
    landmark_chi2,
    landmark_sigma_px,
    projection_jacobians,
    soft_tissue_covariance,
)

#: Levenberg-Marquardt iterations of a camera refit.
REFIT_ITERATIONS = 25

#: Finite-difference steps of the refit's parameters: rotation vector (rad), translation (mm),
#: log focal.
FD_STEPS = np.array([1e-4, 1e-4, 1e-4, 1e-2, 1e-2, 1e-2, 1e-4])

#: Fewest cohort skulls a normalisation needs.
MIN_COHORT = 5


@dataclass(frozen=True)
class Cohort:
    """Skulls of other people, as landmarks only.

    Attributes
    ----------
    landmarks_mm : tuple of dict
        Per skull, cranial name -> ``(3,)`` point (each skull in its own frame).
    axes : tuple of dict
        Per skull, cranial name -> unit ``(3,)`` soft-tissue axis.
    provenance : dict
    """

    landmarks_mm: tuple
    axes: tuple
    provenance: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.landmarks_mm)


def kabsch(source_mm, target_mm):
    """Rigid ``(R, t)`` with ``target ~ source @ R.T + t`` (least squares, no reflection).

    Parameters
    ----------
    source_mm, target_mm : ndarray of shape (N, 3)
    """
    cs, ct = source_mm.mean(axis=0), target_mm.mean(axis=0)
    H = (source_mm - cs).T @ (target_mm - ct)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T))
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    return R, ct - cs @ R.T


def _whitened(R, t, f, pp, points, cov, uv, sigma_px):
    """Whitened residuals ``(K, 2N)`` of K skulls under K cameras (R ``(K,3,3)``, t ``(K,3)``,
    f ``(K,)``): ``points`` ``(K, N, 3)`` are the skulls' mean facial points, ``cov``
    ``(K, N, 3, 3)`` their soft-tissue covariances; the marginal covariance
    ``S = J Sigma J^T + sigma^2 I`` of each landmark whitens its residual, so the squared norm
    is ``sum r^T S^-1 r``. The numpy path; compiled, :func:`refit_cameras` calls
    :func:`~lilium.identification._cohort_kernels.refit_whitened_kernel` instead."""
    r = (uv if uv.ndim == 3 else uv[None]) - project_points(points, R, t, f, pp)  # NaN: behind
    bad = ~np.isfinite(r).all(axis=(1, 2))
    J = projection_jacobians(to_camera_frame(points, R, t), R, f)
    S = J @ cov @ np.swapaxes(J, -1, -2)
    S[..., 0, 0] += sigma_px**2
    S[..., 1, 1] += sigma_px**2
    a = np.sqrt(S[..., 0, 0])
    b = S[..., 1, 0] / a
    c = np.sqrt(np.maximum(S[..., 1, 1] - b**2, 1e-12))
    w0 = r[..., 0] / a
    w = np.stack([w0, (r[..., 1] - b * w0) / c], axis=-1).reshape(len(R), -1)
    w[bad | ~np.isfinite(w).all(axis=1)] = 1e3
    return w


def _cameras(R0, t0, f0, p):
    return rotvec_to_matrix(p[:, :3]) @ R0, t0 + p[:, 3:6], f0 * np.exp(p[:, 6])


def refit_cameras(R0, t0, f0, pp, cranial, axes, mean_mm, sd_mm, uv, sigma_px):
    """Refit K cameras, one per skull, to one photo's landmarks under the marginal likelihood.

    Parameters
    ----------
    R0 : ndarray of shape (K, 3, 3)
    t0 : ndarray of shape (K, 3)
    f0 : ndarray of shape (K,)
        Starting cameras (skull frame to camera frame, mm, px).
    pp : ndarray of shape (2,)
        Principal point (kept).
    cranial, axes : ndarray of shape (K, N, 3)
        Each skull's cranial landmarks and unit soft-tissue axes.
    mean_mm, sd_mm : ndarray of shape (N,)
        Population depth statistics.
    uv : ndarray of shape (N, 2) or (K, N, 2)
        The photo's facial landmarks, or one photo per camera (the skull cohort).
    sigma_px : ndarray of shape (N,)
        The landmarks' 2D errors (kept fixed).

    Returns
    -------
    R : ndarray of shape (K, 3, 3)
    t : ndarray of shape (K, 3)
    f : ndarray of shape (K,)
    """
    K = len(R0)
    cov = soft_tissue_covariance(axes.reshape(-1, 3), np.tile(mean_mm, K), np.tile(sd_mm, K))
    args = (pp, cranial + mean_mm[None, :, None] * axes, cov.reshape(K, -1, 3, 3), uv, sigma_px)
    if jit.compiled():  # the cameras' moves and the residuals in one call per evaluation
        c = np.asarray(pp, dtype=float)
        fixed = (
            np.ascontiguousarray(R0, dtype=float), np.ascontiguousarray(t0, dtype=float),
            np.ascontiguousarray(f0, dtype=float), float(c[0]), float(c[1]),
            np.ascontiguousarray(args[1], dtype=float), np.ascontiguousarray(args[2], dtype=float),
            np.ascontiguousarray(uv if uv.ndim == 3 else np.broadcast_to(uv, (K,) + uv.shape)),
            np.ascontiguousarray(sigma_px, dtype=float),
        )  # fmt: skip

        def whitened(q):
            return refit_whitened_kernel(np.ascontiguousarray(q), *fixed)
    else:

        def whitened(q):
            return _whitened(*_cameras(R0, t0, f0, q), *args)

    # A trial step that runs off (a focal overflowing, a point behind the camera) is scored
    # 1e3 per residual by _whitened and rejected; its floating-point warnings say nothing more.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        p = np.zeros((K, 7))
        w = whitened(p)
        cost = np.sum(w**2, axis=1)
        lam = np.full(K, 1e-3)
        for _ in range(REFIT_ITERATIONS):
            J = np.empty((K, w.shape[1], 7))
            for j in range(7):
                q = p.copy()
                q[:, j] += FD_STEPS[j]
                J[:, :, j] = (whitened(q) - w) / FD_STEPS[j]
            JtJ = np.swapaxes(J, 1, 2) @ J
            g = np.einsum("kmj,km->kj", J, w)
            A = JtJ + lam[:, None, None] * (np.eye(7) * np.diagonal(JtJ, axis1=1, axis2=2)[:, None]
                                            + 1e-9 * np.eye(7))
            step = -np.linalg.solve(A, g[..., None])[..., 0]
            trial = p + step
            w_trial = whitened(trial)
            cost_trial = np.sum(w_trial**2, axis=1)
            better = cost_trial < cost
            p[better], w[better], cost[better] = trial[better], w_trial[better], cost_trial[better]
            lam = np.where(better, lam * 0.3, lam * 10.0)
    return _cameras(R0, t0, f0, p)


def refit_views(views):
    """The candidate's views with each camera refitted to its photo's landmarks alone
    (:func:`refit_cameras` from the SFO's camera): the best fit the landmarks allow this
    skull, whatever its outline does on the photo.

    Parameters
    ----------
    views : sequence of View

    Returns
    -------
    list of View
        The same views, each with its refitted camera.
    """
    refitted = []
    for view in views:
        cam = view.camera
        R, t, f = refit_cameras(
            cam.R[None], cam.t[None], np.array([cam.focal_px]), cam.principal_point_px,
            view.cranial_mm[None], view.axes[None], view.depth_mean_mm, view.depth_sd_mm,
            view.uv_px, landmark_sigma_px(view),
        )
        refitted.append(
            replace(view, camera=Camera.from_rt(R[0], t[0], f[0], cam.principal_point_px))
        )
    return refitted


def _aligned(views, cohort):
    """The cohort members with every landmark of ``views`` and the rigid fit ``(R, t)`` of each
    onto the candidate skull (cohort frame -> candidate frame, by their common landmarks)."""
    names = sorted({n for v in views for n in v.names})
    members = [k for k in range(len(cohort)) if all(
        n in cohort.landmarks_mm[k] and n in cohort.axes[k] for n in names)]
    candidate = {n: c for v in views for n, c in zip(v.names, v.cranial_mm, strict=True)}
    target = np.array([candidate[n] for n in names])
    moves = [kabsch(np.array([cohort.landmarks_mm[k][n] for n in names]), target)
             for k in members]
    return members, moves


def _landmarks(cohort, members, names):
    """Cranial landmarks ``(K, N, 3)`` and unit soft-tissue axes ``(K, N, 3)`` of ``members``
    (each in its own frame), in the order of ``names``."""
    cranial = np.array([[cohort.landmarks_mm[k][n] for n in names] for k in members], float)
    axes = np.array([[cohort.axes[k][n] for n in names] for k in members], float)
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    return cranial, axes


def _log_stats(values):
    """Mean and SD of ``ln`` of the finite, positive ``values`` (None, None when fewer than
    :data:`MIN_COHORT`)."""
    values = np.log(values[np.isfinite(values) & (values > 0)])
    if len(values) < MIN_COHORT:
        return None, None
    return float(values.mean()), float(max(values.std(), 1e-6))


def _refitted(view, R0, t0, cranial, axes):
    """K skulls' views of one photo (``cranial``, ``axes`` ``(K, N, 3)``), each camera
    refitted to the photo's landmarks by :func:`refit_cameras` from ``R0`` ``(K, 3, 3)``,
    ``t0`` ``(K, 3)`` and the view's focal length."""
    cam = view.camera
    R, t, f = refit_cameras(
        R0, t0, np.full(len(R0), cam.focal_px), cam.principal_point_px, cranial, axes,
        view.depth_mean_mm, view.depth_sd_mm, view.uv_px, landmark_sigma_px(view),
    )
    return [replace(view, camera=Camera.from_rt(R[j], t[j], f[j], cam.principal_point_px),
                    cranial_mm=cranial[j], axes=axes[j]) for j in range(len(R0))]


def cohort_views(views, cohort):
    """Every cohort skull's views of the photos of ``views``, each camera refitted to the
    photo's landmarks (:func:`refit_cameras`, from the candidate's camera moved onto the cohort
    skull by the rigid fit of their common landmarks).

    Parameters
    ----------
    views : sequence of View
        The candidate's views (its correspondences and SFO cameras), one per photo.
    cohort : Cohort

    Returns
    -------
    list of list of View
        Per cohort skull that has every landmark the views use (the others are left out), one
        view per photo: its own landmarks and axes under its refitted camera.
    """
    members, moves = _aligned(views, cohort)
    if not members:
        return []
    member_views = [[] for _ in members]
    for view in views:
        cam = view.camera
        R0 = np.array([cam.R @ Ra for Ra, _ in moves])
        t0 = np.array([cam.R @ ta + cam.t for _, ta in moves])
        cranial, axes = _landmarks(cohort, members, view.names)
        for j, refitted in enumerate(_refitted(view, R0, t0, cranial, axes)):
            member_views[j].append(refitted)
    return member_views


def cohort_chi2(views, cohort):
    """``landmark_chi2`` ``(K',)`` of every cohort skull against the photos of ``views``
    (:func:`cohort_views`; several photos still share each skull's soft tissue)."""
    return np.array([landmark_chi2(v)[0] for v in cohort_views(views, cohort)])


def centred_cohort_views(views, cohort):
    """The cohort's variation around the candidate skull, each member refitted to the photos.

    Member ``k``'s landmarks, moved onto the candidate (rigid fit of the common landmarks),
    differ from the members' mean by ``D_k``; its stand-in is the candidate's own landmarks
    plus ``D_k``, with the candidate's soft-tissue axes: another person's differences, on this
    skull. Each stand-in's camera is refitted to each photo's landmarks (:func:`refit_cameras`,
    from the candidate's camera). Unlike :func:`cohort_views` nothing here is compared with the
    generated population's mean shape, only with its spread.

    Parameters
    ----------
    views : sequence of View
    cohort : Cohort

    Returns
    -------
    list of list of View
        Per member that has every landmark the views use, one view per photo.
    """
    members, moves = _aligned(views, cohort)
    if len(members) < MIN_COHORT:
        return []
    names = sorted({n for v in views for n in v.names})
    moved = np.array([[cohort.landmarks_mm[k][n] @ R.T + t for n in names]
                      for k, (R, t) in zip(members, moves, strict=True)])
    deltas = dict(zip(names, np.moveaxis(moved - moved.mean(axis=0), 1, 0), strict=True))
    K = len(members)
    member_views = [[] for _ in members]
    for view in views:
        cam = view.camera
        cranial = view.cranial_mm[None] + np.stack([deltas[n] for n in view.names], axis=1)
        axes = np.repeat(view.axes[None], K, axis=0)
        R0, t0 = np.repeat(cam.R[None], K, axis=0), np.repeat(cam.t[None], K, axis=0)
        for j, refitted in enumerate(_refitted(view, R0, t0, cranial, axes)):
            member_views[j].append(refitted)
    return member_views


def centred_cohort_terms(views, cohort):
    """Mean and SD of ``ln landmark_chi2`` over :func:`centred_cohort_views` (None, None when
    fewer than :data:`MIN_COHORT` members have the views' landmarks)."""
    chi2 = np.array([landmark_chi2(v)[0] for v in centred_cohort_views(views, cohort)])
    return _log_stats(chi2)


def cohort_terms(views, cohort):
    """The cohort's fit to the photo(s): mean and SD of ``ln landmark_chi2`` over the cohort
    skulls (None, None when fewer than :data:`MIN_COHORT` have the views' landmarks).

    They describe the photo, not the candidate skull: how hard it is for any skull to fit
    these landmarks. The calibration reads them beside the candidate's own ``landmark_chi2``.
    """
    return _log_stats(cohort_chi2(views, cohort))


def skull_cohort_chi2(views, cohort):
    """``landmark_chi2`` of the candidate skull against every cohort person's face.

    The photo cohort (:func:`cohort_chi2`) asks how well other skulls fit this photo; this asks
    the converse, how well this skull fits other people's faces. Each cohort person's face
    (their cranial landmarks plus the population mean depth along their own axes) is moved
    onto the candidate skull (rigid fit of the common landmarks) and projected by each view's
    SFO camera: a noise-free photo with the same landmarks, view and camera as the real one.
    The candidate's camera is refitted to it as in :func:`refit_cameras` and the candidate's
    ``landmark_chi2`` computed (several views still share their soft tissue).

    Parameters
    ----------
    views : sequence of View
    cohort : Cohort

    Returns
    -------
    ndarray of shape (K',)
        One value per cohort person who has every landmark the views use.
    """
    members, moves = _aligned(views, cohort)
    if not members:
        return np.empty(0)
    K = len(members)
    per_member = [[] for _ in members]
    for view in views:
        cam = view.camera
        cranial, axes = _landmarks(cohort, members, view.names)
        faces = [(c + view.depth_mean_mm[:, None] * a) @ Ra.T + ta
                 for c, a, (Ra, ta) in zip(cranial, axes, moves, strict=True)]
        R0 = np.repeat(cam.R[None], K, axis=0)
        t0 = np.repeat(cam.t[None], K, axis=0)
        f0 = np.full(K, cam.focal_px)
        uv = project_points(np.array(faces), R0, t0, f0, cam.principal_point_px)
        R, t, f = refit_cameras(
            R0, t0, f0, cam.principal_point_px,
            np.repeat(view.cranial_mm[None], K, axis=0), np.repeat(view.axes[None], K, axis=0),
            view.depth_mean_mm, view.depth_sd_mm, uv, landmark_sigma_px(view),
        )
        for j in range(K):
            per_member[j].append(replace(
                view, camera=Camera.from_rt(R[j], t[j], f[j], cam.principal_point_px),
                uv_px=uv[j],
            ))
    return np.array([landmark_chi2(v)[0] for v in per_member])


def skull_cohort_terms(views, cohort):
    """The candidate skull's fit to the cohort's faces: mean and SD of ``ln landmark_chi2``
    (None, None when fewer than :data:`MIN_COHORT` cohort people have the views' landmarks).

    They describe the skull against other people, not the photo's person: a skull that fits
    anyone's landmarks (one near the population's average) gives its own ``landmark_chi2``
    less weight. Zero normalisation ("Z-norm") of speaker recognition, beside the photo's test
    normalisation (:func:`cohort_terms`); the calibration weighs both.
    """
    return _log_stats(skull_cohort_chi2(views, cohort))
