"""Identification as a likelihood ratio (docs/method/identification.md), its terms: the marginal
landmark
term (the soft tissue integrated out, shared between views), the camera priors' excess, the
camera refits, the photo and skull cohorts, the landmarks' tension, and the late terms added to
older records. The calibration is ``test_lr_calibration.py``'s; the conclusion and the records
``test_lr_casework.py``'s."""

import json
from dataclasses import replace

import numpy as np
import pytest

from lilium.geometry.camera import Camera
from lilium.identification.terms import (
    View,
    landmark_chi2,
    landmark_worst,
    prior_excess,
    soft_tissue_covariance,
)
from lilium.inputs import Priors


def _view(rng, scale=1.0, n=40, camera=None, noise=True, sigma_px=None):
    """A view whose observations follow the model (soft tissue and 2D noise drawn from it)
    for a skull ``scale`` times the one observed (1 = the true skull)."""
    camera = camera or Camera.from_rt(np.diag([1.0, -1.0, -1.0]), [0, 0, 1500.0], 3000.0,
                                      [500.0, 400.0])
    cranial = rng.normal(0, 40, (n, 3))
    cranial[:, 2] = -np.abs(cranial[:, 2]) - 60  # facing the camera (camera looks down -z)
    axes = rng.normal(0, 1, (n, 3)) + [0, 0, -3]
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    mean, sd = np.full(n, 8.0), np.full(n, 2.0)
    cov = soft_tissue_covariance(axes, mean, sd)
    delta = np.array([rng.multivariate_normal(np.zeros(3), c) for c in cov]) if noise else 0
    facial = cranial * scale + mean[:, None] * axes + delta
    uv = camera.project(facial)
    if noise:
        eye_px = 90.0 * camera.focal_px / 1500.0
        uv = uv + rng.normal(0, max(1.5, 0.02 * eye_px) if sigma_px is None else sigma_px, uv.shape)
    return View(camera, cranial, axes, mean, sd, uv, ("manual",) * n,
                tuple(f"p{k}" for k in range(n)))


def test_marginal_chi2_is_one_for_the_model_and_larger_for_another_skull():
    rng = np.random.default_rng(0)
    true = [landmark_chi2([_view(rng)])[0] for _ in range(20)]
    assert 0.8 < np.mean(true) < 1.2  # the residuals' own covariance: 1 per coordinate
    wrong = [landmark_chi2([_view(rng, scale=1.08)])[0] for _ in range(20)]
    assert np.mean(wrong) > 1.5 * np.mean(true)


def test_worst_landmark_follows_the_model_and_finds_one_misfit():
    """Under the model a landmark's misfit per coordinate in one photo is exponential (mean
    1), so the largest of N is about the harmonic number H_N; one landmark moved by 40 px
    (about 8 of its errors: some 5 px per coordinate, 2D noise and soft tissue) raises the
    worst landmark far more than the mean term, which spreads it over all N."""
    rng = np.random.default_rng(3)
    views = [_view(rng) for _ in range(40)]
    worst = [landmark_worst([v]) for v in views]
    assert np.mean(worst) == pytest.approx(np.sum(1.0 / np.arange(1, 41)), rel=0.15)
    view = views[0]
    moved = replace(view, uv_px=view.uv_px + np.r_[[[40.0, 0.0]], np.zeros((39, 2))])
    worst_ratio = landmark_worst([moved]) / landmark_worst([view])
    chi2_ratio = landmark_chi2([moved])[0] / landmark_chi2([view])[0]
    assert worst_ratio > 3 and chi2_ratio < 2 and worst_ratio > 2 * chi2_ratio
    behind = View(view.camera, view.cranial_mm + [0, 0, 3000.0], *list(vars(view).values())[2:])
    assert landmark_worst([behind]) == np.inf


