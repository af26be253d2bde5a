"""Joint Lilium: one soft tissue shared by every photo of a person (docs/method/joint.md).

One DE genotype (the soft tissue) for all photos, one camera per photo. The genes are defined
over the *union* of the cranial landmarks any photo uses (in the order of
:data:`~lilium.softtissue.landmarks.CRANIAL_TO_FACIAL`, the bilateral hybrid over the union's
twins), decoded once per member; each photo uses the rows of its own visible landmarks. Each
photo keeps its own :class:`~lilium.methods.lilium.LiliumProblem` (its correspondences, priors,
focal cap, P_skof and P_pll, terms switched off): the joint problem calls its two halves,
:meth:`~LiliumProblem.camera_terms` then :meth:`~LiliumProblem.add_image_terms`, with that
photo's rows of the shared facial landmarks.

Design (measured in ``benchmarks/bench_joint.py``, results in ``docs/method/joint.md``):

- **Camera chains.** The DE payload holds one camera per photo per member (arrays of shape
  ``(S, P, ...)``); photo ``p``'s trial camera is warm-started from photo ``p``'s camera of the
  member it competes with, so each photo has its own chain, as in a single SFO. The initial
  population gets one POSEST per photo.
- **Fitness.** ``sum_p w_p fitness_p`` with each photo's fitness as in a single SFO (MSE_pix,
  P_cam, P_skof, P_pll with its camera, mask, curve and priors). ``weighting="scale"`` (the
  default, :data:`DEFAULT_WEIGHTING`): ``w_p = (k / k_p)^2`` with ``k_p`` the photo's pixels
  per millimetre at the face (:func:`photo_scale_px_per_mm`) and ``k`` their geometric mean,
  so the sum is in the same units for every photo: a photo whose face is twice as large in
  pixels (MSE_pix and P_skof four times larger for the same error in mm) does not weigh four
  times as much. Equal-scale photos get ``w_p = 1``, the plain sum; ``weighting="sum"`` is
  the plain sum always. ``result.json`` gives each photo's own (unweighted) fitness and its
  ``weight``; the total is the weighted sum DE ranked.
- **Camera fit.** ``camera="priors"`` (the default, :data:`DEFAULT_CAMERA`): each photo's
  camera is fitted to the landmarks (as in a single SFO), then, where it lies outside the
  photo's priors, refined further on that photo's MSE_pix + P_cam (:func:`camera_on_priors`).
  A single SFO lets its soft tissue bend until its least-squares camera lands inside the
  priors; one shared soft tissue cannot do that for every photo at once, and with least-squares
  cameras even the *true* soft tissue scores P_cam in the millions (the focal length of a
  least-squares camera is 0.2-6 x the truth under Exp. C's landmark noise), so the joint DE
  bent the soft tissue away from the face. ``camera="least_squares"`` is the design before
  (docs/decisions/0006-joint-sfo-cameras-and-budget.md).
- **Early exit.** A trial's image penalties of photo ``p`` are skipped when the partial sum
  over all photos already exceeds its threshold (the other photos' partial sums are the
  offset): the run is the same, with fewer P_skof/P_pll evaluations. Each term is added for
  every photo before the next (P_pll, then the costlier P_skof), so P_skof's pruning knows
  every photo's P_pll.
- **Angular prior.** The DE minimises the weighted sum plus ``lambda mean_g (alpha_g /
  tau)^2`` (:data:`ANGLE_PRIOR_WEIGHT`, ``alpha_g`` the polar angle a gene puts a facial point
  at from its cone axis, ``tau`` = :data:`~lilium.constants.DIRECTION_SD_DEG`): with one
  frontal and one lateral photo a shared soft tissue still had the cones' angular freedom to
  absorb the landmarks' noise (it fitted them tighter than either single SFO), and a real face
  may lie outside the depth table (the headsq CT's canthi and alare), so the prior is on the
  direction only. The result's fitness is the photos' weighted sum without it
  (docs/method/joint.md); ``joint_fitness`` in ``extra`` is the DE's, with it.
  ``prior_weight=0`` is the design before (docs/decisions/0007-joint-sfo-soft-tissue-prior.md).
- **Budget.** ``generations_factor`` scales the DE generations (default
  :data:`DEFAULT_GENERATIONS_FACTOR`, 0.5: with the cameras on the priors half the generations
  gave the same BPE as all of them on 8 generated subjects x 3 seeds, complete and
  mandible-less, and on headsq, at about half the time; one joint generation costs more than
  the photos' single generations together, the lower-bound pruning skipping fewer image
  terms once P_cam no longer rules trials out: 1.2-1.8 x the independent pair's time). The
  wall-clock limit
  (``options.de.max_seconds``) bounds the joint run as a whole.
"""

