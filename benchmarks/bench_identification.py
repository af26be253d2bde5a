"""Identification on generated Exp. C photos: every method and Lilium variant, per view.

Run: ``.venv/bin/python benchmarks/bench_identification.py [--out DIR] [--subjects 8]
[--workers 2] [--generations 750] [--joint-subjects 12]``. It generates (or reuses) a
dataset of ``--subjects`` subjects with one frontal and one lateral photo each (dataset seeds
``--dataset-seeds``; with ``--joint-subjects`` also a joint-SFO dataset), runs Exp. C (one axis
set, one run, Lilium seed ``--seed``) for POSEST-SFO and the four Lilium variants against
every skull with :func:`lilium.experiments.runner.run_experiment` (resumable: the same command
again continues, or only prints when all is stored), and prints:

1. per method, variant and view: mean rank of the true skull, rank-1 rate, ROC AUC per photo
   (:mod:`lilium.experiments.identification`), mean BPE of the positive pairs and the number of
   photos;
2. per Lilium variant and view, the fitness terms of the true skull against the best-scoring
   wrong skull of the same photo: medians over the photos of ``mse_pix``, ``p_pll``, ``p_skof``
   and the score, and on how many photos the true skull wins;
3. the same identification figures for each Lilium variant ranked, instead of by its fitness,
   by the mean pixel error of the mean-depth facial landmarks (POSEST-SFO's 3D points) under
   the camera Lilium found: a diagnostic, not a method. It tells the camera from the score: if
   the cameras are good but the fitness ranks poorly, the fitness's freedom (three soft-tissue
   genes per landmark fit the landmarks of any skull) is what limits identification.

Then, over every database pooled: each decision's cross-validated log10 LR (Cllr, Cllr_min,
misleading evidence, wrong conclusions), the shipped logistic calibration beside the
bi-Gaussianized one (docs/method/identification.md), where the misleading evidence falls (the equal
error
rate no calibration can beat, and look-alike skulls: ``lookalikes.py``), the rankings by the
LR, and with ``--headsq`` the headsq CT's conclusions.

At the full budget (DE 30 x 750, 8 subjects: 128 SFOs per method, 640 in all) it took 438 s on
2 workers and 936 s on one (measured); ``--generations 3 --subjects 3`` checks the pipeline in
under a minute. Results and their discussion:
docs/decisions/0012-identification-marginal-likelihood.md.
"""

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lilium.experiments.calibrate import DatasetInputs, validate
from lilium.experiments.config import (
    ALL_METHODS,
    DatasetConfig,
    ExperimentConfig,
    method_label,
    parse_methods,
    view_group,
)
from lilium.experiments.identification import (
    complete_photo_runs,
    identification_table,
    ranking_score,
)
from lilium.experiments.lr_report import calibrate_databases
from lilium.experiments.lr_validation import roc_auc
from lilium.experiments.report import load_rows
from lilium.experiments.runner import run_experiment
from lilium.experiments.store import COLUMNS, ResultStore
from lilium.geometry.camera import Camera
from lilium.identification.terms import COHORT_CALIBRATED_TERMS
from lilium.methods.pairs import correspondences
from lilium.methods.posest_sfo import mean_depth_landmarks
from lilium.optimisation.de import DEOptions

#: The data tools (benchmarks/datasets: ``headsq_case``) and studies (benchmarks/studies:
#: ``lookalikes``) this script imports.
sys.path[:0] = [str(Path(__file__).resolve().parent / d) for d in ("datasets", "studies")]

TERMS = ("mse_pix", "p_pll", "p_skof", "score")


def mean_depth_error_px(camera, skull, photo):
    """Mean pixel error of the mean-depth facial landmarks (POSEST-SFO's 3D points) of
    ``skull`` under ``camera`` (:class:`Camera`), over the landmarks ``photo`` marks."""
    corr = correspondences(skull, photo)
    uv = camera.project(mean_depth_landmarks(corr))
    return float(np.linalg.norm(uv - corr.uv_px, axis=1).mean())