def test_shared_soft_tissue_couples_two_views():
    """Two photos of the same soft tissue: the coupled likelihood sees one soft-tissue draw;
    counting each photo alone would count it twice (chi2 per coordinate unchanged). The same
    view twice is not twice the evidence: the shared part is counted once."""
    rng = np.random.default_rng(1)
    view = _view(rng, noise=True, sigma_px=0.01)
    single, _ = landmark_chi2([view])
    twice, _ = landmark_chi2([view, view])
    # With (almost) no 2D noise the residual is the soft tissue's, identical in both photos:
    # independent photos would keep chi2 per coordinate at `single`; coupled, it drops.
    assert twice < 0.75 * single


def test_landmark_behind_the_camera_is_infinitely_unlikely():
    rng = np.random.default_rng(2)
    view = _view(rng)
    behind = View(view.camera, view.cranial_mm + [0, 0, 3000.0], *list(vars(view).values())[2:])
    assert landmark_chi2([behind])[0] == np.inf


def test_prior_excess_zero_inside_and_grows_outside():
    camera = Camera.from_rt(np.eye(3), [0, 0, 1000.0], 3000.0, [0, 0])
    priors = Priors(focal_px=(2900, 3100), scd_mm=(950, 1050))
    assert prior_excess(camera, priors, np.zeros(3)) == 0.0
    far = Priors(focal_px=(1400, 1500), scd_mm=(950, 1050))
    assert prior_excess(camera, far, np.zeros(3)) == pytest.approx(1.0)
    assert prior_excess(camera, Priors(), np.zeros(3)) is None


def _rotation(rotvec):
    from lilium.geometry.rotations import rotvec_to_matrix

    return rotvec_to_matrix(np.asarray(rotvec, float))


def test_camera_refit_recovers_the_camera_and_kabsch_the_pose():
    from lilium.identification.cohort import kabsch, refit_cameras
    from lilium.identification.terms import landmark_sigma_px

    rng = np.random.default_rng(6)
    view = _view(rng, noise=False)
    cam = view.camera
    R0 = (_rotation([0.03, -0.02, 0.01]) @ cam.R)[None]
    R, t, f = refit_cameras(R0, (cam.t + [4.0, -3.0, 60.0])[None], np.array([cam.focal_px * 1.1]),
                            cam.principal_point_px, view.cranial_mm[None], view.axes[None],
                            view.depth_mean_mm, view.depth_sd_mm, view.uv_px,
                            landmark_sigma_px(view))
    refit = Camera.from_rt(R[0], t[0], f[0], cam.principal_point_px)
    mean_mm = view.cranial_mm + view.depth_mean_mm[:, None] * view.axes
    assert np.abs(refit.project(mean_mm) - view.uv_px).max() < 0.05  # exact data: fitted
    assert f[0] == pytest.approx(cam.focal_px, rel=2e-3)
    Rt = _rotation([0.2, -0.4, 0.1])
    Ra, ta = kabsch(view.cranial_mm, view.cranial_mm @ Rt.T + [5.0, 6.0, 7.0])
    np.testing.assert_allclose(Ra, Rt, atol=1e-9)
    np.testing.assert_allclose(ta, [5.0, 6.0, 7.0], atol=1e-9)


