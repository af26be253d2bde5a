"""Speed of Lilium's image terms (P_skof, P_pll) for populations of cameras, on synthetic cases.

Run: ``.venv/bin/python benchmarks/bench_terms.py [DATASET]`` (about a minute). Without
``DATASET`` a small synthetic dataset (2 subjects, 2 photos each, experiment C) is generated in
a temporary folder. Times are CPU times (``time.process_time``), best of 5, per individual, for
populations of 30 cameras drawn around the ground truth ("near": 2 deg, 10 mm, 3 % focal; "far":
8 deg, 40 mm, 15 %), for every frontal and lateral photo.

Reported per term and view:

- P_pll: the readable per-curve oracle of the tests (``tests/pll_oracle.py``, one individual at
  a time: detect_curve + pll_penalty), production one individual at a time
  (:meth:`PllContext.evaluate`, a batch of one) and the batched
  :meth:`PllContext.evaluate_batch`, and the largest difference between the oracle's totals and
  the batched ones (must be 0).
- P_skof: :meth:`SkofTerm.outside_pixels` (projection + exact union count) on the full
  skull (exact, with its shortcut), and the pixel-count difference of the term against the
  full mesh on the same cameras (relative to the full count and to ``|S|``).
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from lilium.casework.build import read_photo, read_skull
from lilium.fitness.skof import prepare_skof, skull_outside_pixels_batch
from lilium.geometry.camera import Cameras, principal_point_of
from lilium.io.truth import read_ground_truth
from lilium.methods.lilium_terms import PllTerm, SkofTerm

# The tests' readable per-curve P_pll, the reference the batched totals must equal.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import pll_oracle  # noqa: E402

POPULATION = 30
REPEAT = 5
SPREADS = {"near": (2.0, 10.0, 0.03), "far": (8.0, 40.0, 0.15)}


def cameras_around(skull2cam, focal_px, spread, n=POPULATION, rng=0):
    """``n`` cameras perturbed around a ground truth (rotation deg, translation mm, focal)."""
    rng = np.random.default_rng(rng)
    deg, mm, rel = spread
    R0, t0 = np.asarray(skull2cam)[:3, :3], np.asarray(skull2cam)[:3, 3]
    dR = Rotation.from_rotvec(np.deg2rad(deg) * rng.standard_normal((n, 3))).as_matrix()
    R = dR @ R0
    t = t0 + mm * rng.standard_normal((n, 3))
    f = focal_px * (1 + rel * rng.standard_normal(n))
    return R, t, f


def best_time(fn, repeat=REPEAT):
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def load_cases(root):
    root = Path(root)
    for folder in sorted((root / "photos").glob("*/*")):
        photo = read_photo(folder, load_image=False)
        truth = read_ground_truth(folder)
        skull = read_skull(root / "subjects" / truth.subject)
        yield folder.name, skull, photo, truth


def bench_case(name, skull, photo, truth):
    centre = principal_point_of(photo.image_size_wh)
    pll = PllTerm(skull, photo, centre)
    skof = SkofTerm(skull, photo, centre)
    full = prepare_skof(skull.faces, photo.face_mask)
    for label, spread in SPREADS.items():
        R, t, f = cameras_around(truth.camera.skull2cam, truth.camera.focal_px, spread)
        uv = Cameras(R, t, f, centre).project(pll.region_vertices_mm)
        span_v = None
        if pll.span_mm is not None:
            span_v = Cameras(R, t, f, centre).project(pll.span_mm)[..., 1]
        ctx = pll.context

        def reference(uv=uv, span_v=span_v, ctx=ctx):
            return np.array(
                [
                    pll_oracle.pll_penalty(
                        pll_oracle.detect_curve(
                            u,
                            view=ctx.view,
                            span_v=None if span_v is None else span_v[i],
                            topology=ctx.topology,
                            image_shape=ctx.image_shape,
                        ),
                        ctx.face_curve,
                        ctx.view,
                    ).total
                    for i, u in enumerate(uv)
                ]
            )

        def one_by_one(uv=uv, span_v=span_v, ctx=ctx):
            return np.array(
                [
                    ctx.evaluate(u, None if span_v is None else span_v[i]).total
                    for i, u in enumerate(uv)
                ]
            )

        t_ref, ref = best_time(reference)
        t_one, one = best_time(one_by_one)
        t_new, new = best_time(lambda uv=uv, span_v=span_v, ctx=ctx: ctx.evaluate_batch(uv, span_v))
        assert np.array_equal(one, new)
        diff = np.max(np.abs(ref - new))
        t_skof, dec = best_time(lambda R=R, t=t, f=f: skof.outside_pixels(Cameras(R, t, f, centre)))
        uv_full = Cameras(R, t, f, centre).project(skull.vertices_mm)
        exact = skull_outside_pixels_batch(
            uv_full, topology=full.topology, mask_index=full.mask_index
        )
        t_full, _ = best_time(
            lambda R=R, t=t, f=f: skull_outside_pixels_batch(
                Cameras(R, t, f, centre).project(skull.vertices_mm),
                topology=full.topology,
                mask_index=full.mask_index,
            ),
            repeat=2,
        )
        rel = np.abs(dec - exact) / np.maximum(exact, 1)
        ms = 1e3 / len(R)
        print(
            f"{name:8s} {photo.view:13s} {label:4s} | P_pll oracle {t_ref * ms:6.3f} ms  "
            f"one by one {t_one * ms:6.3f} ms  batch {t_new * ms:6.3f} ms  "
            f"x{t_ref / max(t_new, 1e-9):4.1f}  max|diff| {diff:.3g}"
            f" | P_skof {len(skof.context.topology.faces)} faces {t_skof * ms:6.3f} ms, "
            f"{len(skull.faces)} faces {t_full * ms:6.3f} ms; |S\\F| median {np.median(exact):.0f}"
            f" px, term-full median {np.median(dec - exact):+.0f} px "
            f"(max {np.max(rel) * 100:.1f} %)"
        )


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv:
        root = argv[0]
    else:
        from lilium.synthetic.dataset import generate_dataset

        root = tempfile.mkdtemp(prefix="bench_terms_")
        generate_dataset(root, 2, 2, seed=0, experiments=("C",))
    for case in load_cases(root):
        bench_case(*case)


if __name__ == "__main__":
    main()
