import numpy as np
import pytest

from lilium.evaluation.metrics import (
    back_projection_error,
    back_projection_error_from_dicts,
    back_projection_errors,
    implausible_sfo,
    rank_of_true,
)
from lilium.geometry.camera import Camera, principal_point_of
from lilium.geometry.rotations import rotvec_to_matrix


def _camera():
    T = np.eye(4)
    T[:3, :3] = np.diag([1.0, -1.0, -1.0]) @ rotvec_to_matrix([0.1, -0.2, 0.05])
    T[:3, 3] = [10.0, -20.0, 1500.0]
    return T, 3000.0, principal_point_of((1600, 1200))


def _points(seed=0):
    return np.random.default_rng(seed).normal(scale=60.0, size=(20, 3))


def test_bpe_of_the_true_camera_is_zero():
    T, f, c = _camera()
    F = _points()
    uv = Camera(T, f, c).project(F)
    assert back_projection_error(F, uv, Camera(T, f, c)) == pytest.approx(0.0, abs=1e-9)
    names = [f"p{i}" for i in range(len(F))]
    points, image = dict(zip(names, F, strict=True)), dict(zip(names, uv, strict=True))
    bpe = back_projection_error_from_dicts(points, image, Camera(T, f, c))
    assert bpe == pytest.approx(0.0, abs=1e-9)


def test_bpe_grows_with_the_camera_error():
    T, f, c = _camera()
    F = _points(1)
    uv = Camera(T, f, c).project(F)
    previous = 0.0
    for shift_mm in (1.0, 5.0, 20.0):
        Te = T.copy()
        Te[:3, 3] += [shift_mm, 0.0, 0.0]
        bpe = back_projection_error(F, uv, Camera(Te, f, c))
        assert bpe > previous
        previous = bpe
    # A pure lateral shift of s mm moves every ray by about s mm near the subject.
    assert previous == pytest.approx(20.0, rel=0.05)
    # A wrong focal length also shows.
    assert back_projection_error(F, uv, Camera(T, 1.2 * f, c)) > 1.0
    assert back_projection_errors(F, uv, Camera(T, f, c)).shape == (20,)


def test_bpe_rejects_bad_input():
    T, f, c = _camera()
    with pytest.raises(ValueError, match="one image point per 3D landmark"):
        back_projection_errors(_points(), np.zeros((3, 2)), Camera(T, f, c))
    with pytest.raises(ValueError, match="focal_px must be positive"):
        back_projection_errors(_points(), np.zeros((20, 2)), Camera(T, 0.0, c))
    with pytest.raises(ValueError, match="share no landmark"):
        back_projection_error_from_dicts({"a": [0, 0, 0]}, {"b": [0, 0]}, Camera(T, f, c))


def test_rank_with_ties():
    assert rank_of_true([3.0, 1.0, 1.0, 5.0], 1) == 1.5
    assert rank_of_true([3.0, 1.0, 1.0, 5.0], 2) == 1.5
    assert rank_of_true([3.0, 1.0, 1.0, 5.0], 0) == 3.0
    assert rank_of_true([3.0, 1.0, 1.0, 5.0], 3) == 4.0
    assert rank_of_true([2.0, 2.0, 2.0], 0) == 2.0
    assert rank_of_true([0.5], 0) == 1.0
    assert rank_of_true([3.0, 1.0, 5.0], 2, lower_is_better=False) == 1.0
    # A failed SFO (NaN) ranks last.
    assert rank_of_true([np.nan, 1.0, 2.0], 0) == 3.0
    assert rank_of_true([np.nan, 1.0, np.nan], 1) == 1.0
    with pytest.raises(ValueError, match="outside the 3 scores"):
        rank_of_true([1.0, 2.0, 3.0], 3)


def test_implausible_sfo_counts_skull_pixels_outside_the_face():
    face = np.zeros((10, 10), dtype=np.uint8)
    face[2:8, 2:8] = 255
    skull = np.zeros((10, 10), dtype=bool)
    skull[3:6, 3:6] = True
    inside = implausible_sfo(skull, face)
    assert (inside.outside_px, inside.skull_px, inside.percent_outside) == (0, 9, 0.0)
    assert not inside.implausible
    skull[6:9, 3:6] = True  # rows 8 fall outside
    out = implausible_sfo(skull, face)
    assert out.outside_px == 3 and out.skull_px == 18
    assert out.percent_outside == pytest.approx(100 * 3 / 18)
    assert out.implausible
    assert implausible_sfo(np.zeros((4, 4)), np.zeros((4, 4))).percent_outside == 0.0
    with pytest.raises(ValueError, match="differ in shape"):
        implausible_sfo(np.zeros((4, 4)), np.zeros((4, 5)))
