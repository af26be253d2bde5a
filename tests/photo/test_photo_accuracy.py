"""Automatic landmarks against landmarks placed by hand on real public-domain portraits.

The portraits ship with our dependencies: scikit-image's ``astronaut`` (Eileen Collins, NASA,
public domain) and Matplotlib's ``grace_hopper.jpg`` (US Navy, public domain). No other
public-domain portrait ships with an installed package or one we could install (Pillow's
``hopper`` is the same photograph, scikit-image's ``camera`` is a profile, the others' licences
do not allow it), so two portraits is all the evidence: thin, and ``docs/method/photo.md`` says so.

The points below were placed by hand on zoomed crops (upscaled, with a pixel grid; pixels,
u = column, v = row); only points visible in the photo are listed. Placement rules for the
points beyond the eyes, nose and mouth (soft tissue, docs/method/skull.md, frontal view):

- the **midline** points (nasion, pogonion, gnathion) lie on the face's midline, the line
  through the hand-placed subnasale perpendicular to the hand-placed exocanthion line; only
  their height ``v`` is read on the image;
- **gnathion**: the chin's lower outline on the midline, at the strongest brightness step
  from the lit chin to the shadow under it (the mean of the 7-8 columns around the midline);
- **pogonion**: the chin's most prominent point seen from the front, midway between the
  mentolabial sulcus (the darkest row below the lower lip) and gnathion;
- **nasion**: the deepest point of the nasal root, at the height of the upper-eyelid creases
  (astronaut; under the bridge of Grace Hopper's glasses, not listed there);
- **zygion**: the face outline just in front of the ear at the height of the zygomatic arch
  (below the lower eyelid, at the tragus); its height is uncertain by several pixels;
- **gonion**: the jaw angle, where the near-vertical outline below the ear lobe turns into the
  mandible's lower border (astronaut; Grace Hopper's jaw angle is lost in jowls, not listed).

Run this file with ``-s`` to print the per-landmark table.
"""

from pathlib import Path

import matplotlib
import numpy as np
import pytest

pytest.importorskip("ai_edge_litert")

from lilium.photo.analysis import analyse_face  # noqa: E402
from lilium.photo.landmarks import MESH_LANDMARKS, TEMPLATE, TRACKED  # noqa: E402

#: Median and worst error of the tracked landmarks, over the eye-corner distance (issue 19).
MEDIAN_TRACKED = 0.05
WORST_TRACKED = 0.10
#: A template point is promoted to tracked when it lies within this fraction of the
#: eye-corner distance of the hand-placed point on every face where it is visible, and it is
#: measured on at least PROMOTE_MIN_FACES faces (issue 25 item 6 asked two portraits; issue 55
#: ten faces, real renders and portraits with hand marks: two portraits here, and MediaPipe
#: finds no usable face on the renders, benchmarks/studies/photo_chin.py).
PROMOTE_BOUND = 0.05
PROMOTE_MIN_FACES = 10

HAND = {
    "astronaut": {
        "exocanthion_r": (191.8, 100.3),
        "endocanthion_r": (213.3, 101.5),
        "exocanthion_l": (258.5, 102.8),
        "endocanthion_l": (235.3, 103.3),
        "alare_r": (207.0, 127.5),
        "alare_l": (238.0, 128.0),
        "subnasale": (224.0, 132.0),
        "labiale_superius": (222.5, 137.8),
        "cheilion_r": (202.3, 139.5),
        "cheilion_l": (244.0, 140.5),
        "nasion": (225.3, 96.5),
        "pogonion": (222.7, 166.3),
        "gnathion": (222.2, 177.5),
        "zygion_r": (181.5, 113.0),
        "zygion_l": (265.5, 115.0),
        "gonion_r": (184.0, 148.0),
        "gonion_l": (263.5, 151.0),
    },
    "grace_hopper": {
        "exocanthion_r": (208.0, 191.0),
        "endocanthion_r": (236.0, 191.0),
        "exocanthion_l": (321.0, 186.0),
        "endocanthion_l": (292.0, 189.0),
        "alare_r": (239.5, 241.5),
        "alare_l": (294.5, 240.0),
        "subnasale": (266.6, 251.6),
        "labiale_superius": (266.6, 271.6),
        "cheilion_r": (229.5, 279.2),
        "cheilion_l": (305.2, 276.6),
        "pogonion": (269.3, 311.8),
        "gnathion": (269.7, 329.5),
        "zygion_r": (186.0, 212.0),
        "zygion_l": (348.0, 212.0),
    },
}


def portrait(name):
    if name == "astronaut":
        from skimage import data

        return data.astronaut()
    from PIL import Image

    path = Path(matplotlib.get_data_path()) / "sample_data" / "grace_hopper.jpg"
    return np.asarray(Image.open(path).convert("RGB"))


def errors(name):
    """Per landmark: (error px, error / hand eye-corner distance, quality)."""
    hand = {k: np.array(v) for k, v in HAND[name].items()}
    found = analyse_face(portrait(name))
    assert found, found.message
    scale = np.linalg.norm(hand["exocanthion_l"] - hand["exocanthion_r"])
    return {
        k: (
            float(np.linalg.norm(found.landmarks[k] - p)),
            float(np.linalg.norm(found.landmarks[k] - p) / scale),
            MESH_LANDMARKS[k][1],
        )
        for k, p in hand.items()
    }


@pytest.fixture(scope="module")
def tables():
    return {name: errors(name) for name in sorted(HAND)}


@pytest.mark.parametrize("name", sorted(HAND))
def test_tracked_landmarks_match_the_hand_placed_ones(tables, name):
    table = tables[name]
    print(f"\n{name}: landmark, mesh vertex, error px, % of exocanthion distance, quality")
    for k, (px, rel, quality) in table.items():
        print(f"  {k:18s} {MESH_LANDMARKS[k][0]:4d} {px:5.1f} {100 * rel:5.1f}  {quality}")
    tracked = [rel for _, rel, q in table.values() if q == TRACKED]
    print(f"  median tracked {100 * np.median(tracked):.1f} %, worst {100 * max(tracked):.1f} %")
    assert np.median(tracked) <= MEDIAN_TRACKED
    assert max(tracked) <= WORST_TRACKED


def test_only_points_within_the_bound_on_every_portrait_are_tracked(tables):
    """Issues 25 and 55: no point beyond the eyes, nose and mouth is measured on ten faces, so all
    stay template, the chin points included (within the bound on both portraits, not on ten)."""
    measured = {}
    for table in tables.values():
        for k, (_, rel, _) in table.items():
            measured.setdefault(k, []).append(rel)
    beyond_eyes_nose_mouth = ("nasion", "pogonion", "gnathion", "zygion", "gonion")
    for k, rels in measured.items():
        if not k.startswith(beyond_eyes_nose_mouth):
            continue
        within = len(rels) >= PROMOTE_MIN_FACES and max(rels) <= PROMOTE_BOUND
        assert (MESH_LANDMARKS[k][1] == TRACKED) == within, (k, [round(100 * r, 1) for r in rels])
    assert MESH_LANDMARKS["pogonion"][1] == MESH_LANDMARKS["gnathion"][1] == TEMPLATE
