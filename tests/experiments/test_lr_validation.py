"""The calibration's range (``outside_calibration``) and the validation of shipped models on
held-out pairs (:mod:`lilium.experiments.lr_validation`): ROC AUC, the equal error rate, and a
frontal + lateral decision scored as a case scores it."""

import json

import numpy as np
import pytest

from lilium.experiments.lr_validation import (
    criteria_rows,
    equal_error_rate,
    figures,
    roc_auc,
    score_decisions,
)
from lilium.identification.calibration import VIEWS_LOG10_LR, Calibration, fit


def _pairs(rng, n_subjects=15, shift=2.0, view="frontal"):
    out = []
    for person in range(n_subjects):
        for skull in range(n_subjects):
            same = person == skull
            chi2 = np.exp(rng.normal(0.0 if same else shift, 0.5))
            out.append(dict(terms={"landmark_chi2": chi2, "landmark_worst": 2.0 * chi2},
                            same=same, person=f"0:s{person}", skull=f"0:s{skull}",
                            photo=f"s{person}_{view[0]}", run=(0, "m", "", 1, 1)))
    return out


def test_the_range_is_each_class_bulk_and_round_trips():
    """The range of a feature runs from the lower of the two classes' 0.5 % quantiles to the
    higher of their 99.5 % ones; a value beyond it is named, a missing term never is, and the
    range survives the file; the LR does not extrapolate beyond it."""
    rng = np.random.default_rng(0)
    pairs = _pairs(rng)
    model = fit([p["terms"] for p in pairs], [p["same"] for p in pairs])
    log_chi2 = np.log([p["terms"]["landmark_chi2"] for p in pairs])
    same = np.array([p["same"] for p in pairs])
    lo, hi = model.ranges["landmark_chi2"]
    assert lo == pytest.approx(np.quantile(log_chi2[same], 0.005))
    assert hi == pytest.approx(np.quantile(log_chi2[~same], 0.995))
    assert model.outside({"landmark_chi2": np.exp(lo + 0.1), "landmark_worst": 1.0}) == []
    name, value, bounds = model.outside({"landmark_chi2": np.exp(hi + 1.0)})[0]
    assert name == "landmark_chi2" and value == pytest.approx(hi + 1.0) and bounds == (lo, hi)
    assert model.outside({"landmark_chi2": None, "landmark_worst": None}) == []
    # No extrapolation: beyond its range a feature reads as the range's edge.
    worst = float(np.exp(model.ranges["landmark_worst"][0]) * 2.0)
    edge, beyond = model.log10_lr([{"landmark_chi2": np.exp(v), "landmark_worst": worst}
                                   for v in (lo, lo - 3.0)])
    assert beyond == pytest.approx(edge)
    assert model.outside({"landmark_chi2": np.inf})[0][0] == "landmark_chi2"
    again = Calibration.from_dict(json.loads(json.dumps(model.to_dict())))
    assert again.ranges == model.ranges
    broken = model.to_dict()
    broken["ranges"]["landmark_chi2"] = [1.0, 0.0]
    with pytest.raises(ValueError, match="lo <= hi"):
        Calibration.from_dict(broken)
    del broken["ranges"]["landmark_chi2"]
    with pytest.raises(ValueError, match="ranges.landmark_chi2 is missing"):
        Calibration.from_dict(broken)


def test_auc_and_equal_error_rate():
    same = np.array([True, True, True, False, False, False, False])
    assert roc_auc([3, 2, 1, 0, -1, -2, -3], same) == 1.0
    assert roc_auc([0, 0, 0, 0, 0, 0, 0], same) == 0.5
    assert roc_auc([1, 2, 3, 4, 5, 6, 7], same) == 0.0
    assert equal_error_rate([3, 2, 1, 0, -1, -2, -3], same) == 0.0
    # One same-person pair below every different-person one, one different-person pair above
    # every same-person one: one error of each kind.
    lr = [3, 2, -5, 0, -1, -2, 5]
    assert roc_auc(lr, same) == pytest.approx(1 - (4 + 1 + 1) / 12)
    assert equal_error_rate(lr, same) == pytest.approx(np.mean([1 / 3, 1 / 4]))


def test_held_out_pairs_are_scored_as_a_case_scores_them():
    """Models fitted on one draw score another: the frontal + lateral decision adds the two
    photos' LRs and calibrates the sum with its views' model, its figures pass the criteria
    on well separated pairs, and a decision whose photo lies beyond the range is counted."""
    rng = np.random.default_rng(1)
    train = {v: _pairs(rng, view=v) for v in ("frontal", "lateral")}
    models = {f"m//{v}": fit([p["terms"] for p in train[v]], [p["same"] for p in train[v]])
              for v in train}
    sums = [models["m//frontal"].log10_lr([f["terms"]])[0]
            + models["m//lateral"].log10_lr([lat["terms"]])[0]
            for f, lat in zip(train["frontal"], train["lateral"], strict=True)]
    models["m//pair_sum"] = fit([{VIEWS_LOG10_LR: s} for s in sums],
                                [p["same"] for p in train["frontal"]], (VIEWS_LOG10_LR,))
    test = {v: _pairs(np.random.default_rng(2), view=v) for v in ("frontal", "lateral")}
    test["frontal"][0]["terms"]["landmark_chi2"] = 1e6  # beyond the range
    decision_pairs = {("m", "", v): test[v] for v in test}
    decision_pairs[("m", "", "pair_sum")] = [dict(p, parts=None) for p in test["frontal"]]
    scored = score_decisions(decision_pairs, models)
    expected = (models["m//frontal"].log10_lr([test["frontal"][1]["terms"]])[0]
                + models["m//lateral"].log10_lr([test["lateral"][1]["terms"]])[0])
    assert scored[("m", "", "pair_sum")]["log10_lr"][1] == pytest.approx(
        models["m//pair_sum"].log10_lr([{VIEWS_LOG10_LR: expected}])[0])
    assert scored[("m", "", "pair_sum")]["outside"][0]
    outside = scored[("m", "", "frontal")]["outside"]
    assert outside[0] and outside[1:].mean() < 0.05  # a fresh draw: a few pairs by chance
    by_decision = {key: figures(entry) for key, entry in scored.items()}
    assert by_decision[("m", "", "pair_sum")]["auc"] > 0.99
    rows = criteria_rows(by_decision)
    assert {r[1] for r in rows} == {"m frontal", "m lateral", "m frontal + lateral"}
    auc_rows = [r for r in rows if r[2] == "auc"]
    assert all(r[5] for r in auc_rows)
