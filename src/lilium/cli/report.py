"""``lilium report``: the paper's tables and plots from an experiment database."""

import sys
from pathlib import Path

from .argtypes import dataset_folder
from .options import add_options


def register(subparsers):
    p = subparsers.add_parser(
        "report",
        help="tables and plots from an experiment database",
        description=(
            "Mean rank and BPE (frontal/lateral), time per SFO, Wilcoxon signed-rank tests "
            "(Bonferroni-corrected) and worst-case implausible SFOs, as Markdown and CSV, plus "
            "PNG plots."
        ),
    )
    p.add_argument("db", type=Path, help="results database written by lilium experiment")
    add_options(p, "out", required=("out",))
    p.add_argument(
        "--dataset",
        type=dataset_folder,
        help="the dataset folder, when it moved since the database was written (for the "
        "identification LR of rows without stored terms)",
    )
    p.set_defaults(func=run)


def run(args):
    from ..experiments.report import write_report

    def warn(line):
        print(f"lilium report: warning: {line}", file=sys.stderr)

    paths = write_report(args.db, args.out, dataset=args.dataset, log=warn)
    print(f"report: {paths['markdown']} ({len(paths)} files in {args.out})")
    return 0
