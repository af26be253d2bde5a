"""Pictures of P_pll's curves: a photo's true skull against its best-scoring wrong skull.

Run: ``.venv/bin/python benchmarks/studies/pll_curves.py DB PHOTO [--variant skof+pll] [--out PNG]``
on a database of :mod:`benchmarks.bench_identification` (or of any ``lilium experiment`` whose
generated dataset lies in ``dataset/`` beside the database; ``--axes-set`` and ``--repetition`` pick
the run, default the first of Exp. C). For the photo, three panels on the photo's chin-jaw (frontal)
or forehead (lateral) region: the true skull at the ground-truth camera, the true skull at the
camera Lilium found, and the wrong skull Lilium scored best at its camera. Each shows the skull
curve as detected (orange) and trimmed (red), the facial curve (cyan), every fourth pair (yellow),
and the terms Delta_d, P_conv, P_int with the end and mean distances in pixels.
"""

import argparse
import json
import sqlite3
import sys
from pathlib import Path

import matplotlib
import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.fitness.pll import pair_curves_batch, terms_from_pairs, trim_curves_batch
from lilium.geometry.camera import Camera, principal_point_of
from lilium.io.truth import read_ground_truth
from lilium.methods.lilium_terms import PllTerm, TermOff

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


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
    parser.add_argument("--axes-set", type=int, default=1, help="Exp. C axis set (A, B: 0)")
    parser.add_argument("--repetition", type=int, default=0)
    parser.add_argument("--out", default=None, help="PNG (default PHOTO-VARIANT-curves.png)")
    args = parser.parse_args(argv)
    db = Path(args.db)
    root = db.parent / "dataset"
    folder = root / "photos" / args.experiment / args.photo
    if not db.is_file() or not folder.is_dir():
        print(f"{db}: no database, or no photo folder {folder}")
        return 1
    rows = sqlite3.connect(f"file:{db}?mode=ro", uri=True).execute(
        "SELECT subject, axes_set, score, result FROM sfo WHERE method = 'lilium' AND "
        "variant = ? AND photo = ? AND experiment = ? AND axes_set = ? AND repetition = ? "
        "AND success = 1",
        (args.variant, args.photo, args.experiment, args.axes_set, args.repetition),
    )
    results = {
        subject: (axes_set, score, json.loads(result)) for subject, axes_set, score, result in rows
    }
    truth = read_ground_truth(folder)
    wrong = sorted((s for s in results if s != truth.subject), key=lambda s: results[s][1])
    if truth.subject not in results or not wrong:
        print(
            f"{db}: Lilium {args.variant} has no result of {args.photo} on its true skull "
            "and on a wrong one in that run"
        )
        return 1
    photo = read_photo(folder)
    centre = principal_point_of(photo.image_size_wh)
    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    true_result, wrong_result = results[truth.subject], results[wrong[0]]
    panels = (
        (truth.subject, truth.camera, "true skull, true camera", true_result[0]),
        (
            truth.subject,
            Camera.from_dict(true_result[2]["camera"]),
            f"true skull (score {true_result[1]:.1f})",
            true_result[0],
        ),
        (
            wrong[0],
            Camera.from_dict(wrong_result[2]["camera"]),
            f"best wrong skull {wrong[0]} (score {wrong_result[1]:.1f})",
            wrong_result[0],
        ),
    )
    for ax, (subject, camera, label, axes_set) in zip(axes, panels, strict=True):
        axes_file = root / "subjects" / subject / f"axes_{args.experiment}{axes_set}.json"
        skull = read_skull(
            root / "subjects" / subject, axes_path=axes_file if axes_file.is_file() else None
        )
        try:
            term = PllTerm(skull, photo, centre)
        except TermOff as exc:
            print(f"P_pll cannot apply to {args.photo} with skull {subject}: {exc}")
            return 1
        draw(ax, photo.image, term, camera, label)
    out = Path(args.out or f"{args.photo}-{args.variant}-curves.png")
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
