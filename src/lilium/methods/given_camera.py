"""A method's result for a camera given to score, without search (an examiner's camera,
``--camera``; docs/method/workbench.md): :func:`posest_sfo_at` and :func:`lilium_at`, the
``score`` of :data:`~lilium.methods.registry.METHODS`.
"""

import time

import numpy as np

from ..pose.residuals import reprojection_sq_errors
from .lilium import LiliumProblem, lilium_sfo
from .lilium_outcome import outcome_fitness, photo_outcome
from .options import SfoOptions
from .pairs import correspondences
from .posest_sfo import mean_depth_landmarks
from .result import SfoResult


def posest_sfo_at(skull, photo, camera, options=SfoOptions()):
    """POSEST-SFO's score of a given camera (no search): its facial landmarks (the population
    mean depth along each axis) under ``camera``.

    Parameters
    ----------
    skull, photo, options
        As :func:`posest_sfo` (``options.depth_table``).
    camera : Camera
        Checked by the caller (:func:`~lilium.methods.checks.check_given_camera`).

    Returns
    -------
    SfoResult
        As :func:`posest_sfo`'s for that camera: ``fitness`` the mean pixel error,
        ``terms["mse_pix"]`` the mean squared one; the SFO's own camera gives its fitness back.
    """
    start = time.perf_counter()
    corr = correspondences(skull, photo)
    facial_mm = mean_depth_landmarks(corr, options.depth_table)
    uv_c = corr.uv_px - camera.principal_point_px
    sq = reprojection_sq_errors(
        uv_c, facial_mm, camera.R[None], camera.t[None], np.array([camera.focal_px])
    )[0]
    return SfoResult(
        method="posest-sfo",
        variant=None,
        seed=None,
        skull_id=skull.id,
        photo_id=photo.id,
        camera=camera,
        fitness=float(np.mean(np.sqrt(sq))),
        terms={"mse_pix": float(np.mean(sq)), "p_cam": None, "p_skof": None, "p_pll": None},
        facial_landmarks_mm=dict(zip(corr.facial_names, facial_mm, strict=True)),
        seconds=time.perf_counter() - start,
    )


def lilium_at(skull, photo, given, options=SfoOptions(), seed=0):
    """Lilium's result for a given camera, without a camera search.

    The soft tissue is the one the camera came with when it has a facial landmark for every
    correspondence of the photo (``given.facial_landmarks_mm``: the result ``workbench.html``
    showed, or a ``result.json``'s), so the score is that of what the examiner saw, and the
    SFO's own camera and soft tissue give back its fitness and terms; else the best soft tissue
    under the camera (:func:`~lilium.methods.lilium.lilium_sfo` with ``camera``: the DE over
    the cones only, seeded). ``extra["soft_tissue"]`` says which (``"given"``, ``"fitted"``).

    Parameters
    ----------
    skull, photo, options, seed
        As :func:`~lilium.methods.lilium.lilium_sfo`.
    given : GivenCamera
        Checked by the caller (:func:`~lilium.methods.checks.check_given_camera`).

    Returns
    -------
    SfoResult
    """
    start = time.perf_counter()
    facial = given.facial_landmarks_mm or {}
    names = correspondences(skull, photo).facial_names
    if not all(name in facial for name in names):
        result = lilium_sfo(skull, photo, options, seed, camera=given.camera)
        result.extra["soft_tissue"] = "fitted"
        return result
    problem = LiliumProblem(skull, photo, options, rng=seed, camera=given.camera)
    points = np.array([facial[name] for name in names], dtype=float)
    terms = problem.add_image_terms(problem.camera_terms(points[None]))
    best = {k: v[0] for k, v in terms.items()}
    camera, terms, error, warnings = photo_outcome(problem, best, seed)
    return SfoResult(
        method="lilium",
        variant=options.variant,
        seed=seed,
        skull_id=skull.id,
        photo_id=photo.id,
        camera=camera,
        fitness=outcome_fitness(problem, best["fitness"], camera, terms),
        terms=terms,
        facial_landmarks_mm=dict(zip(names, points, strict=True)),
        seconds=time.perf_counter() - start,
        error=error,
        warnings=warnings,
        terms_off=dict(problem.terms_off),
        extra={"soft_tissue": "given", **problem.level_extra()},
    )
