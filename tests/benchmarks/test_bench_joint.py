"""benchmarks/bench_joint.py's off-centre priors
(docs/decisions/0010-joint-sfo-cameras-on-prior-edges.md, "The joint SFO's cameras on
the edge of the priors")."""

import sys
from pathlib import Path

import numpy as np

from lilium.fitness.camera_penalty import CameraPriors
from lilium.inputs import Photo

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_joint  # noqa: E402


def _photo(photo_id, focal=(950.0, 1050.0), scd=(900.0, 1100.0)):
    return Photo(
        id=photo_id,
        image_size_wh=(640, 480),
        view="frontal",
        landmarks_uv={"n": np.array([320.0, 200.0])},
        priors=CameraPriors(
            focal_px=focal, scd_mm=scd, head_rotation_skull2cam=np.eye(3), head_tolerance_deg=10.0
        ),
    )


def test_off_centre_priors_keep_widths_and_the_truth_inside():
    lo, hi = bench_joint.OFF_CENTRE_RANGE
    positions = []
    for k in range(40):
        photo = _photo(f"s{k:02d}_f00")
        moved = bench_joint.off_centre_priors(photo, seed=0)
        for key, truth in (("focal_px", 1000.0), ("scd_mm", 1000.0)):
            a, b = getattr(moved.priors, key)
            a0, b0 = getattr(photo.priors, key)
            assert np.isclose(b - a, b0 - a0)
            q = (truth - a) / (b - a)
            assert lo <= q <= hi
            positions.append(q)
        assert moved.priors.head_tolerance_deg == 10.0
        np.testing.assert_array_equal(moved.priors.head_rotation_skull2cam, np.eye(3))
    # drawn, not fixed: the positions spread over the range, and both sides of the centre
    assert min(positions) < 0.3 and max(positions) > 0.7


def test_off_centre_priors_repeat_per_seed_and_photo():
    photo = _photo("s01_f00")
    one = bench_joint.off_centre_priors(photo, seed=3).priors.focal_px
    assert bench_joint.off_centre_priors(photo, seed=3).priors.focal_px == one
    assert bench_joint.off_centre_priors(photo, seed=4).priors.focal_px != one
    assert bench_joint.off_centre_priors(_photo("s02_f00"), seed=3).priors.focal_px != one


def test_off_centre_priors_leave_a_missing_prior_missing():
    photo = _photo("s01_f00", scd=None)
    moved = bench_joint.off_centre_priors(photo, seed=0)
    assert moved.priors.scd_mm is None
    assert moved.priors.focal_px != photo.priors.focal_px