def test_cohort_reads_a_photo_against_other_skulls(tmp_path):
    """Candidate and cohort skulls in different frames: the cohort fits are found from the
    candidate's camera through the rigid fit of the skulls, and the true skull fits its photo
    better than the cohort's skulls do."""
    from lilium.identification.cohort import Cohort, cohort_chi2, cohort_terms
    from lilium.io.calibration import read_cohort, write_cohort

    rng = np.random.default_rng(7)
    view = _view(rng)
    names = view.names
    landmarks, axes = [], []
    for k in range(8):
        other = _view(np.random.default_rng(100 + k), noise=False)  # another person's skull
        moved = other.cranial_mm @ _rotation([0.0, 0.3 * k, 0.0]).T + [10.0 * k, 0.0, 0.0]
        landmarks.append(dict(zip(names, moved, strict=True)))
        axes.append(dict(zip(names, other.axes @ _rotation([0.0, 0.3 * k, 0.0]).T, strict=True)))
    cohort = Cohort(tuple(landmarks), tuple(axes), {"test": True})
    values = cohort_chi2([view], cohort)
    assert len(values) == 8 and np.all(values > 3 * landmark_chi2([view])[0])
    mean, sd = cohort_terms([view], cohort)
    assert mean == pytest.approx(np.log(values).mean()) and sd > 0
    write_cohort(tmp_path / "cohort.json", cohort)
    again = read_cohort(tmp_path / "cohort.json")
    assert again.provenance == {"test": True}
    assert cohort_terms([view], again) == pytest.approx((mean, sd))
    (tmp_path / "bad.json").write_text('{"format": "lilium-cohort", "skulls": [{"axes": {}}]}')
    with pytest.raises(ValueError, match="bad.json: skull 0 needs"):
        read_cohort(tmp_path / "bad.json")
    # A cohort without the views' landmarks gives no terms.
    assert cohort_terms([view], Cohort(({"x": np.zeros(3)},), ({"x": np.ones(3)},))) == (None, None)


def test_skull_cohort_reads_a_skull_against_other_faces():
    """The skull cohort: the candidate skull against other people's faces, each projected by
    the SFO's camera. A cohort person with the candidate's own skull (in another frame) gives a
    noise-free photo the candidate fits exactly; other people's faces fit it worse; two views
    of one person share the soft tissue; too few members give no terms."""
    from lilium.identification.cohort import Cohort, skull_cohort_chi2, skull_cohort_terms

    rng = np.random.default_rng(8)
    view = _view(rng)
    names = view.names
    landmarks, axes = [], []
    for k in range(6):
        other = view if k == 0 else _view(np.random.default_rng(200 + k), noise=False)
        turn = _rotation([0.0, 0.4 * k, 0.1])
        landmarks.append(dict(zip(names, other.cranial_mm @ turn.T + [0.0, 5.0 * k, 0.0],
                                  strict=True)))
        axes.append(dict(zip(names, other.axes @ turn.T, strict=True)))
    cohort = Cohort(tuple(landmarks), tuple(axes))
    values = skull_cohort_chi2([view], cohort)
    assert len(values) == 6
    assert values[0] < 1e-3  # its own face, without noise: fitted exactly
    assert np.all(values[1:] > 100 * values[0])
    mean, sd = skull_cohort_terms([view], cohort)
    assert mean == pytest.approx(np.log(values).mean()) and sd == pytest.approx(
        np.log(values).std())
    # Two views: one value per cohort person, the views stacked.
    side = replace(view, camera=Camera.from_rt(_rotation([0.0, 0.1, 0.0]) @ view.camera.R,
                                                view.camera.t + [40.0, 0.0, 100.0],
                                                view.camera.focal_px,
                                                view.camera.principal_point_px))
    assert len(skull_cohort_chi2([view, side], cohort)) == 6
    few = Cohort(cohort.landmarks_mm[:4], cohort.axes[:4])
    assert skull_cohort_terms([view], few) == (None, None)


def test_landmark_tension_is_what_a_camera_off_the_landmarks_costs():
    """The landmarks' own best fit (``landmark_refit``) under a camera moved off the one that
    fits them: the refit finds the landmark optimum again, so the tension grows with the
    move, and is near 0 at the camera the landmarks were drawn with."""
    from lilium.identification.cohort import refit_views
    from lilium.identification.terms import CALIBRATED_TERMS, landmark_tension

    rng = np.random.default_rng(8)
    view = _view(rng)
    cam = view.camera
    tensions = []
    for angle in (0.0, 0.03, 0.06):
        moved = Camera.from_rt(_rotation([angle, 0.0, 0.0]) @ cam.R, cam.t, cam.focal_px,
                               cam.principal_point_px)
        chi2 = landmark_chi2([replace(view, camera=moved)])[0]
        refit = landmark_chi2(refit_views([replace(view, camera=moved)]))[0]
        assert refit <= chi2 + 1e-9  # the refit only accepts better fits
        tensions.append(landmark_tension({"landmark_chi2": chi2, "landmark_refit": refit}))
    # At the true camera the refit only overfits the noise: seven camera parameters against
    # 80 coordinates take about 7 / 80 of the chi2: a tension near 0.09, 0.04-0.17 over draws
    # (which also differ between machines: the soft tissue's draw goes through LAPACK).
    assert tensions[0] < 0.25 < tensions[1] < tensions[2]
    assert landmark_tension({"landmark_chi2": 1.0}) is None  # older terms: filled by the model
    assert "landmark_tension" in CALIBRATED_TERMS


