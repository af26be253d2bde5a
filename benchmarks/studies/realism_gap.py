"""The realism gap of the identification's photo-level terms: real photos against generated ones.

Each photo of a dataset is taken with its own skull under the photo's true camera (no SFO: what
is measured is the landmarks, not an optimiser), and this prints, per view and population:

1. the photo- and skull-level terms (``cohort_mean``, ``cohort_sd``, ``skull_mean``,
   ``skull_sd``), the own skull's ``landmark_chi2`` and ``landmark_refit`` (camera refitted to
   the landmarks alone), as median and range;
2. per landmark, the misfit (``r^T S^-1 r`` per coordinate, the marginal model of
   :mod:`lilium.identification.terms`) of the cohort's skulls, each under its own refitted
   camera (:func:`lilium.identification.cohort.cohort_views`), and of the own skull under its
   refitted camera: the landmarks that make a real photo fit the generated cohort worse.

Run::

    PYTHONPATH=src python benchmarks/studies/realism_gap.py --generated DATASET [--real DATASET ...]

``--generated`` is a generated dataset folder (``lilium synth`` or ``bench_identification``'s
``OUT/seed-K/dataset``); ``--real`` the real-anatomy datasets (default: the headsq case,
``benchmarks/datasets/headsq_case.py``, built under ``--work`` when the CT is there, and the Cranium
case, ``benchmarks/datasets/cranium_case.py``, when its file is there).
"""

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.geometry.camera import Camera
from lilium.identification.cohort import (
    centred_cohort_terms,
    cohort_terms,
    cohort_views,
    refit_views,
    skull_cohort_terms,
)
from lilium.identification.terms import landmark_blocks, landmark_chi2, make_view
from lilium.io.calibration import shipped_cohort
from lilium.io.jsonio import read_json
from lilium.methods.pairs import correspondences

#: The data tools (benchmarks/datasets) this study imports: ``headsq_case``, ``cranium_case``.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "datasets"))


def true_pairs(root, experiment="C", axes_set=1):
    """``(photo_id, view, skull, photo, camera)`` of every photo of a dataset with its own
    skull (soft-tissue axes set ``axes_set`` of Exp. C) and its true camera."""
    root = Path(root)
    index = read_json(root / "dataset.json")
    entries = {s["id"]: s for s in index["subjects"]}
    for entry in index["photos"]:
        subject = entries[entry["subject"]]
        folder = root / subject["path"]
        axes = folder / subject["axes_C"][axes_set - 1] if experiment == "C" else None
        skull = read_skull(folder, axes_path=axes)
        photo_dir = root / entry["paths"][experiment]
        photo = read_photo(photo_dir, load_image=False)
        truth = read_json(photo_dir / "photo.json")["ground_truth"]
        skull2cam = np.asarray(truth["skull2cam"])
        camera = Camera.from_rt(skull2cam[:3, :3], skull2cam[:3, 3], truth["focal_px"],
                                truth["principal_point_px"])
        view = "frontal" if entry["view"] == "frontal" else "lateral"
        yield entry["id"], view, skull, photo, camera


def misfits(views):
    """``{cranial name: misfit per coordinate}`` of :func:`landmark_blocks` (empty when a
    landmark lies behind the camera)."""
    blocks = landmark_blocks(views)
    if blocks is None:
        return {}
    names, quad, _, coords = blocks
    return dict(zip(names, quad / coords, strict=True))


def measure(root, cohort, experiment="C"):
    """Per photo: its terms and per-landmark misfits (module docstring)."""
    rows = []
    for photo_id, view, skull, photo, camera in true_pairs(root, experiment):
        corr = correspondences(skull, photo)
        views = [make_view(camera, corr, photo.landmark_sources)]
        members = cohort_views(views, cohort)
        per_member = defaultdict(list)
        for member in members:
            for name, value in misfits(member).items():
                per_member[name].append(value)
        c_mean, c_sd = cohort_terms(views, cohort)
        s_mean, s_sd = skull_cohort_terms(views, cohort)
        refit = refit_views(views)
        n_mean, n_sd = centred_cohort_terms(views, cohort)
        chi2 = landmark_chi2(views)[0]
        rows.append({
            "photo": photo_id,
            "view": view,
            "terms": {
                "cohort_mean": c_mean, "cohort_sd": c_sd, "skull_mean": s_mean,
                "skull_sd": s_sd, "centred_mean": n_mean, "centred_sd": n_sd,
                "centred_z": (np.log(chi2) - n_mean) / n_sd if n_mean is not None else None,
                "landmark_chi2": chi2,
                "landmark_refit": landmark_chi2(refit)[0],
            },
            "cohort_misfit": {n: float(np.median(v)) for n, v in per_member.items()},
            "own_misfit": misfits(refit),
        })
    return rows


def _summary(values):
    values = np.asarray([v for v in values if v is not None and np.isfinite(v)], float)
    if not len(values):
        return "-"
    return f"{np.median(values):.2f} [{values.min():.2f}, {values.max():.2f}]"


def print_tables(populations, file=sys.stdout):
    """The two tables of the module docstring for ``{population name: rows}``."""
    names = list(populations)
    for view in ("frontal", "lateral"):
        print(f"\n### {view}: terms (median [min, max] over the photos)\n", file=file)
        print("| term | " + " | ".join(names) + " |", file=file)
        print("|---|" + "---|" * len(names), file=file)
        terms = next(iter(populations.values()))[0]["terms"]
        for term in terms:
            cells = [_summary(r["terms"][term] for r in populations[p] if r["view"] == view)
                     for p in names]
            print(f"| {term} | " + " | ".join(cells) + " |", file=file)
        print(f"\n### {view}: per-landmark misfit, cohort skulls / own skull (refitted camera; "
              "median over the photos; 1 expected under the model)\n", file=file)
        print("| landmark | " + " | ".join(names) + " |", file=file)
        print("|---|" + "---|" * len(names), file=file)
        landmarks = sorted({n for p in names for r in populations[p] if r["view"] == view
                            for n in r["cohort_misfit"]})
        for name in landmarks:
            cells = []
            for p in names:
                rows = [r for r in populations[p] if r["view"] == view]
                cohort = [r["cohort_misfit"].get(name, np.nan) for r in rows]
                own = [r["own_misfit"].get(name, np.nan) for r in rows]
                cells.append(f"{np.nanmedian(cohort):.2f} / {np.nanmedian(own):.2f}"
                             if np.isfinite(cohort).any() else "-")
            print(f"| {name} | " + " | ".join(cells) + " |", file=file)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generated", required=True, help="a generated dataset folder")
    parser.add_argument("--real", action="append", default=[], help="a real-anatomy dataset")
    parser.add_argument("--work", default="realism-gap", help="where to build the real cases")
    parser.add_argument("--photos", type=int, default=6, help="per view and real head")
    args = parser.parse_args(argv)
    real = [Path(r) for r in args.real]
    if not real:
        from headsq_case import ensure_dataset

        built = ensure_dataset(Path(args.work) / "headsq", n_photos=args.photos)
        real += [] if built is None else [built]
        try:
            from cranium_case import ensure_dataset as ensure_cranium
        except ImportError:
            ensure_cranium = None
        if ensure_cranium is not None:
            built = ensure_cranium(Path(args.work) / "cranium", n_photos=args.photos)
            real += [] if built is None else [built]
    cohort = shipped_cohort()
    populations = {"generated": measure(args.generated, cohort)}
    for root in real:
        populations[root.name] = measure(root, cohort)
    print_tables(populations)
    return 0


if __name__ == "__main__":
    sys.exit(main())
