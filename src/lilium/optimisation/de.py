"""DE/rand/1/exp on the unit cube, vectorised over the population.

Shape of scipy's ``differential_evolution``: a solver object that is also an iterator (one
generation per ``next``), a thin function over it, and a frozen result. The objective evaluates a
whole population at once: ``(S, D) -> (S,)``.

Decisions the paper leaves open (docs/method/lilium.md), fixed here:

- Population initialised uniformly at random in ``[0, 1]^D``.
- Mutant ``x_r1 + F (x_r2 - x_r3)``, with ``r1, r2, r3`` distinct and different from the target.
- Exponential crossover: a random start gene, then a run of ``L`` consecutive genes (cyclic) with
  ``P(L >= k) = CR^(k-1)``, taken from the mutant.
- Out-of-range genes: periodic genes (azimuths) wrap modulo 1; the others are reflected at the
  violated bound (``-x`` or ``2 - x``), and redrawn uniformly if still outside.
- Greedy one-to-one selection (a trial replaces its target when not worse).
- Termination: a generation count, a wall-clock limit, or a stagnation count (generations without
  improvement of the best fitness), whichever comes first; each can be switched off.

Payloads: an objective may return, with the fitness, a *payload* per member: a dict of arrays
whose first axis is the population (e.g. each member's camera and fitness terms). The solver
keeps the payload of every member next to its genes, hands the payload of the members the trials
compete with back to the objective (warm starts), replaces it where a trial wins, and returns the
best member's payload with its genes: what the result reports is exactly what DE ranked.
"""

import time
from dataclasses import dataclass

import numpy as np

from .. import jit
from ._de_kernels import trial_kernel


@dataclass(frozen=True)
class DEOptions:
    """Options of the DE solver.

    Defaults: population 30, F = 0.8, CR = 0.9, 750 generations and 500 s as in the paper.
    Chosen by measurement on generated Exp. C photos (8 frontal, 8 lateral, Lilium skof+pll,
    see ``docs/decisions/0002-de-defaults.md``): with F = 0.5 the best fitness is still falling at
    750 generations;
    F = 0.8 converges further and lowered the mean BPE from 2.47 to 1.89 mm (frontal) and from
    3.36 to 2.76 mm (lateral); CR = 0.5 or 0.7 and F = 0.9 did worse; a population of 30 costs
    about 60 % of the time of 50 for a similar BPE.

    Attributes
    ----------
    population_size : int
    F : float
        Differential weight.
    CR : float
        Crossover rate of the exponential crossover.
    max_generations : int
    max_seconds : float or None
        Wall-clock limit (checked between generations).
    stagnation_generations : int or None
        Stop after this many generations without improving the best fitness by more than
        ``stagnation_tol`` (relative); ``None`` switches it off.
    stagnation_tol : float
    """

    population_size: int = 30
    F: float = 0.8
    CR: float = 0.9
    max_generations: int = 750
    max_seconds: float | None = 500.0
    stagnation_generations: int | None = None
    stagnation_tol: float = 1e-9


@dataclass(frozen=True)
class DEResult:
    """Outcome of a DE run.

    Attributes
    ----------
    x : ndarray of shape (D,)
        Best genotype.
    fun : float
    nit : int
        Generations run.
    nfev : int
        Objective evaluations (individuals).
    message : str
        Why it stopped.
    population : ndarray of shape (S, D)
    population_fitness : ndarray of shape (S,)
    history : ndarray of shape (nit + 1,)
        Best fitness after initialisation and after every generation.
    seconds : float
    payload : dict of str -> ndarray or None
        The best member's payload (each array indexed at that member), when the objective
        returns payloads.
    population_payload : dict of str -> ndarray of shape (S, ...) or None
    """

    x: np.ndarray
    fun: float
    nit: int
    nfev: int
    message: str
    population: np.ndarray
    population_fitness: np.ndarray
    history: np.ndarray
    seconds: float
    payload: dict | None = None
    population_payload: dict | None = None


def _split(output):
    """``(fitness (S,) float, payload dict or None)`` of an objective's return value."""
    if isinstance(output, tuple):
        fitness, payload = output
    else:
        fitness, payload = output, None
    return np.asarray(fitness, dtype=float), payload


