"""``lilium sfo``: one skull-face overlay, without a report.

The skull is a subject folder or a mesh with its cranial landmarks, the photo a photo folder or
an image with its files (the options and sidecar files of ``lilium case``). With two or more
``--photo`` of the same person, ``--method lilium`` runs one joint SFO: one soft tissue shared
by the photos, one camera each; ``OUT/result.json`` has ``"joint": true`` and a ``photos``
list, with ``OUT/overlay_<photo id>.png`` per photo.
"""

import sys

from ..casework.identify import conclusion_line
from ..casework.single import joint_sfo, single_sfo
from .options import PHOTO_FILES, PRIORS, SFO, add_options, case_request

#: The method ``lilium sfo`` runs without ``--method``: the baseline.
DEFAULT_METHOD = "posest-sfo"


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
    add_options(
        p, "skull", "landmarks", "axes", "photo", *PHOTO_FILES, "camera", "out", *SFO, *PRIORS,
        "depth_table", required=("skull", "photo", "out"), shown={"method": DEFAULT_METHOD},
    )
    p.add_argument("--no-overlay", action="store_true", help="skip overlay.png")
    add_options(p, "calibration")
    p.set_defaults(func=run, default_method=DEFAULT_METHOD)


def _request(args):
    request = case_request(args)
    if len(request.methods) > 1:
        raise ValueError(
            f"--method given {len(request.methods)} times: lilium sfo runs one method; use "
            "lilium case to run several"
        )
    return request


def run(args):
    request = _request(args)
    if len(request.photos) > 1:
        return run_joint(request)
    result = single_sfo(request, log=print)
    for warning in result.warnings:
        print(f"warning {warning.code}: {warning.message}", file=sys.stderr)
    if not result:
        print(
            f"SFO failed: {result.error} (written to {request.out / 'result.json'})",
            file=sys.stderr,
        )
        return 1
    name = result.method + (f" {result.variant}" if result.variant else "")
    if result.camera_source == "examiner":
        name += ", the given camera scored"
    print(
        f"{name}: focal {result.camera.focal_px:.0f} px, score {result.fitness:.3f}, "
        f"{result.seconds:.2f} s -> {request.out}"
    )
    for term, why in result.terms_off.items():  # inputs missing: ran without it
        print(f"  {term} switched off: {why}")
    print(conclusion_line(result.extra["identification"]))
    return 0


def run_joint(request):
    """``lilium sfo`` with two or more ``--photo``: one joint SFO."""
    (method,) = request.methods
    if method != "lilium":
        raise ValueError(
            f"--method {method}: a joint SFO of {len(request.photos)} photos runs with --method "
            "lilium only; give one --photo for each SFO, or --method lilium"
        )
    result = joint_sfo(request, log=print)
    for single in result.photos:
        for warning in single.warnings:
            print(f"warning {warning.code} ({single.photo_id}): {warning.message}", file=sys.stderr)
    print(
        f"lilium {result.variant} joint ({len(result.photos)} photos): score "
        f"{result.fitness:.3f}, {result.seconds:.2f} s -> {request.out}"
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
            f"joint SFO failed for a photo: {result.error} "
            f"(written to {request.out / 'result.json'})",
            file=sys.stderr,
        )
        return 1
    print(conclusion_line(result.extra["identification"]))
    return 0
