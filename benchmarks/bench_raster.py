"""Speed and exactness of the fitness rasters (P_skof) and of one P_pll evaluation.

Run: ``.venv/bin/python benchmarks/bench_raster.py`` (one core is enough; ~1 minute;
``--pll`` for the P_pll part only). Times are CPU times (``time.process_time``), best of 3,
so other processes on the machine inflate them less than wall-clock times.

Input: closed, bumpy (non-convex, noisy) triangulated ellipsoids of about 3k, 20k and 50k faces
(semi-axes 70 x 95 x 90 mm), seen 600 mm away with f = 2500 px in a 1600 x 2400 (rows x columns)
photo, so the skull covers about 600 x 800 px; the face mask is an ellipse that leaves part of
the skull outside. Reference: the union of the triangles each tested on its own (pixel centres,
closed triangles), and OpenCV's per-triangle ``fillConvexPoly`` loop.
"""

import sys
import time
from functools import partial
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.spatial.transform import Rotation

from lilium.fitness.curves import CurveBatch, face_curve_from_mask
from lilium.fitness.pll import pll_terms_batch
from lilium.fitness.pll_context import PllContext
from lilium.fitness.regions import submesh
from lilium.fitness.skof import face_mask_index, skull_outside_pixels, skull_outside_pixels_batch
from lilium.geometry.camera import Camera
from lilium.imaging.raster import mesh_edge_topology, skull_raster

# The reference rasters are test oracles, not package code.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from raster_oracle import skull_raster_cv2, skull_raster_per_triangle  # noqa: E402

HEIGHT, WIDTH = 1600, 2400
FOCAL_PX = 2500.0
PRINCIPAL = np.array([(WIDTH - 1) / 2, (HEIGHT - 1) / 2])
BATCH = 20


def bumpy_ellipsoid(n_faces, rng=0, noise=0.004):
    """A closed, consistently oriented, non-convex ellipsoid of about ``n_faces`` faces (mm)."""
    rng = np.random.default_rng(rng)
    n_lon = max(8, round(np.sqrt(n_faces / 2 * 1.3)))
    n_lat = max(3, round(n_faces / (2 * n_lon)))
    theta = np.linspace(0, np.pi, n_lat + 2)[1:-1]
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    r = 1 + 0.12 * np.sin(3 * T) * np.cos(5 * P) + 0.05 * np.sin(7 * P + 2 * T)
    r = r * (1 + noise * rng.standard_normal(r.shape))
    xyz = np.stack([np.sin(T) * np.cos(P), np.cos(T), np.sin(T) * np.sin(P)], -1) * r[..., None]
    verts = np.vstack([[0, 1, 0], xyz.reshape(-1, 3), [0, -1, 0]]) * [70.0, 95.0, 90.0]
    idx = 1 + np.arange(n_lat * n_lon).reshape(n_lat, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    quads_a, quads_b = idx[:-1], nxt[:-1]
    quads_c, quads_d = nxt[1:], idx[1:]
    faces = [
        np.stack([quads_a, quads_b, quads_c], -1).reshape(-1, 3),
        np.stack([quads_a, quads_c, quads_d], -1).reshape(-1, 3),
        np.stack([np.zeros(n_lon, int), nxt[0], idx[0]], -1),
        np.stack([np.full(n_lon, len(verts) - 1), idx[-1], nxt[-1]], -1),
    ]
    return verts, np.vstack(faces)


def skull2cam(yaw_deg, pitch_deg, distance_mm=600.0):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("yx", [yaw_deg, pitch_deg], degrees=True).as_matrix()
    T[:3, 3] = [0, 0, distance_mm]
    return T


def ellipse_mask(centre_uv, axes_uv):
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH]
    return ((u - centre_uv[0]) / axes_uv[0]) ** 2 + ((v - centre_uv[1]) / axes_uv[1]) ** 2 <= 1


def timeit(fn, repeat):
    """Best of 3 of the mean CPU time (s) per call: robust to other processes on the machine."""
    fn()
    best = np.inf
    for _ in range(3):
        t0 = time.process_time()
        for _ in range(repeat):
            fn()
        best = min(best, (time.process_time() - t0) / repeat)
    return best