def _copy(value):
    """A row of a payload array, detached from it (a numpy scalar as it is)."""
    return value.copy() if isinstance(value, np.ndarray) else value


def select_payload(accepted, trial, current):
    """Member payloads after selection: ``trial[k][i]`` where ``accepted[i]``, else ``current``
    (``current``'s arrays are updated in place and returned)."""
    if current is None:
        return None
    if np.any(accepted):
        for key, old in current.items():
            old[accepted] = np.asarray(trial[key])[accepted]
    return current


def crossover_runs(n_members, n_genes, CR, rng):
    """Exponential crossover's first gene and run length ``(S,)`` of each member (cyclic)."""
    start = rng.integers(n_genes, size=n_members)
    length = (
        np.minimum(rng.geometric(1.0 - CR, size=n_members), n_genes)
        if CR < 1
        else np.full(n_members, n_genes)
    )
    return start, length


def exponential_crossover_mask(n_members, n_genes, CR, rng):
    """Genes taken from the mutant under exponential crossover.

    Returns
    -------
    mask : ndarray of shape (S, D), bool
        At least one gene per row.
    """
    start, length = crossover_runs(n_members, n_genes, CR, rng)
    offset = (np.arange(n_genes)[None, :] - start[:, None]) % n_genes
    return offset < length[:, None]


def distinct_others(n_members, k, rng=None, keys=None):
    """For each member i, k distinct indices of other members.

    The ``k`` smallest of ``keys[i]`` (uniform draws, ``(S, S - 1)``; drawn from ``rng`` when
    not given) pick them.

    Returns
    -------
    ndarray of shape (S, k), int
    """
    keys = rng.random((n_members, n_members - 1)) if keys is None else keys
    picks = np.argsort(keys, axis=1)[:, :k]
    return picks + (picks >= np.arange(n_members)[:, None])


def fold_into_cube(x, periodic, rng):
    """Bring genes back into [0, 1]: wrap periodic ones, reflect (then redraw) the rest."""
    x = np.where(periodic, np.mod(x, 1.0), x)
    x = np.where(x < 0, -x, x)
    x = np.where(x > 1, 2.0 - x, x)
    bad = (x < 0) | (x > 1)
    if bad.any():
        x[bad] = rng.random(int(bad.sum()))
    return x


#: :attr:`DifferentialEvolution.message` of a run its callback stopped.
STOPPED_BY_CALLBACK = "stopped by the callback"


