"""``lilium case``: superimpose one skull on one or more photos and report them together.

Inputs are docs/contract.md folders or the files a practitioner already has::

    lilium case --skull SUBJECT_DIR --photo PHOTO_DIR [--photo PHOTO_DIR ...] --out DIR
    lilium case --skull SUBJECT_DIR --auto-landmarks --photo portrait.jpg --out DIR
    lilium case --skull skull.stl --landmarks skull.mrk.json \\
        --photo front.jpg --photo-landmarks front.csv [--mask front_mask.png] \\
        [--face-curve front_face_curve.json] --out DIR

Sidecar files stand in for an option that is not given, and each one found is printed
(:data:`EPILOG`). Priors: ``--focal-px``/``--scd-mm`` override ``photo.json``; without either,
the focal prior comes from the photo's EXIF when it has one.

Writes ``DIR/report.html`` and, per photo and method, ``DIR/<photo>/<method>[-<variant>]/``
with ``result.json`` and ``overlay.png`` (:func:`lilium.methods.method_tag`), whatever the
number of methods.
"""

import argparse
import shlex
from pathlib import Path

from ..casework.case import run_case
from ..constants import VIEWS
from ..methods import METHODS
from .argtypes import output_folder, positive_float
from .sfo import (
    AXES_FILE,
    DEPTH_TABLE_FILE,
    add_calibration_option,
    add_lilium_options,
    options_from,
)

#: What ``lilium case --help`` says after the options: the face mask, the sidecar files and
#: the output layout (docs/conventions.md and docs/contract.md say the same).
EPILOG = """\
face mask (--mask FILE, NAME_mask.png beside an image, face_mask.png in a photo folder):
  a PNG of the photo's size, non-zero on the head as seen in the photo: the face, the
  forehead, the hair and the ears, down to the upper neck just below the chin and jaw; zero
  on the shoulders, the clothes and the background. Hair makes the mask larger than the
  skull, and that is intended: the vault under the hair is inside the head. A mask drawn
  from the hairline to the chin makes the vault count as "skull outside the face" (P_skof,
  the report's outside figure). Picture: docs/images/face_mask.png (docs/conventions.md).

sidecar files (used when the option is not given; each one found is printed, e.g.
"front: using mask front_mask.png (found beside the photo)"):
  beside a mesh SKULL.ply   SKULL.mrk.json/.fcsv/.pp/.csv/.tsv/.txt/.json or
                            SKULL_landmarks.* (cranial landmarks, --landmarks)
  beside an image NAME.png  NAME.csv/.json/.tsv/.txt or NAME_landmarks.* (facial
                            landmarks, --photo-landmarks), NAME_mask.png (face mask,
                            --mask), NAME_face_curve.json (facial curve, --face-curve)
  in a photo folder         image.png/.jpg, photo.json, face_mask.png, face_curve.json

automatic landmarks (lilium photo, docs/method/photo.md): a folder written by lilium photo is a
  photo folder; its tracked landmarks are used, its template ones only once confirmed in
  review.html, its priors with "source": "automatic", its head orientation turned into
  head_rotation_skull2cam through the skull's frame. --auto-landmarks prepares each bare
  image itself into OUT/<photo>/prepared/ (nothing is written beside the image); the report
  says the landmarks are automatic and unreviewed and links the review page (docs/method/photo.md).

facial curve (face_curve.json format): {"chin_jaw": [[u, v], ...]} for a frontal photo,
  {"forehead": [[u, v], ...]} for a lateral one (pixels); without one, the pll variants
  derive it from the face mask.

outputs: DIR/report.html, and one folder per photo and method whatever their number,
  DIR/<photo>/<method>[-<variant>]/result.json and overlay.png, e.g. DIR/front/posest-sfo/
  and DIR/front/lilium-skof+pll/.
"""


