"""Make docs/images/photo_landmarks.png: hand marks against the automatic landmarks.

    cd docs/images && PYTHONPATH=../../src:../../tests python photo_landmarks_figure.py out.png

The faces of both public-domain portraits of ``tests/photo/test_photo_accuracy.py`` (scikit-image's
astronaut, Matplotlib's Grace Hopper), enlarged: green rings = the hand marks of its ``HAND``
table (eyes, nose, mouth, chin, zygion, gonion), red dots = tracked automatic landmarks, blue
dots = template ones, each joined to its hand mark by a thin line.
"""

import sys

from PIL import Image, ImageDraw

from lilium.photo.analysis import analyse_face
from lilium.photo.landmarks import MESH_LANDMARKS, TRACKED
from test_photo_accuracy import HAND, portrait

#: Crop (u0, v0, u1, v1) of each portrait and its enlargement.
CROPS = {"astronaut": ((160, 80, 290, 190), 3), "grace_hopper": ((150, 160, 380, 350), 1.75)}
HAND_RGB, TRACKED_RGB, TEMPLATE_RGB = (40, 220, 90), (235, 40, 40), (40, 110, 250)


def panel(name):
    (u0, v0, u1, v1), scale = CROPS[name]
    image = portrait(name)
    found = analyse_face(image)
    crop = Image.fromarray(image[v0:v1, u0:u1])
    crop = crop.resize((round((u1 - u0) * scale), round((v1 - v0) * scale)), Image.LANCZOS)
    draw = ImageDraw.Draw(crop)

    def xy(uv):
        return ((uv[0] - u0 + 0.5) * scale, (uv[1] - v0 + 0.5) * scale)

    for key, hand in HAND[name].items():
        (hx, hy), (ax, ay) = xy(hand), xy(found.landmarks[key])
        rgb = TRACKED_RGB if MESH_LANDMARKS[key][1] == TRACKED else TEMPLATE_RGB
        draw.line([(hx, hy), (ax, ay)], fill=rgb, width=1)
        draw.ellipse([hx - 5, hy - 5, hx + 5, hy + 5], outline=HAND_RGB, width=2)
        draw.ellipse([ax - 3, ay - 3, ax + 3, ay + 3], fill=rgb)
    return crop


def main(out_path):
    panels = [panel(name) for name in sorted(CROPS)]
    height = max(p.height for p in panels)
    sheet = Image.new("RGB", (sum(p.width for p in panels) + 10, height), "white")
    x = 0
    for p in panels:
        sheet.paste(p, (x, 0))
        x += p.width + 10
    sheet.quantize(colors=192, dither=Image.Dither.NONE).save(out_path, optimize=True)


if __name__ == "__main__":
    main(sys.argv[1])
