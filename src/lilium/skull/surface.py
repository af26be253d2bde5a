"""Views of a normalised skull mesh the landmark rules read (skull frame, mm).

- :class:`FrontalMap`: the surface seen from the front (rays along ``-z``): the z of the first
  surface point per pixel, as the generator's frontal rays see it
  (:func:`lilium.synthetic.anatomy.landmarks.front_profile`);
- :func:`midline_section`: the mesh cut by the plane ``x = 0`` (points on the cut's segments);
- :func:`rim_edge`: the edge of an opening along a scan of the frontal map (the generator's
  rule).
"""

from dataclasses import dataclass

import numpy as np

#: Pixel of the frontal map (mm); faces behind this z (mm) are not drawn (the face's map).
FRONTAL_PX_MM = 0.4
FRONTAL_MIN_Z_MM = -40.0
#: The rim edge: the first scan point whose height passes this share from the deepest to the
#: crest (the generator's :data:`~lilium.synthetic.anatomy.landmarks.RIM_FRACTION`).
RIM_FRACTION = 0.75
#: Spacing (mm) of the points along the midline cut.
SECTION_STEP_MM = 0.25


@dataclass(frozen=True)
class FrontalMap:
    """Height map of a mesh seen from the front.

    Attributes
    ----------
    z : ndarray of shape (H, W)
        z (mm) of the first surface point along ``-z`` at each pixel centre; NaN where none.
        Row ``v`` is ``y = y0 - v * px``, column ``u`` is ``x = x0 + u * px``.
    x0, y0, px : float
        mm.
    """

    z: np.ndarray
    x0: float
    y0: float
    px: float

    def at(self, xy):
        """Surface points ``(N, 3)`` at ``xy`` ``(N, 2)`` (nearest pixel); NaN rows outside."""
        xy = np.atleast_2d(np.asarray(xy, float))
        u = np.round((xy[:, 0] - self.x0) / self.px).astype(int)
        v = np.round((self.y0 - xy[:, 1]) / self.px).astype(int)
        H, W = self.z.shape
        ok = (u >= 0) & (u < W) & (v >= 0) & (v < H)
        z = np.full(len(xy), np.nan)
        z[ok] = self.z[v[ok], u[ok]]
        return np.column_stack([self.x0 + u * self.px, self.y0 - v * self.px, z])

    def scan(self, start, end, step=None):
        """Surface points ``(N, 3)`` along the segment ``start -> end`` (x, y; mm)."""
        start, end = np.asarray(start, float)[:2], np.asarray(end, float)[:2]
        n = max(2, int(np.ceil(np.linalg.norm(end - start) / (step or self.px))) + 1)
        s = np.linspace(0.0, 1.0, n)[:, None]
        return self.at(start + s * (end - start))


def frontal_map(vertices, faces, px_mm=FRONTAL_PX_MM, min_z_mm=FRONTAL_MIN_Z_MM):
    """:class:`FrontalMap` of a normalised mesh.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        Normalised frame, mm.
    faces : ndarray of shape (F, 3), int
    px_mm, min_z_mm : float

    Returns
    -------
    FrontalMap
    """
    from ..synthetic.render import rasterize_face_index

    faces = faces[vertices[faces, 2].max(axis=1) > min_z_mm]
    used = vertices[np.unique(faces)]
    lo, hi = used.min(axis=0) - 2 * px_mm, used.max(axis=0) + 2 * px_mm
    W = int(np.ceil((hi[0] - lo[0]) / px_mm)) + 1
    H = int(np.ceil((hi[1] - lo[1]) / px_mm)) + 1
    distance = 1e6  # far away: parallel rays
    cam = np.column_stack(
        [vertices[:, 0] - lo[0], hi[1] - vertices[:, 1], distance + hi[2] - vertices[:, 2]]
    )
    index = rasterize_face_index(cam, faces, distance / px_mm, (W, H), (0.0, 0.0))
    v, u = np.nonzero(index >= 0)
    tri = vertices[faces[index[v, u]]]
    x, y = lo[0] + u * px_mm, hi[1] - v * px_mm
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nz = np.where(np.abs(n[:, 2]) > 1e-12, n[:, 2], 1e-12)
    z = tri[:, 0, 2] - (n[:, 0] * (x - tri[:, 0, 0]) + n[:, 1] * (y - tri[:, 0, 1])) / nz
    z = np.clip(z, tri[:, :, 2].min(axis=1), tri[:, :, 2].max(axis=1))
    out = np.full((H, W), np.nan)
    out[v, u] = z
    return FrontalMap(out, float(lo[0]), float(hi[1]), float(px_mm))


