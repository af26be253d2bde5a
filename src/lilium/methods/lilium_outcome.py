"""What one photo's best Lilium member becomes: its camera, its terms at full level, and the
error or warnings it gives (a single SFO and each photo of a joint SFO alike).

Without a camera the message says why (behind the skull, over the focal cap, run off towards an
infinite focal length) and what to fix; without a focal prior, warning ``focal_cap`` when
members fitted the landmarks better than the result but exceeded the cap, or when the mean soft
tissue fits a focal length above the cap.

A search whose best camera looks at the head from far outside the photo's head-orientation prior
(:func:`missed_head_prior`) is run again with other seeds
(:func:`~lilium.methods.lilium.lilium_sfo`). :func:`de_extra` is a finished run's record.
"""

import numpy as np

from ..geometry.camera import Camera
from .checks import facing_failure
from .lilium_terms import full_image_terms
from .posest_sfo import RUN_OFF_FACTOR, focal_cap_message, focal_cap_warning, long_lens_focal_px
from .prior_checks import far_from_head_prior, head_deviation_of
from .working_level import WorkingPll


def photo_outcome(problem, best, seed):
    """The camera, terms, error and warnings of one photo's best member.

    Parameters
    ----------
    problem : lilium.methods.lilium.LiliumProblem
    best : dict
        The best member's payload for this photo (``R``, ``t``, ``focal_px``, ``success``,
        ``mse_pix``, ``p_cam``, ``p_skof``, ``p_pll``; scalars).
    seed : int
        For the long-lens check (:func:`~lilium.methods.posest_sfo.long_lens_focal_px`).

    Returns
    -------
    camera : Camera or None
    terms : dict of str -> float or None
    error : str
        "" when the photo has a camera.
    warnings : tuple of CaseWarning
        ``focal_cap`` (no focal prior, and a better fit above the cap).
    """
    ok = bool(best["success"])
    camera = None
    if ok:
        camera = Camera.from_rt(best["R"], best["t"], best["focal_px"], problem.centre)
    terms = {
        k: (None if np.isnan(best[k]) else float(best[k]))
        for k in ("mse_pix", "p_cam", "p_skof", "p_pll")
    }
    error, warnings = "", ()
    photo, skull = problem.photo, problem.skull
    if ok and not problem.level.is_full:
        asked = (problem.skof is not None, problem.pll is not None)
        working_pll = problem.pll.term if isinstance(problem.pll, WorkingPll) else None
        exact, problem.outside = full_image_terms(skull, photo, camera, *asked, working_pll)
        terms.update(exact)
    if not ok:
        error = _failure_message(problem, best)
    elif photo.priors.focal_px is None:
        if problem.capped_mse < terms["mse_pix"]:
            warnings = (focal_cap_warning(problem.capped_focal_px, photo),)
        elif (long_lens := long_lens_focal_px(skull, photo, problem.options, seed)) is not None:
            warnings = (focal_cap_warning(long_lens, photo),)
    return camera, terms, error, warnings


#: Searches run again, each with its own seed, after one whose best camera missed the head prior
#: (:func:`missed_head_prior`); the result is the search of lowest fitness.
MAX_RESTARTS = 2


def missed_head_prior(photo, best):
    """Whether the best member's camera looks at the head from more than
    :data:`~lilium.methods.prior_checks.FAR_TOLERANCES` tolerances off the photo's
    head-orientation prior: the identification's rule ``head_outside_prior``
    (:func:`~lilium.methods.prior_checks.far_from_head_prior`).

    On a lateral photo the DE's whole population can start in the wrong branch of the pose
    solutions (measured: 2 of 240 same-person SFOs, both lateral, fitness 7e5-2e6 against tens, the
    camera 47-57 degrees off the prior); another seed finds the right one.

    Parameters
    ----------
    photo : Photo
    best : dict
        The best member's payload (``R``, ``success``).

    Returns
    -------
    bool
        False without a head prior or a camera.
    """
    if not bool(best["success"]):
        return False
    return far_from_head_prior(photo, head_deviation_of(photo, best["R"]))


def outcome_fitness(problem, de_fitness, camera, terms):
    """The result's fitness of one photo: the DE's own ``de_fitness``, or, when the DE ran at a
    working level and the photo has a camera, the sum of :func:`photo_outcome`'s ``terms``
    (recomputed at full level), as a single SFO and each photo of a joint SFO report it."""
    if camera is not None and not problem.level.is_full:
        return float(sum(v for v in terms.values() if v is not None))
    return float(de_fitness)


def _px(focal_px):
    """A focal length for a message: whole pixels, or 3 significant digits for a run-off fit."""
    return f"{focal_px:.0f}" if focal_px < 1e6 else f"{focal_px:.3g}"


def _failure_message(problem, best):
    """Why the best member has no camera: behind the skull, over the focal cap, or neither."""
    R, t, f = np.asarray(best["R"]), np.asarray(best["t"]), float(best["focal_px"])
    finite = np.isfinite(f) and np.all(np.isfinite(R)) and np.all(np.isfinite(t))
    if finite and problem.facing is not None and not problem.facing(R[None], t[None])[0]:
        return facing_failure(problem.skull, problem.photo)
    if finite and f > RUN_OFF_FACTOR * problem.focal_cap_px:
        return _run_off_message(problem, f)
    if finite and f > problem.focal_cap_px:
        return (
            f"no camera found: the best soft-tissue estimate needs a focal length of {_px(f)} px; "
            + focal_cap_message(problem.photo, f)
        )
    return "no camera found for the best soft-tissue estimate"


def _run_off_message(problem, focal_px):
    """The failure of an SFO whose cameras all ran off towards an infinite focal length.

    In a single SFO only when POSEST-SFO's soft tissue has no camera either (else
    :func:`~lilium.methods.lilium.rescue_population` gave the population one). The labels
    passed the left/right checks before the SFO (:func:`~lilium.methods.checks.check_inputs`),
    so the message does not blame them: it says how flat the landmarks are, the usual cause.
    """
    points = problem.corr.cranial_mm - problem.corr.cranial_mm.mean(axis=0)
    rms = np.linalg.svd(points, compute_uv=False) / np.sqrt(len(points))
    mean_tissue = "no camera either" if problem.posest_sfo_member() is None else "one"
    return (
        f"no camera found: the camera of every soft-tissue estimate ran off towards an infinite "
        f"focal length ({_px(focal_px)} px); POSEST-SFO's mean soft tissue has {mean_tissue}. "
        f"The {len(points)} landmark pairs lie nearly in one plane ({rms[2]:.1f} mm RMS out of "
        f"it, {rms[0]:.1f} mm across), so they hardly fix the focal length and the distance: "
        "mark landmarks away from that plane (zygion, gonion, pogonion, frontotemporale), or "
        "look for a misplaced landmark"
    )


def de_extra(de, fallbacks):
    """The ``extra`` of an SFO result from its finished :class:`DifferentialEvolution` run:
    ``history``, ``generations``, ``evaluations``, ``stop``, ``genes``, ``fallbacks``."""
    return {
        "history": de.history.tolist(),
        "generations": de.nit,
        "evaluations": de.nfev,
        "stop": de.message,
        "genes": de.x.tolist(),
        "fallbacks": fallbacks,
    }
