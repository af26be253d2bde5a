"""``lilium experiment``: run (or resume) the paper's protocol from a TOML config or a preset."""

from pathlib import Path

from ..experiments.config import PRESETS


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
    p.add_argument(
        "--workers", type=int, help="local worker processes (default: the config's; 0 = all cores)"
    )
    p.add_argument("--db", type=Path, help="results database (default: the config's)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args):
    from ..experiments.config import check_int, load_config
    from ..experiments.runner import run_experiment

    if args.workers is not None:
        check_int("--workers (0 = all cores)", args.workers, "workers")
    cfg = load_config(args.config)
    summary = run_experiment(
        cfg,
        scheduler=args.scheduler,
        workers=args.workers,
        db=args.db,
        progress=not args.no_progress,
    )
    return 0 if summary.complete else 1
