"""Identification as a likelihood ratio (SPEC section 12): the marginal landmark term, the
calibration, the conclusion and its caps, and the ``"identification"`` record of ``lilium sfo``
and ``lilium case``."""

import json
from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.identify import conclusion_line
from lilium.cli.main import main
from lilium.geometry.camera import Camera
from lilium.identification.calibration import (
    Calibration,
    bigaussian_warp,
    cllr,
    cross_validated,
    fit,
    pav_log10_lr,
    performance,
)
from lilium.identification.conclusion import conclude, level, material_caps
from lilium.identification.terms import (
    View,
    landmark_chi2,
    prior_excess,
    soft_tissue_covariance,
)
from lilium.inputs import Priors
from standin_case import scaled_photo


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


def _synthetic_pairs(rng, n_subjects=12, shift=2.0):
    pairs = []
    for person in range(n_subjects):
        for skull in range(n_subjects):
            same = person == skull
            chi2 = np.exp(rng.normal(0.0 if same else shift, 0.5))
            pairs.append(dict(terms={"landmark_chi2": chi2, "outside_fraction": 0.0},
                              same=same, person=f"s{person}", skull=f"s{skull}"))
    return pairs


def test_calibration_separates_bounds_and_round_trips():
    rng = np.random.default_rng(3)
    pairs = _synthetic_pairs(rng)
    model = fit([p["terms"] for p in pairs], [p["same"] for p in pairs])
    assert model.names == ("landmark_chi2",)  # a constant term is left out
    lr = model.log10_lr([p["terms"] for p in pairs])
    same = np.array([p["same"] for p in pairs])
    assert lr[same].mean() > 0 > lr[~same].mean()
    lo, hi = model.bounds
    assert lo == pytest.approx(-np.log10(12)) and hi == pytest.approx(np.log10(132))
    assert np.all((lr >= lo - 1e-12) & (lr <= hi + 1e-12))
    again = Calibration.from_dict(json.loads(json.dumps(model.to_dict())))
    np.testing.assert_allclose(again.log10_lr([p["terms"] for p in pairs]), lr)
    assert np.isnan(model.log10_lr([None])[0])


def test_cross_validation_and_performance():
    rng = np.random.default_rng(4)
    pairs = _synthetic_pairs(rng)
    pairs[0]["terms"] = None  # a failed SFO
    lr = cross_validated(pairs, folds=4)
    assert np.isnan(lr[0]) and np.isfinite(lr[1:]).all()
    perf = performance(lr, [p["same"] for p in pairs])
    assert perf["failed"] == 1
    assert perf["cllr_min"] <= perf["cllr"] < 0.6
    assert perf["misleading_same"] <= 0.2 and perf["misleading_diff"] <= 0.1
    # A wrong conclusion is a misleading LR beyond the undetermined band (|log10 LR| >= 0.5).
    assert perf["wrong_conclusion_same"] <= perf["misleading_same"]
    assert perf["wrong_conclusion_diff"] <= perf["misleading_diff"]
    bands = performance([-0.6, -0.4, 0.2, 0.4, 0.5, 1.5, -3.0], [1, 1, 1, 0, 0, 0, 0])
    assert bands["misleading_same"] == pytest.approx(2 / 3)
    assert bands["wrong_conclusion_same"] == pytest.approx(1 / 3)
    assert bands["misleading_diff"] == pytest.approx(3 / 4)
    assert bands["wrong_conclusion_diff"] == pytest.approx(2 / 4)
    # An uninformative system costs 1 bit; PAV of random scores cannot do much better.
    same = np.array([p["same"] for p in pairs])
    assert cllr(np.zeros(len(same)), same) == pytest.approx(1.0)
    noise = rng.normal(size=len(same))
    assert cllr(pav_log10_lr(noise, same), same) > 0.7