import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..constants import CONE_MAX_POLAR_DEG, DIRECTION_SD_DEG
from ..optimisation.de import DifferentialEvolution
from ..pose.prior_refine import refine_with_priors
from ..pose.residuals import reprojection_sq_errors
from ..softtissue.cones import decode
from ..softtissue.landmarks import CRANIAL_TO_FACIAL
from .lilium import IMAGE_TERMS, LiliumProblem, build_cones
from .lilium_outcome import de_extra, outcome_fitness, photo_outcome
from .options import SfoOptions
from .result import SfoResult, finite_or_none

#: How the photos' fitnesses are summed (see the module notes).
WEIGHTINGS = ("sum", "scale")

#: How each photo's camera is fitted to a member's soft tissue (see the module notes).
CAMERAS = ("priors", "least_squares")

#: The defaults, chosen by ``benchmarks/bench_joint.py`` (full budget, seeds 1-3, scale
#: weighting; mean BPE of both photos against the independent SFOs of the same photos,
#: docs/decisions/0006-joint-sfo-cameras-and-budget.md): least-squares cameras x1.044 / x1.177 on 8
#: generated subjects complete /
#: without mandible and x1.223 / x1.440 on headsq ``hq`` / ``hq_nm``; cameras on the priors at
#: half the generations x0.898 / x1.022 / x1.101 / x1.058 (all the generations: x0.894 /
#: x0.995 / x1.141 / x1.015), x0.922 / x0.995 / x1.018 / x1.034 since the refinement takes 10
#: iterations (:data:`PRIOR_CAMERA_ITERATIONS`). The plain sum (``weighting="sum"``) was worse
#: with either camera.
DEFAULT_CAMERA = "priors"
DEFAULT_WEIGHTING = "scale"
DEFAULT_GENERATIONS_FACTOR = 0.5

#: Weight ``lambda`` of the joint DE's angular soft-tissue prior (module notes): 0 = none.
#: Measured as the defaults above (ratios to the independent SFOs, generated complete / without
#: mandible, headsq ``hq`` / ``hq_nm``): none x0.922 / x0.995 / x1.018 / x1.034; lambda 10
#: x0.885 / x0.982 / x1.001 / x0.943; 30 x0.866 / x0.978 / x0.969 / x0.979; 100 (mandible-less
#: only) x1.047.
ANGLE_PRIOR_WEIGHT = 30.0


def angle_prior(genes, weight):
    """The joint DE's angular soft-tissue prior of a population ``(S, 3U)``: ``(S,)``,
    ``weight`` times the mean over the genes of ``(alpha / tau)^2``, ``alpha`` the polar angle
    (degrees) a gene's second component sets (before the bilateral hybrid), ``tau`` =
    :data:`~lilium.constants.DIRECTION_SD_DEG`."""
    genes = np.atleast_2d(genes)
    if not weight:
        return np.zeros(len(genes))
    alpha = CONE_MAX_POLAR_DEG * genes[:, 1::3]
    return weight * np.mean((alpha / DIRECTION_SD_DEG) ** 2, axis=1)