def register(subparsers):
    p = subparsers.add_parser(
        "case",
        help="superimpose a skull on one or more photos; HTML report",
        description=(
            "Run the SFO of one skull against each photo and write DIR/report.html with "
            "DIR/<photo>/<method>[-<variant>]/result.json and overlay.png."
        ),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--skull",
        required=True,
        type=Path,
        help="subject folder (docs/contract.md) or a skull mesh (PLY/OBJ/STL, mm)",
    )
    p.add_argument(
        "--landmarks",
        type=Path,
        help="cranial landmarks: .mrk.json/.fcsv (3D Slicer), .pp (MeshLab), .csv, .json",
    )
    p.add_argument(
        "--axes", type=AXES_FILE, help="soft-tissue axes JSON (default: the skull's own)"
    )
    p.add_argument(
        "--photo",
        required=True,
        action="append",
        type=Path,
        help="photo folder or image (PNG/JPEG); repeat for several photos of the person",
    )
    p.add_argument(
        "--auto-landmarks",
        action="store_true",
        help=(
            "prepare each --photo image that has no landmark file (none given, none beside it) "
            "with lilium photo into OUT/<photo>/prepared/ and use its tracked landmarks, head "
            "mask and priors; the report says they are automatic and unreviewed (needs "
            "pip install 'lilium[photo]')"
        ),
    )
    p.add_argument(
        "--photo-landmarks",
        action="append",
        type=Path,
        default=[],
        help="facial landmarks (CSV name,u,v or JSON) of each photo image, in --photo order",
    )
    p.add_argument(
        "--mask",
        action="append",
        type=Path,
        default=[],
        help=(
            "face mask PNG of each photo image, in --photo order: the head as seen (face, "
            "forehead, hair, ears, down to the upper neck), see below"
        ),
    )
    p.add_argument(
        "--face-curve",
        action="append",
        type=Path,
        default=[],
        help=(
            "facial curve JSON (face_curve.json format) of each photo image, in --photo order; "
            "default NAME_face_curve.json beside the image, else derived from the mask"
        ),
    )
    p.add_argument(
        "--view",
        action="append",
        choices=VIEWS,
        default=[],
        help=(
            "view of each photo image (once for all images, or once per image; default "
            "frontal); photo folders take theirs from photo.json"
        ),
    )
    p.add_argument("--out", required=True, type=output_folder, help="output folder")
    p.add_argument(
        "--method",
        action="append",
        choices=list(METHODS),
        default=[],
        help="method; repeat to run several (default lilium)",
    )
    add_lilium_options(p, de_defaults=False)
    p.add_argument("--focal-px", type=float, nargs=2, metavar=("LO", "HI"), help="focal prior")
    p.add_argument("--scd-mm", type=float, nargs=2, metavar=("LO", "HI"), help="SCD prior (mm)")
    p.add_argument(
        "--sensor-width-mm",
        type=positive_float(),
        help="camera sensor width, for the EXIF focal prior",
    )
    p.add_argument("--no-exif", action="store_true", help="do not take a focal prior from EXIF")
    p.add_argument(
        "--depth-table", type=DEPTH_TABLE_FILE, help="CSV: landmark,mean,sd,min,max (mm)"
    )
    p.add_argument(
        "--joint",
        action="store_true",
        help=(
            "run Lilium as one joint SFO of all the photos (two or more of the same person): "
            "one soft tissue shared by the photos, one camera each; outputs in "
            "DIR/joint/lilium-<variant>/. Measured: 0.87-0.98 x the separate "
            "SFOs' BPE on generated subjects, level on a real CT head, where more of its "
            "overlays leave the face (docs/method/joint.md)"
        ),
    )
    add_calibration_option(p)
    p.add_argument("--title", help="report title")
    p.set_defaults(func=run)


def command_line(args, methods):
    """The ``lilium case`` command line equivalent to ``args`` (for the provenance)."""
    parts = ["lilium", "case", "--skull", str(args.skull)]
    for option in ("landmarks", "axes", "depth_table", "calibration"):
        if getattr(args, option) is not None:
            parts += [f"--{option.replace('_', '-')}", str(getattr(args, option))]
    for photo in args.photo:
        parts += ["--photo", str(photo)]
    if args.auto_landmarks:
        parts.append("--auto-landmarks")
    for option in ("photo_landmarks", "mask", "face_curve", "view"):
        for value in getattr(args, option):
            parts += [f"--{option.replace('_', '-')}", str(value)]
    for method in methods:
        parts += ["--method", method]
    if "lilium" in methods:
        parts += ["--variant", args.variant, "--seed", str(args.seed)]
        for option in ("generations", "population", "max_seconds"):
            if getattr(args, option) is not None:
                parts += [f"--{option.replace('_', '-')}", f"{getattr(args, option):g}"]
    for option in ("focal_px", "scd_mm"):
        if getattr(args, option) is not None:
            parts += [f"--{option.replace('_', '-')}", *(f"{x:g}" for x in getattr(args, option))]
    if args.sensor_width_mm is not None:
        parts += ["--sensor-width-mm", f"{args.sensor_width_mm:g}"]
    if args.no_exif:
        parts.append("--no-exif")
    if getattr(args, "joint", False):
        parts.append("--joint")
    parts += ["--out", str(args.out)]
    return " ".join(shlex.quote(p) for p in parts)


def run(args):
    methods = list(dict.fromkeys(args.method)) or ["lilium"]
    entries = run_case(
        args.skull,
        args.photo,
        args.out,
        landmarks=args.landmarks,
        axes=args.axes,
        methods=methods,
        options=options_from(args),
        seed=args.seed,
        depth_table=args.depth_table,
        title=args.title,
        command=command_line(args, methods),
        photo_landmarks=args.photo_landmarks,
        masks=args.mask,
        face_curves=args.face_curve,
        views=args.view,
        focal_px=args.focal_px,
        scd_mm=args.scd_mm,
        use_exif=not args.no_exif,
        sensor_width_mm=args.sensor_width_mm,
        auto_landmarks=args.auto_landmarks,
        joint=args.joint,
        calibration=args.calibration,
    )
    return 0 if all(e.result for e in entries) else 1
