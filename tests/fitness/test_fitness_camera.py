"""P_cam: exact values of docs/method/lilium.md's camera penalty."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lilium.constants import C_INF
from lilium.fitness.camera_penalty import (
    CameraPriors,
    camera_penalty,
    camera_penalty_from_priors,
    head_deviation_deg,
)


def test_no_prior_no_penalty_for_a_valid_camera():
    assert camera_penalty([1000.0, 9999.0]).tolist() == [0.0, 0.0]


def test_focal_interval_squares_the_excess():
    p = camera_penalty([900.0, 1000.0, 1200.0, 1250.0], focal_interval_px=(1000, 1200))
    assert p.tolist() == [100.0**2, 0.0, 0.0, 50.0**2]


def test_scd_interval_squares_the_excess():
    p = camera_penalty([1000.0] * 3, scd_mm=[450.0, 600.0, 1003.0], scd_interval_mm=(500, 1000))
    assert p.tolist() == [2500.0, 0.0, 9.0]


def test_head_tolerance_squares_the_excess():
    p = camera_penalty([1000.0] * 3, dbeta_deg=[5.0, 10.0, 13.5], tolerance_deg=10)
    assert p.tolist() == [0.0, 0.0, 12.25]


def test_terms_add_up():
    p = camera_penalty(
        [1300.0],
        scd_mm=[400.0],
        dbeta_deg=[12.0],
        focal_interval_px=(1000, 1200),
        scd_interval_mm=(500, 1000),
        tolerance_deg=10,
    )
    assert p.tolist() == [100.0**2 + 100.0**2 + 2.0**2]


def test_failures_cost_c_inf():
    p = camera_penalty(
        [1000.0, 0.0, -5.0, 10_000.5, np.nan, 10_000.0],
        success=[False, True, True, True, True, True],
    )
    assert p.tolist() == [C_INF, C_INF, C_INF, C_INF, C_INF, 0.0]


def test_failure_keeps_its_finite_terms_and_nan_with_prior_is_failure():
    p = camera_penalty([0.0], focal_interval_px=(100, 200))
    assert p.tolist() == [C_INF + 100.0**2]
    p = camera_penalty([1000.0, 1000.0], scd_mm=[np.nan, 700.0], scd_interval_mm=(500, 1000))
    assert p.tolist() == [C_INF, 0.0]
    # Without the SCD prior, a NaN SCD is ignored.
    assert camera_penalty([1000.0], scd_mm=[np.nan]).tolist() == [0.0]


def test_priors_object_and_head_deviation():
    R_prior = Rotation.from_euler("y", 20, degrees=True).as_matrix()
    R = np.stack(
        [R_prior, Rotation.from_euler("y", 35, degrees=True).as_matrix(), np.full((3, 3), np.nan)]
    )
    assert np.allclose(head_deviation_deg(R[:2], R_prior), [0.0, 15.0])
    priors = CameraPriors(
        focal_px=(800, 1200), scd_mm=None, head_rotation_skull2cam=R_prior, head_tolerance_deg=10
    )
    p = camera_penalty_from_priors([1000.0, 1300.0, 1000.0], [0.0] * 3, R, [True] * 3, priors)
    assert np.allclose(p, [0.0, 100.0**2 + 5.0**2, C_INF])
    # Rotation without tolerance: the head term is off.
    no_head = CameraPriors(head_rotation_skull2cam=R_prior)
    assert camera_penalty_from_priors([1000.0], [0.0], R[2:], [True], no_head).tolist() == [0.0]


def test_invalid_priors_say_what_is_wrong():
    with pytest.raises(ValueError, match="focal_px must be a finite interval"):
        CameraPriors(focal_px=(1200, 800))
    with pytest.raises(
        ValueError, match=r"scd_mm must be a finite interval \[lo, hi\] with 0 < lo"
    ):
        CameraPriors(scd_mm=(-5, 800))
    with pytest.raises(
        ValueError, match=r"focal_interval_px must be a finite interval.*\[nan, 1\]"
    ):
        camera_penalty([1000.0], focal_interval_px=(np.nan, 1))
    with pytest.raises(ValueError, match="head_tolerance_deg must be >= 0"):
        CameraPriors(head_tolerance_deg=-1)
    with pytest.raises(ValueError, match="scd_mm is needed"):
        camera_penalty([1000.0], scd_interval_mm=(1, 2))
    with pytest.raises(ValueError, match="success has shape"):
        camera_penalty([1000.0, 1.0], success=[True])