#: Per-photo arrays of the DE payload, shape ``(S, P, ...)``.
PHOTO_KEYS = ("fitness", "mse_pix", "p_cam", "p_skof", "p_pll", "R", "t", "focal_px", "success")


@dataclass(frozen=True)
class _Union:
    """The cranial landmarks any photo uses (what :func:`build_cones` needs)."""

    cranial_names: tuple
    axes: np.ndarray
    cranial_mm: np.ndarray


def photo_scale_px_per_mm(corr):
    """Pixels per millimetre of a photo at the face: the RMS spread of its 2D landmarks (px)
    over the RMS spread of their cranial landmarks (mm), both about their centroids.

    Parameters
    ----------
    corr : Correspondences

    Returns
    -------
    float
    """
    uv = corr.uv_px - corr.uv_px.mean(axis=0)
    xyz = corr.cranial_mm - corr.cranial_mm.mean(axis=0)
    return float(np.sqrt(np.mean(np.sum(uv**2, axis=1)) / np.mean(np.sum(xyz**2, axis=1))))


class JointLiliumProblem:
    """Fitness of a population of shared genotypes for one skull and several photos.

    ``(S, D) -> (S,)`` with a payload of one camera (and the terms) per photo per member.

    Parameters
    ----------
    skull : Skull
    photos : sequence of Photo
        Two or more, with distinct ids.
    options : SfoOptions
    rng : seed or numpy Generator
        For the RANSAC of the initial and fallback POSEST runs (shared by the photos).
    weighting : {"sum", "scale"}
    camera : {"priors", "least_squares"}
        ``"priors"``: each photo's least-squares camera is refined further on its MSE_pix +
        P_cam (:func:`camera_on_priors`); ``"least_squares"``: as a single SFO.
    prior_weight : float
        :func:`angle_prior`'s weight (:data:`ANGLE_PRIOR_WEIGHT`; 0 = none).

    Raises
    ------
    ValueError
        Fewer than two photos, repeated photo ids, an unknown weighting or camera, or what a
        single :class:`LiliumProblem` refuses (an unknown variant, too few landmarks in a photo).
    """

    def __init__(
        self,
        skull,
        photos,
        options=SfoOptions(),
        rng=0,
        weighting=DEFAULT_WEIGHTING,
        camera=DEFAULT_CAMERA,
        prior_weight=ANGLE_PRIOR_WEIGHT,
    ):
        photos = list(photos)
        if len(photos) < 2:
            raise ValueError(f"a joint SFO needs two or more photos, got {len(photos)}")
        ids = [p.id for p in photos]
        if len(set(ids)) != len(ids):
            raise ValueError(
                f"photo ids repeat in the joint SFO ({', '.join(ids)}); give each photo once"
            )
        if weighting not in WEIGHTINGS:
            raise ValueError(f"unknown weighting {weighting!r}; use one of {', '.join(WEIGHTINGS)}")
        if camera not in CAMERAS:
            raise ValueError(f"unknown camera {camera!r}; use one of {', '.join(CAMERAS)}")
        self.camera = camera
        self.prior_weight = float(prior_weight)
        self.rng = np.random.default_rng(rng)
        self.skull, self.photos, self.options = skull, photos, options
        self.problems = [LiliumProblem(skull, p, options, rng=self.rng) for p in photos]
        used = set().union(*(pr.corr.cranial_names for pr in self.problems))
        names = tuple(c for c in CRANIAL_TO_FACIAL if c in used)
        self.union = _Union(
            names,
            np.array([skull.axes[c] for c in names], dtype=float),
            np.array([skull.landmarks_mm[c] for c in names], dtype=float),
        )
        self.facial_names = tuple(CRANIAL_TO_FACIAL[c] for c in names)
        self.cones = build_cones(skull, self.union, options.depth_table)
        self.periodic = np.tile([False, False, True], len(names))
        self.rows = [
            np.array([names.index(c) for c in pr.corr.cranial_names]) for pr in self.problems
        ]
        scale = np.array([photo_scale_px_per_mm(pr.corr) for pr in self.problems])
        if weighting == "scale":
            self.weights = np.exp(np.mean(np.log(scale))) ** 2 / scale**2
        else:
            self.weights = np.ones(len(photos))
        self.scale_px_per_mm = scale

    @property
    def n_genes(self):
        return self.cones.n_genes

    def facial_landmarks(self, genes):
        """Shared facial 3D landmarks ``(S, U, 3)`` of a population ``(S, 3U)`` (the union)."""
        return self.union.cranial_mm + decode(np.atleast_2d(genes), self.cones)

    def evaluate(self, genes, members=None, thresholds=None):
        """Every photo's terms for a population, and the weighted sum.

        Parameters
        ----------
        genes : ndarray of shape (S, 3U)
        members : dict or None
            Payload of the members the trials compete with; None = initial population.
        thresholds : ndarray of shape (S,), optional
            As in :meth:`LiliumProblem.evaluate`, on the joint fitness.

        Returns
        -------
        dict of str -> ndarray
            ``fitness`` (S,) the joint fitness (with :func:`angle_prior`); per photo (axis 1,
            in photo order) ``photo_fitness``, ``mse_pix``, ``p_cam``, ``p_skof``, ``p_pll`` (S, P),
            ``success`` (S, P), cameras ``R`` (S, P, 3, 3), ``t`` (S, P, 3), ``focal_px`` (S, P).
        """
        facial = self.facial_landmarks(genes)
        prior = angle_prior(genes, self.prior_weight)
        per = []
        for p, problem in enumerate(self.problems):
            mine = None
            if members is not None:
                mine = {k: np.asarray(members[k])[:, p] for k in ("R", "t", "focal_px", "success")}
            terms = problem.camera_terms(facial[:, self.rows[p]], mine)
            if self.camera == "priors":
                camera_on_priors(problem, facial[:, self.rows[p]], terms, mine)
            per.append(terms)
        w = self.weights
        # Fitnesses of hopeless trials reach 1e60 and more (P_cam of a run-off camera); their
        # weighted sums may overflow to inf, which ranks them last as it should.
        with np.errstate(over="ignore", invalid="ignore"):
            partial = np.array([w[p] * per[p]["fitness"] for p in range(len(per))])
            # Each term for every photo before the next: P_skof's pruning (the costly count)
            # then knows every photo's P_pll.
            for name in IMAGE_TERMS:
                for p, problem in enumerate(self.problems):
                    # The other photos' partial sums and the prior bound the trial's rest.
                    offset = np.delete(partial, p, axis=0).sum(axis=0) + prior
                    problem.add_image_terms(per[p], thresholds, offset, w[p], names=(name,))
                    partial[p] = w[p] * per[p]["fitness"]
            total = partial.sum(axis=0) + prior
        out = {k: np.stack([t[k] for t in per], axis=1) for k in PHOTO_KEYS}
        out["photo_fitness"] = out.pop("fitness")
        out["fitness"] = total
        return out

    def __call__(self, genes, members=None, thresholds=None):
        """DE's objective: ``(fitness (S,), payload)``."""
        terms = self.evaluate(genes, members, thresholds)
        return terms["fitness"], terms


