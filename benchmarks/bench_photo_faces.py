"""Faces found in group photos, and the detector's time on large photos (``lilium photo``).

Builds group photos offline from scikit-image's astronaut (public domain): copies of her head,
scaled so that the detector's face box is ``FACE`` px wide, pasted side by side on a gray,
softly textured canvas; counts the faces ``lilium photo`` lists there
(:func:`lilium.photo.analysis.find_faces`; before it existed, the detector's faces, which
``analyse_face`` numbered) -- a hit: a box centre within half a face width of a pasted face;
every other box is a false face. Then times the search on such canvases of 12, 24 and 100 MP
with four 60 px faces, and counts the faces found on scikit-image's pictures without a face
(coffee, chelsea, rocket, ...) enlarged to 12 MP. With ``--command``, also times the whole
``lilium photo`` on the 12 and 100 MP canvases (saved as JPEG). One core; wall and CPU seconds.

    python benchmarks/bench_photo_faces.py [--sizes 40 60 100 230] [--canvas 2000 1428]
        [--megapixels 12 24 100] [--command] [--json out.json]
"""

import argparse
import json
import time

import cv2
import numpy as np

#: The astronaut's head crop (rows, columns) and the detector's face box inside it (u0, v0, w).
HEAD_ROWS, HEAD_COLS = slice(0, 240), slice(110, 340)
FACE_IN_HEAD = (68.0, 81.0, 94.0)


def group_photo(face_px, size_wh, n_faces=2, rng=0):
    """A ``(H, W, 3)`` uint8 canvas with ``n_faces`` heads side by side, and their face centres
    ``(n_faces, 2)`` uv."""
    from skimage import data

    rng = np.random.default_rng(rng)
    w, h = size_wh
    noise = cv2.resize(rng.normal(0, 12, (max(2, h // 64), max(2, w // 64))), (w, h))
    canvas = np.clip(150 + noise[..., None] + np.zeros(3), 0, 255).astype(np.uint8)
    head = data.astronaut()[HEAD_ROWS, HEAD_COLS]
    s = face_px / FACE_IN_HEAD[2]
    head = cv2.resize(head, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
    hh, hw = head.shape[:2]
    gap = w / (n_faces + 1)
    centres = []
    for k in range(n_faces):
        u0, v0 = int(gap * (k + 1) - hw / 2), int(h / 2 - hh / 2)
        canvas[v0 : v0 + hh, u0 : u0 + hw] = head
        u, v, fw = (x * s for x in FACE_IN_HEAD)
        centres.append((u0 + u + fw / 2, v0 + v + fw / 2))
    return canvas, np.array(centres)


def count(faces, centres, face_px):
    """(hits, false faces) of ``detect_faces``' result against the pasted faces."""
    boxes = np.array([f.box_uv if hasattr(f, "box_uv") else f[1] for f in faces])
    boxes = boxes.reshape(-1, 4)
    found = (boxes[:, :2] + boxes[:, 2:]) / 2
    near = np.linalg.norm(found[:, None] - centres[None], axis=2) < face_px / 2
    return int(near.any(axis=0).sum()), int((~near.any(axis=1)).sum())


def time_command(image):
    """Seconds of ``lilium photo`` (in this process, models loaded) on ``image`` as a JPEG."""
    import tempfile
    from pathlib import Path

    from PIL import Image

    from lilium.cli.main import main as lilium

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "group.jpg"
        Image.fromarray(image).save(path, quality=90)
        start = time.perf_counter()
        lilium(["photo", str(path), "--out", str(Path(tmp) / "out")])
        return time.perf_counter() - start


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=float, nargs="+", default=[40, 60, 100, 230])
    parser.add_argument("--canvas", type=int, nargs=2, default=[2000, 1428])
    parser.add_argument("--megapixels", type=float, nargs="*", default=[12, 24, 100])
    parser.add_argument("--command", action="store_true", help="time lilium photo too")
    parser.add_argument("--json", help="write the figures here too")
    args = parser.parse_args(argv)
    from lilium.photo import analysis, runtime

    find = getattr(analysis, "find_faces", runtime.detect_faces)
    find(np.zeros((64, 64, 3), np.uint8))  # load the model
    rows = {"group": [], "time": [], "no_face": []}
    print(f"group photo {args.canvas[0]}x{args.canvas[1]}, two faces:")
    for face_px in args.sizes:
        image, centres = group_photo(face_px, args.canvas)
        hits, false = count(find(image), centres, face_px)
        rows["group"].append({"face_px": face_px, "found": hits, "false": false})
        print(f"  face {face_px:5.0f} px: {hits}/2 found, {false} false")
    for mp in args.megapixels:
        w = int(round(np.sqrt(mp * 1e6 * 4 / 3)))
        h = int(round(w * 3 / 4))
        image, centres = group_photo(60, (w, h), n_faces=4)
        start, cpu = time.perf_counter(), time.process_time()
        faces = find(image)
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        hits, false = count(faces, centres, 60)
        rows["time"].append(
            {"megapixels": mp, "seconds": seconds, "cpu": cpu, "found": hits, "false": false}
        )
        print(
            f"  {w}x{h} ({mp:g} MP), four 60 px faces: {seconds:.2f} s ({cpu:.2f} s CPU), "
            f"{hits}/4 found, {false} false"
        )
        if args.command and mp in (12, 100):
            rows["time"][-1]["command_seconds"] = time_command(image)
            print(f"    lilium photo: {rows['time'][-1]['command_seconds']:.1f} s")
        del image
    from skimage import data

    for name in (
        "coffee",
        "chelsea",
        "rocket",
        "hubble_deep_field",
        "immunohistochemistry",
        "colorwheel",
        "retina",
        "logo",
    ):
        picture = getattr(data, name)()[..., :3]
        if picture.dtype != np.uint8:
            picture = (255 * picture).astype(np.uint8)
        s = np.sqrt(12e6 / (picture.shape[0] * picture.shape[1]))
        picture = cv2.resize(picture, None, fx=s, fy=s, interpolation=cv2.INTER_CUBIC)
        faces = find(picture)
        scores = [round(float(getattr(f, "score", f[0])), 2) for f in faces]
        rows["no_face"].append({"picture": name, "faces": len(faces), "scores": scores})
        print(f"  {name} at 12 MP: {len(faces)} faces {scores}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
