"""Pictures of P_pll's curves: a photo's true skull against its best-scoring wrong skull.

Run: ``.venv/bin/python benchmarks/pll_curves.py DB PHOTO [--variant skof+pll] [--out PNG]``
on a database of :mod:`benchmarks.bench_identification` (or any ``lilium experiment`` run of
generated photos). For the photo, three panels on the photo's chin-jaw (frontal) or forehead
(lateral) region: the true skull at the ground-truth camera, the true skull at the camera
Lilium found, and the wrong skull Lilium scored best at its camera. Each shows the skull curve
as detected (orange) and trimmed (red), the facial curve (cyan), every fourth pair (yellow),
and the terms Delta_d, P_conv, P_int with the end and mean distances in pixels.
"""

import argparse
import json
import sqlite3
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from lilium.fitness.pll import pair_curves_batch, terms_from_pairs, trim_curves_batch  # noqa: E402
from lilium.geometry.camera import Camera, principal_point_of  # noqa: E402
from lilium.io.case import read_photo, read_skull  # noqa: E402
from lilium.io.truth import read_ground_truth  # noqa: E402
from lilium.methods.lilium_terms import PllTerm  # noqa: E402


def curves_and_pairs(term, camera):
    """Detected and trimmed skull curves ``(K, 2)``, the pairs and the terms under ``camera``."""
    cameras = camera.as_batch()
    uv = cameras.project(term.region_vertices_mm)
    span = None if term.span_mm is None else cameras.project(term.span_mm)[..., 1]
    context = term.context
    curves = context.skull_curves(uv, span)
    trimmed, lo, hi = trim_curves_batch(curves, context.face_index)
    pairs = pair_curves_batch(trimmed, context.face_index, lo, hi)
    return curves.curve(0), trimmed.curve(0), pairs, terms_from_pairs(pairs, context.view).member(0)


def draw(ax, image, term, camera, title):
    raw, trimmed, pairs, terms = curves_and_pairs(term, camera)
    face = term.context.face_curve
    ax.imshow(image)
    ax.plot(raw[:, 0], raw[:, 1], "-", color="orange", lw=0.8, label="skull curve")
    ax.plot(trimmed[:, 0], trimmed[:, 1], "-", color="red", lw=1.5, label="trimmed")
    ax.plot(face[:, 0], face[:, 1], "-", color="cyan", lw=1.5, label="face curve")
    for s, f in zip(pairs.skull[::4], pairs.face[::4], strict=True):
        ax.plot([s[0], f[0]], [s[1], f[1]], "-", color="yellow", lw=0.4)
    d = pairs.distance
    points = [p for p in (raw, face) if len(p)]
    if points:
        stack = np.vstack(points)
        lo, hi = stack.min(axis=0) - 40, stack.max(axis=0) + 40
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(hi[1], lo[1])
    ends = f"d ends {d[0]:.1f} / {d[-1]:.1f}, mean {d.mean():.1f}" if len(d) else "no pairs"
    ax.set_title(
        f"{title}\nDelta_d {terms.delta_d:.1f}  P_conv {terms.p_conv:.1f}  "
        f"P_int {terms.p_int:.0f}\n{ends} px",
        fontsize=8,
    )
    ax.legend(fontsize=6, loc="upper right")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("db")
    parser.add_argument("photo")
    parser.add_argument("--variant", default="skof+pll")
    parser.add_argument("--experiment", default="C")
    parser.add_argument("--out", default=None, help="PNG (default PHOTO-VARIANT-curves.png)")
    args = parser.parse_args(argv)
    db = Path(args.db)
    root = db.parent / "dataset"
    folder = root / "photos" / args.experiment / args.photo
    rows = sqlite3.connect(f"file:{db}?mode=ro", uri=True).execute(
        "SELECT subject, score, result FROM sfo WHERE method = 'lilium' AND variant = ? "
        "AND photo = ? AND experiment = ? AND success = 1",
        (args.variant, args.photo, args.experiment),
    )
    results = {subject: (score, json.loads(result)) for subject, score, result in rows}
    truth = read_ground_truth(folder)
    if truth.subject not in results:
        print(f"{db}: no Lilium {args.variant} result of {args.photo} on its true skull")
        return 1
    wrong = min((s for s in results if s != truth.subject), key=lambda s: results[s][0])
    photo = read_photo(folder)
    centre = principal_point_of(photo.image_size_wh)
    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    panels = (
        (truth.subject, truth.camera, "true skull, true camera"),
        (truth.subject, Camera.from_dict(results[truth.subject][1]["camera"]), "true skull"),
        (wrong, Camera.from_dict(results[wrong][1]["camera"]), f"best wrong skull {wrong}"),
    )
    for ax, (subject, camera, label) in zip(axes, panels, strict=True):
        skull = read_skull(root / "subjects" / subject)
        score = results[subject][0]
        draw(ax, photo.image, PllTerm(skull, photo, centre), camera, f"{label} (score {score:.1f})")
    out = Path(args.out or f"{args.photo}-{args.variant}-curves.png")
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