def bench_skof():
    mask = ellipse_mask(PRINCIPAL + [140, 120], [340, 430])
    index = face_mask_index(mask)
    inside_index = face_mask_index(ellipse_mask(PRINCIPAL, [520, 620]))
    print("P_skof: |S \\ F| by contour-edge winding scan vs per-triangle unions")
    print(
        f"{'faces':>7} {'|S|':>8} {'|S-F|':>7} {'err vs exact':>12} {'cv2 |S|':>8} "
        f"{'cv2 |S-F|':>9} {'ms/call':>8} {f'ms/indiv (S={BATCH})':>16} {'ms cv2 loop':>11}"
    )
    for n_faces in (3_000, 20_000, 50_000):
        verts, faces = bumpy_ellipsoid(n_faces)
        topo = mesh_edge_topology(faces)
        poses = [skull2cam(25, 10), skull2cam(-40, -5), skull2cam(90, 0)]
        for T in poses:
            uv = Camera(T, FOCAL_PX, PRINCIPAL).project(verts)
            count = skull_outside_pixels(uv, topology=topo, mask_index=index)
            raster = skull_raster(uv, topology=topo, shape=(HEIGHT, WIDTH))
            exact = skull_raster_per_triangle(uv, faces, (HEIGHT, WIDTH))
            exact_out = int(np.count_nonzero(exact & ~mask))
            t0 = time.process_time()
            cv = skull_raster_cv2(uv, faces, (HEIGHT, WIDTH))
            t_cv = time.process_time() - t0
            assert int(np.count_nonzero(raster & ~mask)) == count
            t_one = timeit(
                lambda uv=uv, t=topo: skull_outside_pixels(uv, topology=t, mask_index=index), 20
            )
            batch = np.repeat(uv[None], BATCH, axis=0)
            t_batch = timeit(
                lambda b=batch, t=topo: skull_outside_pixels_batch(b, topology=t, mask_index=index),
                3,
            )
            print(
                f"{len(faces):>7} {int(exact.sum()):>8} {exact_out:>7} {count - exact_out:>12d} "
                f"{int(cv.sum()):>8} {int(np.count_nonzero(cv & ~mask)):>9} "
                f"{1e3 * t_one:>8.3f} {1e3 * t_batch / BATCH:>16.3f} {1e3 * t_cv:>11.1f}"
            )
            if not np.array_equal(raster, exact):
                print(f"{'':>7} raster differs from the exact union at {(raster ^ exact).sum()} px")
        # A well-fitted individual: the skull inside a larger mask (most triangles culled).
        uv = Camera(poses[0], FOCAL_PX, PRINCIPAL).project(verts)
        count = skull_outside_pixels(uv, topology=topo, mask_index=inside_index)
        call = partial(skull_outside_pixels, uv, topology=topo, mask_index=inside_index)
        t_in = timeit(call, 20)
        t_raw = timeit(partial(call, cull=False), 20)
        print(
            f"{len(faces):>7} skull inside the mask (|S-F| = {count}): {1e3 * t_in:.3f} ms/call "
            f"({1e3 * t_raw:.3f} ms without culling)"
        )


def bench_pll():
    verts, faces = bumpy_ellipsoid(50_000)
    # A chin-sized region (about 50 x 20 mm): the lower cap of the ellipsoid, |x| < 25 mm.
    region = submesh((verts[:, 1] < -75) & (np.abs(verts[:, 0]) < 25), faces)
    sub_faces = region.faces
    T = skull2cam(10, 180)  # upside down so the cap is the lower part of the image
    uv = Camera(T, FOCAL_PX, PRINCIPAL).project(region.vertices_of(verts))
    shape = (HEIGHT, WIDTH)
    # Face mask: the region grown by a 12-px band.
    face_mask = ndimage.binary_dilation(skull_raster(uv, sub_faces, shape), iterations=12)
    u, v = uv[:, 0], uv[:, 1]
    mouth_v = np.median(v)
    mouth = {"cheilion_l": [u.min() + 10, mouth_v], "cheilion_r": [u.max() - 10, mouth_v]}
    face_curve = face_curve_from_mask(face_mask, "frontal", mouth)
    ctx = PllContext.build(sub_faces, face_curve, "frontal", image_shape=shape)
    skull_curve = ctx.skull_curve(uv)
    terms = ctx.evaluate(uv)
    t_detect = timeit(lambda: ctx.skull_curve(uv), 50)
    one = CurveBatch.from_curves([skull_curve])
    t_pen = timeit(lambda: pll_terms_batch(one, ctx.face_index, "frontal"), 50)
    t_all = timeit(lambda: ctx.evaluate(uv), 50)
    print(
        f"\nP_pll (frontal, chin-sized region of {len(sub_faces)} faces from the 50k mesh, "
        f"skull curve {len(skull_curve)} px, face curve {len(ctx.face_curve)} px): {terms}"
    )
    print(
        f"skull_curve {1e3 * t_detect:.3f} ms, pll_terms_batch (trim + pair + terms) "
        f"{1e3 * t_pen:.3f} ms, PllContext.evaluate (both) {1e3 * t_all:.3f} ms"
    )


if __name__ == "__main__":
    if "--pll" not in sys.argv:
        bench_skof()
    bench_pll()
