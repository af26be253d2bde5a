"""Lilium and POSEST-SFO on skulls without the mandible, beside the same skulls complete (a
script, not a test).

It generates two Exp. C datasets from one seed (``lilium synth`` with ``--no-mandible-share 0``
and ``1``): the same subjects, faces and photos, once with complete skulls and once with every
skull's mandible removed (its landmarks absent). On every photo, against its own subject's
skull (positive pairs), it runs POSEST-SFO and Lilium ``skof+pll`` (P_pll is switched off where
it cannot apply: frontal photos of a skull without the mandible) and prints, per dataset, method
and view:

- ``ran``: SFOs that found a camera, of those run (a refused or failed SFO counts as not run);
- ``pll off``: Lilium SFOs that ran with P_pll switched off;
- BPE (mm) mean and median, over every true facial landmark (the chin included);
- ``impl %``: implausible overlays, any pixel of the skull *given to the method* (the full
  mesh, not P_skof's decimated one: :func:`lilium.evaluation.outside_face`) outside the face
  mask, % of the SFOs; ``impl+jaw %`` (skulls without the mandible): the same count for the
  complete skull of the subject under that camera, i.e. whether the true mandible would fall
  outside the face;
- ``f max``: the largest estimated focal (px), and the time per SFO (s, one core).

    python benchmarks/bench_incomplete.py --subjects 8 --jobs 2
    python benchmarks/bench_incomplete.py --data DIR   # reuse DIR/complete, DIR/no_mandible

The photos' focal lengths are below 6,000 px (the paper's ranges), so the focal cap of
docs/method/pose.md does not bind here; were it to, the ``ran`` and ``f max`` columns would show it.
"""

import argparse
import statistics
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.evaluation import outside_face, score
from lilium.io.jsonio import read_json
from lilium.io.truth import read_ground_truth
from lilium.methods import SfoOptions, run_sfo
from lilium.optimisation import DEOptions

#: The two datasets: folder name -> share of skulls without the mandible.
DATASETS = {"complete": 0.0, "no_mandible": 1.0}


def _one_thread():
    import os

    import cv2

    os.environ["OMP_NUM_THREADS"] = "1"
    cv2.setNumThreads(1)


def generate(root, subjects, photos, seed, workers):
    from lilium.synthetic.dataset import generate_dataset

    for name, share in DATASETS.items():
        if not (root / name / "dataset.json").is_file():
            t0 = time.perf_counter()
            generate_dataset(
                root / name,
                subjects,
                photos,
                seed=seed,
                experiments=("C",),
                workers=workers,
                no_mandible_share=share,
            )
            print(
                f"dataset {root / name}: {time.perf_counter() - t0:.0f} s to generate", flush=True
            )


def run_photo(task):
    """POSEST-SFO and Lilium on one Exp. C photo against its own subject's skull."""
    root, dataset, entry, axes_set, variant, de, seed = task
    base = root / dataset
    photo_dir = base / entry["paths"]["C"]
    subject_dir = base / "subjects" / entry["subject"]
    truth = read_ground_truth(photo_dir, subject_dir)
    skull = read_skull(subject_dir, axes_path=subject_dir / f"axes_C{axes_set}.json")
    complete = read_skull(root / "complete" / "subjects" / entry["subject"])
    photo = read_photo(photo_dir)
    runs = [
        ("posest-sfo", "posest-sfo", SfoOptions()),
        (f"lilium {variant}", "lilium", SfoOptions(variant, de)),
    ]
    rows = []
    for name, method, options in runs:
        t0 = time.perf_counter()
        try:
            result = run_sfo(method, skull, photo, options, seed)
            error = result.error
        except ValueError as exc:  # refused: counts as not run
            result, error = None, str(exc)
        seconds = time.perf_counter() - t0
        row = {
            "dataset": dataset,
            "method": name,
            "view": entry["view"].split("_")[0],
            "photo": entry["id"],
            "ran": bool(result),
            "error": error,
            "pll_off": bool(result is not None and "p_pll" in result.terms_off),
            "bpe": np.nan,
            "implausible": np.nan,
            "implausible_jaw": np.nan,
            "focal": np.nan,
            "seconds": seconds,
        }
        if result:
            row["bpe"] = score(result, truth).bpe_mm
            row["focal"] = result.camera.focal_px
            given = outside_face(result.camera, skull.vertices_mm, skull.faces, photo.face_mask)
            whole = outside_face(
                result.camera, complete.vertices_mm, complete.faces, photo.face_mask
            )
            row["implausible"] = float(given.outside_px > 0)
            row["implausible_jaw"] = float(whole.outside_px > 0)
        rows.append(row)
    return rows


