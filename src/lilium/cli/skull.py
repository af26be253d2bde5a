"""``lilium skull``: a bare skull mesh to a subject folder with automatic cranial landmarks
(docs/method/skull.md)."""

import time

from .argtypes import existing_file
from .options import add_options


def register(subparsers):
    p = subparsers.add_parser(
        "skull",
        help="place the cranial landmarks of a skull mesh and write a subject folder",
        description=(
            "Read a skull mesh (PLY, OBJ or STL in millimetres, any pose, with or without its "
            "mandible), fit the template skull to it, place every cranial landmark the skull "
            "has and write OUT: skull.ply, cranial_landmarks.json (each point tagged located: "
            "found by its own definition, or template: placed by the fitted template only, not "
            "used by an SFO until confirmed) and soft_tissue_axes.json (outward surface "
            "normals). lilium sfo, case and lineup take the folder as it is."
        ),
    )
    p.add_argument("mesh", type=existing_file("skull mesh"), help="the skull mesh (millimetres)")
    add_options(p, "out", required=("out",))
    p.add_argument(
        "--landmarks",
        type=existing_file("landmark file"),
        help="reviewed cranial landmarks (any format lilium case reads): kept, the rest placed",
    )
    p.set_defaults(func=run)


def run(args):
    from ..io.paths import check_no_links
    from ..skull.prepare import (
        flagged,
        landmark_sources,
        parts_left_out_sentence,
        prepare_skull,
    )

    check_no_links(args.out)
    start = time.perf_counter()
    done = prepare_skull(args.mesh, args.out, args.landmarks)
    result = done["result"]
    counts = {}
    for quality in result.quality.values():
        counts[quality] = counts.get(quality, 0) + 1
    parts = "cranium and mandible" if result.mandible else "cranium (no mandible)"
    print(f"parts found: {parts}")
    summary = ", ".join(f"{n} {q}" for q, n in sorted(counts.items()))
    print(f"landmarks: {len(result.landmarks)} ({summary})")
    template = [n for n, q in result.quality.items() if q == "template"]
    if template:
        print(f"template landmarks (not used until confirmed): {', '.join(template)}")
    for name, why in result.doubtful.items():
        where = "template" if name in result.landmarks else "left out"
        print(f"{name}: not located, {why} ({where})")
    if result.parts_left_out:
        print(parts_left_out_sentence(result.parts_left_out))
    check = flagged(landmark_sources(result))
    if check:
        print(
            "flagged for review (extremes whose place depends on the head's orientation): "
            + ", ".join(check)
        )
    print(
        f"wrote {done['folder']} (skull {done['faces']} faces) in "
        f"{time.perf_counter() - start:.1f} s"
    )
    return 0