def mean_depth_scores(rows, inputs):
    """Lilium rows rescored by :func:`mean_depth_error_px` under their own camera.

    Parameters
    ----------
    rows : list of dict
        Database rows with their ``result`` JSON (``ResultStore.rows(COLUMNS)``).
    inputs : DatasetInputs

    Returns
    -------
    list of dict
        Copies of the Lilium rows with ``score`` replaced; a failed SFO's score is None (it
        ranks last, as in the tables).
    """
    out = []
    for row in rows:
        if row["method"] != "lilium":
            continue
        row = dict(row, score=None)
        if row["success"] and row["result"]:
            camera = Camera.from_dict(json.loads(row["result"])["camera"])
            skull = inputs.skull(row["subject"], row["experiment"], row["axes_set"])
            row["score"] = mean_depth_error_px(
                camera, skull, inputs.photo(row["photo"], row["experiment"])
            )
        out.append(row)
    return out


def config(args, dataset_seed, joint=False):
    """The experiment of one dataset seed; ``joint``: the joint SFO's database instead
    (``OUT/joint``: ``--joint-subjects`` subjects of ``--joint-dataset-seed``, Lilium skof+pll
    and its joint SFO of each frontal + lateral pair)."""
    out = Path(args.out)
    subjects, methods = args.subjects, args.methods
    if joint:
        out, subjects = out / "joint", args.joint_subjects
        methods = "lilium:skof+pll,lilium-joint:skof+pll"
    elif len(args.dataset_seeds) > 1:
        out = out / f"seed-{dataset_seed}"
    return ExperimentConfig(
        name="bench-identification",
        dataset=DatasetConfig(
            out / "dataset", True, subjects, 1, dataset_seed,
            no_mandible_share=0.0 if joint else args.no_mandible_share,
            drop_landmark_rate=0.0 if joint else args.drop_landmark_rate,
        ),
        experiments=("C",),
        methods=parse_methods(methods.split(",")) if methods else ALL_METHODS,
        repetitions=1,
        axes_sets=1,
        runs_per_axes_set=1,
        seed=args.seed,
        de=DEOptions(population_size=30, max_generations=args.generations, max_seconds=500.0),
        workers=args.workers,
        db=out / "results.sqlite",
    )


def bpe_means(rows):
    """Mean BPE (mm) of the positive pairs with a camera, per (method label, view group)."""
    values = defaultdict(list)
    for r in rows:
        if r["positive"] and r["bpe_mm"] is not None:
            values[(method_label(r["method"], r["variant"]), view_group(r["view"]))].append(
                r["bpe_mm"]
            )
    return {k: float(np.mean(v)) for k, v in values.items()}


def term_contrast(rows):
    """Per (method label, view group): the terms of the true skull and of the best wrong one.

    Returns
    -------
    dict
        ``{(label, view): {"true": {term: [...]}, "wrong": {term: [...]}, "wins": int,
        "photos": int}}``, one list entry per complete photo-run.
    """
    by_key = {
        (
            r["experiment"],
            r["method"],
            r["variant"],
            r["axes_set"],
            r["repetition"],
            r["photo"],
            r["subject"],
        ): r
        for r in rows
    }
    out = {}
    for key, view, true_subject, scores in complete_photo_runs(rows, ranking_score):
        exp, method, variant, axes, rep, photo = key
        label, group = method_label(method, variant), view_group(view)
        entry = out.setdefault(
            (label, group),
            {"true": defaultdict(list), "wrong": defaultdict(list), "wins": 0, "photos": 0},
        )
        wrong = min((s for s in scores if s != true_subject), key=lambda s: scores[s])
        entry["photos"] += 1
        entry["wins"] += scores[true_subject] < scores[wrong]
        for side, subject in (("true", true_subject), ("wrong", wrong)):
            row = by_key[(exp, method, variant, axes, rep, photo, subject)]
            for term in TERMS:
                value = row[term]
                entry[side][term].append(np.nan if value is None else float(value))
    return out


