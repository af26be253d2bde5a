"""``lilium report``: the paper's tables and plots from an experiment database."""

from pathlib import Path

from .argtypes import output_folder


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
    p.add_argument("--out", type=output_folder, required=True, help="output folder")
    p.set_defaults(func=run)


def run(args):
    from ..experiments.report import write_report

    paths = write_report(args.db, args.out)
    print(f"report: {paths['markdown']} ({len(paths)} files in {args.out})")
    return 0
