"""Identification as a likelihood ratio (docs/method/identification.md), its calibration: the fitted
model
(classes balanced, bounds, the bi-Gaussian warp, round trips), cross-validation and
performance, two views calibrated as one decision, the derived ``landmark_snorm`` term, and the
models' known error rates (shipped and in the report). The terms are ``test_lr_terms.py``'s;
the conclusion and the records ``test_lr_casework.py``'s."""

import json

import numpy as np
import pytest

from lilium.identification.calibration import (
    Calibration,
    bigaussian_warp,
    cllr,
    cross_validated,
    fit,
    pav_log10_lr,
    performance,
    ridge_for,
)


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
    from lilium.identification.calibration import VIEWS_LOG10_LR, VIEWS_RIDGE, VIEWS_TERMS

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
    # The sum is bi-Gaussianized (calibrate.WARPED), the single photos' models are not.
    assert model.warp is not None and models["m//frontal"].warp is None
    assert model.provenance["ridge"] == VIEWS_RIDGE  # each model says its penalty
    terms_model = models["m//frontal"]
    assert terms_model.provenance["ridge"] == pytest.approx(ridge_for(terms_model.n_same))
    lr = model.log10_lr([{VIEWS_LOG10_LR: x} for x in (-2.0, 0.0, 2.0)])
    slope = (lr[2] - lr[0]) / 4.0
    assert 0.35 < slope < 0.7, slope
    assert "m//pair_sum" not in fit_models(decision_pairs, {}, log=lambda line: None)


def test_balanced_fit_recovers_the_log_lr_of_imbalanced_classes():
    """1 same-person pair in 20: each class weighs half, so the fitted log LR is the classes'
    own (two unit Gaussians of ln chi2 two apart: log LR = 2 (1 - x) in nats) whatever the
    pairs' proportion, to within the sampling error, shrunk a little by the ridge."""
    rng = np.random.default_rng(5)
    x_same, x_diff = rng.normal(0.0, 1.0, 400), rng.normal(2.0, 1.0, 8000)
    terms = [{"landmark_chi2": float(np.exp(x))} for x in np.concatenate([x_same, x_diff])]
    labels = [True] * 400 + [False] * 8000
    grid = np.array([-0.5, 0.5, 1.0, 1.5, 2.5])
    at_grid = [{"landmark_chi2": float(np.exp(x))} for x in grid]
    got = fit(terms, labels).log10_lr(at_grid) * np.log(10)
    true = 2.0 * (1.0 - grid)
    assert abs(got[2]) < 0.1  # even odds where the classes' densities cross
    ratio = got[[0, 1, 3, 4]] / true[[0, 1, 3, 4]]
    assert np.all((ratio > 0.85) & (ratio < 1.15)), ratio
    # The ridge shrinks towards "no evidence" (a conservative LR): never past the unpenalised
    # fit of the same pairs, and more so the larger it is.
    free = fit(terms, labels, ridge=0.0).log10_lr(at_grid) * np.log(10)
    strong = fit(terms, labels, ridge=1e-1).log10_lr(at_grid) * np.log(10)
    assert np.all(np.abs(strong) <= np.abs(got) + 1e-12)
    assert np.all(np.abs(got) <= np.abs(free) + 1e-12)


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
    """Derived from the stored terms, and a feature of a model fitted with the cohort terms
    (the calibration before 2026-12-06); the shipped terms leave it out with them."""
    from lilium.identification.terms import (
        CALIBRATED_TERMS,
        COHORT_CALIBRATED_TERMS,
        landmark_snorm,
    )

    terms = {"landmark_chi2": np.e, "cohort_mean": 0.5, "cohort_sd": 0.25, "skull_mean": 2.0,
             "skull_sd": 0.5}
    assert landmark_snorm(terms) == pytest.approx((1 - 0.5) / 0.25 + (1 - 2.0) / 0.5)
    assert landmark_snorm(dict(terms, skull_sd=None)) is None  # older terms: filled by the model
    assert "landmark_snorm" not in CALIBRATED_TERMS
    rng = np.random.default_rng(5)
    pairs = _synthetic_pairs(rng)
    for p in pairs:
        p["terms"].update(cohort_mean=0.0, cohort_sd=1.0, skull_mean=0.0, skull_sd=1.0)
    terms = [p["terms"] for p in pairs]
    assert "landmark_snorm" in fit(terms, [p["same"] for p in pairs], COHORT_CALIBRATED_TERMS).names
    assert "landmark_snorm" not in fit(terms, [p["same"] for p in pairs]).names


