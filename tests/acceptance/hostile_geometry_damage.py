"""The damage of the geometric degeneracy probes of ``hostile_geometry.py``: set-ups
that leave every file valid in its format but its geometry degenerate or damaged, as real scans
and real hand annotations are.

- Meshes (:func:`_mesh_op` and the operations it applies): a stray triangle or fragment, a
  second copy of the skull, inward or mixed face winding, zero-area and duplicate faces, a
  holey mesh, a CT cut below the orbits or a mesh of the jaw alone (with or without the cut
  vertices kept unreferenced), a vertex no face uses, a skull of 80 or 20 faces, the whole
  subject far from the origin.
- Landmarks: the photo's or the skull's landmark set cut down (the midline alone: coplanar;
  4 or 5 landmarks), a landmark copied onto its twin's place, a cranial landmark pushed off
  the bone, the photo's priors dropped.
- Masks (:func:`_mask`): one pixel, one row, the full frame but a pixel, a second component
  under the chin or in a corner; the face curve removed (to be made from the mask).

The set-ups take ``where``: ``where(ws)`` is the folder they damage (the workspace's subject
or photo); the mesh operations map ``(v, f)`` to ``(v, f)``, the mask makers a boolean mask
to another.
"""

import numpy as np
from hostile_fixtures import _edit_json
from hostile_machinery import _then

# -- set-ups: meshes --------------------------------------------------------------------------


def _mesh_op(where, op, names=("skull.ply",)):
    """Set-up: ``(v, f) = op(v, f)`` on the subject's mesh(es)."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        for name in names:
            path = where(ws) / name
            if path.is_file():
                v, f = read_mesh(path)
                v, f = op(np.asarray(v, float).copy(), np.asarray(f).copy())
                write_mesh(path, v, f)

    return setup


def _blob(centre, radius=10.0, subdivisions=3):
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.asarray(s.vertices) * radius + np.asarray(centre, float), np.asarray(s.faces)


def _add(v, f, v2, f2):
    return np.vstack([v, v2]), np.vstack([f, np.asarray(f2) + len(v)])


def _fragment(centre, radius=10.0, subdivisions=3):
    """A small disconnected fragment (an icosphere) at ``centre`` (mm, skull frame)."""
    return lambda v, f: _add(v, f, *_blob(centre, radius, subdivisions))


def _stray_triangle(centre):
    """One tiny triangle (1 mm) at ``centre``: a stray vertex as scanners leave them."""
    c = np.asarray(centre, float)
    tri = np.array([c, c + [1, 0, 0], c + [0, 1, 0]])
    return lambda v, f: _add(v, f, tri, [[0, 1, 2]])


def _copy_beside(offset):
    """A second copy of the whole skull moved by ``offset`` (mm)."""
    return lambda v, f: _add(v, f, v + np.asarray(offset, float), f)


def _flip_faces(share=1.0):
    """The winding of every (``share`` 1) or every other (``share`` 0.5) face reversed."""

    def op(v, f):
        f = f.copy()
        sel = slice(None) if share == 1.0 else slice(None, None, 2)
        f[sel] = f[sel][:, ::-1]
        return v, f

    return op


def _degenerate_faces(v, f):
    """Every face twice (duplicates) plus a zero-area face (a, a, b) per face."""
    zero = np.column_stack([f[:, 0], f[:, 0], f[:, 1]])
    return v, np.vstack([f, f, zero])


def _holes(share, seed=0):
    """``share`` of the faces dropped at random (a very holey, non-manifold surface)."""

    def op(v, f):
        keep = np.random.default_rng(seed).random(len(f)) >= share
        return v, f[keep]

    return op


def _cut_below(y_mm):
    """Only the faces with every vertex above ``y`` (a CT cut below the orbits, no jaw)."""

    def op(v, f):
        return v, f[np.all(v[f][:, :, 1] > y_mm, axis=1)]

    return op


def _only_below(y_mm):
    """Only the faces with every vertex below ``y`` (a mesh of the jaw alone)."""

    def op(v, f):
        return v, f[np.all(v[f][:, :, 1] < y_mm, axis=1)]

    return op


def _compact(op):
    """``op``, then the vertices no face uses dropped (as "delete faces and vertices" does)."""

    def run(v, f):
        v, f = op(v, f)
        used = np.unique(f)
        index = np.full(len(v), -1)
        index[used] = np.arange(len(used))
        return v[used], index[f]

    return run


def _unreferenced_vertex(point):
    """One vertex no face uses at ``point`` (mm)."""
    return lambda v, f: (np.vstack([v, np.asarray(point, float)]), f)


def _coarse_skull(subdivisions=1):
    """The stand-in skull as an icosphere of 80 (1) or 20 (0) faces on its ellipsoid."""

    def op(v, f):
        import trimesh

        radii = np.array([70.0, 85.0, 92.0])
        s = trimesh.creation.icosphere(subdivisions=subdivisions)
        return np.asarray(s.vertices) * radii, np.asarray(s.faces)

    return op


def _offset_subject(where, offset):
    """The whole subject moved by ``offset`` (mm): meshes, cranial and facial landmarks."""
    off = np.asarray(offset, float)

    def move(data, key):
        data[key] = {k: list(np.asarray(p, float) + off) for k, p in data[key].items()}

    return _then(
        _mesh_op(where, lambda v, f: (v + off, f), names=("skull.ply", "face.ply")),
        _edit_json(where, "cranial_landmarks.json", lambda d: move(d, "landmarks")),
        _edit_json(where, "facial_landmarks.json", lambda d: move(d, "landmarks")),
    )


# -- set-ups: landmarks -----------------------------------------------------------------------


def _keep_photo(where, names):
    return _edit_json(
        where, "photo.json", lambda d: d.update(
            landmarks={k: p for k, p in d["landmarks"].items() if k in names})
    )  # fmt: skip


def _keep_cranial(where, names):
    return _edit_json(
        where, "cranial_landmarks.json", lambda d: d.update(
            landmarks={k: p for k, p in d["landmarks"].items() if k in names})
    )  # fmt: skip


def _copy_photo_lm(where, src, dst, jitter=(0.0, 0.0)):
    """Facial landmark ``dst`` given ``src``'s pixel (a copy-paste slip), plus ``jitter``."""

    def change(d):
        u, v = d["landmarks"][src]
        d["landmarks"][dst] = [u + jitter[0], v + jitter[1]]

    return _edit_json(where, "photo.json", change)