#: Levenberg-Marquardt iterations of :func:`camera_on_priors` per evaluation (it starts from
#: the member's refined camera, so a chain keeps converging over the generations). 10, not 5:
#: with 5 a camera far outside its priors (a mandible-less photo's least-squares focal length)
#: was still on the prior's edge, or outside it, at the end of the run; measured
#: (``bench_joint.py``, seeds 1-3, docs/decisions/0006-joint-sfo-cameras-and-budget.md) 5 -> 10 ->
#: 15 iterations: mean BPE against
#: the independent SFOs x0.898 -> x0.922 -> x0.972 on generated complete subjects, x1.022 ->
#: x0.995 -> x0.974 without mandible, x1.101 -> x1.018 -> x1.088 on headsq ``hq``, x1.058 ->
#: x1.034 -> x1.037 on ``hq_nm``; time x1.19-2.31 -> x1.17-1.82 -> x1.10-1.47 of the pair.
PRIOR_CAMERA_ITERATIONS = 10


def camera_on_priors(problem, facial_mm, terms, members=None):
    """Move the cameras of members outside a photo's priors to the minimum of MSE_pix + P_cam.

    :meth:`LiliumProblem.camera_terms` fits each camera to the landmarks alone; P_cam then
    only judges it. A single SFO lives with that: its soft tissue bends until the
    least-squares camera lands inside the priors. A joint SFO's soft tissue is shared, so it
    cannot do that for every photo at once (docs/decisions/0009-joint-sfo-real-anatomy.md); here the
    camera itself takes the priors into account
    (:func:`~lilium.pose.prior_refine.refine_with_priors`, :data:`PRIOR_CAMERA_ITERATIONS`
    iterations, started from the camera of the member the trial competes with, the previous
    such refinement, where it has a valid one, else from the least-squares camera). A member
    whose least-squares camera is valid and inside every prior (P_cam = 0) keeps it; a refined
    camera replaces it only when it is valid and lowers MSE_pix + P_cam. Along a dolly zoom the
    landmarks hardly tell focal lengths apart, so most refined cameras stop on an edge of the
    focal prior, at little cost in BPE (docs/decisions/0010-joint-sfo-cameras-on-prior-edges.md).

    Parameters
    ----------
    problem : LiliumProblem
        The photo's problem.
    facial_mm : ndarray of shape (S, N, 3)
        The photo's rows of the members' facial landmarks.
    terms : dict
        :meth:`LiliumProblem.camera_terms`' dictionary, updated in place (cameras, ``mse_pix``,
        ``p_cam``, ``fitness``, ``success``).
    members : dict, optional
        This photo's cameras of the members the trials compete with (``R``, ``t``,
        ``focal_px``, ``success``); None for the initial population.

    Returns
    -------
    dict
        ``terms``.
    """
    need = np.flatnonzero(terms["success"] & (terms["p_cam"] > 0.0))
    if len(need) == 0:
        return terms
    priors = problem.photo.priors
    head = priors.uses_head
    points = facial_mm[need]
    R0, t0, f0 = (np.array(terms[k][need]) for k in ("R", "t", "focal_px"))
    if members is not None:
        own = np.asarray(members["success"])[need]
        R0[own] = np.asarray(members["R"])[need][own]
        t0[own] = np.asarray(members["t"])[need][own]
        f0[own] = np.asarray(members["focal_px"])[need][own]
    ref = refine_with_priors(
        problem.uv_c,
        points,
        R0,
        t0,
        f0,
        points[:, problem.scd_index].mean(axis=1),
        focal_interval_px=priors.focal_px,
        scd_interval_mm=priors.scd_mm,
        head_rotation=priors.head_rotation_skull2cam if head else None,
        head_tolerance_deg=priors.head_tolerance_deg if head else None,
        max_iterations=PRIOR_CAMERA_ITERATIONS,
    )
    R, t, f = ref.R, ref.t, ref.focal_px
    # LiliumProblem's own validity rule and terms (focal range, skull front seen).
    ok = problem._valid(f, problem._facing(R, t))
    sq = reprojection_sq_errors(problem.uv_c, points, R, t, np.where(ok, f, 1.0))
    ok &= np.all(np.isfinite(sq), axis=1)
    sq[~ok] = np.inf
    new = problem._terms(points, R, t, f, ok, sq)
    take = ok & (new["fitness"] < terms["fitness"][need])
    rows = need[take]
    for key in ("fitness", "mse_pix", "p_cam", "R", "t", "focal_px", "success"):
        terms[key][rows] = new[key][take]
    return terms


