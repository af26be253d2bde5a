"""Make docs/images/face_mask.png from a generated photo folder and its face mask.

    lilium demo --out /tmp/demo        # seed 0: the frontal photo photos/C/s01_f00
    python docs/images/face_mask_figure.py /tmp/demo/data/photos/C/s01_f00 docs/images/face_mask.png

Three panels of the same photo: the face mask as Lilium wants it (the head as seen: face,
forehead, hair and ears, down to the upper neck), the mask itself, and a mask drawn from the
hairline to the chin without the ears (too small: the vault then counts as outside the face).
"""

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

PANEL_HEIGHT = 300
GOOD_RGB, BAD_RGB = np.array([40, 200, 90]), np.array([230, 50, 50])


def _tint(image, mask, rgb):
    out = image.astype(float)
    out[mask] = 0.6 * out[mask] + 0.4 * rgb
    edge = mask ^ np.pad(mask, 1, mode="edge")[2:, 1:-1] | mask ^ np.pad(mask, 1)[1:-1, 2:]
    out[edge] = rgb
    return out.astype(np.uint8)


def main(photo_dir, out_path):
    photo_dir = Path(photo_dir)
    image = np.asarray(Image.open(photo_dir / "image.png").convert("RGB"))
    mask = np.asarray(Image.open(photo_dir / "face_mask.png").convert("L")) > 0
    lm = json.loads((photo_dir / "photo.json").read_text())["landmarks"]
    rows, cols = np.nonzero(mask)
    pad = 30
    v0, v1 = max(0, rows.min() - pad), min(mask.shape[0], rows.max() + pad)
    u0, u1 = max(0, cols.min() - pad), min(mask.shape[1], cols.max() + pad)
    # "Hairline to chin, no ears": cut above metopion and outside the zygia.
    small = mask.copy()
    small[: int(lm["metopion"][1])] = False
    lo = int(min(lm["zygion_r"][0], lm["zygion_l"][0]))
    hi = int(max(lm["zygion_r"][0], lm["zygion_l"][0]))
    small[:, :lo] = False
    small[:, hi + 1 :] = False
    panels = [
        (_tint(image, mask, GOOD_RGB), "face mask: the head as seen"),
        (np.repeat((mask * 255).astype(np.uint8)[..., None], 3, axis=2), "face_mask.png"),
        (_tint(image, small, BAD_RGB), "not this: hairline to chin"),
    ]
    tiles = []
    for array, caption in panels:
        tile = Image.fromarray(array[v0:v1, u0:u1])
        tile = tile.resize(
            (round(tile.width * PANEL_HEIGHT / tile.height), PANEL_HEIGHT),
            Image.Resampling.LANCZOS,
        )
        draw = ImageDraw.Draw(tile)
        draw.rectangle((0, 0, tile.width, 16), fill=(255, 255, 255))
        draw.text((4, 2), caption, fill=(0, 0, 0))
        tiles.append(tile)
    sheet = Image.new("RGB", (sum(t.width for t in tiles) + 8 * (len(tiles) - 1), PANEL_HEIGHT))
    sheet.paste((255, 255, 255), (0, 0, sheet.width, sheet.height))
    x = 0
    for tile in tiles:
        sheet.paste(tile, (x, 0))
        x += tile.width + 8
    sheet = sheet.quantize(128, method=Image.Quantize.MEDIANCUT)
    sheet.save(out_path, optimize=True)
    print(out_path, sheet.size, Path(out_path).stat().st_size, "bytes")


if __name__ == "__main__":
    main(*sys.argv[1:3])
