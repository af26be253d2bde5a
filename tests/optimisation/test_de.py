import numpy as np
import pytest

from lilium import jit
from lilium.optimisation import DEOptions, DifferentialEvolution, differential_evolution
from lilium.optimisation.de import distinct_others, exponential_crossover_mask, fold_into_cube


def sphere(pop, parents, thresholds):
    return np.sum((pop - 0.3) ** 2, axis=1)


def test_finds_the_optimum_of_a_simple_function():
    res = differential_evolution(sphere, 6, options=DEOptions(30, max_generations=300), rng=1)
    np.testing.assert_allclose(res.x, 0.3, atol=1e-4)
    assert res.fun < 1e-8 and res.nit == 300 and res.nfev == 30 * 301
    assert res.message == "reached 300 generations"
    assert np.all(np.diff(res.history) <= 0)  # greedy selection never loses the best


def test_same_seed_same_result_and_different_seed_differs():
    opts = DEOptions(12, max_generations=40)
    a = differential_evolution(sphere, 5, options=opts, rng=7)
    b = differential_evolution(sphere, 5, options=opts, rng=7)
    c = differential_evolution(sphere, 5, options=opts, rng=8)
    np.testing.assert_array_equal(a.population, b.population)
    assert not np.array_equal(a.population, c.population)


def test_periodic_genes_wrap_and_others_reflect():
    rng = np.random.default_rng(0)
    x = np.array([[-0.25, 1.25, -0.25, 1.25]])
    periodic = np.array([True, True, False, False])
    np.testing.assert_allclose(fold_into_cube(x, periodic, rng), [[0.75, 0.25, 0.25, 0.75]])
    wild = fold_into_cube(np.array([[5.0, -7.0]]), np.array([False, False]), rng)
    assert np.all((wild >= 0) & (wild <= 1))


def test_periodic_optimum_across_the_seam():
    # Optimum at 0 == 1 on a circle: members on both sides of the seam are near it.
    def circle(pop, parents, thresholds):
        return np.sum(1 - np.cos(2 * np.pi * pop), axis=1)

    res = differential_evolution(
        circle, 3, periodic=[True] * 3, options=DEOptions(15, max_generations=150), rng=3
    )
    assert res.fun < 1e-5
    assert np.all(np.minimum(res.x, 1 - res.x) < 1e-3)
    assert np.all((res.population >= 0) & (res.population <= 1))


def test_mutation_indices_are_distinct_and_not_self():
    r = distinct_others(10, 3, np.random.default_rng(0))
    assert r.shape == (10, 3)
    for i, row in enumerate(r):
        assert len(set(row)) == 3 and i not in row


def test_exponential_crossover_lengths():
    rng = np.random.default_rng(0)
    mask = exponential_crossover_mask(20000, 10, 0.5, rng)
    lengths = mask.sum(axis=1)
    assert lengths.min() >= 1
    # P(L >= k) = CR^(k-1): mean of the truncated geometric ~ 1/(1-CR) = 2.
    assert abs(lengths.mean() - 2.0) < 0.05
    # One contiguous (cyclic) run per member.
    runs = np.sum(mask & ~np.roll(mask, 1, axis=1), axis=1)
    assert np.all((runs == 1) | (lengths == 10))


def test_stops_on_wall_clock_stagnation_and_callback():
    slow = DEOptions(8, max_generations=10**6, max_seconds=0.05)
    assert "wall-clock" in differential_evolution(sphere, 2, options=slow, rng=0).message
    flat = DEOptions(8, max_generations=10**6, stagnation_generations=5)
    res = differential_evolution(lambda p, *_: np.zeros(len(p)), 2, options=flat, rng=0)
    assert res.nit == 5 and "no improvement" in res.message
    seen = []
    solver = DifferentialEvolution(
        sphere, 2, options=DEOptions(8), rng=0, callback=lambda s: seen.append(s.nit) or s.nit == 3
    )
    assert solver.solve().nit == 3 and seen == [1, 2, 3]


def test_too_small_population_is_rejected():
    with pytest.raises(ValueError, match="population_size must be at least 4"):
        DifferentialEvolution(sphere, 2, options=DEOptions(3))


@pytest.mark.skipif(not jit.NUMBA_AVAILABLE, reason="numba is not installed")
def test_compiled_trials_are_the_numpy_trials_bit_for_bit():
    """Mutation, crossover, wrapping, reflection and the redraw of genes still outside the
    cube (F = 1.5 throws many out): the compiled path gives the numpy path's populations."""

    def bumpy(pop, parents, thresholds):
        return np.sum((pop - 0.3) ** 2, axis=1) + np.sin(20 * pop).sum(axis=1)

    periodic = np.tile([False, False, True], 7)
    populations = []
    for backend in ("numba", "numpy"):
        with jit.kernels(backend):
            options = DEOptions(30, F=1.5, max_generations=60)
            solver = DifferentialEvolution(bumpy, 21, periodic, options, rng=3)
            for _ in solver:
                pass
            populations.append(solver.population.copy())
    np.testing.assert_array_equal(populations[0], populations[1])


def test_a_returned_result_is_detached_from_the_solver_and_the_objective():
    """Selection updates the solver's payload in place: neither the objective's arrays nor a
    result already returned change when the solver goes on."""
    seen = {}

    def with_payload(pop, members, thresholds):
        fitness = np.sum((pop - 0.3) ** 2, axis=1)
        payload = {"x": pop.copy(), "fitness": fitness}
        seen.setdefault("first", payload)
        return fitness, payload

    solver = DifferentialEvolution(with_payload, 3, options=DEOptions(8, max_generations=5), rng=1)
    first = {k: v.copy() for k, v in seen["first"].items()}
    result = solver.solve()
    kept = result.payload["x"].copy(), result.population_payload["x"].copy()
    solver.options = DEOptions(8, max_generations=40)
    for _ in solver:
        pass
    np.testing.assert_array_equal(seen["first"]["x"], first["x"])
    np.testing.assert_array_equal(result.payload["x"], kept[0])
    np.testing.assert_array_equal(result.population_payload["x"], kept[1])
    assert not np.array_equal(solver.payload["x"], kept[1])
