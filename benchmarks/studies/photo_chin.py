"""The face mesh's chin points (pogonion, gnathion) against the noise-free landmarks of rendered
frontal photos (a script; docs/method/photo.md, "The chin").

For every frontal photo folder (``*_f*``) under the given dataset folders (``lilium synth`` or
the real-head datasets, their ``photos/A``), it runs the face analysis of ``lilium photo`` on
the image and prints the error of each chin point against ``ground_truth.landmarks_noise_free``
in % of the true exocanthion distance (eye-corner distance), with the eye corners' own error
for comparison; a render the detector or the mesh rejects is listed as such.

Run (about 0.1 s a photo)::

    PYTHONPATH=src python benchmarks/studies/photo_chin.py DATASET [DATASET ...]
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from lilium.io.jsonio import read_json
from lilium.photo.analysis import analyse_face

POINTS = ("pogonion", "gnathion", "exocanthion_r", "exocanthion_l")
BOUND = 0.05


def folders(roots):
    for root in roots:
        root = Path(root)
        base = root / "photos" / "A" if (root / "photos" / "A").is_dir() else root
        # ``*_nm_*``: the same photos of the head without its mandible, left out.
        yield from sorted(
            p for p in base.iterdir() if p.is_dir() and "_f" in p.name and "_nm_" not in p.name
        )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("datasets", nargs="+")
    args = parser.parse_args(argv)
    print(f"{'photo':12s} " + " ".join(f"{n[:13]:>13s}" for n in POINTS) + "   (% of eye corners)")
    errors = {n: [] for n in POINTS}
    for folder in folders(args.datasets):
        truth = read_json(folder / "photo.json")["ground_truth"]["landmarks_noise_free"]
        if "pogonion" not in truth:
            print(f"{folder.name:12s} no chin in the truth (head cut above it)")
            continue
        image = np.asarray(Image.open(folder / "image.png").convert("RGB"))
        found = analyse_face(image)
        if not found:
            print(f"{folder.name:12s} {found.message.split(';')[0]}")
            continue
        scale = np.linalg.norm(np.subtract(truth["exocanthion_l"], truth["exocanthion_r"]))
        cells = []
        for n in POINTS:
            err = float(np.linalg.norm(found.landmarks[n] - np.asarray(truth[n])) / scale)
            errors[n].append(err)
            cells.append(f"{100 * err:13.1f}")
        yaw = found.angles_deg["yaw"]
        print(f"{folder.name:12s} " + " ".join(cells) + f"   yaw {yaw:.0f}")
    for label, fn in (("median", np.median), ("worst", np.max)):
        cells = [f"{100 * fn(e):13.1f}" if e else f"{'.':>13s}" for e in errors.values()]
        print(f"{label:12s} " + " ".join(cells))
    cells = [f"{sum(x <= BOUND for x in e):>9d}/{len(e):<3d}" for e in errors.values()]
    print(f"{'within 5 %':12s} " + " ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