class DifferentialEvolution:
    """DE/rand/1/exp solver; iterate it to run one generation per step.

    Parameters
    ----------
    objective : callable
        ``objective(population (S, D), members, thresholds) -> fitness (S,)`` or
        ``(fitness (S,), payload)``, lower is better. ``members`` is the payload of the members
        the trials compete with (trial ``i`` against member ``i``; see the module notes) and
        ``thresholds[i]`` member ``i``'s fitness; both are ``None`` at initialisation. Where an
        objective can prove a trial worse than its threshold (a partial sum of non-negative
        terms already above it) it may return that lower bound instead of the full fitness: the
        trial loses either way, so the run is unchanged and every member's fitness is exact.
    n_genes : int
    periodic : array_like of shape (D,), bool, optional
        Genes that wrap (azimuths).
    options : DEOptions
    rng : seed or numpy Generator
    callback : callable, optional
        ``callback(solver)`` after each generation; return True to stop.
    """

    def __init__(
        self, objective, n_genes, periodic=None, options=DEOptions(), rng=None, callback=None
    ):
        if options.population_size < 4:
            raise ValueError("population_size must be at least 4 for DE/rand/1")
        self.objective = objective
        self.options = options
        self.rng = np.random.default_rng(rng)
        self.periodic = np.zeros(n_genes, bool) if periodic is None else np.asarray(periodic, bool)
        self.callback = callback
        self._start = time.perf_counter()
        self.population = self.rng.random((options.population_size, n_genes))
        self.fitness, payload = _split(objective(self.population, None, None))
        # The solver's own copy: selection updates it in place, never the objective's arrays.
        self.payload = None if payload is None else {k: np.array(v) for k, v in payload.items()}
        self.nfev = options.population_size
        self.nit = 0
        self.history = [float(self.fitness.min())]
        self._since_improvement = 0
        self.message = ""

    @property
    def best_index(self):
        return int(np.argmin(self.fitness))

    @property
    def elapsed(self):
        return time.perf_counter() - self._start

    def _stop_reason(self):
        o = self.options
        if self.nit >= o.max_generations:
            return f"reached {o.max_generations} generations"
        if o.max_seconds is not None and self.elapsed >= o.max_seconds:
            return f"reached the {o.max_seconds:g} s wall-clock limit"
        if o.stagnation_generations and self._since_improvement >= o.stagnation_generations:
            return f"no improvement in {o.stagnation_generations} generations"
        return ""

    def __iter__(self):
        return self

    def __next__(self):
        self.message = self._stop_reason()
        if self.message:
            raise StopIteration
        self.step()
        if self.callback is not None and self.callback(self):
            self.message = STOPPED_BY_CALLBACK
            raise StopIteration
        return self.population[self.best_index], float(self.fitness.min())

    def step(self):
        """Run one generation: mutation, crossover, fold into the cube, evaluation, selection."""
        S, D = self.population.shape
        o = self.options
        trial = self._trials(S, D)
        trial_fitness, trial_payload = _split(
            self.objective(trial, self.payload, self.fitness.copy())
        )
        self.nfev += S
        better = trial_fitness <= self.fitness
        before = self.fitness.min()
        self.population[better] = trial[better]
        self.fitness[better] = trial_fitness[better]
        self.payload = select_payload(better, trial_payload, self.payload)
        self.nit += 1
        best = self.fitness.min()
        improved = best < before - o.stagnation_tol * max(abs(before), 1e-300)
        self._since_improvement = 0 if improved else self._since_improvement + 1
        self.history.append(float(best))

    def _trials(self, S, D):
        """Mutation, crossover and folding into the cube: the generation's trials ``(S, D)``."""
        o, pop = self.options, self.population
        keys = self.rng.random((S, S - 1))
        if jit.compiled():  # the same trials, compiled (optimisation/_de_kernels.py)
            start, length = crossover_runs(S, D, o.CR, self.rng)
            trial, outside = trial_kernel(
                pop, keys, start.astype(np.int64), length.astype(np.int64), o.F, self.periodic
            )
            if outside.any():
                trial[outside] = self.rng.random(int(outside.sum()))
            return trial
        r = distinct_others(S, 3, keys=keys)
        mutant = pop[r[:, 0]] + o.F * (pop[r[:, 1]] - pop[r[:, 2]])
        take = exponential_crossover_mask(S, D, o.CR, self.rng)
        return fold_into_cube(np.where(take, mutant, pop), self.periodic, self.rng)

    def solve(self):
        """Run to termination and return a :class:`DEResult`."""
        for _ in self:
            pass
        i = self.best_index
        return DEResult(
            x=self.population[i].copy(),
            fun=float(self.fitness[i]),
            nit=self.nit,
            nfev=self.nfev,
            message=self.message,
            population=self.population.copy(),
            population_fitness=self.fitness.copy(),
            history=np.asarray(self.history),
            seconds=self.elapsed,
            payload=None
            if self.payload is None
            else {k: _copy(v[i]) for k, v in self.payload.items()},
            population_payload=(
                None if self.payload is None else {k: v.copy() for k, v in self.payload.items()}
            ),
        )


def differential_evolution(
    objective, n_genes, periodic=None, options=DEOptions(), rng=None, callback=None
):
    """Minimise ``objective`` over ``[0, 1]^n_genes`` by DE/rand/1/exp (see the module notes).

    Examples
    --------
    >>> import numpy as np
    >>> sphere = lambda pop, parents, thresholds: np.sum((pop - 0.3) ** 2, axis=1)
    >>> res = differential_evolution(sphere, 3, options=DEOptions(20, max_generations=200), rng=1)
    >>> bool(res.fun < 1e-10)
    True
    """
    return DifferentialEvolution(objective, n_genes, periodic, options, rng, callback).solve()