def rim_edge(points, fraction=RIM_FRACTION, from_deepest=False):
    """The edge of an opening along a scan from inside it outwards (the generator's rule).

    With ``crest`` the highest z of the scan and ``deep`` the lowest before it, the first point
    whose z reaches ``deep + fraction (crest - deep)``. ``from_deepest``: ``deep`` the lowest z
    of the whole scan and ``crest`` the highest after it (a scan that starts on something
    higher than the rim, e.g. the nasal septum or the spine's base at the aperture's midline).

    Parameters
    ----------
    points : ndarray of shape (N, 3)
        Surface points of a scan (:meth:`FrontalMap.scan`), from the opening out.
    fraction : float

    Returns
    -------
    ndarray of shape (3,) or None
        None when the scan has no surface.
    """
    z = np.where(np.isfinite(points[:, 2]), points[:, 2], -np.inf)
    if not np.isfinite(z).any():
        return None
    if from_deepest:
        first = int(np.argmin(np.where(np.isfinite(z), z, np.inf)))
        return rim_edge(points[first:], fraction)
    top = int(np.argmax(z))
    finite = z[: top + 1][np.isfinite(z[: top + 1])]
    deep = finite.min()
    k = int(np.argmax(z[: top + 1] >= deep + fraction * (z[top] - deep)))
    return points[k].copy()


def midline_section(vertices, faces, x0=0.0, step_mm=SECTION_STEP_MM):
    """The mesh cut by the plane ``x = x0``, as points every ``step_mm`` along the cut.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    x0, step_mm : float

    Returns
    -------
    points : ndarray of shape (K, 3)
    face : ndarray of shape (K,), int
        The face each point lies on.
    """
    side = vertices[:, 0] > x0
    s = side[faces]
    cut = np.flatnonzero(s.any(axis=1) & ~s.all(axis=1))
    ends = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        crossing = s[cut, a] != s[cut, b]
        p, q = vertices[faces[cut, a]], vertices[faces[cut, b]]
        t = np.where(crossing, (x0 - p[:, 0]) / np.where(crossing, q[:, 0] - p[:, 0], 1.0), 0)
        ends.append((crossing, p + t[:, None] * (q - p)))
    # Each cut face has two crossing edges: its segment runs between their points.
    first = np.where(ends[0][0][:, None], ends[0][1], ends[1][1])
    second = np.where(ends[2][0][:, None], ends[2][1], ends[1][1])
    n = int(np.clip(np.ceil(np.max(np.linalg.norm(second - first, axis=1), initial=0) / step_mm),
                    1, 40)) + 1  # fmt: skip
    w = np.linspace(0.0, 1.0, n)[None, :, None]
    pts = first[:, None] + w * (second - first)[:, None]
    return pts.reshape(-1, 3), np.repeat(cut, n)


def anterior_profile(points, ys, band_mm):
    """The most anterior of ``points`` within ``band_mm`` of each height: ``(N, 3)``, NaN where
    none (a midline profile, :func:`midline_section`'s points)."""
    out = np.full((len(ys), 3), np.nan)
    order = np.argsort(points[:, 1])
    py = points[order, 1]
    for i, y in enumerate(ys):
        lo, hi = np.searchsorted(py, [y - band_mm, y + band_mm])
        if hi > lo:
            sel = points[order[lo:hi]]
            out[i] = sel[np.argmax(sel[:, 2])]
    return out
