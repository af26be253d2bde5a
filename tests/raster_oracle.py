"""Reference rasters of a projected mesh, to check the production raster against.

Not part of the package: Lilium has one rasteriser, :func:`lilium.imaging.raster.skull_raster`.
These are slow, independent fills of the same union, kept as oracles for the tests and for
``benchmarks/bench_raster.py`` (which puts ``tests/`` on ``sys.path``).
"""

import numpy as np

from lilium.imaging.raster import check_faces


def skull_raster_per_triangle(uv, faces, shape):
    """Reference union: every triangle tested on its own (closed triangles, pixel centres).

    Slow (a Python loop over triangle size classes). Agrees with
    :func:`lilium.imaging.raster.skull_raster` except for pixel centres lying exactly on an edge.
    """
    uv = np.asarray(uv, dtype=float)
    faces = check_faces(faces, len(uv))
    height, width = int(shape[0]), int(shape[1])
    out = np.zeros((height, width), bool)
    tri = uv[faces]  # (F, 3, 2)
    ok = np.all(np.isfinite(tri), axis=(1, 2))
    tri = tri[ok]
    lo = np.ceil(tri.min(axis=1)).astype(np.int64)  # (F, 2) = (u, v)
    hi = np.floor(tri.max(axis=1)).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [width - 1, height - 1])
    size = np.maximum(hi - lo + 1, 0).max(axis=1)
    for k in np.unique(size[size > 0]):
        sel = np.flatnonzero(size == k)
        for chunk in np.array_split(sel, max(1, len(sel) * k * k // 2_000_000 + 1)):
            t = tri[chunk]
            g = np.arange(k)
            cu = lo[chunk, 0, None, None] + g[None, None, :]  # (n, 1, k)
            cv = lo[chunk, 1, None, None] + g[None, :, None]  # (n, k, 1)
            inside = np.ones((len(chunk), k, k), bool)
            area = (t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1]) - (
                t[:, 2, 0] - t[:, 0, 0]
            ) * (t[:, 1, 1] - t[:, 0, 1])
            s = np.sign(area)[:, None, None]
            for i in range(3):
                a, b = t[:, i], t[:, (i + 1) % 3]
                e = (b[:, 0, None, None] - a[:, 0, None, None]) * (cv - a[:, 1, None, None]) - (
                    b[:, 1, None, None] - a[:, 1, None, None]
                ) * (cu - a[:, 0, None, None])
                inside &= s * e >= 0
            inside &= s != 0
            inside &= (cu <= hi[chunk, 0, None, None]) & (cv <= hi[chunk, 1, None, None])
            n, r, q = np.nonzero(inside)
            out[lo[chunk[n], 1] + r, lo[chunk[n], 0] + q] = True
    return out


def skull_raster_cv2(uv, faces, shape, shift=8):
    """Union by a Python loop of ``cv2.fillConvexPoly`` (OpenCV's own fill rule), for comparison.

    ``shift`` fractional bits keep sub-pixel vertex positions. About 2 us per triangle.
    """
    import cv2

    uv = np.asarray(uv, dtype=float)
    faces = check_faces(faces, len(uv))
    out = np.zeros((int(shape[0]), int(shape[1])), np.uint8)
    tri = uv[faces]
    ok = np.all(np.isfinite(tri), axis=(1, 2))
    pts = np.round(tri[ok] * (1 << shift)).astype(np.int32)
    for p in pts:
        cv2.fillConvexPoly(out, p, 1, lineType=cv2.LINE_8, shift=shift)
    return out.astype(bool)
