"""``lilium lineup``: one skull against several candidate persons, ranked by likelihood ratio."""

from pathlib import Path

from ..methods import METHODS
from .argtypes import output_folder
from .sfo import (
    add_calibration_option,
    add_lilium_options,
    options_from,
)


def register(subparsers):
    p = subparsers.add_parser(
        "lineup",
        help="one skull against several candidate persons, ranked by likelihood ratio",
        description=(
            "Runs the SFO of the skull on every photo of every candidate, takes each "
            "candidate's photos together, ranks the candidates by the identification's log10 "
            "LR and writes OUT/report.html (the ranking first, then every "
            "overlay), OUT/lineup.json and OUT/<candidate>/<photo>/<method>/result.json. "
            "Resumable: run the same command again after an interruption."
        ),
    )
    p.add_argument("--skull", required=True, type=Path, help="subject folder or skull mesh")
    p.add_argument("--landmarks", type=Path, help="cranial landmark file (with a mesh)")
    p.add_argument(
        "--candidate",
        required=True,
        action="append",
        nargs="+",
        metavar=("NAME", "PHOTO"),
        help="a candidate's name and one or more photo folders or images; repeat per candidate",
    )
    p.add_argument("--out", required=True, type=output_folder, help="output folder")
    p.add_argument(
        "--method",
        action="append",
        choices=list(METHODS),
        default=[],
        help="method (repeatable; default lilium; the first one ranks)",
    )
    add_lilium_options(p)
    add_calibration_option(p)
    p.add_argument("--title", help="report title")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args):
    from ..casework.lineup import run_lineup

    candidates = [(entry[0], [Path(p) for p in entry[1:]]) for entry in args.candidate]
    ranking = run_lineup(
        args.skull,
        candidates,
        args.out,
        methods=args.method or ["lilium"],
        options=options_from(args),
        seed=args.seed,
        calibration=args.calibration,
        landmarks=args.landmarks,
        title=args.title,
        progress=not args.no_progress,
    )
    return 0 if ranking else 1
