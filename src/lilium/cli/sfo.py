"""``lilium sfo``: one skull-face overlay from a subject folder and a photo folder.

With two or more ``--photo`` folders of the same person, ``--method lilium`` runs one joint SFO
(docs/method/joint.md): one soft tissue shared by the photos, one camera each; ``OUT/result.json``
has ``"joint": true`` and a ``photos`` list, with ``OUT/overlay_<photo id>.png`` per photo.
"""

import sys
from pathlib import Path

from ..casework.folders import joint_sfo_on_folders, sfo_on_folders
from ..casework.identify import conclusion_line
from ..constants import MAX_DE_POPULATION
from ..methods import METHODS, SfoOptions
from ..optimisation.de import DEOptions
from .argtypes import existing_file, int_in, output_folder, positive_float, seed

VARIANTS = METHODS["lilium"].variants

#: Argument types shared with ``lilium case`` (a bad value names its option; exit 2).
GENERATIONS = int_in(1)
POPULATION = int_in(
    4,
    MAX_DE_POPULATION,
    " (DE/rand/1 draws three other members; the paper uses 30, and a population is evaluated "
    "at once, in memory)",
)
MAX_SECONDS = positive_float(allow_inf=True)
AXES_FILE = existing_file("soft-tissue axes file")
DEPTH_TABLE_FILE = existing_file("depth table")
CALIBRATION_FILE = existing_file("calibration file")


def register(subparsers):
    p = subparsers.add_parser(
        "sfo",
        help="run one skull-face overlay",
        description=(
            "Superimpose a skull on a photo; writes OUT/result.json and OUT/overlay.png. With "
            "two or more --photo (photos of the same person) and --method lilium, one joint SFO: "
            "one soft tissue shared by the photos, one camera each; writes OUT/result.json "
            '("joint": true) and OUT/overlay_<photo id>.png per photo.'
        ),
    )
    p.add_argument("--skull", required=True, type=Path, help="subject folder (docs/contract.md)")
    p.add_argument(
        "--photo",
        required=True,
        action="append",
        type=Path,
        help=(
            "photo folder (docs/contract.md); repeat for a joint SFO of several photos of the "
            "same person (--method lilium)"
        ),
    )
    p.add_argument("--out", required=True, type=output_folder, help="output folder")
    p.add_argument("--method", default="posest-sfo", choices=list(METHODS))
    add_lilium_options(p)
    p.add_argument(
        "--axes", type=AXES_FILE, help="soft-tissue axes JSON to use instead of the skull's"
    )
    p.add_argument(
        "--depth-table", type=DEPTH_TABLE_FILE, help="CSV: landmark,mean,sd,min,max (mm)"
    )
    p.add_argument("--no-overlay", action="store_true", help="skip overlay.png")
    add_calibration_option(p)
    p.set_defaults(func=run)


def add_lilium_options(parser, de_defaults=True):
    """``--variant``, ``--seed`` and the DE options ``--generations``, ``--population`` and
    ``--max-seconds`` (shared with ``lilium case`` and ``lilium lineup``). With
    ``de_defaults=False`` the DE options stay None unless given (``lilium case`` writes only
    the options given into its provenance); :func:`options_from` reads None as the default."""
    parser.add_argument(
        "--variant",
        default="skof+pll",
        choices=list(VARIANTS),
        help="Lilium fitness variant (default skof+pll)",
    )
    parser.add_argument("--seed", type=seed, default=0, help="Lilium random seed (default 0)")
    de = DEOptions()
    for option, kind, value, what in (
        ("--generations", GENERATIONS, de.max_generations, "DE generations at most"),
        ("--population", POPULATION, de.population_size, "DE population size"),
        ("--max-seconds", MAX_SECONDS, de.max_seconds, "wall-clock limit per SFO in seconds"),
    ):
        parser.add_argument(
            option,
            type=kind,
            default=value if de_defaults else None,
            help=f"Lilium: {what} (default {value:g})",
        )


def add_calibration_option(parser):
    """``--calibration FILE`` (shared with ``lilium case`` and ``lilium lineup``)."""
    parser.add_argument(
        "--calibration",
        type=CALIBRATION_FILE,
        help="identification calibration written by lilium calibrate (default: the shipped one)",
    )


def options_from(args):
    """The :class:`SfoOptions` of the command-line arguments (DE settings, variant)."""
    return SfoOptions(variant=args.variant).with_de(
        max_generations=args.generations,
        population_size=args.population,
        max_seconds=args.max_seconds,
    )


def run(args):
    if len(args.photo) > 1:
        return run_joint(args)
    result = sfo_on_folders(
        args.skull,
        args.photo[0],
        args.out,
        method=args.method,
        options=options_from(args),
        seed=args.seed,
        axes=args.axes,
        depth_table=args.depth_table,
        overlay=not args.no_overlay,
        calibration=args.calibration,
    )
    for warning in result.warnings:
        print(f"warning {warning.code}: {warning.message}", file=sys.stderr)
    if not result:
        print(
            f"SFO failed: {result.error} (written to {args.out / 'result.json'})", file=sys.stderr
        )
        return 1
    name = result.method + (f" {result.variant}" if result.variant else "")
    print(
        f"{name}: focal {result.camera.focal_px:.0f} px, score {result.fitness:.3f}, "
        f"{result.seconds:.2f} s -> {args.out}"
    )
    for term, why in result.terms_off.items():  # inputs missing: ran without it
        print(f"  {term} switched off: {why}")
    print(conclusion_line(result.extra["identification"]))
    return 0


def run_joint(args):
    """``lilium sfo`` with two or more ``--photo``: one joint SFO (docs/method/joint.md)."""
    if args.method != "lilium":
        raise ValueError(
            f"--method {args.method}: a joint SFO of {len(args.photo)} photos runs with --method "
            "lilium only; give one --photo for each SFO, or --method lilium"
        )
    result = joint_sfo_on_folders(
        args.skull,
        args.photo,
        args.out,
        method=args.method,
        options=options_from(args),
        seed=args.seed,
        axes=args.axes,
        depth_table=args.depth_table,
        overlay=not args.no_overlay,
        calibration=args.calibration,
    )
    for single in result.photos:
        for warning in single.warnings:
            print(f"warning {warning.code} ({single.photo_id}): {warning.message}", file=sys.stderr)
    print(
        f"lilium {result.variant} joint ({len(result.photos)} photos): score "
        f"{result.fitness:.3f}, {result.seconds:.2f} s -> {args.out}"
    )
    for single in result.photos:
        if single:
            line = f"focal {single.camera.focal_px:.0f} px, score {single.fitness:.3f}"
        else:
            line = f"FAILED ({single.error})"
        print(f"  {single.photo_id}: {line}")
        for term, why in single.terms_off.items():
            print(f"    {term} switched off: {why}")
    if not result:
        print(
            f"joint SFO failed for a photo: {result.error} (written to {args.out / 'result.json'})",
            file=sys.stderr,
        )
        return 1
    print(conclusion_line(result.extra["identification"]))
    return 0
