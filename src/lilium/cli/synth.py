"""``lilium synth``: generate a synthetic evaluation dataset (subjects, photos A/B/C)."""

import argparse
import os
import time
from pathlib import Path

from .argtypes import int_in
from .options import add_options

#: ``--subjects``, ``--photos``: as an experiment config's ``dataset.subjects`` / ``photos``; a
#: typing slip (100000000) would otherwise generate for days.
COUNT = int_in(1, 1000, " (as an experiment config's dataset.subjects and dataset.photos)")


def fraction(closed):
    """``--no-mandible-share`` ([0, 1]) / ``--drop-landmark-rate`` ([0, 1)) argument type."""

    def parse(text):
        from ..synthetic.incomplete import check_fraction

        try:
            return check_fraction(text, "the value", closed=closed)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = "fraction"
    return parse


def experiment_list(text):
    """``--experiments`` argument type: comma-separated noise profiles, each once."""
    from ..synthetic.noise import NOISE_PROFILES

    letters = [e.strip().upper() for e in text.split(",") if e.strip()]
    if not letters:
        raise argparse.ArgumentTypeError(f"give at least one of {', '.join(NOISE_PROFILES)}")
    for letter in letters:
        if letter not in NOISE_PROFILES:
            raise argparse.ArgumentTypeError(
                f"{letter!r} is not an experiment; give some of {', '.join(NOISE_PROFILES)}"
            )
        if letters.count(letter) > 1:
            raise argparse.ArgumentTypeError(f"{letter} is given twice; give each once")
    return tuple(letters)


def check_contact_sheet(path):
    """Refuse a ``--contact-sheet`` path that cannot take a PNG, before generating anything."""
    if path is None:
        return
    if path.is_dir():
        raise ValueError(f"--contact-sheet {path}: is a folder; give a file name ending in .png")
    if path.suffix.lower() not in (".png", ".jpg", ".jpeg"):
        raise ValueError(f"--contact-sheet {path}: give a file name ending in .png (or .jpg)")


def register(subparsers):
    p = subparsers.add_parser(
        "synth",
        help="generate a synthetic dataset",
        description=(
            "Generate N synthetic subjects with M frontal and M lateral photos each, for the "
            "experiments A (ideal), B (landmark noise) and C (B + perturbed soft-tissue axes); "
            "writes OUT/subjects, OUT/photos/<exp> and OUT/dataset.json."
        ),
    )
    add_options(p, "out", required=("out",))
    p.add_argument("--subjects", type=COUNT, default=17, help="number of subjects (default 17)")
    p.add_argument(
        "--photos", type=COUNT, default=30, help="frontal (and lateral) photos per subject"
    )
    add_options(p, "seed")
    p.add_argument(
        "--experiments",
        type=experiment_list,
        default="A,B,C",
        help="comma-separated noise profiles (default A,B,C)",
    )
    add_options(p, "workers", workers=2)
    p.add_argument(
        "--no-mandible-share",
        type=fraction(closed=True),
        default=0.0,
        metavar="SHARE",
        help=(
            "share of the subjects whose skull has no mandible, 0 to 1 (default 0: every skull "
            "complete, as in the paper); the face keeps its chin and lips"
        ),
    )
    p.add_argument(
        "--drop-landmark-rate",
        type=fraction(closed=False),
        default=0.0,
        metavar="RATE",
        help=(
            "probability that a visible photo landmark is left unmarked, 0 to <1 (default 0: "
            "every visible landmark marked, as in the paper)"
        ),
    )
    p.add_argument("--contact-sheet", type=Path, help="also write a contact sheet PNG here")
    add_options(p, "no_progress")
    p.set_defaults(func=run)


def run(args):
    from ..synthetic.dataset import generate_dataset

    experiments = args.experiments
    check_contact_sheet(args.contact_sheet)
    bar = None
    if not args.no_progress:
        from tqdm import tqdm

        bar = tqdm(total=args.subjects, unit="subject", desc="lilium synth")

    def progress(done, total):
        if bar is not None:
            bar.update(done - bar.n)

    start = time.perf_counter()
    try:
        index = generate_dataset(
            args.out,
            args.subjects,
            args.photos,
            seed=args.seed,
            experiments=experiments,
            progress=progress,
            workers=args.workers or os.cpu_count() or 1,
            no_mandible_share=args.no_mandible_share,
            drop_landmark_rate=args.drop_landmark_rate,
        )
    finally:
        if bar is not None:
            bar.close()
    print(
        f"wrote {len(index['subjects'])} subjects and {len(index['photos'])} photos "
        f"x {len(experiments)} experiments to {args.out} in {time.perf_counter() - start:.1f} s"
    )
    incomplete = index.get("incomplete")
    if incomplete:
        unmarked = sum(len(p.get("unmarked_landmarks", ())) for p in index["photos"])
        print(
            f"incomplete: {len(incomplete['subjects_without_mandible'])} skull(s) without the "
            f"mandible, {unmarked} landmark(s) left unmarked"
        )
    if args.contact_sheet:
        from ..report.contact_sheet import contact_sheet

        contact_sheet(args.out, args.contact_sheet, experiment=experiments[0])
        print(f"contact sheet: {args.contact_sheet}")
    return 0
