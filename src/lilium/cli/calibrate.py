"""``lilium calibrate``: fit the identification calibration on experiment databases."""

import time
from pathlib import Path

from .argtypes import dataset_folder
from .options import add_options


def register(subparsers):
    p = subparsers.add_parser(
        "calibrate",
        help="fit the identification calibration (log10 LR) on experiment databases",
        description=(
            "Computes every stored SFO's identification terms, fits one log10 LR model per "
            "method, variant and decision (frontal, lateral, a frontal+lateral pair with its "
            "soft tissue shared, the same pair's two LRs added and calibrated, joint), "
            "cross-validated by subject, and writes OUT/calibration.json (give it to lilium "
            "sfo/case/lineup with --calibration) and OUT/calibration.csv (Cllr, Cllr_min, "
            "rates of misleading evidence and of wrong conclusions)."
        ),
    )
    p.add_argument("db", type=Path, nargs="+", help="results databases of lilium experiment")
    add_options(p, "out", required=("out",))
    p.add_argument(
        "--dataset",
        type=dataset_folder,
        help="the dataset folder, when it moved since the databases were written",
    )
    p.set_defaults(func=run)


def run(args):
    from ..experiments.lr_report import calibrate_databases

    paths, *_ = calibrate_databases(args.db, args.out, dataset=args.dataset)
    print(f"calibration: {paths['calibration.json']} ({time.strftime('%Y-%m-%d')})")
    return 0