def _f(value, digits=2):
    return "-" if value is None or not np.isfinite(value) else f"{value:.{digits}f}"


def print_identification(rows, file=sys.stdout):
    ident = identification_table(rows)
    bpe = bpe_means(rows)
    print("| method | view | mean rank | rank-1 | AUC | BPE mm | photos |", file=file)
    print("|---|---|---|---|---|---|---|", file=file)
    for t in ident:
        b = bpe.get((t["method"], t["view"]))
        print(
            f"| {t['method']} | {t['view']} | {_f(t['mean_rank'])} | {_f(t['rank1_rate'])} | "
            f"{_f(t['auc'])} | {_f(b)} | {t['photo_runs']} (of {t['skulls']} skulls) |",
            file=file,
        )


def print_tables(rows, file=sys.stdout):
    print_identification(rows, file)
    print(file=file)
    print(
        "| method | view | true wins | "
        + " | ".join(f"{t} true / best wrong" for t in TERMS)
        + " |",
        file=file,
    )
    print("|---|---|---|" + "---|" * len(TERMS), file=file)
    for (label, view), e in sorted(term_contrast(rows).items(), key=lambda kv: kv[0][::-1]):
        cells = [
            f"{_f(np.nanmedian(e['true'][t]), 1)} / {_f(np.nanmedian(e['wrong'][t]), 1)}"
            if np.isfinite(e["true"][t]).any()
            else "-"
            for t in TERMS
        ]
        print(
            f"| {label} | {view} | {e['wins']}/{e['photos']} | " + " | ".join(cells) + " |",
            file=file,
        )


def print_likelihood_ratios(dbs, out_dir, file=sys.stdout):
    """The identification LR over every database pooled (subjects of different databases are
    different people): cross-validated Cllr and misleading evidence per decision, and every
    decision's ranking by its log10 LR; writes ``out_dir/calibration.json`` (the models fitted
    on every pair, what ``lilium calibrate`` writes), ``calibration.csv`` and ``tippett.png``."""
    _, table, decision_pairs, validated = calibrate_databases(
        dbs, out_dir, log=lambda line: None
    )
    print("| decision | method | pairs same / different | failed | Cllr | Cllr_min | "
          "misleading same | misleading different | wrong conclusion same | "
          "wrong conclusion different |", file=file)
    print("|---|---|---|---|---|---|---|---|---|---|", file=file)
    for (method, variant, decision), v in sorted(validated.items()):
        rows = [(decision, v["performance"])]
        if "performance_added" in v:  # the plain sum beside the calibrated one
            rows.append((f"{decision}, plain sum", v["performance_added"]))
        for label, p in rows:
            print(
                f"| {label} | {method_label(method, variant)} | {p['n_same']} / {p['n_diff']} "
                f"| {p['failed']} | {p['cllr']:.3f} | {p['cllr_min']:.3f} | "
                f"{100 * p['misleading_same']:.1f} % | {100 * p['misleading_diff']:.1f} % | "
                f"{100 * p['wrong_conclusion_same']:.1f} % | "
                f"{100 * p['wrong_conclusion_diff']:.1f} % |",
                file=file,
            )
    print(file=file)
    print_calibration_comparison(decision_pairs, validated, file)
    print(file=file)
    print_terms_comparison(decision_pairs, validated, file)
    print(file=file)
    from lookalikes import print_lookalikes

    print_lookalikes(dbs, decision_pairs, validated, file)
    print(file=file)
    print("| ranked by identification log10 LR | view | mean rank | rank-1 | AUC | photos |",
          file=file)
    print("|---|---|---|---|---|---|", file=file)
    for t in table:
        print(
            f"| {t['method']} | {t['view']} | {_f(t['mean_rank'])} | {_f(t['rank1_rate'])} | "
            f"{_f(t['auc'], 3)} | {t['photo_runs']} |",
            file=file,
        )


