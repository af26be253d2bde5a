"""The generated face's chin-jaw outline follows the mandible (issue 20).

The facial chin-jaw curve of ``face_curve.json`` is the outline of the skin above the jaw-line
cut. A cut by a plane through gnathion and the gonia is seen nearly edge-on from the front, so
the facial curve came out flat whatever the jaw's shape while the bony chin's outline is a U:
P_pll then penalised the true skull at its true camera. Measured on the 8 frontal photos of a
generated Exp. C set (seed 0): the facial curve's rise (lowest point to the mean of its end
tenths, pixels) was a median 0.46 of the trimmed skull curve's with the plane and 0.88 with the
cut that follows the bone.
"""

from pathlib import Path

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.fitness.pll import trim_curves_batch
from lilium.geometry.camera import principal_point_of
from lilium.io.truth import read_ground_truth
from lilium.methods.lilium_terms import PllTerm
from lilium.synthetic.dataset import generate_dataset
from lilium.synthetic.photos import CameraRanges

RANGES = CameraRanges(image_sizes=((1280, 960), (1600, 1200)))


def rise_px(curve):
    """How far the lowest point of a chin curve ``(N, 2)`` lies below the mean of its ends."""
    curve = curve[np.argsort(curve[:, 0])]
    n = max(1, len(curve) // 10)
    return curve[:, 1].max() - 0.5 * (curve[:n, 1].mean() + curve[-n:, 1].mean())


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("jaw")
    generate_dataset(root, 3, 1, seed=0, experiments=("A",), workers=1, ranges=RANGES)
    return root


def test_facial_chin_curve_rises_with_the_bony_one(dataset):
    ratios = []
    for folder in sorted(Path(dataset, "photos", "A").glob("*_f00")):
        photo, truth = read_photo(folder, load_image=False), read_ground_truth(folder)
        skull = read_skull(dataset / "subjects" / truth.subject)
        term = PllTerm(skull, photo, principal_point_of(photo.image_size_wh))
        cameras = truth.camera.as_batch()
        curves = term.context.skull_curves(cameras.project(term.region_vertices_mm))
        skull_curve = trim_curves_batch(curves, term.context.face_index)[0].curve(0)
        assert rise_px(skull_curve) > 5.0  # the bony chin's outline is a U
        ratios.append(rise_px(term.context.face_curve) / rise_px(skull_curve))
    assert len(ratios) == 3
    assert np.median(ratios) > 0.7, ratios