def test_older_terms_are_completed_with_the_late_terms_only(case):
    """Terms stored before the skull cohort and the landmarks' refit get those computed;
    every stored term is kept as it was."""
    from lilium.casework.build import read_photo, read_skull
    from lilium.geometry.camera import principal_point_of
    from lilium.identification.score import LATE_TERMS, identification_terms, with_late_terms
    from lilium.io.calibration import shipped_cohort

    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    truth = json.loads((photo_dir / "photo.json").read_text())["ground_truth"]
    camera = Camera(np.array(truth["skull2cam"]), truth["focal_px"],
                    principal_point_of(photo.image_size_wh))
    full = identification_terms(skull, [photo], [camera], None, cohort=shipped_cohort())
    old = {k: v for k, v in full.items() if k not in LATE_TERMS}
    old["pll_face"] = 123.0  # a stored term is not computed again
    done = with_late_terms(old, skull, [photo], [camera], cohort=shipped_cohort())
    assert done["pll_face"] == 123.0
    for name in LATE_TERMS:
        assert done[name] == pytest.approx(full[name], rel=1e-9)


def test_the_centred_cohort_reads_a_skull_outside_the_population_as_one_inside():
    """People who differ from a common shape by 2 mm per landmark; a candidate from among them,
    and one whose ten first landmarks all sit 15 mm further out (a head unlike every cohort
    skull, as a real head is unlike the generated ones), each with a noise-free photo of its
    own face: the photo cohort's mean moves far (every cohort skull fits that photo badly), the
    centred cohort's (the cohort's differences put on the candidate) stays near the
    in-population candidate's."""
    from lilium.identification.cohort import Cohort, centred_cohort_terms, cohort_terms

    base = _view(np.random.default_rng(11), noise=False)
    names = base.names
    rng = np.random.default_rng(12)
    landmarks = [dict(zip(names, base.cranial_mm + rng.normal(0, 2.0, base.cranial_mm.shape),
                          strict=True)) for _ in range(10)]
    cohort = Cohort(tuple(landmarks), tuple(dict(zip(names, base.axes, strict=True))
                                            for _ in range(10)))

    def photo_of(cranial_mm):
        facial = cranial_mm + base.depth_mean_mm[:, None] * base.axes
        return replace(base, cranial_mm=cranial_mm, uv_px=base.camera.project(facial))

    inside_mm = base.cranial_mm + rng.normal(0, 2.0, base.cranial_mm.shape)
    outside_mm = inside_mm.copy()
    outside_mm[:10, 0] += 15.0 * np.sign(outside_mm[:10, 0] - inside_mm[:, 0].mean())
    views = {"in": photo_of(inside_mm), "out": photo_of(outside_mm)}
    photo = {k: cohort_terms([v], cohort)[0] for k, v in views.items()}
    centred = {k: centred_cohort_terms([v], cohort) for k, v in views.items()}
    assert photo["out"] - photo["in"] > 1.0
    assert abs(centred["out"][0] - centred["in"][0]) < 0.3
    assert centred["in"][1] > 0
    few = Cohort(cohort.landmarks_mm[:4], cohort.axes[:4])
    assert centred_cohort_terms([views["in"]], few) == (None, None)