@dataclass(frozen=True)
class JointSfoResult:
    """Outcome of a joint SFO: one shared soft tissue, one :class:`SfoResult` per photo.

    Falsy when any photo has no camera.

    Attributes
    ----------
    method, variant : str
    seed : int
    skull_id : str
    photos : tuple of SfoResult
        Per photo (in the order given): its camera, its own fitness (unweighted) and terms,
        ``terms_off``, error and warnings; its ``facial_landmarks_mm`` are the shared ones it
        sees (its landmarks), so every per-photo tool (overlay, BPE, landmark error, report)
        takes it. Its ``seconds`` are the joint run's, its ``extra`` says it is part of a joint
        SFO: ``joint_photos`` (the ids), ``joint_fitness``, and the joint ``history``,
        ``generations``, ``evaluations``, ``stop``.
    fitness : float
        The joint fitness ``sum_p w_p fitness_p`` of the photos' fitnesses (each at full level,
        as a single SFO's); it equals the DE's ``history[-1]`` when every photo ran at full
        level (:mod:`~lilium.methods.working_level`).
    facial_landmarks_mm : dict of str -> ndarray of shape (3,)
        The shared soft tissue's facial landmarks (the union of the photos'), skull frame.
    seconds : float
    weights : tuple of float
        ``w_p`` of each photo (all 1 for ``weighting="sum"``).
    extra : dict
        ``history``, ``generations``, ``evaluations``, ``stop``, ``genes``, ``fallbacks``,
        ``weighting``, ``camera_fit`` (how the cameras were fitted, :data:`CAMERAS`).
    """

    method: str
    variant: str
    seed: int
    skull_id: str
    photos: tuple
    fitness: float
    facial_landmarks_mm: dict
    seconds: float
    weights: tuple = ()
    extra: dict = field(default_factory=dict)

    def __bool__(self):
        return all(bool(r) for r in self.photos)

    @property
    def joint(self):
        return True

    @property
    def error(self):
        """The photos' errors, ``"<photo>: <error>"`` joined ("" when every photo has a camera)."""
        return "; ".join(f"{r.photo_id}: {r.error}" for r in self.photos if r.error)

    @property
    def warnings(self):
        """Every photo's warnings, in photo order."""
        return tuple(w for r in self.photos for w in r.warnings)

    def to_dict(self):
        """The ``result.json`` dictionary of docs/method/joint.md.

        Each photo's ``fitness`` is its share of the total, ``weight x`` its own fitness, so
        that the total is the sum of the photos' fitnesses as docs/method/joint.md states; its own
        (unweighted) fitness, the sum of its ``terms``, is ``fitness_unweighted``.
        """
        photos = []
        for r, w in zip(self.photos, self.weights, strict=True):
            d = r.to_dict()
            own = d["fitness"]
            share = None if own is None else float(w) * own
            entry = {"photo": d["photo"], "camera": d["camera"], "fitness": share}
            entry["fitness_unweighted"] = own
            entry["terms"] = d["terms"]
            entry["terms_off"] = d.get("terms_off", {})
            if r.error:
                entry["error"] = r.error
            entry["weight"] = float(w)
            for key in ("landmark_error", "warnings", "priors"):
                if key in d:
                    entry[key] = d[key]
            photos.append(entry)
        out = {
            "method": self.method,
            "variant": self.variant,
            "seed": self.seed,
            "subject": self.skull_id,
            "joint": True,
            "photos": photos,
            "fitness": finite_or_none(self.fitness),
            "facial_landmarks_3d": {
                k: [float(x) for x in v] for k, v in self.facial_landmarks_mm.items()
            },
            "seconds": float(self.seconds),
        }
        if self.error:
            out["error"] = self.error
        out.update(self.extra)
        return out


