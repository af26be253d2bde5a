"""Lilium and POSEST-SFO on frontal photos of skulls without the mandible, with priors (a
script, not a test).

Issue 25, item 3: on a real frontal photo of a mandible-less skull (13 landmark pairs, focal,
distance and head priors) every Lilium evaluation ran off towards an infinite focal length
while POSEST-SFO found a camera. This script generates, per dataset seed, an Exp. C dataset
whose skulls all lack the mandible (``lilium synth --no-mandible-share 1``: the priors of the
paper's protocol, focal +-5 %, distance +-10 %, head within 10 degrees), and on every frontal
photo against its own subject's skull (positive pairs, axes set C1) runs POSEST-SFO and Lilium,
then prints per method and seed:

- ``fail``: SFOs without a camera (Lilium must have 0 wherever POSEST-SFO has a camera);
- BPE (mm) mean and median over the SFOs with a camera;
- ``no cam``: Lilium runs in which some evaluation of the whole population found no valid
  camera and no member had one to lend (the trap of issue 25: before the fix every later warm
  start ran off too); each member then takes its own POSEST (absent before the fix);
- ``rescued``: Lilium runs whose initial population still had no valid camera and got
  POSEST-SFO's soft tissue and camera (absent before the fix);
- ``flat``: median RMS distance (mm) of the used cranial landmarks from their best-fitting
  plane (how little depth the landmarks show);
- the time per SFO (s).

``--complete`` runs the same photos against the complete skulls of the same seeds too (the
same subjects and photos, mandible kept), to show that the fix costs nothing there.
``--unmark`` leaves named landmarks unmarked on every photo (``frontotemporale_l,
frontotemporale_r`` gives the 13 pairs of the real case).

    python benchmarks/bench_no_mandible.py                       # 3 seeds x 16 photos, DE 30 x 750
    python benchmarks/bench_no_mandible.py --generations 50 --seeds 0
    python benchmarks/bench_no_mandible.py --complete --unmark frontotemporale_l,frontotemporale_r
"""

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.evaluation import score
from lilium.io.jsonio import read_json
from lilium.io.truth import read_ground_truth
from lilium.methods import SfoOptions, run_sfo
from lilium.methods.pairs import correspondences
from lilium.optimisation import DEOptions

#: Dataset kinds: folder name -> share of skulls without the mandible.
KINDS = {"no_mandible": 1.0, "complete": 0.0}


def generate(folder, subjects, photos, seed, share):
    from lilium.synthetic.dataset import generate_dataset

    if not (folder / "dataset.json").is_file():
        t0 = time.perf_counter()
        generate_dataset(
            folder,
            subjects,
            photos,
            seed=seed,
            experiments=("C",),
            workers=1,
            no_mandible_share=share,
        )
        print(f"dataset {folder}: {time.perf_counter() - t0:.0f} s to generate", flush=True)


def flatness_mm(skull, photo):
    """RMS distance (mm) of the cranial landmarks paired with the photo from their best plane."""
    points = correspondences(skull, photo).cranial_mm
    points = points - points.mean(axis=0)
    return float(np.linalg.svd(points, compute_uv=False)[2] / np.sqrt(len(points)))


def run_photo(folder, entry, options, seed, unmark):
    photo_dir = folder / entry["paths"]["C"]
    subject_dir = folder / "subjects" / entry["subject"]
    truth = read_ground_truth(photo_dir, subject_dir)
    skull = read_skull(subject_dir, axes_path=subject_dir / "axes_C1.json")
    photo = read_photo(photo_dir)
    if unmark:
        kept = {k: v for k, v in photo.landmarks_uv.items() if k not in unmark}
        photo = replace(photo, landmarks_uv=kept)
    rows = []
    for method in ("posest-sfo", "lilium"):
        t0 = time.perf_counter()
        result = run_sfo(method, skull, photo, options, seed)
        row = {
            "method": method,
            "photo": entry["id"],
            "ran": bool(result),
            "error": result.error,
            "bpe": score(result, truth).bpe_mm if result else np.nan,
            "focal": result.camera.focal_px if result else np.nan,
            "seconds": time.perf_counter() - t0,
            "rescued": bool(result.extra.get("rescued")) if result.extra else False,
            "no_camera": bool(result.extra.get("no_camera_evaluations")) if result.extra else False,
            "flat": flatness_mm(skull, photo),
        }
        rows.append(row)
    return rows


