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

from lilium.evaluation.metrics import back_projection_error_from_dicts, rank_of_true
from lilium.geometry.camera import Camera
from lilium.io.case import read_photo, read_skull
from lilium.io.jsonio import read_json
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
    facial = {
        i: read_json(root / "subjects" / i / "facial_landmarks.json")["landmarks"] for i in ids
    }
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
            truth = read_json(photo_dir / "photo.json")["ground_truth"]
            scores = []
            for skull in skulls:
                t0 = time.perf_counter()
                result = posest_sfo(skull, photo)
                times.append(time.perf_counter() - t0)
                scores.append(result.fitness if result else np.nan)
                if skull.id == truth["subject"]:
                    bpe = (
                        back_projection_error_from_dicts(
                            facial[skull.id],
                            truth["landmarks_noise_free"],
                            result.camera,
                        )
                        if result
                        else np.nan
                    )
                    gt_bpe = back_projection_error_from_dicts(
                        facial[skull.id],
                        truth["landmarks_noise_free"],
                        Camera.from_dict(truth),
                    )
            rank = rank_of_true(scores, ids.index(truth["subject"]))
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