def joint_lilium_sfo(
    skull,
    photos,
    options=SfoOptions(),
    seed=0,
    weighting=DEFAULT_WEIGHTING,
    generations_factor=DEFAULT_GENERATIONS_FACTOR,
    camera=DEFAULT_CAMERA,
    prior_weight=ANGLE_PRIOR_WEIGHT,
):
    """Run one joint Lilium SFO of a skull against several photos of one person.

    Parameters
    ----------
    skull : Skull
    photos : sequence of Photo
        Two or more, distinct ids.
    options : SfoOptions
        The variant and DE settings (the same for every photo).
    seed : int
        Seeds DE and the RANSAC of the POSEST calls: the same seed gives the same result.
    weighting : {"sum", "scale"}
        How the photos' fitnesses are summed (module notes).
    generations_factor : float
        DE generations = ``round(factor x options.de.max_generations)``.
    camera : {"priors", "least_squares"}
        How each photo's camera is fitted (:class:`JointLiliumProblem`).
    prior_weight : float
        The DE's angular soft-tissue prior (:func:`angle_prior`; 0 = none).

    Returns
    -------
    JointSfoResult
        Per photo as :func:`~lilium.methods.lilium.lilium_sfo` reports one SFO (without the
        warnings, priors and landmark error that :func:`lilium.methods.run_joint_sfo` adds).
    """
    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    problem = JointLiliumProblem(
        skull, photos, options, rng=rng, weighting=weighting, camera=camera,
        prior_weight=prior_weight,
    )
    de_options = options.de
    if generations_factor != 1.0:
        generations = max(1, round(generations_factor * de_options.max_generations))
        de_options = replace(de_options, max_generations=generations)
    solver = DifferentialEvolution(problem, problem.n_genes, problem.periodic, de_options, rng=rng)
    de = solver.solve()
    best = de.payload
    shared = problem.facial_landmarks(de.x)[0]
    results = []
    for p, single in enumerate(problem.problems):
        mine = {k: np.asarray(best[k])[p] for k in PHOTO_KEYS if k != "fitness"}
        camera, terms, error, warnings = photo_outcome(single, mine, seed)
        fitness = outcome_fitness(single, np.asarray(best["photo_fitness"])[p], camera, terms)
        rows = problem.rows[p]
        results.append(
            SfoResult(
                method="lilium",
                variant=options.variant,
                seed=seed,
                skull_id=skull.id,
                photo_id=single.photo.id,
                camera=camera,
                fitness=fitness,
                terms=terms,
                facial_landmarks_mm=dict(zip(single.corr.facial_names, shared[rows], strict=True)),
                seconds=0.0,  # the joint run's, below
                error=error,
                warnings=warnings,
                terms_off=dict(single.terms_off),
            )
        )
    total = de.fun  # the photos' weighted sum, unless the DE's also held the prior
    if any(r.camera is not None for r in results) and (
        problem.prior_weight or not all(pr.level.is_full for pr in problem.problems)
    ):
        total = float(sum(w * r.fitness for w, r in zip(problem.weights, results, strict=True)))
    seconds = time.perf_counter() - start
    ids = [r.photo_id for r in results]
    shared_extra = {
        "joint_photos": ids,
        "joint_fitness": de.fun,
        "history": de.history.tolist(),
        "generations": de.nit,
        "evaluations": de.nfev,
        "stop": de.message,
    }
    results = [replace(r, seconds=seconds, extra=dict(shared_extra)) for r in results]
    return JointSfoResult(
        method="lilium",
        variant=options.variant,
        seed=seed,
        skull_id=skull.id,
        photos=tuple(results),
        fitness=total,
        facial_landmarks_mm=dict(zip(problem.facial_names, shared, strict=True)),
        seconds=seconds,
        weights=tuple(float(w) for w in problem.weights),
        extra=de_extra(de, sum(pr.n_fallbacks for pr in problem.problems))
        | {"weighting": weighting, "camera_fit": problem.camera,
           "angle_prior_weight": problem.prior_weight},
    )
