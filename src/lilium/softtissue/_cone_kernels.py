"""Compiled decoding of a population's genes (numba, see :mod:`lilium.jit`).

The formulas of :func:`lilium.softtissue.cones.hybrid_genes` and
:func:`lilium.softtissue.cones.decode`, element by element in the same order; ``sin`` and
``cos`` are libm's as numpy's are, ``atan2`` differs from numpy's SIMD one in the last bit for
a few per cent of arguments (a right twin's azimuth), so the two paths agree to rounding.
"""

import numpy as np

from ..jit import njit


@njit
def decode_kernel(genes, axes, u, v, depth_min, depth_max, pairs, left_weight, polar_max_rad):
    """Soft-tissue vectors ``(S, C, 3)`` of genes ``(S, 3C)`` (see :func:`cones.decode`).

    Parameters
    ----------
    genes : ndarray of shape (S, 3C)
    axes, u, v : ndarray of shape (C, 3)
    depth_min, depth_max : ndarray of shape (C,)
    pairs : ndarray of shape (P, 2) of int64
        ``(i_left, i_right)``: the right twin decodes the hybrid of the two.
    left_weight : float
    polar_max_rad : float
    """
    S = genes.shape[0]
    C = axes.shape[0]
    two_pi = 2 * np.pi
    g = genes.copy().reshape(S, C, 3)
    w = left_weight
    for s in range(S):
        for k in range(pairs.shape[0]):
            il, ir = pairs[k, 0], pairs[k, 1]
            l0, l1, l2 = g[s, il, 0], g[s, il, 1], g[s, il, 2]
            r0, r1, r2 = g[s, ir, 0], g[s, ir, 1], g[s, ir, 2]
            ang_l, ang_r = two_pi * l2, two_pi * r2
            sn = w * np.sin(ang_l) + (1 - w) * np.sin(ang_r)
            cs = w * np.cos(ang_l) + (1 - w) * np.cos(ang_r)
            g[s, ir, 0] = w * l0 + (1.0 - w) * r0
            g[s, ir, 1] = w * l1 + (1.0 - w) * r1
            g[s, ir, 2] = np.mod(np.arctan2(sn, cs) / two_pi, 1.0)
    out = np.empty((S, C, 3))
    for s in range(S):
        for c in range(C):
            depth = depth_min[c] + g[s, c, 0] * (depth_max[c] - depth_min[c])
            alpha = polar_max_rad * g[s, c, 1]
            theta = two_pi * g[s, c, 2]
            ct, st = np.cos(theta), np.sin(theta)
            ca, sa = np.cos(alpha), np.sin(alpha)
            for j in range(3):
                perp = ct * u[c, j] + st * v[c, j]
                out[s, c, j] = depth * (ca * axes[c, j] + sa * perp)
    return out
