"""Lilium: differential evolution over soft-tissue cones with a composite fitness.

Each DE individual is a genotype of three genes per usable cranial landmark (docs/method/lilium.md).
Its fitness (docs/method/lilium.md) is ``MSE_pix + P_cam [+ P_skof] [+ P_pll]``:

1. decode the genes into soft-tissue vectors, facial 3D landmarks ``F = C + ST``;
2. fit the camera to ``(F, f)`` by Levenberg-Marquardt, warm-started from the camera of the
   member the trial competes with (the first population refines from one full POSEST); when
   the warm-started refinement breaks (a point behind the camera) the individual falls back to
   full POSEST (RANSAC + LM), and so does every member when none has a valid camera (the
   least-squares fits of near-coplanar landmarks run off towards an infinite focal length, and
   a warm start from such a camera never comes back); an initial population still without a
   camera gets POSEST-SFO's soft tissue and camera (:func:`rescue_population`), so Lilium finds
   a camera wherever POSEST-SFO does;
3. score the camera: mean squared reprojection error over all used landmarks, camera priors,
   skull pixels outside the face mask, chin-jaw/forehead curve parallelism.

The whole population is evaluated at once (batched LM, batched projections).

A camera that sees the back of the skull (docs/checks.md) or whose focal length exceeds the
photo's focal cap (docs/method/pose.md) is "no solution" (P_cam's C_INF). When the best member has
no camera for one of those reasons the SFO fails with a message that says which and what to
fix. Without a focal prior, warning ``focal_cap`` when members fitted the landmarks better than
the result but exceeded the cap, or when the mean soft tissue fits a focal length above the cap
(:func:`~lilium.methods.posest_sfo.long_lens_focal_px`: a long lens the cap hides).
"""

import time

import numpy as np

from .. import jit
from ..constants import C_INF, FOCAL_MIN_PX, focal_cap_px
from ..fitness._camera_kernels import camera_terms_kernel
from ..fitness.camera_penalty import camera_penalty_from_priors, prior_arrays
from ..geometry.camera import Cameras, principal_point_of
from ..optimisation.de import STOPPED_BY_CALLBACK, DifferentialEvolution
from ..pose.posest import posest
from ..pose.refine import refine_batch
from ..pose.residuals import reprojection_sq_errors
from ..softtissue.cones import decode, encode_depth_only, make_cones, midsagittal_plane
from ..softtissue.depths import depth_stats
from .checks import facing_check
from .lilium_cameras import camera_terms_compiled, checks_compiled
from .lilium_outcome import (
    MAX_RESTARTS,
    de_extra,
    missed_head_prior,
    outcome_fitness,
    photo_outcome,
)
from .lilium_terms import image_terms, prior_terms_off
from .options import SfoOptions, with_focal_cap
from .pairs import correspondences
from .posest_sfo import RUN_OFF_FACTOR, mean_depth_landmarks
from .result import SfoResult
from .working_level import working_level

#: POSEST-SFO's fixed RANSAC seed (:func:`~lilium.methods.posest_sfo.posest_sfo`'s default).
POSEST_SFO_SEED = 0

#: Variants: which optional penalties are on, (P_skof, P_pll).
VARIANTS = {
    "base": (False, False),
    "pll": (False, True),
    "skof": (True, False),
    "skof+pll": (True, True),
}

#: The image terms :meth:`LiliumProblem.add_image_terms` adds, in its order (P_pll first).
IMAGE_TERMS = ("p_pll", "p_skof")


def build_cones(skull, corr, depth_table=None):
    """Cones of the usable landmarks (``corr``: anything with ``cranial_names`` and ``axes``, a
    :class:`~lilium.methods.pairs.Correspondences`), twins with mirror-consistent bases."""
    stats = [depth_stats(c, depth_table) for c in corr.cranial_names]
    _, normal = midsagittal_plane(skull.landmarks_mm)
    return make_cones(
        corr.cranial_names,
        corr.axes,
        [s.min_mm for s in stats],
        [s.max_mm for s in stats],
        mirror_normal=normal,
    )


