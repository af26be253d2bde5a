"""Shared building blocks of the anatomy: primitive specs and how they join a field.

A part of the skull or the soft tissue is a signed-distance primitive of
:mod:`lilium.synthetic.volume_fields` combined into a :class:`~.volume_fields.GridField` inside
a bounding box with a blend radius. :class:`Blob` is the data of an ellipsoid part;
:func:`add_ellipsoid` and :func:`add_capsule` combine one into a field (skull frame, mm).
"""

from dataclasses import dataclass

import numpy as np

from ..volume_fields import capsule, ellipsoid

#: A Gaussian bump (:func:`add_gaussian`) is evaluated within this many sigma of its centre.
GAUSSIAN_REACH_SIGMA = 3.5


@dataclass(frozen=True)
class Blob:
    """An ellipsoid part (skull frame, mm; for a bilateral part, the left one, ``x > 0``).

    Attributes
    ----------
    centre_mm : tuple of 3 float
    radii_mm : tuple of 3 float
        Semi-axes along x, y, z.
    margin_mm : float
        Margin of the bounding box around the ellipsoid (it must hold the blend).
    blend_mm : float
        Blend radius of the smooth combination.
    """

    centre_mm: tuple
    radii_mm: tuple
    margin_mm: float
    blend_mm: float


def box_around(centre, radii, margin=4.0):
    """Cube around ``centre`` of half side ``max(radii) + margin``.

    Parameters
    ----------
    centre : array_like of shape (3,)
        mm.
    radii : array_like
        mm.
    margin : float
        mm.

    Returns
    -------
    lo, hi : ndarray of shape (3,)
        Corners, mm.
    """
    c = np.asarray(centre, float)
    r = np.max(radii) + margin
    return c - r, c + r


def add_ellipsoid(field, centre, radii, margin_mm, op, blend_mm, rotation=None):
    """Combine an ellipsoid into ``field`` (in place) within :func:`box_around` its centre.

    Parameters
    ----------
    field : GridField
    centre : array_like of shape (3,)
        mm.
    radii : array_like of shape (3,)
        Semi-axes, mm.
    margin_mm : float
    op : {"union", "subtract", "intersect"}
    blend_mm : float
    rotation : ndarray of shape (3, 3), optional
        Columns: the ellipsoid's axes in the skull frame.
    """
    field.combine(
        lambda p: ellipsoid(p, centre, radii, rotation),
        *box_around(centre, radii, margin_mm),
        op,
        blend_mm,
    )


def add_capsule(field, a, b, ra, rb, margin_mm, op, blend_mm):
    """Combine a capsule ``a``-``b`` (radius ``ra`` to ``rb``) into ``field`` (in place).

    The bounding box is the segment's box grown by ``margin_mm``.

    Parameters
    ----------
    field : GridField
    a, b : array_like of shape (3,)
        Segment ends, mm.
    ra, rb : float
        Radii at ``a`` and ``b``, mm (``rb=None``: ``ra`` all along).
    margin_mm : float
    op : {"union", "subtract", "intersect"}
    blend_mm : float
    """
    field.combine(
        lambda p: capsule(p, a, b, ra, rb),
        np.minimum(a, b) - margin_mm,
        np.maximum(a, b) + margin_mm,
        op,
        blend_mm,
    )


def add_gaussian(field, centre, height, sigma):
    """Add a Gaussian bump to ``field`` (in place), within :data:`GAUSSIAN_REACH_SIGMA`.

    Adds ``height * exp(-|p - centre|^2 / (2 sigma^2))``: a positive height pushes the surface
    (the zero level) inwards, a negative one outwards.

    Parameters
    ----------
    field : GridField
    centre : array_like of shape (3,)
        mm.
    height : float
        mm.
    sigma : float
        Width, mm.
    """
    centre = np.asarray(centre, dtype=float)
    field.combine(
        lambda p: (
            height
            * np.exp(
                -((p[0] - centre[0]) ** 2 + (p[1] - centre[1]) ** 2 + (p[2] - centre[2]) ** 2)
                / (2 * sigma**2)
            )
        ),
        centre - GAUSSIAN_REACH_SIGMA * sigma,
        centre + GAUSSIAN_REACH_SIGMA * sigma,
        "add",
    )