def print_terms_comparison(decision_pairs, validated, file=sys.stdout):
    """What leaving the cohort terms out of the calibration costs on generated subjects (they
    do not transfer to real photos, docs/method/identification.md): every decision's cross-validated
    AUC, Cllr and misleading evidence with the shipped terms beside the same with the cohort
    terms and ``landmark_snorm`` (the same folds; ``validated`` holds the first)."""
    cohort = validate(decision_pairs, names=COHORT_CALIBRATED_TERMS)
    print("| decision | method | shipped terms: AUC, Cllr, misleading same / different | "
          "with the cohort terms |", file=file)
    print("|---|---|---|---|", file=file)
    for key in sorted(validated):
        same = [p["same"] for p in decision_pairs[key]]
        cells = [
            f"{roc_auc(v['log10_lr'], same):.3f}, {v['performance']['cllr']:.3f}, "
            f"{100 * v['performance']['misleading_same']:.1f} / "
            f"{100 * v['performance']['misleading_diff']:.1f} %"
            for v in (validated[key], cohort[key])
        ]
        print(f"| {key[2]} | {method_label(key[0], key[1])} | {cells[0]} | {cells[1]} |",
              file=file)


def print_calibration_comparison(decision_pairs, validated, file=sys.stdout):
    """Every decision's logistic regression beside its bi-Gaussianized one (Morrison 2024;
    docs/method/identification.md names both), the same folds: Cllr and misleading evidence,
    cross-validated.
    The shipped models warp the decisions of :data:`lilium.experiments.calibrate.WARPED` only
    (``validated``, the LR tables' figures, from :func:`validate`)."""
    logistic = validate(decision_pairs, warped=frozenset())
    warped = validate(decision_pairs, warped={key[2] for key in decision_pairs})
    print("| decision | method | logistic: Cllr, misleading same / different | "
          "bi-Gaussianized: Cllr, misleading same / different |", file=file)
    print("|---|---|---|---|", file=file)
    for key in sorted(validated):
        cells = [
            f"{p['cllr']:.3f}, {100 * p['misleading_same']:.1f} / "
            f"{100 * p['misleading_diff']:.1f} %"
            for p in (logistic[key]["performance"], warped[key]["performance"])
        ]
        print(f"| {key[2]} | {method_label(key[0], key[1])} | {cells[0]} | {cells[1]} |",
              file=file)


