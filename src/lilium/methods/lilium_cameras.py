"""The compiled camera stage of a Lilium problem (:class:`lilium.methods.lilium.LiliumProblem`).

What :meth:`~lilium.methods.lilium.LiliumProblem.camera_terms` does on the numpy path (decode
the genes, refine every trial's camera from its member's, check the cameras, MSE_pix and P_cam)
in one compiled call per generation (:func:`camera_terms_compiled`), or the checks alone after
a refinement (:func:`checks_compiled`): the same kernels in the same order, so the same
numbers, without the numpy glue between them (about a third of the base variant's time). Where
a camera must be replaced by its own POSEST the refined cameras go on to the numpy path
(``LiliumProblem._checked``).
"""

import numpy as np

from ..fitness._camera_kernels import camera_checks_kernel, camera_stage_kernel
from ..pose.refine import BatchRefineResult
from ..softtissue.cones import decode_arguments
from .posest_sfo import RUN_OFF_FACTOR


def _facing_arguments(problem):
    """``(origin (3,), anterior (3,), cos_max)`` of the problem's facing rule (NaN: none)."""
    rule = problem.facing
    if rule is None:
        return np.zeros(3), np.zeros(3), np.nan
    origin = np.ascontiguousarray(rule.directions.origin_mm, dtype=float)
    anterior = np.ascontiguousarray(rule.directions.anterior, dtype=float)
    return origin, anterior, float(rule.cos_max)


def checks_compiled(problem, ref, lender):
    """The checks of refined cameras ``ref`` (:class:`~lilium.pose.refine.BatchRefineResult`)
    by :func:`~lilium.fitness._camera_kernels.camera_checks_kernel`: the validity ``(S,)``
    (``ref.sq_err_px2`` set to inf where invalid, the best capped fit noted on ``problem``), or
    None when a camera must be replaced by its own POSEST (the numpy path does that).

    Parameters
    ----------
    problem : LiliumProblem
    ref : BatchRefineResult
    lender : bool
        Some member has a valid camera to lend.
    """
    cap = problem.focal_cap_px
    done, ok, k, mse = camera_checks_kernel(
        ref.R, ref.t, ref.focal_px, ref.cost, ref.sq_err_px2, *_facing_arguments(problem),
        cap, RUN_OFF_FACTOR * cap, lender,
    )  # fmt: skip
    if not done:
        return None
    if k >= 0 and mse < problem.capped_mse:
        problem.capped_mse, problem.capped_focal_px = float(mse), float(ref.focal_px[k])
    return ok


def camera_terms_compiled(problem, genes, members):
    """``problem.camera_terms`` of the trials ``genes`` warm-started from ``members``, by
    :func:`~lilium.fitness._camera_kernels.camera_stage_kernel`.

    Parameters
    ----------
    problem : LiliumProblem
    genes : ndarray of shape (S, 3N)
    members : dict
        The payload of the members the trials compete with (``R``, ``t``, ``focal_px``,
        ``success``).

    Returns
    -------
    dict
        As :meth:`~lilium.methods.lilium.LiliumProblem.camera_terms`.
    """
    genes = np.ascontiguousarray(genes, dtype=float)
    a = _stage_arguments(problem, len(genes))
    cap = problem.focal_cap_px
    facial, R, t, f, cost, sq, done, ok, k, mse_k, mse, p_cam = camera_stage_kernel(
        genes, a["cranial"], a["cones"], a["uv"], a["w"], members["R"], members["t"],
        members["focal_px"], members["success"], a["refine"], *a["facing"], cap,
        RUN_OFF_FACTOR * cap, a["scd_index"], *problem.prior_arrays[:4],
    )  # fmt: skip
    if not done:
        lender = bool(np.any(members["success"]))
        ref = BatchRefineResult(R, t, f, sq, cost, 0)
        return problem._terms(facial, *problem._checked(facial, ref, lender))
    if k >= 0 and mse_k < problem.capped_mse:
        problem.capped_mse, problem.capped_focal_px = float(mse_k), float(f[k])
    return problem._term_dict(mse, p_cam, R, t, f, ok)


def _stage_arguments(problem, S):
    """The fixed arguments of ``camera_stage_kernel`` for a population of ``S``, built once
    per problem and size (kept in ``problem._stage``)."""
    if S not in problem._stage:
        o = problem.options.refine
        uv = problem.uv_c
        problem._stage[S] = {
            "cranial": np.ascontiguousarray(problem.corr.cranial_mm, dtype=float),
            "cones": decode_arguments(problem.cones),
            "uv": np.ascontiguousarray(np.broadcast_to(uv, (S,) + uv.shape), dtype=float),
            "w": np.ones((S, len(uv))),
            "refine": (
                float(o.min_rms_px), int(o.max_iterations), float(o.initial_lambda),
                float(o.cost_tol), float(o.gradient_tol), float(o.max_lambda),
                float(np.log(o.focal_stop_px)),
            ),  # fmt: skip
            "facing": _facing_arguments(problem),
            "scd_index": np.asarray(problem.scd_index, np.int64),
        }
    return problem._stage[S]