def test_the_ridge_is_a_prior_worth_a_fixed_number_of_same_person_pairs():
    """The fitted loss is a mean over each class, so the default penalty falls as the
    same-person pairs grow: with few of them, the weights of noise terms stay small."""
    assert ridge_for(12) == pytest.approx(10 * ridge_for(120))
    rng = np.random.default_rng(8)
    names = ("landmark_chi2", "cohort_mean", "cohort_sd", "skull_mean", "skull_sd")
    same = np.r_[np.ones(12, bool), np.zeros(240, bool)]
    values = rng.normal(0.0, 1.0, (same.size, len(names)))
    values[:, 0] = np.exp(values[:, 0] + np.where(same, 0.0, 1.5))  # the one real signal
    terms = [dict(zip(names, map(float, row), strict=True)) for row in values]
    default = fit(terms, same, names)
    weak = fit(terms, same, names, ridge=ridge_for(1200))
    noise = list(names[1:])
    assert default.weights["landmark_chi2"] < 0 and weak.weights["landmark_chi2"] < 0
    assert np.linalg.norm([default.weights[n] for n in noise]) < 0.9 * np.linalg.norm(
        [weak.weights[n] for n in noise]
    )


def test_a_misfit_term_never_speaks_for_the_same_person():
    """A term that measures a misfit (here the skull outside the head) keeps a weight at or
    below 0 even where the training pairs would reward it (it rises with the same-person
    pairs here): read beyond those pairs, such a weight would support a skull for leaving
    the head. A reference term (the centred cohort's mean) is free either way."""
    from lilium.identification.calibration import AGAINST

    rng = np.random.default_rng(11)
    pairs = _synthetic_pairs(rng)
    for p in pairs:
        lift = 1.0 if p["same"] else 0.0
        p["terms"]["outside_fraction"] = 0.02 * (lift + rng.uniform())
        p["terms"]["centred_mean"] = lift + rng.normal(0.0, 0.5)
    model = fit([p["terms"] for p in pairs], [p["same"] for p in pairs])
    assert "outside_fraction" in AGAINST and "centred_mean" not in AGAINST
    assert model.weights["outside_fraction"] == pytest.approx(0.0, abs=1e-9)
    assert model.weights["centred_mean"] > 0.1
    assert model.weights["landmark_chi2"] < -0.1


def test_a_missing_term_reads_as_neither_kind_of_pair():
    """A term missing from a decision (a photo without P_pll) takes the value halfway between
    the same-person and the different-person median, not the pooled median (a
    different-person value, with 11 of them to each same-person pair here)."""
    from lilium.identification.calibration import neutral_value

    rng = np.random.default_rng(12)
    pairs = _synthetic_pairs(rng)
    for p in pairs:
        p["terms"]["pll_face"] = float(np.expm1(rng.normal(0.5 if p["same"] else 2.5, 0.2)) / 10)
    same = np.array([p["same"] for p in pairs])
    model = fit([p["terms"] for p in pairs], same)
    column = np.log1p(10 * np.array([p["terms"]["pll_face"] for p in pairs]))
    assert model.fill["pll_face"] == pytest.approx(
        0.5 * (np.median(column[same]) + np.median(column[~same])))
    assert abs(model.fill["pll_face"] - 1.5) < 0.2  # the pooled median would be near 2.5
    # Only one kind of pair holds the term: its median.
    only_diff = np.where(same, np.nan, column)
    assert neutral_value(only_diff, same) == pytest.approx(np.nanmedian(only_diff))
