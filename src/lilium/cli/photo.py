"""``lilium photo``: prepare a photo folder from a plain photograph (docs/method/photo.md).

Exit status: 0 when a face was found and the folder holds automatic landmarks; 3 when no face
was found (the folder is written without automatic landmarks, to be marked by hand in
``review.html``); 2 for an input error (one line naming the file or option).
"""

import sys
import time
from pathlib import Path

from ..constants import VIEWS
from .argtypes import int_in
from .options import add_options

#: Exit status when no face was found but the folder was written for marking by hand.
EXIT_NO_FACE = 3


def register(subparsers):
    p = subparsers.add_parser(
        "photo",
        help="prepare a photo folder (automatic landmarks, head mask, priors, review page)",
        description=(
            "Find the face in IMAGE with the shipped MediaPipe models (offline; needs "
            "pip install 'lilium[photo]') and write OUT: the image, photo.json (landmarks tagged "
            "tracked/template, priors with their source), face_mask.png and review.html. "
            f"Exit status {EXIT_NO_FACE} when no face is found (the folder is still written, "
            "to be marked by hand)."
        ),
    )
    p.add_argument("image", type=Path, help="the photograph (PNG or JPEG)")
    add_options(p, "out", required=("out",))
    p.add_argument("--view", choices=VIEWS, help="default: from the head's yaw")
    p.add_argument(
        "--landmarks",
        type=Path,
        help="reviewed landmarks (review.html's landmarks.json, or any facial landmark file)",
    )
    add_options(p, "sensor_width_mm")
    p.add_argument(
        "--face",
        type=int_in(1, why=" (faces are numbered from the left, 1 = the leftmost)"),
        help="which face of a photo with several (default: the most confident)",
    )
    p.set_defaults(func=run)


def run(args):
    from ..io.paths import check_no_links
    from ..photo.prepare import prepare_photo

    check_no_links(args.out)
    start = time.perf_counter()
    result = prepare_photo(
        args.image,
        args.out,
        args.view,
        args.landmarks,
        sensor_width_mm=args.sensor_width_mm,
        face=args.face,
    )
    seconds = time.perf_counter() - start
    for warning in result.warnings:
        print(f"warning {warning['code']}: {warning['message']}", file=sys.stderr)
    if not result.face_found:
        print(f"lilium photo: {result.message}", file=sys.stderr)
        print(f"wrote {result.folder} ({seconds:.1f} s)")
        return EXIT_NO_FACE
    print(f"{result.message} ({seconds:.1f} s)")
    return 0
