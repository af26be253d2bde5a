"""``lilium sfo``: one skull-face overlay from a subject folder and a photo folder."""

import sys
from dataclasses import replace
from pathlib import Path

from ..io.case import read_depth_table, read_photo, read_skull
from ..io.results import write_result
from ..methods.lilium import VARIANTS, LiliumOptions, lilium_sfo
from ..methods.overlay import result_overlay
from ..methods.posest_sfo import posest_sfo
from ..optimisation.de import DEOptions

METHODS = ("posest-sfo", "lilium")


def register(subparsers):
    p = subparsers.add_parser(
        "sfo",
        help="run one skull-face overlay",
        description="Superimpose a skull on a photo; writes OUT/result.json and OUT/overlay.png.",
    )
    p.add_argument("--skull", required=True, type=Path, help="subject folder (SPEC section 8)")
    p.add_argument("--photo", required=True, type=Path, help="photo folder (SPEC section 8)")
    p.add_argument("--out", required=True, type=Path, help="output folder")
    p.add_argument("--method", default="posest-sfo", choices=METHODS)
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


def lilium_options(variant="skof+pll", generations=None, population=None, max_seconds=None):
    """:class:`LiliumOptions` with the given DE settings (None keeps the default)."""
    de = DEOptions()
    changes = {
        "max_generations": generations,
        "population_size": population,
        "max_seconds": max_seconds,
    }
    de = replace(de, **{k: v for k, v in changes.items() if v is not None})
    return LiliumOptions(variant=variant, de=de)


def run_sfo(
    skull_dir,
    photo_dir,
    out_dir,
    method="posest-sfo",
    axes=None,
    depth_table=None,
    overlay=True,
    options=None,
    seed=0,
):
    """Read the case, run the method, write the outputs; returns the :class:`SfoResult`."""
    skull = read_skull(skull_dir, axes_path=axes)
    photo = read_photo(photo_dir, load_image=overlay)
    table = read_depth_table(depth_table) if depth_table else None
    if method == "posest-sfo":
        result = posest_sfo(skull, photo, depth_table=table)
    elif method == "lilium":
        result = lilium_sfo(skull, photo, options or LiliumOptions(), seed=seed, depth_table=table)
    else:
        raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    write_result(out_dir, result, result_overlay(result, skull, photo) if overlay else None)
    return result


def run(args):
    options = lilium_options(args.variant, args.generations, args.population, args.max_seconds)
    result = run_sfo(
        args.skull,
        args.photo,
        args.out,
        args.method,
        args.axes,
        args.depth_table,
        not args.no_overlay,
        options,
        args.seed,
    )
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
