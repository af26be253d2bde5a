"""``lilium lineup``: one skull against several candidate persons, ranked by likelihood ratio."""

from .options import SFO, add_options, case_request


def register(subparsers):
    p = subparsers.add_parser(
        "lineup",
        help="one skull against several candidate persons, ranked by likelihood ratio",
        description=(
            "Runs the SFO of the skull on every photo of every candidate, takes each "
            "candidate's photos together, ranks the candidates by the identification's log10 "
            "LR (docs/method/identification.md) and writes OUT/report.html (the ranking "
            "first, then every overlay), OUT/lineup.json and "
            "OUT/<candidate>/<photo>/<method>/result.json. "
            "Resumable: run the same command again after an interruption."
        ),
    )
    add_options(p, "skull", "landmarks", required=("skull",))
    p.add_argument(
        "--candidate",
        required=True,
        action="append",
        nargs="+",
        metavar=("NAME", "PHOTO"),
        help="a candidate's name and one or more photo folders or images; repeat per candidate",
    )
    add_options(p, "out", required=("out",))
    add_options(
        p, *SFO, "calibration", "title", "no_progress",
        shown={"method": "lilium; the first ranks"},
    )
    p.set_defaults(func=run)


def run(args):
    from ..casework.lineup import run_lineup

    ranking = run_lineup(case_request(args))
    return 0 if ranking else 1
