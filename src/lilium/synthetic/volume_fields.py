"""Signed-distance-like fields on a voxel grid, for building synthetic CT-like volumes.

Fields are negative inside, positive outside, in mm (approximately: the primitives are the usual
cheap distance bounds, good enough for smooth blending and iso-surfaces). A :class:`GridField`
covers an axis-aligned box of the skull frame; each primitive is evaluated only inside its own
bounding box, so a head at 2 mm costs a few hundred milliseconds.

Arrays are indexed ``[k, j, i]`` = ``[z, y, x]`` (the (Z, Y, X) order of :mod:`lilium.ct.volume`),
so a field converts to a :class:`~lilium.ct.volume.Volume` without copying.
"""

import numpy as np

#: Value of "far outside" before anything is added.
FAR_MM = 1e3


def smin(a, b, k):
    """Smooth minimum (union) with blend radius ``k`` mm (polynomial; ``k=0`` is ``min``)."""
    if k <= 0:
        return np.minimum(a, b)
    h = np.clip(k - np.abs(a - b), 0.0, None) / k
    return np.minimum(a, b) - h * h * k * 0.25


def smax(a, b, k):
    """Smooth maximum (intersection / subtraction) with blend radius ``k`` mm."""
    return -smin(-a, -b, k)


def ellipsoid(p, centre, radii, rotation=None):
    """Approximate signed distance to an ellipsoid.

    Parameters
    ----------
    p : tuple of 3 broadcastable arrays (x, y, z), mm
    centre : array_like of shape (3,)
    radii : array_like of shape (3,)
    rotation : ndarray of shape (3, 3), optional
        Columns: the ellipsoid's axes in the skull frame.
    """
    q = _local(p, centre, rotation)
    r = np.asarray(radii, float)
    k0 = np.sqrt(sum((qi / ri) ** 2 for qi, ri in zip(q, r, strict=True)))
    k1 = np.sqrt(sum((qi / ri**2) ** 2 for qi, ri in zip(q, r, strict=True)))
    return k0 * (k0 - 1.0) / np.maximum(k1, 1e-9)


def superellipsoid(p, centre, radii, exponents, rotation=None):
    """Rough signed distance to ``|x/a|^n1 + |y/b|^n2 + |z/c|^n3 = 1`` (boxier than ellipsoids)."""
    q = _local(p, centre, rotation)
    r = np.asarray(radii, float)
    s = sum(np.abs(qi / ri) ** ni for qi, ri, ni in zip(q, r, exponents, strict=True))
    return (s ** (1.0 / np.mean(exponents)) - 1.0) * r.min()


def elliptic_cylinder(p, centre, radii, z_lo, z_hi):
    """Rough signed distance to an elliptic cylinder along z, cut by the planes ``z_lo``, ``z_hi``.

    Parameters
    ----------
    p : tuple of 3 broadcastable arrays (x, y, z), mm
    centre : array_like
        ``(x, y)`` of the axis, mm (a third value is ignored).
    radii : array_like
        Semi-axes along x and y, mm.
    z_lo, z_hi : float
        The two ends, mm.
    """
    a, b = float(radii[0]), float(radii[1])
    k = np.sqrt(((p[0] - centre[0]) / a) ** 2 + ((p[1] - centre[1]) / b) ** 2)
    return np.maximum((k - 1.0) * min(a, b), np.maximum(z_lo - p[2], p[2] - z_hi))


def capsule(p, a, b, ra, rb=None):
    """Signed distance to a segment ``a``-``b`` thickened by a radius from ``ra`` to ``rb``."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    rb = ra if rb is None else rb
    ab = b - a
    t = ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / (ab @ ab)
    t = np.clip(t, 0.0, 1.0)
    d = np.sqrt(sum((p[i] - (a[i] + t * ab[i])) ** 2 for i in range(3)))
    return d - (ra + t * (rb - ra))


def slab(p, a, b, up, half_width, half_height, radius):
    """Rounded box swept along a segment: a piece of a bar whose cross-section is a rectangle.

    Parameters
    ----------
    a, b : array_like of shape (3,)
        Segment ends (centre line).
    up : array_like of shape (3,)
        Direction of the cross-section's height (made perpendicular to the segment).
    half_width, half_height : float or (float, float)
        Half sizes of the cross-section (without the rounding); a pair varies linearly from
        ``a`` to ``b``.
    radius : float
        Rounding radius (added to the half sizes).
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    ab = b - a
    length = np.linalg.norm(ab)
    t_dir = ab / length
    up = np.asarray(up, float)
    up = up - (up @ t_dir) * t_dir
    up /= np.linalg.norm(up)
    side = np.cross(t_dir, up)
    rel = [p[i] - a[i] for i in range(3)]
    along = sum(rel[i] * t_dir[i] for i in range(3))
    t = np.clip(along / length, 0.0, 1.0)
    hw = _lerp(half_width, t)
    hh = _lerp(half_height, t)
    qa = np.abs(along - t * length)
    qw = np.abs(sum(rel[i] * side[i] for i in range(3))) - hw
    qh = np.abs(sum(rel[i] * up[i] for i in range(3))) - hh
    outside = np.sqrt(
        np.maximum(qw, 0.0) ** 2 + np.maximum(qh, 0.0) ** 2 + np.maximum(qa, 0.0) ** 2
    )
    return outside + np.minimum(np.maximum(qw, qh), 0.0) - radius


