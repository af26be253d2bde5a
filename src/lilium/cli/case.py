"""``lilium case``: superimpose one skull on one or more photos and report them together.

Inputs are docs/contract.md folders or the files a practitioner already has::

    lilium case --skull SUBJECT_DIR --photo PHOTO_DIR [--photo PHOTO_DIR ...] --out DIR
    lilium case --skull SUBJECT_DIR --auto-landmarks --photo portrait.jpg --out DIR
    lilium case --skull skull.stl --landmarks skull.mrk.json \\
        --photo front.jpg --photo-landmarks front.csv [--mask front_mask.png] \\
        [--face-curve front_face_curve.json] --out DIR
    lilium case --skull skull.ply --photo PHOTO_DIR --camera PHOTO_DIR=camera.json --out DIR

Sidecar files stand in for an option that is not given, and each one found is printed
(:data:`EPILOG`). Priors: ``--focal-px``/``--scd-mm`` override ``photo.json``; without either,
the focal prior comes from the photo's EXIF when it has one.

Writes ``DIR/report.html`` and, per photo and method, ``DIR/<photo>/<method>[-<variant>]/``
with ``result.json``, ``overlay.png`` and ``workbench.html`` (:func:`lilium.methods.method_tag`),
whatever the number of methods; a mesh without landmarks gets them placed into
``DIR/prepared-skull/``; a ``--camera`` is scored into ``.../examiner/``.
"""

import argparse

from ..casework.case import run_case
from .options import PHOTO_FILES, PRIORS, SFO, add_options, case_request

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

skull without landmarks (a mesh, none given, none beside it): lilium skull places them into
  OUT/prepared-skull/ with its review.html (docs/method/skull.md); until they are reviewed
  (--landmarks with the file review.html saves) every conclusion stays undetermined.

examiner's camera (--camera PHOTO=FILE, workbench.html's Save or a result.json): scored
  without search beside the photo's SFOs, in DIR/<photo>/<method>/examiner/, labelled in the
  report; its LR is for comparison only (docs/method/workbench.md).

facial curve (face_curve.json format): {"chin_jaw": [[u, v], ...]} for a frontal photo,
  {"forehead": [[u, v], ...]} for a lateral one (pixels); without one, the pll variants
  derive it from the face mask.

outputs: DIR/report.html, and one folder per photo and method whatever their number,
  DIR/<photo>/<method>[-<variant>]/result.json, overlay.png and workbench.html, e.g.
  DIR/front/posest-sfo/ and DIR/front/lilium-skof+pll/.
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
    add_options(p, "skull", "landmarks", "axes", "photo", "auto_landmarks", *PHOTO_FILES, "camera",
                "out", *SFO, *PRIORS, "depth_table", required=("skull", "photo", "out"),
                shown={"method": "lilium"})
    p.add_argument(
        "--joint",
        action="store_true",
        help=(
            "run Lilium as one joint SFO of all the photos (two or more of the same person): "
            "one soft tissue shared by the photos, one camera each; outputs in "
            "DIR/joint/lilium-<variant>/. Measured: 0.87-0.98 x the separate SFOs' BPE on "
            "generated subjects, level on a real CT head, where more of its overlays leave the "
            "face (docs/method/joint.md)"
        ),
    )
    add_options(p, "calibration", "title")
    p.set_defaults(func=run)


def run(args):
    entries = run_case(case_request(args))
    return 0 if all(e.result for e in entries) else 1
