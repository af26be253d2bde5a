"""Validation of the shipped calibration: generated held-out seeds, then real anatomy, apart.

The table of performance characteristics of forensic LR validation (Meuwly, Ramos and Haraksim
2017; :mod:`lilium.experiments.lr_validation`): each characteristic with its metric, criterion
and pass or fail,

1. on results databases of generated subjects that the shipped calibration never saw (``--db``,
   e.g. ``bench_identification.py --out DIR --subjects 20 --dataset-seeds 6,7 --methods
   posest-sfo,lilium:skof+pll``), each decision scored by the shipped models as a case is;
2. on the real-anatomy pairs of ``bench_real_anatomy.py`` (headsq with and without its
   mandible, Cranium; each photo pair against its own skull and the other head's), single
   photos and frontal + lateral decisions: different-person support, own skull LR > 1, LRs at
   a bound, ``outside_calibration``.

Run::

    PYTHONPATH=src python benchmarks/bench_validation.py --db DIR/seed-6/results.sqlite \\
        --db DIR/seed-7/results.sqlite --real-out real-anatomy [--photos 3]
"""

import argparse
import sys
from pathlib import Path

from bench_real_anatomy import print_rows, real_datasets, run_pairs, summary
from lilium.experiments.calibrate import database_decisions
from lilium.experiments.lr_validation import criteria_rows, figures, score_decisions
from lilium.io.calibration import read_calibration

#: Figures printed per decision.
COLUMNS = ("auc", "cllr", "cllr_min", "cllr_cal", "eer", "misleading_same", "misleading_diff",
           "wrong_conclusion_same", "wrong_conclusion_diff", "at_bound", "outside",
           "outside_same")

#: The real-anatomy criteria: (characteristic, figure of :func:`bench_real_anatomy.summary`,
#: test, criterion).
REAL_CRITERIA = (
    ("generalisation", "diff_support", lambda v: v == 0, "no different-person decision supports"),
    ("generalisation", "own_positive", lambda v: v >= 0.9, "own skull log10 LR > 0 in >= 90 %"),
    ("calibration", "own_bound", lambda v: v <= 0.1, "own skull: <= 10 % of LRs at a bound"),
)
# (All LRs at a bound are in the table below the criteria: on real heads they are the
# different-person pairs at the lower bound, the exclusions the model is surest of, which no
# criterion holds against it.)


def _f(value):
    return "-" if value != value else f"{value:.3f}"


def print_generated(dbs, models, file=sys.stdout):
    decision_pairs, _ = database_decisions(dbs, log=lambda line: None)
    scored = score_decisions(decision_pairs, models)
    by_decision = {key: figures(entry) for key, entry in scored.items()}
    print("| decision | pairs same / diff | " + " | ".join(COLUMNS) + " |", file=file)
    print("|---|---|" + "---|" * len(COLUMNS), file=file)
    for (method, variant, decision), fig in sorted(by_decision.items()):
        print(f"| {method} {variant} {decision} | {fig['n_same']} / {fig['n_diff']} | "
              + " | ".join(_f(fig[c]) for c in COLUMNS) + " |", file=file)
    print("\n| characteristic | decision | metric | value | criterion | result |", file=file)
    print("|---|---|---|---|---|---|", file=file)
    for characteristic, label, metric, value, text, passed in criteria_rows(by_decision):
        print(f"| {characteristic} | {label} | {metric} | {value:.3f} | {text} | "
              f"{'pass' if passed else 'FAIL'} |", file=file)


def print_real(rows, file=sys.stdout):
    print("| characteristic | decision | figure | value | criterion | result |", file=file)
    print("|---|---|---|---|---|---|", file=file)
    for (method, kind), s in summary(rows).items():
        for characteristic, name, test, text in REAL_CRITERIA:
            value = s[name]
            print(f"| {characteristic} | {method} {kind} | {name} | {value:.3g} | {text} | "
                  f"{'pass' if test(value) else 'FAIL'} |", file=file)
    print("\n| decision | own skull: LR > 1 / at bound / skull outside head | other person: "
          "LR < 1 / supported | all: at bound / outside_calibration | pairs same / diff |",
          file=file)
    print("|---|---|---|---|---|", file=file)
    for (method, kind), s in summary(rows).items():
        print(f"| {method} {kind} | {s['own_positive']:.2f} / {s['own_bound']:.2f} / "
              f"{s['own_outside_head']:.2f} | {s['diff_negative']:.2f} / {s['diff_support']} | "
              f"{s['bound']:.2f} / {s['outside_calibration']:.2f} | {s['n_same']} / "
              f"{s['n_diff']} |", file=file)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--db", action="append", default=[], help="a held-out results database")
    parser.add_argument("--calibration", help="calibration file (default: the shipped one)")
    parser.add_argument("--real-out", help="work folder of the real-anatomy pairs")
    parser.add_argument("--photos", type=int, default=3, help="photo pairs per real head")
    args = parser.parse_args(argv)
    models, provenance = read_calibration(args.calibration)
    print(f"calibration: {args.calibration or 'shipped'} (fitted {provenance.get('fitted')})")
    if args.db:
        print(f"\n## Generated held-out subjects ({len(args.db)} database(s))\n")
        print_generated([Path(db) for db in args.db], models)
    if args.real_out:
        print("\n## Real anatomy (CT heads; own skull and another person's)\n")
        datasets = real_datasets(Path(args.real_out) / "datasets", args.photos)
        if not datasets:
            print("no real-anatomy CT found: skipped")
            return 0
        rows = run_pairs(
            datasets, args.real_out, args.photos, log=lambda line: None,
            calibration=args.calibration,
        )
        print_real(rows)
        print()
        print_rows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