def test_two_views_that_repeat_each_other_are_not_counted_twice():
    """A frontal and a lateral photo carrying the same evidence (identical terms): added, their
    LRs count it twice; the calibrated sum (``pair_sum``) learns a slope of about one half and
    costs less, cross-validated; its model is the one ``lilium calibrate`` writes."""
    from lilium.experiments.calibrate import VIEWS_MODEL, fit_models, validate
    from lilium.identification.calibration import VIEWS_LOG10_LR, VIEWS_TERMS

    rng = np.random.default_rng(5)
    pairs = _synthetic_pairs(rng, n_subjects=20, shift=1.0)
    decision_pairs = {}
    for view in ("frontal", "lateral"):
        decision_pairs[("m", "", view)] = [
            p | {"photo": f"{p['person']}_{view}", "run": ("r",)} for p in pairs
        ]
    decision_pairs[("m", "", "pair_sum")] = [
        {k: p[k] for k in ("same", "person", "skull")} | {"photo": f"{p['person']}_frontal",
                                                           "run": ("r",)}
        for p in pairs
    ]
    decision_pairs[("m", "", "frontal")][0] = decision_pairs[("m", "", "frontal")][0] | {
        "terms": None  # a failed SFO: its pair has no sum and no LR, and is counted failed
    }
    validated = validate(decision_pairs, folds=4)
    frontal, lateral = (validated[("m", "", v)]["log10_lr"] for v in ("frontal", "lateral"))
    both = validated[("m", "", "pair_sum")]
    np.testing.assert_allclose(both["added"][1:], frontal[1:] + lateral[1:])
    assert np.isnan(both["added"][0]) and np.isnan(both["log10_lr"][0])
    assert both["performance"]["failed"] == both["performance_added"]["failed"] == 1
    assert both["performance"]["cllr"] < both["performance_added"]["cllr"] - 0.02
    models = fit_models(decision_pairs, {}, log=lambda line: None, validated=validated)
    model = models["m//pair_sum"]
    assert model.names == VIEWS_TERMS
    assert model.provenance["model"] == VIEWS_MODEL
    lr = model.log10_lr([{VIEWS_LOG10_LR: x} for x in (-2.0, 0.0, 2.0)])
    slope = (lr[2] - lr[0]) / 4.0
    assert 0.35 < slope < 0.7, slope
    assert "m//pair_sum" not in fit_models(decision_pairs, {}, log=lambda line: None)


def test_conclusion_scale_caps_and_consistency():
    assert [level(x) for x in (-3, -1.5, -0.7, 0.0, 0.7, 1.5, 3)] == list(range(7))
    assert conclude(2.5).label == "strong support"
    caps = material_caps(has_mandible=False, photos=1, unreviewed_automatic=False, pairs=12)
    assert set(caps) == {"no_mandible", "single_photo"}
    capped = conclude(2.5, caps)
    assert capped.label == "limited support" and capped.uncapped == "strong support"
    assert "no mandible" in conclusion_line(
        {"conclusion": capped.label, "conclusion_uncapped": capped.uncapped, "caps": caps,
         "log10_lr": 2.5, "inconsistent": {}})
    four = material_caps(False, 1, True, 6)
    assert conclude(3.0, four).label == "undetermined"
    assert conclude(-2.5, four).label == "strong support for exclusion"  # exclusion uncapped
    inconsistent = conclude(2.5, {}, {"view_mismatch": "the camera looks at the side"})
    assert inconsistent.label == "undetermined"
    # A camera that contradicts the view reads no LR either way; a skull outside the head
    # stops support only.
    assert conclude(-2.5, {}, {"view_mismatch": "sideways"}).label == "undetermined"
    outside = {"skull_outside_head": "40 % of the skull's pixels lie outside the head mask"}
    assert conclude(-2.5, {}, outside).label == "strong support for exclusion"
    assert conclude(None).label == conclude(float("nan")).label == "undetermined"


