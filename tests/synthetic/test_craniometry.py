"""Craniometric measurements of generated skulls and the published targets of the priors."""

import dataclasses

import numpy as np
import pytest

import lilium.synthetic.subjects as subjects
from lilium.synthetic.anatomy.bone import build_bone
from lilium.synthetic.anatomy.craniometry import PUBLISHED, Reference, measure
from lilium.synthetic.anatomy.landmarks import front_profile, locate_cranial_landmarks
from lilium.synthetic.anatomy.shape import SHAPE_PRIORS, draw_shape


def test_pooled_reference_by_hand():
    ref = Reference("x", 132.0, 123.0, 5.0, "howells")
    assert ref.mean_mm == 127.5
    assert ref.sd_mm == pytest.approx(np.sqrt(25.0 + 4.5**2))


def test_priors_stay_inside_their_bounds_and_published_table_is_complete():
    assert set(PUBLISHED) >= {
        "cranial_length",
        "cranial_breadth",
        "bizygomatic_breadth",
        "bigonial_breadth",
        "upper_face_height",
        "nasal_breadth",
        "orbital_breadth",
    }
    for prior in SHAPE_PRIORS.values():
        assert prior.lo < prior.mean < prior.hi and prior.sd > 0


def test_narrow_face_measures_its_own_bizygomatic_breadth(monkeypatch):
    # Before the temporal root scaled with the face width, zygion never measured below
    # 128.6 mm: a 122 mm face measured about 128.6.
    shape = dataclasses.replace(draw_shape(5), face_width=122.0)
    monkeypatch.setattr(subjects, "draw_shape", lambda rng: shape)
    s = subjects.make_subject("narrow", 1)
    m = measure(s.skull_vertices_mm, s.cranial_landmarks)
    assert m["bizygomatic_breadth"] == pytest.approx(122.0, abs=1.0)
    assert 160.0 < m["cranial_length"] < 200.0 and 120.0 < m["cranial_breadth"] < 160.0
    assert m["bigonial_breadth"] == pytest.approx(shape.jaw_width + 8.5, abs=2.0)


def _bone_landmarks(shape):
    bone, design = build_bone(shape, np.random.default_rng(1))
    return bone, locate_cranial_landmarks(bone, design)


def test_dacryon_and_ectoconchion_lie_on_the_orbital_margin():
    # Before the orbital entrance, the face block closed the medial third of the opening:
    # dacryon lay about 22 mm off the midline and dacryon-ectoconchion measured about 30 mm.
    bone, lm = _bone_landmarks(dataclasses.replace(draw_shape(5), orbit=1.0))
    for sx, sfx in ((1, "_l"), (-1, "_r")):
        d, ek = lm["dacryon" + sfx], lm["ectoconchion" + sfx]
        assert 9.0 < sx * d[0] < 17.0
        assert np.linalg.norm(d - ek) == pytest.approx(40.0, abs=2.5)
        # On the edge: 2 mm into the opening a frontal ray falls deep into the orbit; 2 mm
        # out it meets the bone within a few mm of the landmark.
        for p, inward in ((d, sx), (ek, -sx)):
            z_in = front_profile(bone, p[0] + 2.0 * inward, np.array([p[1]]))[0, 2]
            z_out = front_profile(bone, p[0] - 2.0 * inward, np.array([p[1]]))[0, 2]
            assert p[2] - z_in > 10.0 and 0.0 < z_out - p[2] < 7.0


def test_nasal_breadth_follows_the_nasal_width_factor():
    # With the nasal cavity unscaled its walls made the aperture's margins: alare-alare grew
    # about 17 mm per unit of the factor instead of about 21.
    base = draw_shape(5)
    nlb = []
    for factor in (0.9, 1.2):
        _, lm = _bone_landmarks(dataclasses.replace(base, nasal_width=factor))
        nlb.append(np.linalg.norm(lm["alare_l"] - lm["alare_r"]))
    assert nlb[1] - nlb[0] > 5.5


@pytest.mark.slow
def test_generated_spread_matches_published():
    """20 subjects: means within 0.6 published SD, SDs within 0.6-1.4 x (docs/population.md)."""
    values = {k: [] for k in PUBLISHED}
    for s in subjects.make_subjects(20, seed=0):
        for k, v in measure(s.skull_vertices_mm, s.cranial_landmarks).items():
            values[k].append(v)
    for key, ref in PUBLISHED.items():
        x = np.array(values[key])
        assert abs(x.mean() - ref.mean_mm) < 0.6 * ref.sd_mm, key
        assert 0.6 < x.std(ddof=1) / ref.sd_mm < 1.4, key