def _copy_cranial_lm(where, src, dst):
    def change(d):
        d["landmarks"][dst] = list(d["landmarks"][src])

    return _edit_json(where, "cranial_landmarks.json", change)


def _push_cranial(where, name, mm):
    """Cranial landmark ``name`` moved ``mm`` along the skull's anterior axis (+z: off the bone
    for a facial point)."""

    def change(d):
        p = np.asarray(d["landmarks"][name], float)
        d["landmarks"][name] = list(p + [0.0, 0.0, mm])

    return _edit_json(where, "cranial_landmarks.json", change)


def _no_rotation_prior(where):
    def change(d):
        for k in ("head_rotation_skull2cam", "head_tolerance_deg"):
            d.get("priors", {}).pop(k, None)

    return _edit_json(where, "photo.json", change)


def _no_priors(where):
    return _edit_json(where, "photo.json", lambda d: d.pop("priors", None))


MIDLINE_FACE = ("glabella", "nasion", "metopion", "bregma", "subnasale", "labiale_superius",
                "pogonion", "gnathion")  # fmt: skip
MIDLINE_SKULL = ("glabella", "nasion", "metopion", "bregma", "subspinale", "prosthion",
                 "pogonion", "gnathion")  # fmt: skip

# -- set-ups: masks ---------------------------------------------------------------------------


def _mask(where, make):
    """Set-up: ``face_mask.png`` replaced by ``make(old bool array) -> bool array``."""

    def setup(ws):
        from PIL import Image

        path = where(ws) / "face_mask.png"
        with Image.open(path) as im:
            old = np.asarray(im.convert("L")) > 0
        Image.fromarray((make(old) * 255).astype(np.uint8)).save(path)

    return setup


def _one_pixel(old):
    out = np.zeros_like(old)
    ys, xs = np.nonzero(old)
    out[int(ys.mean()), int(xs.mean())] = True
    return out


def _one_row(old):
    out = np.zeros_like(old)
    ys, _ = np.nonzero(old)
    out[int(ys.mean()), :] = True
    return out


def _all_but_corner(old):
    out = np.ones_like(old)
    out[0, 0] = False
    return out


def _blob_below_chin(old):
    """A second component (a hand, another head) under the chin, across its middle."""
    out = old.copy()
    ys, xs = np.nonzero(old)
    h = old.shape[0]
    bottom, cx = ys.max(), int(np.median(xs))
    top = min(h - 40, bottom + 30)
    out[top : min(h - 1, top + 60), max(0, cx - 150) : cx + 150] = True
    return out


def _blob_in_corner(old):
    out = old.copy()
    out[:120, :120] = True
    return out


def _no_curve(where):
    return lambda ws: (where(ws) / "face_curve.json").unlink(missing_ok=True)
