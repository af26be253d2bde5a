"""Soft-tissue cones: decoding genes into soft-tissue vectors (docs/method/lilium.md).

Three genes per cranial landmark, each in [0, 1]: depth ``p1`` (between the population min and max),
polar angle ``p2`` (0 to 40 degrees from the cone axis) and azimuth ``p3`` (0 to 360 degrees about
the axis, periodic). Genotype layout: ``[p11, p12, p13, ..., pC1, pC2, pC3]``.

Bilateral hybrid: the right twin of each pair is decoded from ``0.9 * genes_l + 0.1 * genes_r``
(azimuth mixed on the circle), and twins use mirror-image perpendicular bases, so equal genes give
mirror-symmetric soft tissue.
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import BILATERAL_LEFT_WEIGHT, CONE_MAX_POLAR_DEG
from ._cone_kernels import decode_kernel
from .landmarks import MIDLINE_CRANIAL, bilateral_pairs, side, twin


@dataclass(frozen=True)
class ConeSet:
    """The cones of C cranial landmarks.

    Attributes
    ----------
    names : tuple of str, length C
    axes : ndarray of shape (C, 3)
        Unit cone axes (skull frame).
    u, v : ndarray of shape (C, 3)
        Orthonormal bases of the planes perpendicular to the axes (twins mirrored).
    depth_min_mm, depth_max_mm : ndarray of shape (C,)
    pairs : ndarray of shape (P, 2), int
        ``(i_left, i_right)`` indices of bilateral twins.
    """

    names: tuple
    axes: np.ndarray
    u: np.ndarray
    v: np.ndarray
    depth_min_mm: np.ndarray
    depth_max_mm: np.ndarray
    pairs: np.ndarray

    @property
    def n_genes(self):
        return 3 * len(self.names)


def midsagittal_plane(landmarks_mm):
    """Midsagittal plane of a skull from its landmarks.

    The normal is the mean left-minus-right direction of the bilateral pairs; the plane passes
    through the mean of the pair midpoints and midline landmarks. Without any pair the mesh
    frame's ``x = 0`` plane is taken (documented fallback).

    Parameters
    ----------
    landmarks_mm : dict of str -> array_like of shape (3,)

    Returns
    -------
    point_mm : ndarray of shape (3,)
    normal : ndarray of shape (3,)
        Unit normal, pointing to the subject's left.
    """
    diffs, centres = [], []
    for name, p in landmarks_mm.items():
        if side(name) == "l" and twin(name) in landmarks_mm:
            left, right = np.asarray(p, float), np.asarray(landmarks_mm[twin(name)], float)
            diffs.append(left - right)
            centres.append((left + right) / 2)
    centres += [np.asarray(landmarks_mm[n], float) for n in MIDLINE_CRANIAL if n in landmarks_mm]
    if not diffs:
        return np.zeros(3), np.array([1.0, 0.0, 0.0])
    normal = np.mean([d / np.linalg.norm(d) for d in diffs], axis=0)
    normal /= np.linalg.norm(normal)
    return np.mean(centres, axis=0), normal


def perpendicular_basis(axis):
    """A fixed orthonormal basis ``(u, v)`` of the plane perpendicular to a unit axis.

    ``u`` is made from the world axis least aligned with ``axis``; ``(u, v, axis)`` is
    right-handed.
    """
    axis = np.asarray(axis, float)
    e = np.zeros(3)
    e[np.argmin(np.abs(axis))] = 1.0
    u = np.cross(axis, e)
    u /= np.linalg.norm(u)
    return u, np.cross(axis, u)


def _orthonormalise(vec, against):
    for a in against:
        vec = vec - (vec @ a) * a
    return vec / np.linalg.norm(vec)


def make_cones(names, axes, depth_min_mm, depth_max_mm, mirror_normal=None):
    """Build the cones of a set of cranial landmarks.

    Parameters
    ----------
    names : sequence of str, length C
    axes : array_like of shape (C, 3)
        Cone axes (normalised here).
    depth_min_mm, depth_max_mm : array_like of shape (C,)
    mirror_normal : array_like of shape (3,), optional
        Normal of the midsagittal plane (see :func:`midsagittal_plane`); needed for
        mirror-consistent bases of twins. Default: the mesh frame's x axis.

    Returns
    -------
    ConeSet
    """
    names = tuple(names)
    axes = np.asarray(axes, float)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    n = np.array([1.0, 0, 0]) if mirror_normal is None else np.asarray(mirror_normal, float)
    n = n / np.linalg.norm(n)
    mirror = np.eye(3) - 2.0 * np.outer(n, n)
    u = np.empty_like(axes)
    v = np.empty_like(axes)
    for i, a in enumerate(axes):
        u[i], v[i] = perpendicular_basis(a)
    pairs = np.array(bilateral_pairs(names), dtype=int).reshape(-1, 2)
    for i_l, i_r in pairs:
        a_r = axes[i_r]
        u[i_r] = _orthonormalise(mirror @ u[i_l], [a_r])
        v[i_r] = _orthonormalise(mirror @ v[i_l], [a_r, u[i_r]])
    return ConeSet(
        names,
        axes,
        u,
        v,
        np.asarray(depth_min_mm, float),
        np.asarray(depth_max_mm, float),
        pairs,
    )


def hybrid_genes(genes, pairs):
    """Genes actually decoded: right twins become ``0.9 * left + 0.1 * right``.

    Parameters
    ----------
    genes : ndarray of shape (S, 3C)
    pairs : ndarray of shape (P, 2), int

    Returns
    -------
    ndarray of shape (S, C, 3)
    """
    g = np.array(genes, dtype=float).reshape(len(genes), -1, 3)
    if len(pairs) == 0:
        return g
    w = BILATERAL_LEFT_WEIGHT
    left, right = g[:, pairs[:, 0]], g[:, pairs[:, 1]]
    mixed = w * left + (1.0 - w) * right
    # Azimuth: weighted mean on the circle, back to [0, 1).
    ang_l, ang_r = 2 * np.pi * left[..., 2], 2 * np.pi * right[..., 2]
    s = w * np.sin(ang_l) + (1 - w) * np.sin(ang_r)
    c = w * np.cos(ang_l) + (1 - w) * np.cos(ang_r)
    mixed[..., 2] = np.mod(np.arctan2(s, c) / (2 * np.pi), 1.0)
    g[:, pairs[:, 1]] = mixed
    return g


def decode_arguments(cones):
    """The arguments of :func:`~lilium.softtissue._cone_kernels.decode_kernel` after the genes:
    the cones' arrays and the decoding's constants (a tuple, built once per SFO)."""
    return (
        np.ascontiguousarray(cones.axes, dtype=float),
        np.ascontiguousarray(cones.u, dtype=float),
        np.ascontiguousarray(cones.v, dtype=float),
        np.ascontiguousarray(cones.depth_min_mm, dtype=float),
        np.ascontiguousarray(cones.depth_max_mm, dtype=float),
        np.asarray(cones.pairs, np.int64).reshape(-1, 2),
        BILATERAL_LEFT_WEIGHT,
        float(np.radians(CONE_MAX_POLAR_DEG)),
    )


def decode(genes, cones):
    """Soft-tissue vectors of a population.

    Parameters
    ----------
    genes : array_like of shape (S, 3C) or (3C,)
        Each gene in [0, 1].
    cones : ConeSet

    Returns
    -------
    soft_tissue_mm : ndarray of shape (S, C, 3) (or (C, 3) for one genotype)
        Vectors from cranial to facial landmark, skull frame.
    """
    genes = np.asarray(genes, dtype=float)
    single = genes.ndim == 1
    if jit.compiled():  # the same formulas, compiled (softtissue/_cone_kernels.py)
        st = decode_kernel(np.ascontiguousarray(np.atleast_2d(genes)), *decode_arguments(cones))
        return st[0] if single else st
    g = hybrid_genes(np.atleast_2d(genes), cones.pairs)
    depth = cones.depth_min_mm + g[..., 0] * (cones.depth_max_mm - cones.depth_min_mm)
    alpha = np.radians(CONE_MAX_POLAR_DEG) * g[..., 1]
    theta = 2 * np.pi * g[..., 2]
    perp = np.cos(theta)[..., None] * cones.u + np.sin(theta)[..., None] * cones.v
    direction = np.cos(alpha)[..., None] * cones.axes + np.sin(alpha)[..., None] * perp
    st = depth[..., None] * direction
    return st[0] if single else st


def encode_depth_only(cones, depth_mm):
    """Genes of axis-aligned soft tissue of given depths (polar 0, azimuth 0).

    Parameters
    ----------
    cones : ConeSet
    depth_mm : array_like of shape (C,)

    Returns
    -------
    genes : ndarray of shape (3C,)
    """
    span = cones.depth_max_mm - cones.depth_min_mm
    p1 = np.clip(
        (np.asarray(depth_mm, float) - cones.depth_min_mm) / np.where(span > 0, span, 1), 0, 1
    )
    return np.column_stack([p1, np.zeros_like(p1), np.zeros_like(p1)]).ravel()
