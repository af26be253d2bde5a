"""Profile landmarks (``lilium.photo.profile``) against the noise-free landmarks of rendered
lateral photos (a script; docs/method/photo.md, "Profiles").

For every lateral photo folder (``*_l*``) under the given dataset folders (``lilium synth`` or
the real-head datasets, their ``photos/A``), it reads the profile twice: from the person
segmentation of the image (what ``lilium photo`` does) and from the render's own head mask
(``face_mask.png``, no segmentation error), and prints each landmark's error against
``ground_truth.landmarks_noise_free`` in % of the face height (true nasion to gnathion; a head
cut above the chin, the Cranium scan, has no gnathion: nasion to subnasale times
``NS_TO_FACE_HEIGHT``). Summary: per landmark, the median and worst error, and
how many photos are within 5 %.

Run (about 1 s a photo)::

    PYTHONPATH=src python benchmarks/studies/photo_profile.py DATASET [DATASET ...] [--mask-only]

e.g. ``lilium synth --out /tmp/syn --subjects 6 --photos 2`` then ``... /tmp/syn``.
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from lilium.io.jsonio import read_json
from lilium.photo.profile import PROFILE_LANDMARKS, person_silhouette, read_profile

#: Nasion-subnasale over nasion-gnathion in adults (about 0.43: 52 of 121 mm, Farkas), for heads
#: cut above the chin (the Cranium scan ends at the upper lip).
NS_TO_FACE_HEIGHT = 1 / 0.43
BOUND = 0.05


def face_height(truth):
    if "gnathion" in truth:
        return float(np.linalg.norm(np.subtract(truth["gnathion"], truth["nasion"])))
    nasion_subnasale = np.subtract(truth["subnasale"], truth["nasion"])
    return NS_TO_FACE_HEIGHT * float(np.linalg.norm(nasion_subnasale))


def folders(roots):
    for root in roots:
        root = Path(root)
        base = root / "photos" / "A" if (root / "photos" / "A").is_dir() else root
        # ``*_nm_*``: the same photos of the head without its mandible, left out.
        yield from sorted(
            p for p in base.iterdir() if p.is_dir() and "_l" in p.name and "_nm_" not in p.name
        )


def measure(folder, use_segmentation):
    meta = read_json(folder / "photo.json")
    truth = meta["ground_truth"]["landmarks_noise_free"]
    image = np.asarray(Image.open(folder / "image.png").convert("RGB"))
    if use_segmentation:
        mask = person_silhouette(image)
    else:
        mask = np.asarray(Image.open(folder / "face_mask.png")) > 0
    found = read_profile(mask)
    scale = face_height(truth)
    row = {"view_ok": found.view == meta["view"], "message": found.message}
    for name in PROFILE_LANDMARKS:
        if name in truth and name in found.landmarks:
            err = np.linalg.norm(found.landmarks[name] - np.asarray(truth[name])) / scale
            row[name] = (float(err), found.sources[name]["quality"])
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("datasets", nargs="+")
    parser.add_argument("--mask-only", action="store_true", help="skip the segmentation")
    args = parser.parse_args(argv)
    modes = [("render mask", False)] + ([] if args.mask_only else [("segmentation", True)])
    for label, seg in modes:
        rows = {f.name: measure(f, seg) for f in folders(args.datasets)}
        print(f"\n== {label}: error in % of the face height (t: tracked, -: template)")
        print(f"{'photo':12s} view " + " ".join(f"{n[:9]:>9s}" for n in PROFILE_LANDMARKS))
        for name, row in rows.items():
            cells = []
            for n in PROFILE_LANDMARKS:
                if n in row:
                    err, q = row[n]
                    cells.append(f"{100 * err:8.1f}{'t' if q == 'tracked' else '-'}")
                else:
                    cells.append(f"{'.':>9s}")
            view = "ok" if row["view_ok"] else "BAD"
            print(f"{name:12s} {view:4s} " + " ".join(cells) + f"  {row['message']}")
        print(f"{'median':12s}      ", end="")
        for n in PROFILE_LANDMARKS:
            errs = [r[n][0] for r in rows.values() if n in r]
            print(f"{100 * np.median(errs):9.1f}" if errs else f"{'.':>9s}", end=" ")
        print(f"\n{'worst':12s}      ", end="")
        for n in PROFILE_LANDMARKS:
            errs = [r[n][0] for r in rows.values() if n in r]
            print(f"{100 * max(errs):9.1f}" if errs else f"{'.':>9s}", end=" ")
        print(f"\n{'within 5 %':12s}      ", end="")
        for n in PROFILE_LANDMARKS:
            errs = [r[n][0] for r in rows.values() if n in r]
            print(f"{sum(e <= BOUND for e in errs):>5d}/{len(errs):<3d}", end=" ")
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