def plane(p, point, normal):
    """Signed distance to a half-space; negative on the side ``normal`` points away from."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    return sum((p[i] - point[i]) * n[i] for i in range(3))


def _lerp(value, t):
    if np.ndim(value) == 0:
        return value
    return value[0] + t * (value[1] - value[0])


def _local(p, centre, rotation):
    rel = [p[i] - centre[i] for i in range(3)]
    if rotation is None:
        return rel
    R = np.asarray(rotation, float)
    return [sum(rel[i] * R[i, c] for i in range(3)) for c in range(3)]


def rotation_xyz(rx_deg=0.0, ry_deg=0.0, rz_deg=0.0):
    """Rotation matrix ``Rz @ Ry @ Rx`` from angles in degrees (columns = rotated axes).

    :mod:`lilium.geometry.rotations` has no Euler-angle constructor; composing three
    :func:`~lilium.geometry.rotations.rotvec_to_matrix` gives the same rotation but rounds
    differently (about half of all angles differ in the last bit), which would change every
    seeded synthetic subject, so this stays.
    """
    ax, ay, az = np.radians([rx_deg, ry_deg, rz_deg])
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


class GridField:
    """A scalar field sampled on a regular grid of the skull frame.

    Parameters
    ----------
    lo_mm, hi_mm : array_like of shape (3,)
        Corners of the box (x, y, z), mm.
    voxel_mm : float
        Grid spacing.

    Attributes
    ----------
    values : ndarray of shape (Z, Y, X), float32
        Field samples, ``values[k, j, i]`` at ``lo_mm + (i, j, k) * voxel_mm``.
    """

    def __init__(self, lo_mm, hi_mm, voxel_mm, fill=FAR_MM):
        self.lo = np.asarray(lo_mm, float)
        self.voxel = float(voxel_mm)
        self.n = np.floor((np.asarray(hi_mm, float) - self.lo) / self.voxel).astype(int) + 1
        self.axes = [self.lo[i] + self.voxel * np.arange(self.n[i]) for i in range(3)]
        self.values = np.full(self.n[::-1], fill, dtype=np.float32)

    def copy(self):
        other = GridField.__new__(GridField)
        other.lo, other.voxel, other.n, other.axes = self.lo, self.voxel, self.n, self.axes
        other.values = self.values.copy()
        return other

    def window(self, lo_mm, hi_mm):
        """Slices ``(k, j, i)`` and open-grid coordinates ``(x, y, z)`` of a sub-box."""
        i0 = np.clip(np.floor((np.asarray(lo_mm) - self.lo) / self.voxel).astype(int), 0, self.n)
        i1 = np.clip(np.ceil((np.asarray(hi_mm) - self.lo) / self.voxel).astype(int) + 1, 0, self.n)
        sl = tuple(slice(i0[c], i1[c]) for c in (2, 1, 0))
        x = self.axes[0][i0[0] : i1[0]][None, None, :]
        y = self.axes[1][i0[1] : i1[1]][None, :, None]
        z = self.axes[2][i0[2] : i1[2]][:, None, None]
        return sl, (x, y, z)

    def combine(self, fn, lo_mm, hi_mm, op="union", k=0.0):
        """Combine ``fn(p)`` into the field inside the box ``[lo_mm, hi_mm]``.

        ``op``: ``"union"`` (smooth min), ``"subtract"`` (smooth max with ``-fn``), ``"intersect"``
        (smooth max) or ``"add"`` (plain sum, e.g. noise). The box must hold the whole region
        where the primitive can change the field (its surface plus the blend radius).
        """
        sl, p = self.window(lo_mm, hi_mm)
        if any(s.stop - s.start <= 0 for s in sl):
            return
        d = np.asarray(fn(p), dtype=np.float32)
        current = self.values[sl]
        if op == "union":
            self.values[sl] = smin(current, d, k)
        elif op == "subtract":
            self.values[sl] = smax(current, -d, k)
        elif op == "intersect":
            self.values[sl] = smax(current, d, k)
        elif op == "add":
            self.values[sl] = current + d
        else:
            raise ValueError(f"unknown field operation {op!r}")

    def sample(self, points_mm, order=1):
        """Field values at points (trilinear by default); outside the grid: ``FAR_MM``.

        Parameters
        ----------
        points_mm : array_like of shape (N, 3)

        Returns
        -------
        ndarray of shape (N,)
        """
        from scipy.ndimage import map_coordinates

        pts = np.atleast_2d(np.asarray(points_mm, float))
        idx = ((pts - self.lo) / self.voxel)[:, ::-1].T
        return map_coordinates(self.values, idx, order=order, mode="constant", cval=FAR_MM)

    def gradient(self, points_mm, h=0.5):
        """Central-difference gradient of the interpolated field at points, shape (N, 3)."""
        pts = np.atleast_2d(np.asarray(points_mm, float))
        g = np.empty_like(pts)
        for c in range(3):
            e = np.zeros(3)
            e[c] = h
            g[:, c] = (self.sample(pts + e) - self.sample(pts - e)) / (2 * h)
        return g

    def ray_hit(self, origins_mm, directions, max_mm=250.0, step_mm=0.5):
        """First entry of rays into the inside (field < 0), refined linearly.

        Parameters
        ----------
        origins_mm : array_like of shape (N, 3)
            Starting points, outside.
        directions : array_like of shape (N, 3) or (3,)

        Returns
        -------
        points_mm : ndarray of shape (N, 3)
            Hit points; NaN rows where a ray never enters.
        """
        o = np.atleast_2d(np.asarray(origins_mm, float))
        d = np.broadcast_to(np.asarray(directions, float), o.shape)
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        t = np.arange(0.0, max_mm, step_mm)
        pts = o[:, None, :] + t[None, :, None] * d[:, None, :]
        f = self.sample(pts.reshape(-1, 3)).reshape(len(o), len(t))
        inside = f < 0
        first = np.argmax(inside, axis=1)
        hit = inside[np.arange(len(o)), first] & (first > 0)
        out = np.full(o.shape, np.nan)
        k = first[hit]
        rows = np.nonzero(hit)[0]
        f0, f1 = f[rows, k - 1], f[rows, k]
        frac = f0 / np.where(f0 - f1 == 0, 1, f0 - f1)
        tt = t[k - 1] + frac * step_mm
        out[rows] = o[rows] + tt[:, None] * d[rows]
        return out

    def snap(self, points_mm, iterations=6):
        """Move points onto the zero level set along the field gradient (Newton steps)."""
        p = np.atleast_2d(np.asarray(points_mm, float)).copy()
        for _ in range(iterations):
            f = self.sample(p)
            g = self.gradient(p)
            gg = np.maximum(np.einsum("ij,ij->i", g, g), 1e-6)
            p -= (f / gg)[:, None] * g
        return p


def sweep(p, centres, half_width, half_height, radius, up=(0.0, 1.0, 0.0)):
    """Rounded rectangle swept along a polyline (a curved bar without seams).

    Each point takes the cross-section of its nearest centre-line segment (linearly
    interpolated sizes); the cross-section's height follows ``up`` made perpendicular to the
    segment.

    Parameters
    ----------
    centres : array_like of shape (M, 3)
    half_width, half_height : array_like of shape (M,)
    radius : float
    """
    c = np.asarray(centres, float)
    hw_all = np.asarray(half_width, float)
    hh_all = np.asarray(half_height, float)
    best = None
    for m in range(len(c) - 1):
        a, b = c[m], c[m + 1]
        ab = b - a
        length = np.linalg.norm(ab)
        t_dir = ab / length
        u = np.asarray(up, float) - (np.asarray(up, float) @ t_dir) * t_dir
        u /= np.linalg.norm(u)
        side = np.cross(t_dir, u)
        rel = [p[i] - a[i] for i in range(3)]
        along = sum(rel[i] * t_dir[i] for i in range(3))
        t = np.clip(along / length, 0.0, 1.0)
        qw = sum(rel[i] * side[i] for i in range(3))
        qh = sum(rel[i] * u[i] for i in range(3))
        qa = along - t * length
        centre_dist = qw * qw + qh * qh + qa * qa
        hw = hw_all[m] + t * (hw_all[m + 1] - hw_all[m])
        hh = hh_all[m] + t * (hh_all[m + 1] - hh_all[m])
        dw, dh = np.abs(qw) - hw, np.abs(qh) - hh
        d = (
            np.sqrt(np.maximum(dw, 0.0) ** 2 + np.maximum(dh, 0.0) ** 2 + qa * qa)
            + np.minimum(np.maximum(dw, dh), 0.0)
            - radius
        )
        if best is None:
            best, best_d = centre_dist, d
        else:
            closer = centre_dist < best
            best = np.where(closer, centre_dist, best)
            best_d = np.where(closer, d, best_d)
    return best_d