def headsq_conclusions(out_dir, calibration, other_skull, file=sys.stdout):
    """On the headsq CT (real anatomy, ``benchmarks/datasets/headsq_case.py``): its frontal and
    lateral photo against its own skull, complete and without the mandible, and against a
    generated one, through ``lilium case`` (the full budget, both methods): each photo's and the
    pair's conclusion. Skipped without the CT."""
    from headsq_case import build_headsq_dataset
    from lilium.casework.case import run_case
    from lilium.casework.identify import decide
    from lilium.casework.request import CaseRequest, PhotoSource, SkullSource
    from lilium.io.calibration import Calibrations

    root = build_headsq_dataset(Path(out_dir) / "dataset", 1, 0, variants=("hq", "hq_nm"))
    if root is None:
        print("headsq CT not found (../shared/data/headsq): skipped", file=file)
        return
    photos = [root / "photos" / "C" / "hq_f00", root / "photos" / "C" / "hq_l00"]
    print("| skull | method | decision | conclusion | log10 LR | capped by |", file=file)
    print("|---|---|---|---|---|---|", file=file)
    calibrations = Calibrations(calibration)
    skulls = (
        ("headsq (true)", "hq", root / "subjects" / "hq"),
        ("headsq without mandible (true)", "hq_nm", root / "subjects" / "hq_nm"),
        ("generated", "generated", other_skull),
    )
    for name, folder, skull_dir in skulls:
        request = CaseRequest(
            SkullSource(skull_dir), Path(out_dir) / folder,
            photos=tuple(PhotoSource(p) for p in photos), methods=("lilium", "posest-sfo"),
            calibration=calibration,
        )
        entries = run_case(request, log=lambda line: None)
        by_method = defaultdict(list)
        for e in entries:
            by_method[e.result.method].append(e)
        for method, items in by_method.items():
            decisions = [(e.photo.id, e.result.extra["identification"]) for e in items]
            pair = decide(items[0].skull, [e.photo for e in items], [e.result for e in items],
                          calibrations).to_dict()
            for what, record in decisions + [("frontal + lateral", pair)]:
                lr = record["log10_lr"]
                print(
                    f"| {name} | {method} | {what} | {record['conclusion']} | "
                    f"{'-' if lr is None else f'{lr:+.2f}'} | "
                    f"{', '.join([*record['inconsistent'], *record['caps']]) or '-'} |",
                    file=file,
                )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="bench-identification")
    parser.add_argument("--subjects", type=int, default=8)
    parser.add_argument(
        "--dataset-seeds",
        default="0",
        type=lambda text: [int(x) for x in text.split(",")],
        help="comma-separated dataset seeds, one dataset each (OUT/seed-K with several)",
    )
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--generations", type=int, default=750)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--methods", default="", help="comma-separated, e.g. posest-sfo,lilium:skof (default all)"
    )
    parser.add_argument(
        "--joint-subjects",
        type=int,
        default=0,
        help="also a joint-SFO database of this many subjects (OUT/joint), pooled in the LR tables",
    )
    parser.add_argument("--joint-dataset-seed", type=int, default=2)
    parser.add_argument(
        "--no-mandible-share", type=float, default=0.0,
        help="share of the generated skulls without the mandible (default 0)",
    )
    parser.add_argument(
        "--drop-landmark-rate", type=float, default=0.0,
        help="probability that a visible photo landmark is left unmarked (default 0)",
    )
    parser.add_argument("--print-only", action="store_true", help="only print the stored rows")
    parser.add_argument(
        "--db", action="append", default=[], help="more databases to pool in the LR tables"
    )
    parser.add_argument(
        "--headsq", action="store_true", help="also the headsq CT's conclusions (real anatomy)"
    )
    args = parser.parse_args(argv)
    if args.joint_subjects and args.joint_dataset_seed in args.dataset_seeds:
        # Pooled databases are taken as different people: the same seed twice would not be.
        parser.error("--joint-dataset-seed must differ from every --dataset-seeds value")
    dbs = []
    runs = [(seed, False) for seed in args.dataset_seeds]
    if args.joint_subjects:
        runs.append((args.joint_dataset_seed, True))
    for dataset_seed, joint in runs:
        cfg = config(args, dataset_seed, joint)
        if not args.print_only:
            run_experiment(cfg, progress=False)
        print(f"\n## Dataset seed {dataset_seed}{' (joint SFO)' if joint else ''} ({cfg.db})\n")
        print_tables(load_rows(cfg.db))
        with ResultStore(cfg.db, read_only=True) as store:
            rescored = mean_depth_scores(
                store.rows(list(COLUMNS)), DatasetInputs(cfg.dataset.path)
            )
        print("\nLilium ranked by the mean-depth landmarks' pixel error under its camera:")
        print_identification(rescored)
        dbs.append(cfg.db)
    dbs += [Path(db) for db in args.db]
    print(f"\n## Identification log10 LR, {len(dbs)} database(s) pooled, cross-validated\n")
    print_likelihood_ratios(dbs, Path(args.out) / "calibration")
    if args.headsq:
        print("\n## headsq CT: conclusions with the calibration just fitted\n")
        other = Path(config(args, args.dataset_seeds[0]).dataset.path) / "subjects" / "s01"
        headsq_conclusions(
            Path(args.out) / "headsq", Path(args.out) / "calibration" / "calibration.json", other
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
