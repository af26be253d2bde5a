"""``lilium experiment``: run (or resume) the paper's protocol from a TOML config or a preset."""

from pathlib import Path

from ..experiments.config import PRESETS
from .options import add_options


def register(subparsers):
    p = subparsers.add_parser(
        "experiment",
        help="run the evaluation protocol (Exps. A, B, C)",
        description=(
            "Run every photo against every skull with the configured methods and repetitions; "
            "each finished SFO is stored at once in a SQLite database, and running the same "
            f"command again resumes. CONFIG is a TOML file or a preset ({', '.join(PRESETS)}); "
            "see docs/experiments.md."
        ),
    )
    p.add_argument("config", help=f"TOML config file, or a preset name: {', '.join(PRESETS)}")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on this Dask distributed scheduler (e.g. tcp://host:8786) instead of locally",
    )
    add_options(p, "workers", shown={"workers": "the config's"})
    p.add_argument("--db", type=Path, help="results database (default: the config's)")
    add_options(p, "no_progress")
    p.set_defaults(func=run)


def run(args):
    from ..experiments.config import load_config
    from ..experiments.runner import run_experiment

    cfg = load_config(args.config)
    summary = run_experiment(
        cfg,
        scheduler=args.scheduler,
        workers=args.workers,
        db=args.db,
        progress=not args.no_progress,
    )
    return 0 if summary.complete else 1