class LiliumProblem:
    """Fitness of a population of genotypes for one skull and one photo (``(S, D) -> (S,)``).

    Stateless between calls apart from its RANSAC generator: the cameras of the population
    members travel with DE as their payload (:mod:`lilium.optimisation.de`).

    Parameters
    ----------
    skull : Skull
    photo : Photo
    options : SfoOptions
    rng : seed or numpy Generator
        For the RANSAC of initial and fallback POSEST runs.
    camera : Camera, optional
        A fixed camera (an examiner's, :func:`lilium_sfo`'s ``camera``): every member gets it,
        so the DE searches the soft tissue only; its principal point replaces the image centre.
        The image terms, which depend on the camera alone, are computed once.
    """

    def __init__(self, skull, photo, options=SfoOptions(), rng=0, camera=None):
        if options.variant not in VARIANTS:
            raise ValueError(
                f"unknown Lilium variant {options.variant!r}; use one of {', '.join(VARIANTS)}"
            )
        self.skull, self.photo = skull, photo
        self.options = with_focal_cap(options, photo.priors.focal_px)
        self.focal_cap_px = focal_cap_px(photo.priors.focal_px)
        self.facing = facing_check(skull)
        self.use_skof, self.use_pll = VARIANTS[options.variant]
        self.corr = correspondences(skull, photo)
        self.cones = build_cones(skull, self.corr, options.depth_table)
        self.camera = camera
        self.centre = (
            principal_point_of(photo.image_size_wh)
            if camera is None
            else np.asarray(camera.principal_point_px, dtype=float)
        )
        self._fixed_terms = {}  # the image terms of the fixed camera, once computed
        self.uv_c = self.corr.uv_px - self.centre
        names = self.corr.facial_names
        self.scd_index = [names.index("nasion")] if "nasion" in names else list(range(len(names)))
        self.rng = np.random.default_rng(rng)
        self.periodic = np.tile([False, False, True], len(self.corr.cranial_names))
        # Asked-for terms whose inputs are missing are switched off (docs/method/lilium.md), and so
        # is
        # each P_cam part without its prior: ``terms_off`` says which and why.
        # Without image terms the DE scores nothing at a working level: none is built.
        images = self.use_skof or self.use_pll
        face_px = options.working_face_px if images else None
        self.level = working_level(skull, photo, self.corr, face_px)
        self.skof, self.pll, self.terms_off = image_terms(
            skull, photo, self.centre, self.use_skof, self.use_pll, self.level
        )
        self.terms_off.update(prior_terms_off(photo.priors))
        self.outside = None  # the result's ImplausibleSFO, once photo_outcome computed it
        self.n_fallbacks = 0  # statistics only
        # Evaluations where no member had a camera to lend and no fit found one (statistics).
        self.n_no_camera = 0
        # Lowest MSE (px^2) of a camera refused for the focal cap, and its focal length.
        self.capped_mse, self.capped_focal_px = np.inf, None
        self.prior_arrays = prior_arrays(photo.priors)
        self._stage = {}  # camera_stage_kernel's fixed arguments, per population size

    def level_extra(self):
        """The working level of the DE and the result's outside count, for ``SfoResult.extra``:
        ``working_scale``, ``working_faces``, ``working_cell_mm`` and, when the result's
        P_skof was recomputed at full level, ``outside_px`` and ``skull_px``."""
        extra = {
            "working_scale": self.level.scale,
            "working_faces": len(self.level.skull.faces),
            "working_cell_mm": self.level.cell_mm,
        }
        if self.outside is not None:
            extra["outside_px"] = self.outside.outside_px
            extra["skull_px"] = self.outside.skull_px
        return extra

    # -- evaluation -------------------------------------------------------------------------
    def facial_landmarks(self, genes):
        """Facial 3D landmarks ``(S, N, 3)`` of a population ``(S, 3N)``."""
        return self.corr.cranial_mm + decode(np.atleast_2d(genes), self.cones)

    def _posest(self, facial_mm):
        """Full POSEST for one member's facial landmarks: ``(R, t, focal_px)`` or None."""
        pose = posest(
            self.corr.uv_px,
            facial_mm,
            self.centre,
            self.options.posest,
            rng=self.rng,
            camera_check=self.facing,
        )
        if not pose:
            return None
        return pose.camera.R, pose.camera.t, pose.camera.focal_px

    def _initial_camera(self, facial_mm):
        """Camera of the first member whose POSEST succeeds (a 1 m guess if none does)."""
        for points in facial_mm:
            camera = self._posest(points)
            if camera is not None:
                return camera
        return np.eye(3), np.array([0.0, 0.0, 1000.0]), 1000.0

    def cameras(self, facial_mm, members=None):
        """Cameras of a population: warm-started LM, POSEST where that fails.

        Parameters
        ----------
        facial_mm : ndarray of shape (S, N, 3)
        members : dict or None
            Payload of the members the trials compete with (``R``, ``t``, ``focal_px``,
            ``success``): each trial starts from its member's camera. None = initial population.

        Returns
        -------
        R (S, 3, 3), t (S, 3), focal_px (S,), success (S,) bool, sq_err_px2 (S, N)
        """
        S = len(facial_mm)
        if self.camera is not None:
            c = self.camera
            R, t = np.repeat(c.R[None], S, axis=0), np.repeat(c.t[None], S, axis=0)
            return self._scored(facial_mm, R, t, np.full(S, c.focal_px))
        if members is None:
            # One POSEST, then every member refines from that camera (members it does not suit
            # fall back to their own POSEST below).
            R1, t1, f1 = self._initial_camera(facial_mm)
            R0, t0, f0 = (
                np.repeat(R1[None], S, axis=0),
                np.repeat(t1[None], S, axis=0),
                np.full(S, f1),
            )
        else:
            R0, t0, f0 = (np.array(members[k]) for k in ("R", "t", "focal_px"))
            ok = members["success"]
            # A member without a valid camera lends none: start from a valid member's.
            if (~ok).any() and ok.any():
                j = np.flatnonzero(ok)[0]
                R0[~ok], t0[~ok], f0[~ok] = R0[j], t0[j], f0[j]
        ref = refine_batch(self.uv_c, facial_mm, R0, t0, f0, options=self.options.refine)
        lender = members is not None and bool(np.any(members["success"]))
        if jit.compiled():  # the checks below, compiled, unless a camera must be replaced
            ok = checks_compiled(self, ref, lender)
            if ok is not None:
                return ref.R, ref.t, ref.focal_px, ok, ref.sq_err_px2
        return self._checked(facial_mm, ref, lender)

    def _checked(self, facial_mm, ref, lender):
        """:meth:`cameras`' checks of refined cameras ``ref`` (:class:`BatchRefineResult`) on
        the numpy path, each broken camera replaced by its own POSEST; ``lender``: some member
        has a valid camera. Returns :meth:`cameras`' tuple."""
        R, t, f = ref.R, ref.t, ref.focal_px
        # Numerical failure (a point behind the camera): fall back to full POSEST.
        broken = ~np.isfinite(ref.cost) | ~np.all(np.isfinite(ref.sq_err_px2), axis=1)
        self._own_posest(facial_mm, R, t, f, broken, broken)
        replaced = broken.copy()  # cameras no longer the refined ones
        # A camera out of range is that soft tissue's failure (C_INF) while some member has a
        # valid camera to lend. When none has (the initial population, or every member failed)
        # and no fit of this batch found one, the least-squares fits over all landmarks ran off
        # towards an infinite focal length (near-coplanar landmarks: a skull without the
        # mandible seen from the front) and every later warm start would start from a run-off
        # camera and run off again: each member takes its own POSEST, whose inliers fix a
        # finite focal length (docs/decisions/0004-no-camera-on-flat-landmarks.md, "No camera on a
        # mandible-less frontal photo").
        facing = self._facing(R, t)
        ok = self._valid(f, facing)
        if not lender and not ok.any():
            self.n_no_camera += 1
            self._own_posest(facial_mm, R, t, f, ~ok & ~broken, np.zeros_like(broken))
            replaced |= ~ok
            facing = self._facing(R, t)
            ok = self._valid(f, facing)
        # The refinement's errors are those of its cameras (same projection, same inputs); only
        # the replaced cameras need theirs (a run-off one overflows to inf: invalid, set below).
        sq = ref.sq_err_px2
        if replaced.any():
            with np.errstate(over="ignore", invalid="ignore"):
                sq[replaced] = reprojection_sq_errors(
                    self.uv_c, facial_mm[replaced], R[replaced], t[replaced], f[replaced]
                )
        self._note_capped(f, facing, sq)
        sq[~ok] = np.inf
        return R, t, f, ok, sq

    def _own_posest(self, facial_mm, R, t, f, which, lost):
        """Replace the cameras of members ``which`` by their own POSEST (in place, in member
        order); where POSEST fails too, a member in ``lost`` gets a NaN focal length."""
        for i in np.flatnonzero(which):
            self.n_fallbacks += 1
            camera = self._posest(facial_mm[i])
            if camera is not None:
                R[i], t[i], f[i] = camera
            elif lost[i]:
                f[i] = np.nan

    def _facing(self, R, t):
        """``(S,)`` bool: the camera sees the skull's front (all True without the rule)."""
        return np.ones(len(R), bool) if self.facing is None else self.facing(R, t)

    def _valid(self, f, facing):
        """``(S,)`` bool: focal length in ``[FOCAL_MIN_PX, cap]`` and the skull's front seen
        (``facing``, :meth:`_facing`)."""
        with np.errstate(invalid="ignore"):
            return (f >= FOCAL_MIN_PX) & (f <= self.focal_cap_px) & facing

    def _note_capped(self, f, facing, sq_px2):
        """Remember the best fit refused only for its focal length (the cap was hit; a fit
        that ran off towards an orthographic camera does not count). ``sq_px2`` ``(S, N)``:
        each member's squared errors under its camera."""
        capped = (f > self.focal_cap_px) & (f <= RUN_OFF_FACTOR * self.focal_cap_px) & facing
        if not capped.any():
            return
        mse = np.mean(sq_px2[capped], axis=1)
        k = int(np.argmin(mse))
        if mse[k] < self.capped_mse:
            self.capped_mse, self.capped_focal_px = float(mse[k]), float(f[capped][k])

    def evaluate(self, genes, members=None, thresholds=None):
        """All fitness terms of a population.

        Parameters
        ----------
        genes : ndarray of shape (S, 3N)
        members : dict or None
            Payload of the members the trials compete with (warm start); None = initial
            population.
        thresholds : ndarray of shape (S,), optional
            Fitness each trial must reach to win. The image penalties (the expensive terms) are
            skipped for a trial whose cheaper terms already exceed its threshold; its fitness is
            then that lower bound and the skipped terms are NaN (the trial loses either way).

        Returns
        -------
        dict of str -> ndarray of shape (S, ...)
            ``fitness``, ``mse_pix``, ``p_cam``, ``p_skof``, ``p_pll`` (NaN when off or
            skipped), ``success`` and the cameras ``R``, ``t``, ``focal_px``.
        """
        if members is not None and jit.compiled() and self.camera is None:
            terms = camera_terms_compiled(self, genes, members)
        else:
            terms = self.camera_terms(self.facial_landmarks(genes), members)
        return self.add_image_terms(terms, thresholds)

    def camera_terms(self, facial_mm, members=None):
        """The cheap terms of a population given its facial landmarks: cameras, MSE, P_cam.

        The first half of :meth:`evaluate`; :meth:`add_image_terms` completes it. A joint SFO
        (:mod:`lilium.methods.joint`) calls both per photo with that photo's rows of the shared
        soft tissue.

        Parameters
        ----------
        facial_mm : ndarray of shape (S, N, 3)
            Facial 3D landmarks of this photo's correspondences (skull frame).
        members : dict or None
            As in :meth:`evaluate`.

        Returns
        -------
        dict of str -> ndarray of shape (S, ...)
            As :meth:`evaluate`, with ``fitness = mse_pix + p_cam`` and the image penalties NaN.
        """
        return self._terms(facial_mm, *self.cameras(facial_mm, members))

    def _terms(self, facial_mm, R, t, f, ok, sq):
        """:meth:`camera_terms` of given cameras (``ok``: valid; ``sq``: squared errors)."""
        i = self.scd_index
        centre = facial_mm[:, i[0]] if len(i) == 1 else facial_mm[:, i].mean(axis=1)
        if jit.compiled():  # the same terms, compiled (fitness/_camera_kernels.py)
            mse, p_cam = camera_terms_kernel(
                sq, ok, R, t, f, np.ascontiguousarray(centre), *self.prior_arrays
            )
            return self._term_dict(mse, p_cam, R, t, f, ok)
        mse = np.where(ok, np.mean(sq, axis=1), C_INF)
        mse = np.where(np.isfinite(mse), mse, C_INF)
        # Cameras that ran off (huge focal and depth) overflow here; P_cam gives them C_INF.
        with np.errstate(over="ignore", invalid="ignore"):
            scd = np.linalg.norm(np.einsum("sij,sj->si", R, centre) + t, axis=1)
            p_cam = camera_penalty_from_priors(f, scd, R, ok, self.photo.priors)
        return self._term_dict(mse, p_cam, R, t, f, ok)

    @staticmethod
    def _term_dict(mse, p_cam, R, t, f, ok):
        S = len(R)
        return {
            "fitness": mse + p_cam,
            "mse_pix": mse,
            "p_cam": p_cam,
            "p_skof": np.full(S, np.nan),
            "p_pll": np.full(S, np.nan),
            "R": R,
            "t": t,
            "focal_px": f,
            "success": ok,
        }

    def posest_sfo_member(self):
        """POSEST-SFO's soft tissue as a member: its genes and its terms under POSEST-SFO's camera.

        The genes put every facial landmark at the population mean depth along its axis (polar
        angle 0), POSEST-SFO's facial landmarks; the camera is POSEST on those landmarks with
        POSEST-SFO's options and fixed RANSAC seed, so exactly POSEST-SFO's camera.

        Returns
        -------
        (genes (D,), terms) or None
            ``terms`` as :meth:`evaluate`'s dictionary for one member (arrays of shape (1, ...));
            None when POSEST-SFO finds no camera either.
        """
        table = self.options.depth_table
        depth = [depth_stats(c, table).mean_mm for c in self.corr.cranial_names]
        genes = encode_depth_only(self.cones, depth)
        pose = posest(
            self.corr.uv_px,
            mean_depth_landmarks(self.corr, table),
            self.centre,
            self.options.posest,
            rng=POSEST_SFO_SEED,
            camera_check=self.facing,
        )
        if not pose:
            return None
        facial = self.facial_landmarks(genes)
        c = pose.camera
        scored = self._scored(facial, c.R[None], c.t[None], np.array([c.focal_px]))
        return genes, self.add_image_terms(self._terms(facial, *scored))

    def _scored(self, facial_mm, R, t, f):
        """:meth:`cameras`' tuple for given cameras ``R (S, 3, 3)``, ``t (S, 3)``, ``f (S,)``
        (no fit): a camera is valid when its focal length and facing pass and every point lies
        in front of it."""
        sq = reprojection_sq_errors(self.uv_c, facial_mm, R, t, f)
        ok = self._valid(f, self._facing(R, t)) & np.all(np.isfinite(sq), axis=1)
        sq[~ok] = np.inf
        return R, t, f, ok, sq

    def add_image_terms(self, terms, thresholds=None, offset=0.0, weight=1.0, names=IMAGE_TERMS):
        """Add P_skof and P_pll to :meth:`camera_terms`' dictionary (in place; returned).

        P_pll first: a trial that P_pll already puts above its threshold loses whatever P_skof
        adds (both are >= 0), and P_skof is 0 for almost every trial near the optimum, so
        P_skof's count runs for about a third as many trials (1,601 against 4,829 cameras in a
        600k-face SFO of 750 generations; the same DE run to rounding: the fitness is summed in
        another order).

        Parameters
        ----------
        terms : dict
            From :meth:`camera_terms`.
        thresholds : ndarray of shape (S,), optional
            As in :meth:`evaluate`: a term is skipped (NaN) for a trial whose
            ``offset + weight * fitness`` already exceeds its threshold.
        offset : float or ndarray of shape (S,)
            A lower bound of the rest of the trial's fitness (a joint SFO: the other photos'
            weighted partial sums); 0 for one photo.
        weight : float
            This photo's weight in the trial's fitness (a joint SFO); 1 for one photo.
        names : tuple of str
            The terms to add, of :data:`IMAGE_TERMS` and in its order (a joint SFO adds each
            term for every photo before the next, so that the pruning of one photo's P_skof
            knows the other photos' P_pll).
        """
        fitness, ok = terms["fitness"], terms["success"]
        R, t, f = terms["R"], terms["t"], terms["focal_px"]
        S = len(fitness)
        bound = np.full(S, np.inf) if thresholds is None else np.asarray(thresholds, float)
        for name, term in (("p_pll", self.pll), ("p_skof", self.skof)):
            values = terms[name]
            if term is None or name not in names:
                continue
            with np.errstate(over="ignore", invalid="ignore"):
                todo = ok & (offset + weight * fitness <= bound)
            if todo.any():
                values[todo] = self._image_term(name, term, R[todo], t[todo], f[todo])
                fitness[todo] += values[todo]
            values[~ok] = 0.0
        return terms

    def _image_term(self, name, term, R, t, f):
        """One image term of cameras ``R (K, 3, 3)``, ``t (K, 3)``, ``f (K,)``: ``(K,)``; with a
        fixed camera its value is computed once (it does not depend on the soft tissue)."""
        if self.camera is None:
            return term(Cameras(R, t, f, self.centre))
        if name not in self._fixed_terms:
            self._fixed_terms[name] = term(Cameras(R[:1], t[:1], f[:1], self.centre))[0]
        return np.full(len(R), self._fixed_terms[name])

    def __call__(self, genes, members=None, thresholds=None):
        """DE's objective: ``(fitness (S,), payload)``, the payload being :meth:`evaluate`'s
        dictionary (each member's camera and terms)."""
        terms = self.evaluate(genes, members, thresholds)
        return terms["fitness"], terms


