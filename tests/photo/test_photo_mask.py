"""The head mask on grayscale, sepia and faded prints (issue 55; docs/method/photo.md, "Head mask").

The reference head outline is the colour photo's own mask (on the colour astronaut: hair and
ears, docs/images/photo_mask.png). A washed-out grayscale print of the astronaut's
head-and-shoulders crop made the person segmentation return nothing, so the mask fell back to
the face outline (52 % of the head); ``benchmarks/studies/head_mask_prints.py`` measures every
print kind.
"""

import cv2
import numpy as np
import pytest

pytest.importorskip("ai_edge_litert")

from lilium.photo.analysis import analyse_face  # noqa: E402
from lilium.photo.mask import (  # noqa: E402
    head_mask,
    head_share_beyond_face,
    is_head_mask,
    polygon_mask,
)

#: Required of every print: the share of the reference head inside the mask, and the mask's
#: area outside the reference over the reference's area.
MIN_COVER = 0.90
MAX_OUTSIDE = 0.10


def _gray(image):
    return np.repeat(cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)[:, :, None], 3, axis=2)


def _sepia(image):
    g = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY).astype(float) / 255
    return np.clip(255 * (0.15 + 0.7 * np.stack([g, 0.78 * g, 0.55 * g], 2)), 0, 255).astype(
        np.uint8
    )


def _faded(image, contrast):
    f = image.astype(float)
    return np.clip(f.mean() + contrast * (f - f.mean()), 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def crop():
    from skimage import data

    image = np.ascontiguousarray(data.astronaut()[10:190, 150:300])
    return image, analyse_face(image).mask


@pytest.mark.parametrize(
    "kind, make",
    [
        ("grayscale", _gray),
        ("sepia", _sepia),
        ("faded sepia", lambda x: _faded(_sepia(x), 0.15)),
        ("faded grayscale", lambda x: _faded(_gray(x), 0.1)),
    ],
)
def test_prints_get_the_head_not_the_face(crop, kind, make):
    image, reference = crop
    assert is_head_mask(reference, analyse_face(image).mesh_xyz)
    found = analyse_face(make(image))
    cover = np.count_nonzero(found.mask & reference) / np.count_nonzero(reference)
    outside = np.count_nonzero(found.mask & ~reference) / np.count_nonzero(reference)
    assert cover >= MIN_COVER, kind
    assert outside <= MAX_OUTSIDE, kind
    assert is_head_mask(found.mask, found.mesh_xyz), kind


def test_the_face_outline_alone_is_not_a_head(crop):
    image, _ = crop
    found = analyse_face(image)
    face_only = head_mask(np.zeros(image.shape[:2]), found.mesh_xyz)
    assert head_share_beyond_face(face_only, found.mesh_xyz) == 0.0
    assert not is_head_mask(face_only, found.mesh_xyz)


def test_polygon_mask_fills_the_outline():
    square = [[2, 2], [7, 2], [7, 5], [2, 5]]
    mask = polygon_mask(square, (10, 8))
    assert mask.shape == (8, 10)
    assert mask[2:6, 2:8].all() and mask.sum() == 24
