"""``lilium sfo``: one skull-face overlay from a subject folder and a photo folder."""

import sys
from pathlib import Path

from ..casework.folders import sfo_on_folders
from ..methods import METHODS, SfoOptions
from ..optimisation.de import DEOptions

VARIANTS = METHODS["lilium"].variants


def register(subparsers):
    p = subparsers.add_parser(
        "sfo",
        help="run one skull-face overlay",
        description="Superimpose a skull on a photo; writes OUT/result.json and OUT/overlay.png.",
    )
    p.add_argument("--skull", required=True, type=Path, help="subject folder (SPEC section 8)")
    p.add_argument("--photo", required=True, type=Path, help="photo folder (SPEC section 8)")
    p.add_argument("--out", required=True, type=Path, help="output folder")
    p.add_argument("--method", default="posest-sfo", choices=list(METHODS))
    p.add_argument(
        "--variant",
        default="skof+pll",
        choices=list(VARIANTS),
        help="Lilium fitness variant (default skof+pll)",
    )
    p.add_argument("--seed", type=int, default=0, help="Lilium random seed (default 0)")
    de = DEOptions()
    p.add_argument(
        "--generations",
        type=int,
        default=de.max_generations,
        help=f"Lilium: DE generations at most (default {de.max_generations})",
    )
    p.add_argument(
        "--population",
        type=int,
        default=de.population_size,
        help=f"Lilium: DE population size (default {de.population_size})",
    )
    p.add_argument(
        "--max-seconds",
        type=float,
        default=de.max_seconds,
        help=f"Lilium: wall-clock limit in seconds (default {de.max_seconds:g})",
    )
    p.add_argument("--axes", type=Path, help="soft-tissue axes JSON to use instead of the skull's")
    p.add_argument("--depth-table", type=Path, help="CSV: landmark,mean,sd,min,max (mm)")
    p.add_argument("--no-overlay", action="store_true", help="skip overlay.png")
    p.set_defaults(func=run)


def options_from(args):
    """The :class:`SfoOptions` of the command-line arguments (DE settings, variant)."""
    return SfoOptions(variant=args.variant).with_de(
        max_generations=args.generations,
        population_size=args.population,
        max_seconds=args.max_seconds,
    )


def run(args):
    result = sfo_on_folders(
        args.skull,
        args.photo,
        args.out,
        method=args.method,
        options=options_from(args),
        seed=args.seed,
        axes=args.axes,
        depth_table=args.depth_table,
        overlay=not args.no_overlay,
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
    return 0