def lilium_sfo(skull, photo, options=SfoOptions(), seed=0, callback=None, camera=None):
    """Run Lilium on one skull and one photo.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    options : SfoOptions
    seed : int
        Seeds DE and the RANSAC of POSEST calls: the same seed gives the same result.
    callback : callable, optional
        ``callback(solver) -> bool`` after every generation (progress; True stops).
    camera : Camera, optional
        Score this camera instead of searching one: the DE runs over the soft-tissue cones
        only, every member under this camera, and the result is the best soft tissue under it
        (its terms, fitness and facial landmarks; ``camera`` itself).

    Returns
    -------
    SfoResult
        The best member DE ranked: its camera, and its terms and fitness at full level (with
        the DE at a working level, :mod:`~lilium.methods.working_level`, the image terms are
        recomputed at the photo's resolution on the full mesh, and ``fitness``, their sum, may
        differ from the last value of ``history``; at full level it equals it); ``terms_off``
        names the terms the variant asks for that could not apply, and the P_cam parts without
        a prior. ``extra``
        holds ``history`` (best fitness per generation), ``generations``, ``evaluations``,
        ``stop``, ``genes``, ``fallbacks``, ``no_camera_evaluations`` (population evaluations
        where no member had a camera and each took its own POSEST), ``rescued`` (the initial
        population got POSEST-SFO's soft tissue and camera, :func:`rescue_population`) and the
        working level's (:meth:`LiliumProblem.level_extra`), and ``restarts``: the searches
        run again with the seeds ``[seed, 1]``, ``[seed, 2]`` because the best camera missed
        the head-orientation prior (:func:`~lilium.methods.lilium_outcome.missed_head_prior`),
        at most :data:`~lilium.methods.lilium_outcome.MAX_RESTARTS` (none after the callback
        stopped a search; each search has the DE's whole budget); the result is the search of
        lowest fitness.
    """
    start = time.perf_counter()
    problem, de, rescued = _search(skull, photo, options, seed, callback, camera)
    restarts, stopped = 0, de.message == STOPPED_BY_CALLBACK
    while (camera is None and not stopped and restarts < MAX_RESTARTS
           and missed_head_prior(photo, de.payload)):
        restarts += 1
        again = _search(skull, photo, options, [seed, restarts], callback, camera)
        stopped = again[1].message == STOPPED_BY_CALLBACK
        if again[1].fun < de.fun:
            problem, de, rescued = again
    best = de.payload
    camera, terms, error, warnings = photo_outcome(problem, best, seed)
    fitness = outcome_fitness(problem, de.fun, camera, terms)
    facial = problem.facial_landmarks(de.x)[0]
    return SfoResult(
        method="lilium",
        variant=options.variant,
        seed=seed,
        skull_id=skull.id,
        photo_id=photo.id,
        camera=camera,
        fitness=fitness,
        terms=terms,
        facial_landmarks_mm=dict(zip(problem.corr.facial_names, facial, strict=True)),
        seconds=time.perf_counter() - start,
        error=error,
        warnings=warnings,
        terms_off=dict(problem.terms_off),
        extra={
            **de_extra(de, problem.n_fallbacks),
            "no_camera_evaluations": problem.n_no_camera,
            "rescued": rescued,
            "restarts": restarts,
            **problem.level_extra(),
        },
    )


