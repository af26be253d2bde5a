"""Lilium vs POSEST-SFO on generated Exp. C photos, positive pairs (a script, not a test).

For every photo of a generated dataset's Exp. C (noisy landmarks, perturbed soft-tissue axes) it
runs, on its own subject's skull, POSEST-SFO and each Lilium variant one after the other in this
process (one core), and prints per method and view: the back-projection error (BPE, mm), the share
of implausible overlays (any skull pixel outside the face mask), and the time per SFO.

    python benchmarks/bench_lilium.py --subjects 4 --photos 2
    python benchmarks/bench_lilium.py --dataset DIR   # reuse a dataset from `lilium synth`
"""

import argparse
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.evaluation import outside_face, score
from lilium.io.jsonio import read_json
from lilium.io.truth import read_ground_truth
from lilium.methods import METHODS, SfoOptions, run_sfo
from lilium.optimisation import DEOptions

VARIANTS = METHODS["lilium"].variants


def evaluate(result, skull, photo, truth):
    """BPE (mm) and implausibility of one SFO result."""
    if not result:
        return np.nan, True, np.nan
    bpe = score(result, truth).bpe_mm
    imp = outside_face(result.camera, skull.vertices_mm, skull.faces, photo.face_mask)
    return bpe, imp.outside_px > 0, imp.percent_outside


def _one_thread():
    import os

    import cv2

    os.environ["OMP_NUM_THREADS"] = "1"
    cv2.setNumThreads(1)


def run_photo(task):
    """POSEST-SFO and each Lilium variant on one Exp. C photo and its own skull."""
    root, entry, axes_set, variants, de, seed = task
    photo_dir = root / entry["paths"]["C"]
    subject_dir = root / "subjects" / entry["subject"]
    truth = read_ground_truth(photo_dir, subject_dir)
    skull = read_skull(subject_dir, axes_path=subject_dir / f"axes_C{axes_set}.json")
    photo = read_photo(photo_dir)
    # POSEST-SFO is deterministic: run once, with the first seed.
    runs = [("posest-sfo", lambda: run_sfo("posest-sfo", skull, photo))] if seed == 0 else []
    runs += [
        (f"lilium {v}", lambda v=v: run_sfo("lilium", skull, photo, SfoOptions(v, de), seed))
        for v in variants
    ]
    rows = []
    for name, run in runs:
        t0 = time.perf_counter()
        result = run()
        seconds = time.perf_counter() - t0
        bpe, implausible, pct = evaluate(result, skull, photo, truth)
        rows.append(
            (name, entry["view"].split("_")[0], bpe, implausible, pct, seconds, entry["id"])
        )
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dataset", type=Path, help="existing dataset folder (default: generate)")
    p.add_argument("--subjects", type=int, default=4)
    p.add_argument("--photos", type=int, default=2, help="frontal (and lateral) photos each")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--axes-set", type=int, default=1, help="Exp. C perturbed axes set (1-5)")
    p.add_argument("--variants", default=",".join(VARIANTS))
    p.add_argument("--generations", type=int, default=DEOptions().max_generations)
    p.add_argument("--population", type=int, default=DEOptions().population_size)
    p.add_argument("--limit", type=int, help="use only N photos (spread over the dataset)")
    p.add_argument("--jobs", type=int, default=1, help="photos run in parallel (one per core)")
    p.add_argument("--seeds", type=int, default=1, help="Lilium runs per photo (seeds 0..N-1)")
    args = p.parse_args(argv)

    root = args.dataset
    if root is None:
        from lilium.synthetic.dataset import generate_dataset

        root = Path(tempfile.mkdtemp(prefix="lilium-bench-"))
        t0 = time.perf_counter()
        generate_dataset(root, args.subjects, args.photos, seed=args.seed, experiments=("C",))
        print(f"dataset: {root} ({time.perf_counter() - t0:.0f} s to generate)")
    index = read_json(root / "dataset.json")
    photos = index["photos"]
    if args.limit and args.limit < len(photos):
        pick = np.linspace(0, len(photos) - 1, args.limit).round().astype(int)
        photos = [photos[i] for i in pick]
    variants = [v for v in args.variants.split(",") if v]
    de = DEOptions(args.population, max_generations=args.generations)
    tasks = [
        (root, entry, args.axes_set, variants, de, seed)
        for seed in range(args.seeds)
        for entry in photos
    ]
    rows = []
    # One photo per process; each SFO runs single-threaded, so its time is one core's.
    with ProcessPoolExecutor(args.jobs, initializer=_one_thread) as pool:
        for k, photo_rows in enumerate(pool.map(run_photo, tasks)):
            for row in photo_rows:
                name, view, bpe, implausible, _, seconds, pid = row
                print(
                    f"[{k + 1}/{len(tasks)}] {pid:>8} {name:<18} BPE {bpe:6.2f} mm  "
                    f"implausible {str(implausible):5}  {seconds:7.2f} s",
                    flush=True,
                )
            rows += [r[:6] for r in photo_rows]

    print(
        f"\nExp. C positive pairs: {len(photos)} photos, DE population {de.population_size}, "
        f"F {de.F}, CR {de.CR}, {de.max_generations} generations at most, axes set "
        f"C{args.axes_set}, {args.seeds} Lilium run(s) per photo"
    )
    print(
        f"{'method':<18} {'view':<8} {'n':>3} {'BPE mean':>9} {'BPE med':>8} "
        f"{'implaus %':>9} {'s/SFO med':>9} {'s/SFO mean':>10}"
    )
    for name in dict.fromkeys(r[0] for r in rows):
        for view in ("frontal", "lateral"):
            sel = [r for r in rows if r[0] == name and r[1] == view]
            if not sel:
                continue
            bpe = [r[2] for r in sel]
            sec = [r[5] for r in sel]
            print(
                f"{name:<18} {view:<8} {len(sel):>3} {np.nanmean(bpe):9.3f} "
                f"{np.nanmedian(bpe):8.3f} {100 * np.mean([r[3] for r in sel]):9.1f} "
                f"{statistics.median(sec):9.3f} {np.mean(sec):10.3f}"
            )
    return rows


if __name__ == "__main__":
    main()