def test_sfo_writes_the_identification_and_prints_the_conclusion(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    code = main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    ident = json.loads((out / "result.json").read_text())["identification"]
    assert set(ident) >= {"score", "terms", "log10_lr", "conclusion", "caps", "calibration"}
    assert ident["calibration"]["model"] == "posest-sfo//frontal"
    assert "single_photo" in ident["caps"]
    assert ident["terms"]["landmark_chi2"] > 0
    assert f"identification: {ident['conclusion']}" in stdout


def test_case_without_a_calibrated_model_says_so(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    calibration = tmp_path / "empty.json"
    calibration.write_text(json.dumps({"format": "lilium-calibration", "models": {}}))
    out = tmp_path / "out"
    other = scaled_photo(photo_dir, tmp_path / "other", 0.75)
    code = main(["case", "--skull", str(subject_dir), "--photo", str(photo_dir),
                 "--photo", str(other), "--method", "posest-sfo",
                 "--calibration", str(calibration), "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    assert "no calibration for posest-sfo//frontal" in stdout
    assert "together, posest-sfo: identification: undetermined" in stdout
    text = (out / "report.html").read_text()
    assert text.index("Identification") < text.index("Summary")
    assert "the paper&#x27;s alignment score" in text or "the paper's alignment score" in text


def test_a_file_that_is_not_a_calibration_is_refused(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    code = main(["sfo", "--skull", str(subject_dir), "--photo", str(photo_dir),
                 "--calibration", str(bad), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and "not a Lilium calibration file" in err and str(bad) in err


def test_lineup_orders_ties_at_the_bound_by_what_was_clipped():
    from lilium.casework.lineup import rank_key

    def entry(name, lr, views=None, score=None, method="lilium-skof+pll"):
        record = {"log10_lr": lr, "views_log10_lr": views, "score": score}
        return {"candidate": name, "method": method, "identification": record}

    entries = [
        entry("none", None),
        entry("bound, smaller sum", 2.95, [1.5, 0.8], 3.0),
        entry("other method", 3.5, method="posest-sfo"),
        entry("bound, larger sum", 2.95, [2.5, 1.9], 9.0),
        entry("below", 1.2, [0.5, 0.6], 1.0),
        entry("one photo, bound, lower score", 2.95, None, 2.0),
    ]
    ranked = sorted(entries, key=lambda e: rank_key(e, "lilium-skof+pll"))
    assert [e["candidate"] for e in ranked] == [
        "bound, larger sum", "bound, smaller sum", "one photo, bound, lower score", "below",
        "none", "other method",
    ]


def test_rankings_break_ties_at_the_bound_by_the_plain_sum():
    from lilium.experiments.identification import photo_matches
    from lilium.experiments.lr_report import ranking_rows

    pairs = [dict(run=(0, "e", "m", "", "C1", 0), photo="p1", person="a", skull=s)
             for s in ("a", "b", "c")]
    lr = np.array([2.95, 2.95, 1.0])  # the true skull and a wrong one at the upper bound
    for added, better, tied in (([5.0, 3.0, 0.5], 0, 0), ([3.0, 5.0, 0.5], 1, 0),
                                (None, 0, 1)):
        rows = ranking_rows(pairs, lr, "frontal", None if added is None else np.array(added))
        match = photo_matches(rows)[0]
        assert (match["better"], match["tied"]) == (better, tied)


def test_lineup_ranks_candidates_and_resumes(case, tmp_path, capsys, monkeypatch):
    subject_dir, photo_dir = case
    out = tmp_path / "lineup"
    # Each photo once (a photo given twice is refused): bea's are the stand-in at other sizes.
    bea = [scaled_photo(photo_dir, tmp_path / f"bea{k}", f) for k, f in enumerate((0.5, 0.75))]
    argv = ["lineup", "--skull", str(subject_dir), "--candidate", "anna", str(photo_dir),
            "--candidate", "bea", *map(str, bea), "--method", "posest-sfo",
            "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    stdout = capsys.readouterr().out
    ranking = json.loads((out / "lineup.json").read_text())["ranking"]
    assert [e["rank"] for e in ranking] == [1, 2]
    assert {e["candidate"] for e in ranking} == {"anna", "bea"}
    lrs = [e["identification"]["log10_lr"] for e in ranking]
    assert lrs[0] >= lrs[1]
    assert (out / "anna" / "standin_frontal" / "posest-sfo" / "overlay.png").is_file()
    assert "1. " in stdout and (out / "report.html").is_file()

    import lilium.casework.lineup as lineup

    def no_rerun(*args, **kwargs):
        raise AssertionError("a stored SFO ran again")

    monkeypatch.setattr(lineup, "run_sfo", no_rerun)
    assert main(argv) == 0  # every SFO read back
    again = json.loads((out / "lineup.json").read_text())["ranking"]
    assert [e["identification"]["log10_lr"] for e in again] == lrs


def test_lineup_refuses_a_name_given_twice(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    code = main(["lineup", "--skull", str(subject_dir), "--candidate", "a", str(photo_dir),
                 "--candidate", "a", str(photo_dir), "--out", str(tmp_path / "o")])
    assert code == 2 and "given twice" in capsys.readouterr().err


def test_balanced_fit_recovers_the_log_lr_of_imbalanced_classes():
    """1 same-person pair in 20: each class weighs half, so the fitted log LR is the classes'
    own (two unit Gaussians of ln chi2 two apart: log LR = 2 (1 - x) in nats) whatever the
    pairs' proportion, shrunk a little by the ridge."""
    rng = np.random.default_rng(5)
    x_same, x_diff = rng.normal(0.0, 1.0, 400), rng.normal(2.0, 1.0, 8000)
    terms = [{"landmark_chi2": float(np.exp(x))} for x in np.concatenate([x_same, x_diff])]
    model = fit(terms, [True] * 400 + [False] * 8000)
    grid = np.array([-0.5, 0.5, 1.0, 1.5, 2.5])
    got = model.log10_lr([{"landmark_chi2": float(np.exp(x))} for x in grid]) * np.log(10)
    true = 2.0 * (1.0 - grid)
    assert abs(got[2]) < 0.1  # even odds where the classes' densities cross
    # The ridge shrinks towards "no evidence" (a conservative LR), never past the true one.
    ratio = got[[0, 1, 3, 4]] / true[[0, 1, 3, 4]]
    assert np.all((ratio > 0.7) & (ratio <= 1.05)), ratio


def test_bigaussian_warp_keeps_a_calibrated_system_and_balances_the_errors():
    """Bi-Gaussianized calibration (Morrison 2024): the log LRs of a perfectly calibrated
    bi-Gaussian system come back about as they were; LRs whose 1 lies off the equal-error
    point (every log LR one nat too high) come back in the same order, with same- and
    different-person pairs misled about equally often."""
    rng = np.random.default_rng(6)
    sigma = 3.0
    same = np.r_[np.ones(2000, bool), np.zeros(20000, bool)]
    ln_lr = np.where(same, 0.5, -0.5) * sigma**2 + sigma * rng.normal(size=len(same))
    warp = bigaussian_warp(ln_lr, same)
    back = np.interp(ln_lr, warp["knots"], warp["ln_lr"])
    central = np.abs(ln_lr) < 6.0
    assert np.max(np.abs(back[central] - ln_lr[central])) < 0.3
    shifted = ln_lr + 1.0
    warp = bigaussian_warp(shifted, same)
    out = np.interp(shifted, warp["knots"], warp["ln_lr"])
    assert np.all(np.diff(out[np.argsort(shifted, kind="stable")]) >= 0)
    before = np.mean(shifted[same] < 0), np.mean(shifted[~same] > 0)
    after = np.mean(out[same] < 0), np.mean(out[~same] > 0)
    assert before[1] > before[0] + 0.05  # the shift misleads different-person pairs more
    assert abs(after[0] - after[1]) < 0.005, after
    assert after[1] < before[1] - 0.03


def test_a_warped_model_round_trips_and_refuses_a_broken_warp():
    rng = np.random.default_rng(7)
    pairs = _synthetic_pairs(rng)
    terms, same = [p["terms"] for p in pairs], [p["same"] for p in pairs]
    plain, warped = fit(terms, same), fit(terms, same, warp=True)
    assert plain.warp is None and warped.warp is not None
    lr = warped.log10_lr(terms)
    order = np.argsort(plain.log10_lr(terms), kind="stable")
    assert np.all(np.diff(lr[order]) >= -1e-12)  # the warp keeps the logistic order
    again = Calibration.from_dict(json.loads(json.dumps(warped.to_dict())))
    np.testing.assert_allclose(again.log10_lr(terms), lr)
    data = warped.to_dict()
    data["warp"] = {"knots": [0.0, 1.0], "ln_lr": [1.0, 0.0]}
    with pytest.raises(ValueError, match="increasing"):
        Calibration.from_dict(data)


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


def test_a_frontal_and_a_lateral_photo_add_their_log_lrs(case, tmp_path, monkeypatch):
    """Separate SFOs of one frontal and one lateral photo: the decision's log10 LR is the sum
    of the two photos' own (each from its view's model) calibrated by the method's
    ``pair_sum`` model, or the plain sum without one; other sets use the pair model."""
    from dataclasses import replace
    from types import SimpleNamespace

    from lilium.casework.identify import Calibrations, identify
    from lilium.io.case import read_photo, read_skull

    subject_dir, photo_dir = case
    assert main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    result = SimpleNamespace(method="posest-sfo", variant="", warnings=[],
                             camera=Camera.from_dict(data["camera"]), facial_landmarks_mm=None)
    skull, frontal = read_skull(subject_dir), read_photo(photo_dir)
    lateral = replace(frontal, view="lateral_left")  # the same landmarks, scored as lateral
    calibrations = Calibrations()
    one = [identify(skull, [p], [result], calibrations) for p in (frontal, lateral)]
    both = identify(skull, [frontal, lateral], [result, result], calibrations)
    assert both["calibration"]["model"] == (
        "posest-sfo//frontal + posest-sfo//lateral -> posest-sfo//pair_sum"
    )
    added = one[0]["log10_lr"] + one[1]["log10_lr"]
    assert both["views_log10_lr"] == [one[0]["log10_lr"], one[1]["log10_lr"]]
    views = calibrations.get("posest-sfo//pair_sum")
    assert both["calibration"]["views_model"] == "posest-sfo//pair_sum"
    assert both["log10_lr"] == pytest.approx(views.log10_lr([{"views_log10_lr": added}])[0])
    assert "calibrated as one decision" in both["note"]
    without = Calibrations()
    del without.models["posest-sfo//pair_sum"]
    plain = identify(skull, [frontal, lateral], [result, result], without)
    assert plain["log10_lr"] == pytest.approx(added)
    assert "as if independent" in plain["note"] and plain["calibration"]["views_model"] is None
    assert plain["calibration"]["model"] == "posest-sfo//frontal + posest-sfo//lateral"
    assert "single_photo" not in both["caps"]
    # Each photo's LR comes from its own SFO's soft tissue, not the first photo's.
    import lilium.casework.identify as identify_module

    own = {k: np.asarray(v, float) for k, v in data["facial_landmarks_3d"].items()}
    moved = {k: v + np.array([4.0, -3.0, 8.0]) for k, v in own.items()}
    first = SimpleNamespace(**{**vars(result), "facial_landmarks_mm": own})
    second = SimpleNamespace(**{**vars(result), "facial_landmarks_mm": moved})
    seen = []

    def recording(skull, photos, cameras, facial, **kwargs):
        seen.append(([p.view for p in photos], facial))
        return terms_of(skull, photos, cameras, facial, **kwargs)

    terms_of = identify_module.identification_terms
    monkeypatch.setattr(identify_module, "identification_terms", recording)
    identify(skull, [frontal, lateral], [first, second], calibrations)
    singles = {tuple(views): facial for views, facial in seen if len(views) == 1}
    assert singles[("frontal",)] is own and singles[("lateral_left",)] is moved
    # The photos' terms together take the frontal photo's soft tissue, as the calibration's
    # pairs do, whichever photo comes first.
    seen.clear()
    identify(skull, [lateral, frontal], [second, first], calibrations)
    assert [facial for views, facial in seen if len(views) == 2] == [own]
    two_frontal = identify(skull, [frontal, frontal], [result, result], calibrations)
    assert two_frontal["calibration"]["model"] == "posest-sfo//pair"
    assert "these photos differ" in two_frontal["note"]


def test_report_states_the_models_known_error_rates():
    from lilium.report.conclusion_html import conclusion_section

    provenance = {"cv_wrong_conclusion_same": 0.019, "cv_wrong_conclusion_diff": 0.044,
                  "pairs_same": 52, "pairs_different": 892}
    record = {"conclusion": "limited support", "log10_lr": 0.7,
              "calibration": {"model": "lilium/skof+pll/frontal", "provenance": provenance}}
    html = conclusion_section([("f00", "", record)])
    assert "1.9 % of same-person and 4.4 % of different-person pairs" in html
    assert "on 52 same- and 892 different-person pairs" in html
    record["calibration"]["provenance"] = {"pairs_same": 52}  # an older calibration file
    assert "known error rate" not in conclusion_section([("f00", "", record)])


def test_shipped_calibration_states_its_error_rates():
    from lilium.experiments.lr_report import CV_RATES
    from lilium.io.calibration import read_calibration

    models, _ = read_calibration()
    lilium = [m for key, m in models.items() if key.startswith("lilium/")]
    assert lilium
    for model in lilium:
        for name in CV_RATES:
            assert 0.0 <= model.provenance[f"cv_{name}"] <= 1.0


def test_landmark_snorm_is_derived_from_the_stored_terms():
    from lilium.identification.terms import CALIBRATED_TERMS, landmark_snorm

    terms = {"landmark_chi2": np.e, "cohort_mean": 0.5, "cohort_sd": 0.25, "skull_mean": 2.0,
             "skull_sd": 0.5}
    assert landmark_snorm(terms) == pytest.approx((1 - 0.5) / 0.25 + (1 - 2.0) / 0.5)
    assert landmark_snorm(dict(terms, skull_sd=None)) is None  # older terms: filled by the model
    assert "landmark_snorm" in CALIBRATED_TERMS
    rng = np.random.default_rng(5)
    pairs = _synthetic_pairs(rng)
    for p in pairs:
        p["terms"].update(cohort_mean=0.0, cohort_sd=1.0, skull_mean=0.0, skull_sd=1.0)
    model = fit([p["terms"] for p in pairs], [p["same"] for p in pairs])
    assert "landmark_snorm" in model.names


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
    from lilium.geometry.camera import principal_point_of
    from lilium.identification.score import LATE_TERMS, identification_terms, with_late_terms
    from lilium.io.calibration import shipped_cohort
    from lilium.io.case import read_photo, read_skull

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


def test_two_photos_reuse_each_photos_own_decision(case, tmp_path, monkeypatch):
    """A frontal and a lateral photo's decision reads each photo's LR from the record its
    result already carries (same calibration file and model), not from a second
    computation; the decision is the one computed from scratch."""
    from dataclasses import replace
    from pathlib import Path
    from types import SimpleNamespace

    import lilium.casework.identify as identify_module
    from lilium.casework.identify import Calibrations, identify
    from lilium.io.case import read_photo, read_skull

    subject_dir, photo_dir = case
    assert main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    result = SimpleNamespace(method="posest-sfo", variant="", warnings=[], extra={},
                             camera=Camera.from_dict(data["camera"]), facial_landmarks_mm=None)
    skull, frontal = read_skull(subject_dir), read_photo(photo_dir)
    lateral = replace(frontal, view="lateral_left")
    calibrations = Calibrations()
    scratch = identify(skull, [frontal, lateral], [result, result], calibrations)
    # What with_identification stores in a result's extra.
    own = [SimpleNamespace(**{**vars(result), "extra": {
        "identification": identify(skull, [p], [result], calibrations)}})
        for p in (frontal, lateral)]
    calls = []
    real = identify_module.identification_terms
    monkeypatch.setattr(identify_module, "identification_terms",
                        lambda *a, **k: calls.append(len(a[1])) or real(*a, **k))
    reused = identify(skull, [frontal, lateral], own, calibrations)
    assert calls == [2]  # the pair's own terms only
    assert reused["log10_lr"] == pytest.approx(scratch["log10_lr"], abs=1e-12)
    assert reused["views_log10_lr"] == pytest.approx(scratch["views_log10_lr"], abs=1e-12)
    (tmp_path / "other.json").write_bytes(Path(calibrations.path).read_bytes())
    other = Calibrations(tmp_path / "other.json")  # another file: computed again
    calls.clear()
    identify(skull, [frontal, lateral], own, other)
    assert calls == [2, 1, 1]
