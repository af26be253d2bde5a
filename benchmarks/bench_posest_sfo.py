"""POSEST-SFO over a generated dataset: BPE of positive pairs, mean rank, time (a script).

For each experiment (A, B, C; for C the first perturbed axes set) every photo is superimposed
with every skull; the true skull's rank among them (1 = best, ties share the mean rank) and,
for positive pairs, the back-projection error (mm) are reported frontal and lateral apart, with
the BPE of the ground-truth camera as a check (0 by construction).

    lilium synth --out dataset --subjects 17 --photos 30
    python benchmarks/bench_posest_sfo.py dataset
"""

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from lilium.evaluation import rank_of_true, score
from lilium.io.case import read_photo, read_skull
from lilium.io.jsonio import read_json
from lilium.io.truth import read_ground_truth
from lilium.methods.posest_sfo import posest_sfo


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dataset", type=Path)
    p.add_argument("--experiments", default="A,B,C")
    p.add_argument("--limit", type=int, help="use only N photos (spread over the dataset)")
    args = p.parse_args(argv)
    root = args.dataset
    index = read_json(root / "dataset.json")
    ids = [s["id"] for s in index["subjects"]]
    photos = index["photos"]
    if args.limit and args.limit < len(photos):
        photos = [
            photos[i] for i in np.linspace(0, len(photos) - 1, args.limit).round().astype(int)
        ]
    print(f"{len(ids)} subjects, {len(photos)} photos per experiment")
    print(
        f"{'exp':<4}{'view':<9}{'photos':>7}{'mean rank':>10}{'BPE mean':>10}{'BPE med':>9}"
        f"{'GT BPE max':>11}{'failed':>7}{'ms/SFO med':>11}"
    )
    for exp in args.experiments.split(","):
        axes = "axes_C1.json" if exp == "C" else "soft_tissue_axes.json"
        skulls = [
            read_skull(root / "subjects" / i, axes_path=root / "subjects" / i / axes) for i in ids
        ]
        stats = {"frontal": [], "lateral": []}
        times = []
        for entry in photos:
            photo_dir = root / entry["paths"][exp]
            photo = read_photo(photo_dir, load_image=False)
            truth = read_ground_truth(photo_dir, root / "subjects" / entry["subject"])
            scores = []
            for skull in skulls:
                t0 = time.perf_counter()
                result = posest_sfo(skull, photo)
                times.append(time.perf_counter() - t0)
                scores.append(result.fitness if result else np.nan)
                if skull.id == truth.subject:
                    bpe = score(result, truth).bpe_mm
                    gt_bpe = score(truth.camera, truth).bpe_mm
            rank = rank_of_true(scores, ids.index(truth.subject))
            stats[entry["view"].split("_")[0]].append((rank, bpe, gt_bpe))
        for view, rows in stats.items():
            if not rows:
                continue
            r = np.array(rows)
            print(
                f"{exp:<4}{view:<9}{len(r):>7}{r[:, 0].mean():>10.3f}{np.nanmean(r[:, 1]):>10.3f}"
                f"{np.nanmedian(r[:, 1]):>9.3f}{r[:, 2].max():>11.2e}"
                f"{int(np.isnan(r[:, 1]).sum()):>7}{1e3 * statistics.median(times):>11.2f}"
            )


if __name__ == "__main__":
    main()
