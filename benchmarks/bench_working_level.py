"""Does the DE's working level change Lilium's results? Old path (every evaluation at full level)
against the working level, on identical seeds (issue 26).

For every Exp. C photo of a generated dataset (each on its own skull, axes set C1), Lilium
skof+pll at ``--generations`` x 30, for each seed of ``--seeds`` (the spread between seeds of
one path is the noise the difference between the paths is measured against), twice: with
``working_face_px=None`` (the full level, the path before issue 26) and with the default
working level. Optionally the same at real size
(``--faces``, ``--megapixels``: the skull subdivided, the photo resampled, :mod:`real_size`).
Prints per photo and in total: BPE (mm), the result's skull pixels outside the face mask (full
mesh, full resolution; "implausible" when > 0), fitness and CPU seconds. With ``--identify``
every photo also runs against every other skull of the dataset, and each path's photos rank
their skulls by the shipped calibration's log10 LR (rank-1, per-photo AUC).

    python benchmarks/bench_working_level.py --subjects 4 --photos 2 --generations 300
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import itertools  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from lilium.casework.build import read_photo, read_skull  # noqa: E402
from lilium.evaluation.scoring import score  # noqa: E402
from lilium.io.jsonio import read_json  # noqa: E402
from lilium.io.truth import read_ground_truth  # noqa: E402
from lilium.methods import SfoOptions, run_sfo  # noqa: E402

#: The data tools (benchmarks/datasets) this script imports: ``real_size``.
sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))
from real_size import photo_at, skull_at  # noqa: E402


def cases(root, faces, megapixels):
    """``(label, skull, photo, truth, camera_scale)`` of every Exp. C photo of a dataset."""
    index = read_json(root / "dataset.json")
    skulls = {}
    for entry in index["photos"]:
        subject = root / "subjects" / entry["subject"]
        if entry["subject"] not in skulls:
            skull = read_skull(subject, axes_path=subject / "axes_C1.json")
            skulls[entry["subject"]] = skull_at(skull, faces) if faces else skull
        photo_dir = root / entry["paths"]["C"]
        photo = read_photo(photo_dir)
        truth = read_ground_truth(photo_dir, subject)
        scale = 1.0
        if megapixels:
            width = photo.image_size_wh[0]
            photo = photo_at(photo, megapixels)
            scale = photo.image_size_wh[0] / width
        yield entry["id"], skulls[entry["subject"]], photo, truth, scale


def scaled_truth_bpe(result, truth, scale):
    """BPE (mm) of a result on a resampled photo: its camera brought back to the truth's pixels
    (BPE is in mm, but the truth's noise-free landmarks are in the original photo's pixels)."""
    if not result:
        return float("nan")
    camera = result.camera.cropped((0.0, 0.0), 1.0 / scale) if scale != 1.0 else result.camera
    return score(camera, truth).bpe_mm


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dataset", type=Path)
    p.add_argument("--subjects", type=int, default=4)
    p.add_argument("--photos", type=int, default=2)
    p.add_argument("--generations", type=int, default=300)
    p.add_argument("--faces", type=int, default=0, help="subdivide each skull to this many")
    p.add_argument("--megapixels", type=float, default=0.0, help="resample each photo")
    p.add_argument("--seeds", default="1", help="comma-separated DE seeds")
    p.add_argument("--identify", action="store_true", help="also rank every skull per photo")
    args = p.parse_args(argv)
    root = args.dataset
    if root is None or not (root / "dataset.json").exists():
        from lilium.synthetic.dataset import generate_dataset

        root = root or Path(tempfile.mkdtemp(prefix="lilium-working-"))
        generate_dataset(root, args.subjects, args.photos, seed=0, experiments=("C",), workers=1)
    base = SfoOptions("skof+pll").with_de(max_generations=args.generations, max_seconds=1e9)
    paths = {"full": SfoOptions(**{**base.__dict__, "working_face_px": None}), "working": base}
    rows = []
    print(
        f"{'photo':<10} {'path':<8} {'seed':>4} {'BPE mm':>7} {'outside px':>10} "
        f"{'fitness':>9} {'s':>6}"
    )
    seeds = [int(s) for s in args.seeds.split(",")]
    for label, skull, photo, truth, scale in cases(root, args.faces, args.megapixels):
        for (name, options), seed in itertools.product(paths.items(), seeds):
            t0 = time.process_time()
            result = run_sfo("lilium", skull, photo, options, seed)
            seconds = time.process_time() - t0
            bpe = scaled_truth_bpe(result, truth, scale)
            outside = score(result, skull=skull, face_mask=photo.face_mask).implausible
            out_px = outside.outside_px if outside is not None else -1
            rows.append((label, name, bpe, out_px, result.fitness, seconds, seed))
            print(
                f"{label:<10} {name:<8} {seed:4d} {bpe:7.3f} {out_px:10d} {result.fitness:9.2f} "
                f"{seconds:6.2f}",
                flush=True,
            )
    print(f"\n{len(rows) // 2 // len(seeds)} photos, {args.generations} generations, seeds {seeds}")
    for name in paths:
        mine = [r for r in rows if r[1] == name]
        bpe = np.array([r[2] for r in mine])
        implausible = sum(r[3] > 0 for r in mine)
        print(
            f"{name:<8} BPE mean {np.nanmean(bpe):.3f} median {np.nanmedian(bpe):.3f} mm; "
            f"implausible {implausible}/{len(mine)}; CPU {sum(r[5] for r in mine):.1f} s"
        )
        for seed in seeds:
            bpe = np.array([r[2] for r in mine if r[6] == seed])
            print(f"  seed {seed}: BPE mean {np.nanmean(bpe):.3f} mm")
    if args.identify:
        identify_paths(root, paths, seeds[0])


def identify_paths(root, paths, seed):
    """Each path's identification: every photo against every skull, ranked by log10 LR."""
    from lilium.casework.identify import decide
    from lilium.io.calibration import Calibrations

    calibrations = Calibrations()
    photos = [(label, photo, truth) for label, _, photo, truth, _ in cases(root, 0, 0.0)]
    index = read_json(root / "dataset.json")
    subject_of = {e["id"]: e["subject"] for e in index["photos"]}
    skulls = {}
    for sid in sorted(set(subject_of.values())):
        folder = root / "subjects" / sid
        skulls[sid] = read_skull(folder, axes_path=folder / "axes_C1.json")
    print(f"\nidentification, {len(photos)} photos x {len(skulls)} skulls, seed {seed}")
    for name, options in paths.items():
        ranks, aucs = [], []
        for label, photo, _ in photos:
            lrs = {}
            for sid, skull in skulls.items():
                result = run_sfo("lilium", skull, photo, options, seed)
                record = decide(skull, [photo], [result], calibrations).to_dict() if result else {}
                lr = record.get("log10_lr")
                lrs[sid] = -np.inf if lr is None else lr
            true = lrs[subject_of[label]]
            others = np.array([v for k, v in lrs.items() if k != subject_of[label]])
            ranks.append(1 + int(np.sum(others > true)))
            aucs.append(float(np.mean((others < true) + 0.5 * (others == true))))
        print(f"{name:<8} rank-1 {np.mean(np.array(ranks) == 1):.2f}, mean rank "
              f"{np.mean(ranks):.2f}, AUC {np.mean(aucs):.3f}", flush=True)


if __name__ == "__main__":
    main()
