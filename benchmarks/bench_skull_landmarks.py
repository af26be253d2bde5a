"""Automatic cranial landmarks (``lilium skull``, :mod:`lilium.skull`) against known placements.

Skulls:

- generated: ``--subjects`` skulls from each of two dataset seeds, with and without the
  mandible (the generator's own landmarks are the truth: :mod:`lilium.synthetic.anatomy.landmarks`);
- real heads (``benchmarks/datasets/headsq_case.py``, ``cranium_case.py``; built under
  ``--real`` when missing, left out without their CT): headsq with (``hq``) and without
  (``hq_nm``) its mandible, Cranium (``cr``); the truth is the written hand placement rules of
  ``benchmarks/datasets/headsq_landmarks.py`` and ``cranium_landmarks.py``.

Each skull three times: as it is (the canonical skull frame), after a random rigid motion, and
after that motion plus quadric decimation to ``min(100k, F / 2)`` faces (the generated skulls
and headsq have fewer than 100k faces). Per landmark and overall: median, 90th percentile and
worst distance (mm) to the truth, and the share placed as ``located``; overall also without
ectoconchion and dacryon, whose rules take the craniometric definitions the hand placements
follow and not the generator's (:data:`lilium.skull.rules.CRANIOMETRIC`). With ``--draws N``,
each real head is also placed with ``N`` seeds of the fit's random draws (``rng`` of
:func:`lilium.skull.locate_skull_landmarks`): the range of its median and worst error over the
draws, which one seed's table does not show. The timing: a
600k-face skull (``benchmarks/datasets/real_size.py``: a generated skull decimated and
subdivided) with the per-stage profile, on one core (``OMP_NUM_THREADS=1`` etc. are set here).

Run::

    PYTHONPATH=src python benchmarks/bench_skull_landmarks.py [--subjects 6] [--real DIR]
        [--draws 20]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from lilium.skull.rules import CRANIOMETRIC  # noqa: E402
from lilium.softtissue.landmarks import base_name  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

#: Dataset seeds of the generated skulls.
SEEDS = (0, 1)
#: Real heads: dataset module -> subject ids.
REAL = {"headsq_case": ("hq", "hq_nm"), "cranium_case": ("cr",)}
DECIMATED_FACES = 100_000
SPEED_FACES = 600_000


def generated_skull(seed, index, mandible):
    """Skull mesh and true landmarks of generated subject ``index`` of dataset ``seed``
    (:func:`lilium.synthetic.subjects.make_skull`)."""
    from lilium.synthetic.subjects import make_skull

    return make_skull(np.random.SeedSequence(seed).spawn(index + 1)[index], mandible)


def real_skulls(work):
    """``{subject id: (vertices, faces, truth)}`` of the real heads whose CT is here."""
    import importlib

    from lilium.io.case import parse_cranial_landmarks
    from lilium.io.mesh import read_mesh

    out = {}
    for module, ids in REAL.items():
        head = module.removesuffix("_case")
        try:
            root = importlib.import_module(module).ensure_dataset(Path(work) / head, n_photos=1)
        except (ImportError, OSError, ValueError) as exc:
            print(f"{head}: left out ({exc})")
            continue
        if root is None:
            print(f"{head}: left out (no CT)")
            continue
        for sid in ids:
            folder = Path(root) / "subjects" / sid
            v, f = read_mesh(folder / "skull.ply")
            out[sid] = (v, f, parse_cranial_landmarks(folder / "cranial_landmarks.json"))
    return out


def random_motion(rng):
    """A random rotation ``(3, 3)`` and a translation ``(3,)`` of up to 200 mm."""
    from scipy.spatial.transform import Rotation

    return Rotation.random(random_state=rng).as_matrix(), rng.uniform(-200, 200, 3)


def variants(v, f, truth, rng):
    """``{variant: (vertices, faces, truth)}``: canonical, moved, moved + decimated."""
    from lilium.geometry.mesh import decimate

    R, t = random_motion(rng)
    moved = v @ R.T + t
    moved_truth = {n: R @ p + t for n, p in truth.items()}
    dv, df = decimate(moved, f, min(DECIMATED_FACES, len(f) // 2))
    return {
        "canonical": (v, f, truth),
        "moved": (moved, f, moved_truth),
        "decimated": (dv, df, moved_truth),
    }


def score(result, truth):
    """``{name: (error_mm or nan, quality)}`` over the truth's landmarks; and the names
    placed that the truth lacks."""
    out = {}
    for name, p in truth.items():
        if name in result.landmarks:
            out[name] = (float(np.linalg.norm(result.landmarks[name] - p)), result.quality[name])
        else:
            out[name] = (np.nan, "missing")
    extra = sorted(set(result.landmarks) - set(truth))
    return out, extra


def run(skulls, rng, log=print):
    """Scores of every skull and variant: list of dicts."""
    from lilium.skull import locate_skull_landmarks

    rows = []
    for sid, (v, f, truth) in skulls.items():
        for variant, (vv, ff, tt) in variants(v, f, truth, rng).items():
            t0 = time.perf_counter()
            result = locate_skull_landmarks(vv, ff, source=sid)
            seconds = time.perf_counter() - t0
            errors, extra = score(result, tt)
            rows.append(
                {"skull": sid, "variant": variant, "errors": errors, "extra": extra,
                 "mandible": result.mandible, "seconds": seconds}
            )  # fmt: skip
            e = np.array([x for x, _ in errors.values()])
            log(
                f"{sid:10s} {variant:10s} mandible {result.mandible!s:5s} median "
                f"{np.nanmedian(e):5.2f} p90 {np.nanpercentile(e, 90):5.2f} worst "
                f"{np.nanmax(e):5.2f} missing {int(np.isnan(e).sum())} extra {extra} "
                f"{seconds:.1f}s"
            )
    return rows


def draws(skulls, n, log=print):
    """Each skull placed with ``n`` seeds of the fit: the range of its median and worst error
    (mm) over the seeds, and how many refused it as no skull."""
    from lilium.skull import locate_skull_landmarks

    log(f"\nreal heads, {n} draws of the fit: median error min-max, worst landmark min-max (mm)")
    for sid, (v, f, truth) in skulls.items():
        medians, worst, refused = [], [], 0
        for seed in range(n):
            try:
                errors, _ = score(locate_skull_landmarks(v, f, rng=seed), truth)
            except ValueError:  # "does not look like a skull"
                refused += 1
                continue
            e = np.array([x for x, _ in errors.values()])
            medians.append(np.nanmedian(e))
            worst.append(np.nanmax(e))
        log(f"{sid:10s} median {min(medians):5.2f}-{max(medians):5.2f}  worst {min(worst):5.1f}-"
            f"{max(worst):5.1f}  refused as no skull {refused} of {n}")  # fmt: skip


def table(rows, title, file=sys.stdout):
    """Per-landmark and overall median / p90 / worst (mm) and located share."""
    names = sorted({n for r in rows for n in r["errors"]})
    print(f"\n{title}", file=file)
    print(f"{'landmark':28s} {'n':>3s} {'median':>7s} {'p90':>7s} {'worst':>7s} {'located':>8s}"
          " missing", file=file)  # fmt: skip
    for name in names + ["ALL", "ALL BUT " + "/".join(CRANIOMETRIC)]:
        if name == "ALL":
            pairs = [x for r in rows for x in r["errors"].values()]
        elif name.startswith("ALL BUT"):  # the rules that are the generator's own
            pairs = [x for r in rows for n, x in r["errors"].items()
                     if base_name(n) not in CRANIOMETRIC]  # fmt: skip
        else:
            pairs = [r["errors"][name] for r in rows if name in r["errors"]]
        e = np.array([x for x, _ in pairs])
        ok = e[np.isfinite(e)]
        loc = np.mean([q == "located" for _, q in pairs])
        stats = (np.median(ok), np.percentile(ok, 90), ok.max()) if len(ok) else (np.nan,) * 3
        print(
            f"{name:28s} {len(e):3d} {stats[0]:7.2f} {stats[1]:7.2f} {stats[2]:7.2f} "
            f"{loc:8.0%} {int(np.isnan(e).sum())}",
            file=file,
        )


def speed(rng, log=print):
    """Seconds per stage for a 600k-face skull (a generated one, decimated and subdivided)."""
    import trimesh

    from lilium.geometry.mesh import decimate
    from lilium.skull import locate_skull_landmarks

    v, f, _ = generated_skull(SEEDS[0], 0, True)
    v, f = decimate(v, f, SPEED_FACES // 16)
    for _ in range(2):
        v, f = trimesh.remesh.subdivide(v, f)
    R, t = random_motion(rng)
    v = v @ R.T + t
    t0 = time.perf_counter()
    result = locate_skull_landmarks(v, f)
    total = time.perf_counter() - t0
    stages = ", ".join(f"{k} {s:.2f}" for k, s in result.profile_s.items())
    log(f"speed: {len(f)} faces, {total:.1f} s on one core ({stages})")
    return total, result.profile_s


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subjects", type=int, default=6, help="per seed and mandible variant")
    parser.add_argument("--real", default="real-heads", help="folder of the real-head datasets")
    parser.add_argument("--no-generated", action="store_true")
    parser.add_argument("--no-real", action="store_true")
    parser.add_argument("--no-speed", action="store_true")
    parser.add_argument("--seed", type=int, default=0, help="random motions")
    parser.add_argument("--draws", type=int, default=0, help="seeds of the fit per real head")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    if not args.no_generated:
        skulls = {}
        for seed in SEEDS:
            for i in range(args.subjects):
                for mandible in (True, False):
                    sid = f"g{seed}_{i:02d}{'' if mandible else '_nm'}"
                    skulls[sid] = generated_skull(seed, i, mandible)
        rows = run(skulls, rng)
        for variant in ("canonical", "moved", "decimated"):
            table([r for r in rows if r["variant"] == variant], f"generated, {variant}")
    if not args.no_real:
        rows = run(real_skulls(args.real), rng)
        for variant in ("canonical", "moved", "decimated"):
            table([r for r in rows if r["variant"] == variant], f"real heads, {variant}")
        if args.draws:
            draws(real_skulls(args.real), args.draws)
    if not args.no_speed:
        speed(rng)
    return 0


if __name__ == "__main__":
    sys.exit(main())
