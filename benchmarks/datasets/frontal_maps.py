"""The frontal height map of a skull mesh and the orbit and aperture rules on it, shared by the
written hand placements of the real heads (``headsq_landmarks``, ``cranium_landmarks``, whose
docstrings state the rules).

Frame: the generator's skull frame, mm (x = the subject's left, y = up, z = anterior).
"""

import numpy as np

HEIGHT_MAP_PX_MM = 1.0
CLOSING_RADIUS_MM = 20.0
DEEP_MM = 8.0
RIM_FRACTION = 0.75
ALARE_FRACTION = 0.9
ORBIT_SCAN_MM = 30.0
ECTOCONCHION_SCAN_MM = 40.0
CREST_PLATEAU_MM = 0.5
DACRYON_BEHIND_MM = 4.0
ALARE_SCAN_MM = 25.0


def _height_map(vertices, faces):
    """Frontal height map of a mesh: (z per pixel or NaN, triangle per pixel, pixel -> x, y)."""
    from lilium.geometry.camera import Camera
    from lilium.synthetic import photos, render

    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = 0.5 * (lo + hi)
    size = np.ceil((hi[:2] - lo[:2]) / HEIGHT_MAP_PX_MM).astype(int) + 21
    distance = 1e6
    focal = distance / HEIGHT_MAP_PX_MM
    R = photos.R_FRONTAL
    t = np.array([0.0, 0.0, distance]) - R @ centre
    pp = 0.5 * (size - 1)
    camera = Camera.from_rt(R, t, focal, pp)
    faces_index = render.render_mesh(vertices, faces, camera, tuple(int(s) for s in size))
    index = faces_index.face_index
    z_tri = vertices[faces].mean(axis=1)[:, 2]
    height = np.where(index >= 0, z_tri[np.maximum(index, 0)], np.nan)

    def xy(u, v):
        return np.array(
            [centre[0] + (u - pp[0]) * HEIGHT_MAP_PX_MM, centre[1] - (v - pp[1]) * HEIGHT_MAP_PX_MM]
        )

    return height, index, xy


def _pixel_vertex(vertices, faces, index, xy, u, v):
    """The vertex of the triangle at pixel (u, v) nearest to it in x, y."""
    tri = faces[index[v, u]]
    d = np.linalg.norm(vertices[tri, :2] - xy(u, v), axis=1)
    return vertices[tri[int(np.argmin(d))]].copy()