def _mean(values):
    values = [v for v in values if np.isfinite(v)]
    return float(np.mean(values)) if values else np.nan


def table(rows):
    """The printed table (one line per dataset, method and view)."""
    head = (
        f"{'skulls':<12} {'method':<16} {'view':<8} {'ran':>6} {'pll off':>7} {'BPE mean':>8} "
        f"{'BPE med':>7} {'impl %':>6} {'impl+jaw %':>10} {'f max':>6} {'s/SFO':>6}"
    )
    lines = [head]
    for dataset in DATASETS:
        for method in dict.fromkeys(r["method"] for r in rows):
            for view in ("frontal", "lateral"):
                sel = [
                    r
                    for r in rows
                    if (r["dataset"], r["method"], r["view"]) == (dataset, method, view)
                ]
                if not sel:
                    continue
                ran = [r for r in sel if r["ran"]]
                bpe = [r["bpe"] for r in ran]
                pll = sum(r["pll_off"] for r in sel) if method.startswith("lilium") else "-"
                jaw = (
                    f"{100 * _mean([r['implausible_jaw'] for r in ran]):10.1f}"
                    if dataset != "complete"
                    else f"{'-':>10}"
                )
                focal = max((r["focal"] for r in ran), default=np.nan)
                lines.append(
                    f"{dataset:<12} {method:<16} {view:<8} {len(ran):>3}/{len(sel):<2} "
                    f"{pll!s:>7} {_mean(bpe):8.3f} {np.nanmedian(bpe) if bpe else np.nan:7.3f} "
                    f"{100 * _mean([r['implausible'] for r in ran]):6.1f} {jaw} {focal:6.0f} "
                    f"{statistics.median(r['seconds'] for r in sel):6.2f}"
                )
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", type=Path, default=Path("out/bench_incomplete"))
    p.add_argument("--subjects", type=int, default=8)
    p.add_argument("--photos", type=int, default=1, help="frontal (and lateral) photos each")
    p.add_argument("--seed", type=int, default=0, help="dataset seed")
    p.add_argument("--axes-set", type=int, default=1, help="Exp. C perturbed axes set (1-5)")
    p.add_argument("--variant", default="skof+pll")
    p.add_argument("--generations", type=int, default=DEOptions().max_generations)
    p.add_argument("--population", type=int, default=DEOptions().population_size)
    p.add_argument("--lilium-seed", type=int, default=0)
    p.add_argument("--jobs", type=int, default=1, help="photos run in parallel (one per core)")
    args = p.parse_args(argv)

    generate(args.data, args.subjects, args.photos, args.seed, max(1, args.jobs))
    de = DEOptions(args.population, max_generations=args.generations)
    tasks = [
        (args.data, name, entry, args.axes_set, args.variant, de, args.lilium_seed)
        for name in DATASETS
        for entry in read_json(args.data / name / "dataset.json")["photos"]
    ]
    rows = []
    with ProcessPoolExecutor(args.jobs, initializer=_one_thread) as pool:
        for k, photo_rows in enumerate(pool.map(run_photo, tasks)):
            for r in photo_rows:
                status = f"BPE {r['bpe']:6.2f} mm" if r["ran"] else f"NOT RUN ({r['error']})"
                print(
                    f"[{k + 1}/{len(tasks)}] {r['dataset']:<11} {r['photo']:>7} "
                    f"{r['method']:<16} {status}  pll off {r['pll_off']!s:5} "
                    f"{r['seconds']:6.2f} s",
                    flush=True,
                )
            rows += photo_rows
    print(
        f"\nExp. C positive pairs, {args.subjects} subjects x {2 * args.photos} photos, dataset "
        f"seed {args.seed}, axes set C{args.axes_set}; DE population {de.population_size}, "
        f"{de.max_generations} generations at most, Lilium seed {args.lilium_seed}"
    )
    print(table(rows))
    return rows


if __name__ == "__main__":
    main()