def table(rows):
    head = (
        f"{'skulls':<12} {'method':<11} {'seed':>4} {'fail':>7} {'BPE mean':>8} {'BPE med':>7} "
        f"{'no cam':>6} {'rescued':>7} {'flat':>5} {'s/SFO':>6}"
    )
    lines = [head]
    keys = dict.fromkeys((r["kind"], r["method"], r["seed"]) for r in rows)
    for kind, method, seed in list(keys) + [
        (k, m, "all") for k, m in dict.fromkeys((r["kind"], r["method"]) for r in rows)
    ]:
        sel = [
            r
            for r in rows
            if (r["kind"], r["method"]) == (kind, method) and seed in ("all", r["seed"])
        ]
        bpe = [r["bpe"] for r in sel if r["ran"]]
        lilium = method == "lilium"
        no_cam = f"{sum(r['no_camera'] for r in sel):6d}" if lilium else f"{'-':>6}"
        rescued = f"{sum(r['rescued'] for r in sel):7d}" if lilium else f"{'-':>7}"
        lines.append(
            f"{kind:<12} {method:<11} {seed!s:>4} {len(sel) - len(bpe):>3}/{len(sel):<3} "
            f"{np.mean(bpe) if bpe else np.nan:8.3f} {np.median(bpe) if bpe else np.nan:7.3f} "
            f"{no_cam} {rescued} {statistics.median(r['flat'] for r in sel):5.1f} "
            f"{statistics.median(r['seconds'] for r in sel):6.2f}"
        )
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", type=Path, default=Path("out/bench_no_mandible"))
    p.add_argument("--seeds", default="0,1,2", help="dataset seeds (Lilium runs with the same)")
    p.add_argument("--subjects", type=int, default=8)
    p.add_argument("--photos", type=int, default=2, help="frontal photos per subject")
    p.add_argument("--variant", default="skof+pll")
    p.add_argument("--generations", type=int, default=DEOptions().max_generations)
    p.add_argument("--population", type=int, default=DEOptions().population_size)
    p.add_argument("--complete", action="store_true", help="also the complete skulls")
    p.add_argument("--unmark", default="", help="comma-separated landmarks left unmarked")
    args = p.parse_args(argv)

    options = SfoOptions(args.variant, DEOptions(args.population, max_generations=args.generations))
    unmark = {n for n in args.unmark.split(",") if n}
    kinds = [k for k in KINDS if k == "no_mandible" or args.complete]
    rows = []
    for seed in (int(s) for s in args.seeds.split(",")):
        for kind in kinds:
            folder = args.data / f"seed{seed}" / kind
            generate(folder, args.subjects, args.photos, seed, KINDS[kind])
            frontal = [
                e for e in read_json(folder / "dataset.json")["photos"] if e["view"] == "frontal"
            ]
            for entry in frontal:
                for r in run_photo(folder, entry, options, seed, unmark):
                    rows.append({**r, "kind": kind, "seed": seed})
                    status = f"BPE {r['bpe']:6.2f} mm" if r["ran"] else f"FAILED ({r['error']})"
                    print(
                        f"seed {seed} {kind:<11} {r['photo']:>7} {r['method']:<10} {status} "
                        f"f {r['focal']:7.0f} px  no cam {r['no_camera']!s:5} "
                        f"rescued {r['rescued']!s:5} {r['seconds']:6.2f} s",
                        flush=True,
                    )
    print(
        f"\nExp. C frontal positive pairs with priors, {args.subjects} subjects x {args.photos} "
        f"photos per seed, Lilium {args.variant}, DE {args.population} x {args.generations}"
        + (f", unmarked: {', '.join(sorted(unmark))}" if unmark else "")
    )
    print(table(rows))


if __name__ == "__main__":
    main()