def _deep_regions(height):
    import cv2
    from scipy import ndimage as ndi

    inside = np.isfinite(height)
    floor = np.nanmin(height) - 1.0
    h = np.where(inside, height, floor).astype(np.float32)
    r = int(round(CLOSING_RADIUS_MM / HEIGHT_MAP_PX_MM))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
    closed = cv2.morphologyEx(h, cv2.MORPH_CLOSE, kernel)
    hull = cv2.morphologyEx(inside.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
    deep = hull & ((closed - h) > DEEP_MM)
    labels, n = ndi.label(deep)
    return labels, n


def _over(skin, point, direction, radius_mm=2.0, max_t_mm=35.0, outermost=True):
    """The outermost (or first) skin vertex within ``radius_mm`` of the ray
    ``point + t direction``, ``0 < t < max_t_mm`` (outermost: the outer skin, not the airway
    surfaces a ray from inside the face crosses first)."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    rel = skin - point
    t = rel @ d
    perp = np.linalg.norm(rel - t[:, None] * d, axis=1)
    for radius in radius_mm + np.arange(8.0):
        ok = (t > 0) & (t < max_t_mm) & (perp < radius)
        if ok.any():
            k = np.flatnonzero(ok)
            return skin[k[np.argmax(t[k]) if outermost else np.argmin(t[k])]].copy()
    raise ValueError(f"no skin over {point} along {d}")


def rim_edge(heights, fraction=RIM_FRACTION):
    """Index of the rim edge of a scan line (see the module notes), or None."""
    z = np.where(np.isfinite(heights), heights, -np.inf)
    if not np.isfinite(z).any():
        return None
    top = int(np.argmax(z))
    deep = np.min(z[: top + 1][np.isfinite(z[: top + 1])])
    reached = z[: top + 1] >= deep + fraction * (z[top] - deep)
    return int(np.argmax(reached))


class _Map:
    """The frontal height map of a mesh (with its deep regions when ``regions``) and its
    pixel <-> frame conversions (1 mm pixels; u to +x, v to -y)."""

    def __init__(self, skull, faces, regions=True):
        self.skull, self.faces = skull, faces
        self.height, self.index, self.xy = _height_map(skull, faces)
        if regions:
            self.labels, self.n = _deep_regions(self.height)
        self.x0 = self.xy(0, 0)[0]
        self.y0 = self.xy(0, 0)[1]

    def u_of(self, x):
        return int(round(x - self.x0))

    def v_of(self, y):
        return int(round(self.y0 - y))

    def scan(self, u, v, du, dv, length_mm):
        """Pixels (u, v) and heights of a scan line from (u, v) in steps (du, dv)."""
        H, W = self.height.shape
        steps = np.arange(int(length_mm) + 1)
        us, vs = u + du * steps, v + dv * steps
        ok = (us >= 0) & (us < W) & (vs >= 0) & (vs < H)
        us, vs = us[ok], vs[ok]
        return us, vs, self.height[vs, us]

    def vertex(self, u, v):
        return _pixel_vertex(self.skull, self.faces, self.index, self.xy, int(u), int(v))

    def profile(self, x):
        """The midline profile at ``x``: the vertex of every row's pixel, top-down (K, 3)."""
        u = self.u_of(x)
        rows = np.flatnonzero(np.isfinite(self.height[:, u]))
        return np.array([self.vertex(u, v) for v in rows])

    def region(self, lab):
        v, u = np.nonzero(self.labels == lab)
        return u, v


def _orbit_landmarks(m, orbits, x_mid):
    """Ectoconchion, dacryon, orbitale of both sides; the superior margins' mean y and the
    transverse axis' mean y."""
    cranial, tops, axes = {}, [], []
    u_mid = m.u_of(x_mid)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        u, v = orbits[side]
        uc, vc = int(round(u.mean())), int(round(v.mean()))
        us, vs, h = m.scan(uc, vc, 0, -1, ORBIT_SCAN_MM)
        v_top = vs[rim_edge(h)]
        us, vs, h = m.scan(uc, vc, 0, 1, ORBIT_SCAN_MM)
        v_bottom = vs[rim_edge(h)]
        v_ax = int(round(0.5 * (v_top + v_bottom)))
        tops.append(m.xy(0, v_top)[1])
        axes.append(m.xy(0, v_ax)[1])
        step = 1 if sign > 0 else -1  # +u is +x (the subject's left)
        us, vs, h = m.scan(uc, v_ax, step, 0, ECTOCONCHION_SCAN_MM)
        z = np.where(np.isfinite(h), h, -np.inf)
        crest = int(np.flatnonzero(z >= z.max() - CREST_PLATEAU_MM)[0])
        cranial[f"ectoconchion_{side}"] = m.vertex(us[crest], v_ax)
        us, vs, h = m.scan(uc, v_ax, -step, 0, abs(uc - u_mid))
        k = rim_edge(h)
        margin = m.vertex(us[k], v_ax)
        target = margin - np.array([0.0, 0.0, DACRYON_BEHIND_MM])
        near = np.argmin(np.linalg.norm(m.skull - target, axis=1))
        cranial[f"dacryon_{side}"] = m.skull[near].copy()
        lo, hi = np.percentile(u, [25, 75])
        best = None
        for col in range(int(lo), int(hi) + 1):
            rows = v[u == col]
            if len(rows) == 0:
                continue
            us, vs, h = m.scan(col, int(rows.mean()), 0, 1, ORBIT_SCAN_MM)
            k = rim_edge(h)
            if k is not None and (best is None or vs[k] > best[1]):
                best = (col, vs[k])
        cranial[f"orbitale_{side}"] = m.vertex(*best)
    return cranial, float(np.mean(tops)), float(np.mean(axes))


def _aperture(m, x_mid, axis_y):
    """The nasal aperture's region (u, v): the deep region on the midline column nearest below
    the orbits' transverse axis."""
    u_mid = m.u_of(x_mid)
    best = None
    for lab in range(1, m.n + 1):
        u, v = m.region(lab)
        if (u == u_mid).any() and m.xy(0, v.mean())[1] < axis_y:
            if best is None or v.mean() < best[1].mean():
                best = (u, v)
    return best


def _alare(m, aperture, x_mid):
    """The cranial alare of both sides (see the module notes)."""
    u, v = aperture
    u_mid = m.u_of(x_mid)
    out = {}
    for side, sign in (("l", 1.0), ("r", -1.0)):
        step = 1 if sign > 0 else -1
        edges = []
        for row in np.unique(v):
            us, _, h = m.scan(u_mid, row, step, 0, ALARE_SCAN_MM)
            k = rim_edge(h, ALARE_FRACTION)
            if k is not None:
                edges.append((abs(int(us[k]) - u_mid), int(us[k]), int(row)))
        widest = max(e[0] for e in edges)
        rows = [e for e in edges if e[0] == widest]
        _, col, row = rows[len(rows) // 2]  # the middle of a vertical stretch of the margin
        out[f"alare_{side}"] = m.vertex(col, row)
    return out
