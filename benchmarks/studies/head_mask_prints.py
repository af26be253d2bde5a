"""The head mask on grayscale, sepia, faded and scanned prints (a script; issue 55).

Two public-domain portraits that ship with our dependencies (scikit-image's ``astronaut``,
Matplotlib's ``grace_hopper.jpg``), whole and as head-and-shoulders crops, are turned into
prints: grayscale, sepia, faded (contrast around the mean times 0.3, 0.15, 0.1, 0.05), small
(120 px), and a faded print scanned with a white margin and a dark strip. Each print's head mask
(:func:`lilium.photo.analysis.analyse_face`) is compared with the colour photo's own mask, the
reference head outline (on the colour astronaut it holds hair and ears; docs/images/
photo_mask.png): ``cover`` = share of the reference inside the print's mask, ``outside`` = the
print's mask outside the reference over the reference's area, ``beyond`` =
:func:`lilium.photo.mask.head_share_beyond_face` (0: the face outline alone), ``head`` =
:func:`lilium.photo.mask.is_head_mask`. ``--plain`` runs the segmentation on the print as it is
(the mask before issue 55) instead of :func:`lilium.photo.mask.segmentation_input`; the
reference is the colour photo's mask from the same pipeline as the prints'.

Run (about 15 s)::

    PYTHONPATH=src python benchmarks/studies/head_mask_prints.py [--plain] [--png DIR]

``--png DIR`` writes one picture per print (dimmed: outside the mask; green: the mask's
outline; red: the reference's).
"""

import argparse
from pathlib import Path

import cv2
import matplotlib
import numpy as np
from PIL import Image
from skimage import data

from lilium.photo import analysis, mask

#: Head-and-shoulders crops (u0, v0, u1, v1) of the two portraits.
CROPS = {"astronaut": (150, 10, 300, 190), "grace_hopper": (150, 80, 390, 350)}


def portraits():
    """``{name: RGB image}``: the two portraits whole and cropped."""
    path = Path(matplotlib.get_data_path()) / "sample_data" / "grace_hopper.jpg"
    whole = {
        "astronaut": data.astronaut(),
        "grace_hopper": np.asarray(Image.open(path).convert("RGB")),
    }
    out = dict(whole)
    for name, (u0, v0, u1, v1) in CROPS.items():
        out[f"{name}_crop"] = np.ascontiguousarray(whole[name][v0:v1, u0:u1])
    return out


def grayscale(image):
    g = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    return np.repeat(g[:, :, None], 3, axis=2)


def sepia(image):
    g = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY).astype(float) / 255
    tinted = np.stack([g, 0.78 * g, 0.55 * g], axis=2)
    return np.clip(255 * (0.15 + 0.7 * tinted), 0, 255).astype(np.uint8)


def faded(image, contrast):
    f = image.astype(float)
    return np.clip(f.mean() + contrast * (f - f.mean()), 0, 255).astype(np.uint8)


def small(image, side=120):
    h, w = image.shape[:2]
    s = side / max(h, w)
    return cv2.resize(image, (round(w * s), round(h * s)), interpolation=cv2.INTER_AREA)


#: Margin of a scanned print, over its long side.
SCAN_MARGIN = 0.25


def scanned(image):
    """The print on a white scanner bed with a dark strip (the lid) along the top."""
    h, w = image.shape[:2]
    b = int(SCAN_MARGIN * max(h, w))
    out = np.full((h + 2 * b, w + 2 * b, 3), 245, np.uint8)
    out[b : b + h, b : b + w] = image
    out[: b // 3] = 10
    return out


PRINTS = {
    "colour": lambda x: x,
    "grayscale": grayscale,
    "sepia": sepia,
    "sepia faded 0.3": lambda x: faded(sepia(x), 0.3),
    "sepia faded 0.15": lambda x: faded(sepia(x), 0.15),
    "gray faded 0.1": lambda x: faded(grayscale(x), 0.1),
    "gray faded 0.05": lambda x: faded(grayscale(x), 0.05),
    "sepia small 120 px": lambda x: small(faded(sepia(x), 0.5)),
    "gray faded 0.1 scanned": lambda x: scanned(faded(grayscale(x), 0.1)),
    "sepia faded 0.15 scanned": lambda x: scanned(faded(sepia(x), 0.15)),
}


def reference_in(print_image, reference, kind):
    """The reference mask in the print's pixels (resized, or placed inside the scan's margin)."""
    if kind.endswith("scanned"):
        h, w = reference.shape
        b = int(SCAN_MARGIN * max(h, w))
        out = np.zeros(print_image.shape[:2], bool)
        out[b : b + h, b : b + w] = reference
        return out
    if print_image.shape[:2] != reference.shape:
        size = print_image.shape[1::-1]
        return cv2.resize(reference.astype(np.uint8), size, interpolation=cv2.INTER_NEAREST) > 0
    return reference


def picture(image, found, reference):
    out = image.astype(float)
    out[~found] *= 0.4
    out = out.astype(np.uint8)
    for m, colour in ((reference, (255, 0, 0)), (found, (0, 255, 0))):
        line = mask.mask_outline(m).astype(np.int32)
        if len(line):
            cv2.polylines(out, [line], True, colour, 1)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plain", action="store_true", help="segment the print as it is")
    parser.add_argument("--png", type=Path, help="folder for one picture per print")
    args = parser.parse_args(argv)
    if args.plain:  # the pipeline before issue 55
        analysis.segmentation_input = lambda image: image
    if args.png:
        args.png.mkdir(parents=True, exist_ok=True)
    print(f"{'portrait':18s} {'print':26s} {'cover':>6s} {'outside':>8s} {'beyond':>7s} head")
    worst = {}
    for name, image in portraits().items():
        reference = analysis.analyse_face(image).mask
        for kind, make in PRINTS.items():
            print_image = make(image)
            found = analysis.analyse_face(print_image)
            if not found:
                print(f"{name:18s} {kind:26s} no face ({found.message.split(';')[0]})")
                continue
            ref = reference_in(print_image, reference, kind)
            cover = np.count_nonzero(found.mask & ref) / np.count_nonzero(ref)
            outside = np.count_nonzero(found.mask & ~ref) / np.count_nonzero(ref)
            beyond = mask.head_share_beyond_face(found.mask, found.mesh_xyz)
            head = mask.is_head_mask(found.mask, found.mesh_xyz)
            print(f"{name:18s} {kind:26s} {cover:6.3f} {outside:8.3f} {beyond:7.2f} {head}")
            lo, hi = worst.get(kind, (1.0, 0.0))
            worst[kind] = (min(lo, cover), max(hi, outside))
            if args.png:
                slug = f"{name}_{kind}".replace(" ", "_").replace(".", "")
                sheet = picture(print_image, found.mask, ref)
                Image.fromarray(sheet).save(args.png / f"{slug}.png")
    print("\nper print kind: lowest cover, highest outside")
    for kind, (lo, hi) in worst.items():
        print(f"  {kind:26s} {lo:6.3f} {hi:8.3f}")


if __name__ == "__main__":
    main()