def _search(skull, photo, options, seed, callback, camera):
    """One DE search of :func:`lilium_sfo` seeded by ``seed`` (an int, or ``[seed, k]`` for its
    k-th restart): ``(problem, DE result, rescued)``."""
    rng = np.random.default_rng(seed)
    problem = LiliumProblem(skull, photo, options, rng=rng, camera=camera)
    solver = DifferentialEvolution(
        problem, problem.cones.n_genes, problem.periodic, options.de, rng=rng, callback=callback
    )
    rescued = camera is None and rescue_population(problem, solver)
    return problem, solver.solve(), rescued


def rescue_population(problem, solver):
    """Give an initial population without any valid camera POSEST-SFO's soft tissue and camera.

    DE's greedy selection never loses its best member, so once one member has a camera the
    result has one: Lilium then finds a camera wherever POSEST-SFO does. Replaces the worst
    member (they all failed) in place.

    Parameters
    ----------
    problem : LiliumProblem
    solver : DifferentialEvolution
        Just initialised (its population evaluated).

    Returns
    -------
    bool
        Whether a member was replaced.
    """
    if np.any(solver.payload["success"]):
        return False
    member = problem.posest_sfo_member()
    if member is None:
        return False
    genes, terms = member
    k = int(np.argmax(solver.fitness))
    solver.population[k] = genes
    solver.fitness[k] = terms["fitness"][0]
    for key, values in solver.payload.items():
        values[k] = terms[key][0]
    solver.history[0] = float(solver.fitness.min())
    return True
