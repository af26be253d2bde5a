"""Compiled trial generation of :mod:`lilium.optimisation.de` (numba, see :mod:`lilium.jit`).

Mutation, exponential crossover and folding into the cube of a whole population in one pass, from
the same random draws as the numpy path (:func:`~lilium.optimisation.de.distinct_others`'s keys,
the crossover's start genes and run lengths), with the same arithmetic element by element: the
two paths give the same trials bit for bit (``tests/optimisation/test_de.py``).
"""

import numpy as np

from ..jit import njit


@njit
def _three_smallest(key, out):
    """Indices of the three smallest entries of ``key`` in increasing order (``argsort(key)[:3]``
    for distinct keys; a tie goes to the lower index, as a stable sort would)."""
    out[0] = out[1] = out[2] = -1
    for j in range(key.shape[0]):
        k = key[j]
        if out[0] < 0 or k < key[out[0]]:
            out[2], out[1], out[0] = out[1], out[0], j
        elif out[1] < 0 or k < key[out[1]]:
            out[2], out[1] = out[1], j
        elif out[2] < 0 or k < key[out[2]]:
            out[2] = j


@njit
def trial_kernel(population, keys, start, length, F, periodic):
    """Trials of DE/rand/1/exp before the redraw of genes still outside the cube.

    Parameters
    ----------
    population : ndarray of shape (S, D)
    keys : ndarray of shape (S, S - 1)
        Uniform draws: the three smallest of row ``i`` pick member ``i``'s donors among the
        other members (:func:`~lilium.optimisation.de.distinct_others`).
    start, length : ndarray of shape (S,) of int64
        First gene and number of genes taken from the mutant (cyclic).
    F : float
    periodic : ndarray of shape (D,) of bool

    Returns
    -------
    trial : ndarray of shape (S, D)
    outside : ndarray of shape (S, D) of bool
        Genes still outside ``[0, 1]`` after wrapping and reflecting (to be redrawn).
    """
    S, D = population.shape
    trial = np.empty((S, D))
    outside = np.zeros((S, D), np.bool_)
    donors = np.empty(3, np.int64)
    for i in range(S):
        _three_smallest(keys[i], donors)
        r0, r1, r2 = donors[0], donors[1], donors[2]
        r0 += r0 >= i
        r1 += r1 >= i
        r2 += r2 >= i
        for d in range(D):
            if (d - start[i]) % D < length[i]:
                x = population[r0, d] + F * (population[r1, d] - population[r2, d])
            else:
                x = population[i, d]
            if periodic[d]:
                x = np.mod(x, 1.0)
            if x < 0:
                x = -x
            if x > 1:
                x = 2.0 - x
            trial[i, d] = x
            outside[i, d] = (x < 0) or (x > 1)
    return trial, outside
