"""``lilium sfo``: one skull-face overlay from a subject folder and a photo folder."""

import sys
from pathlib import Path

from ..io.case import read_depth_table, read_photo, read_skull
from ..io.results import write_result
from ..methods.overlay import result_overlay
from ..methods.posest_sfo import posest_sfo

METHODS = ("posest-sfo",)


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
    p.add_argument("--axes", type=Path, help="soft-tissue axes JSON to use instead of the skull's")
    p.add_argument("--depth-table", type=Path, help="CSV: landmark,mean,sd,min,max (mm)")
    p.add_argument("--no-overlay", action="store_true", help="skip overlay.png")
    p.set_defaults(func=run)


def run_sfo(
    skull_dir, photo_dir, out_dir, method="posest-sfo", axes=None, depth_table=None, overlay=True
):
    """Read the case, run the method, write the outputs; returns the :class:`SfoResult`."""
    skull = read_skull(skull_dir, axes_path=axes)
    photo = read_photo(photo_dir, load_image=overlay)
    table = read_depth_table(depth_table) if depth_table else None
    result = posest_sfo(skull, photo, depth_table=table)
    write_result(out_dir, result, result_overlay(result, skull, photo) if overlay else None)
    return result


def run(args):
    result = run_sfo(
        args.skull,
        args.photo,
        args.out,
        args.method,
        args.axes,
        args.depth_table,
        not args.no_overlay,
    )
    if not result:
        print(
            f"SFO failed: {result.error} (written to {args.out / 'result.json'})", file=sys.stderr
        )
        return 1
    print(
        f"{result.method}: focal {result.focal_px:.0f} px, score {result.fitness:.3f}, "
        f"{result.seconds * 1e3:.1f} ms -> {args.out}"
    )
    return 0
