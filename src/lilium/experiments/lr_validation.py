"""Validation of a shipped calibration the way forensic LR systems are validated.

Meuwly, Ramos and Haraksim (Forensic Science International 2017) ask of an LR method a table of
performance characteristics, each with a metric, a criterion and a pass or fail, measured on data
the method was not developed on: accuracy (Cllr), discriminating power (Cllr_min, EER, ROC
AUC), calibration (``Cllr_cal = Cllr - Cllr_min``), robustness and generalisation. Here the
data are (a) results databases of generated subjects that no shipped model saw (held-out dataset
seeds), each decision scored by the shipped models exactly as a case is (:func:`score_decisions`:
no refit, no cross-validation), and (b) real-anatomy pairs (``benchmarks/bench_real_anatomy.py``),
which have too few pairs for Cllr and get their own criteria (no different-person support, the
own skull's LR above 1, few LRs at a bound).

Maths and tables only; the benchmark that runs it is ``benchmarks/bench_validation.py``.
"""

import numpy as np

from ..identification.calibration import VIEWS_LOG10_LR, performance


def _key(method, variant, decision):
    return f"{method}/{variant or ''}/{decision}"


def _score(model, terms_list):
    """log10 LRs ``(P,)`` and outside-the-range flags ``(P,)`` of term dictionaries (None:
    failed, NaN and not outside)."""
    lr = model.log10_lr(terms_list)
    outside = np.array([t is not None and bool(model.outside(t)) for t in terms_list])
    return lr, outside


def score_decisions(decision_pairs, models):
    """Every decision of held-out databases scored by fitted models, as a case scores it.

    Parameters
    ----------
    decision_pairs : dict
        :func:`lilium.experiments.calibrate.database_decisions`' decisions.
    models : dict of str -> Calibration
        The calibration's models by key.

    Returns
    -------
    dict
        ``{(method, variant, decision): {"log10_lr", "same", "outside", "at_bound",
        "database"}}``, arrays ``(P,)``; a frontal + lateral decision (``pair_sum``) adds its
        photos' LRs and calibrates the sum with its views' model, and is outside the
        calibration when either photo's features are.
    """
    out = {}
    singles = {}
    for key, pairs in decision_pairs.items():
        model = models.get(_key(*key))
        if key[2] == "pair_sum" or model is None:
            continue
        lr, outside = _score(model, [p["terms"] for p in pairs])
        singles[key] = {(p["run"], p["person"], p["skull"], p["photo"]): (v, o)
                        for p, v, o in zip(pairs, lr, outside, strict=True)}
        out[key] = _entry(pairs, lr, outside, model.bounds)
    for key, pairs in decision_pairs.items():
        model = models.get(_key(*key))
        if key[2] != "pair_sum" or model is None:
            continue
        frontal = singles.get((key[0], key[1], "frontal"), {})
        lateral_first = {}
        for (run, person, skull, _), value in sorted(
            singles.get((key[0], key[1], "lateral"), {}).items(), key=lambda kv: str(kv[0])
        ):
            lateral_first.setdefault((run, person, skull), value)
        added, outside = [], []
        for p in pairs:
            f = frontal.get((p["run"], p["person"], p["skull"], p["photo"]), (np.nan, False))
            lat = lateral_first.get((p["run"], p["person"], p["skull"]), (np.nan, False))
            added.append(f[0] + lat[0])
            outside.append(bool(f[1] or lat[1]))
        terms = [{VIEWS_LOG10_LR: float(a)} if np.isfinite(a) else None for a in added]
        lr, _ = _score(model, terms)
        out[key] = _entry(pairs, lr, np.array(outside), model.bounds)
    return out


def _entry(pairs, lr, outside, bounds):
    lr = np.asarray(lr, float)
    return {
        "log10_lr": lr,
        "same": np.array([p["same"] for p in pairs], bool),
        "outside": np.asarray(outside, bool),
        "at_bound": np.isfinite(lr) & ((np.abs(lr - bounds[0]) < 1e-6)
                                       | (np.abs(lr - bounds[1]) < 1e-6)),
        "database": np.array([p["person"].split(":")[0] for p in pairs]),
    }


def roc_auc(log10_lr, same):
    """The area under the ROC curve of LRs (ties count half): the chance that a random
    same-person pair gets a larger LR than a random different-person pair."""
    from scipy.stats import rankdata

    v = np.asarray(log10_lr, float)
    same = np.asarray(same, bool)
    ok = np.isfinite(v)
    v, same = v[ok], same[ok]
    n1, n0 = same.sum(), (~same).sum()
    if not n1 or not n0:
        return float("nan")
    ranks = rankdata(v)
    return float((ranks[same].sum() - n1 * (n1 + 1) / 2) / (n1 * n0))


def equal_error_rate(log10_lr, same):
    """The rate at which misses (same-person pairs at or below a threshold) equal false alarms
    (different-person pairs above it), the best threshold's; the mean of the two where they
    cross between pairs."""
    v = np.asarray(log10_lr, float)
    same = np.asarray(same, bool)
    ok = np.isfinite(v)
    v, same = v[ok], same[ok]
    if not same.any() or same.all():
        return float("nan")
    thresholds = np.unique(np.concatenate([[-np.inf], v]))
    miss = np.array([np.mean(v[same] <= t) for t in thresholds])
    false_alarm = np.array([np.mean(v[~same] > t) for t in thresholds])
    k = int(np.argmin(np.abs(miss - false_alarm)))
    return float(0.5 * (miss[k] + false_alarm[k]))


def figures(entry):
    """The validation's figures of one decision's scored pairs (:func:`score_decisions`).

    Returns
    -------
    dict
        :func:`lilium.identification.calibration.performance`'s, plus ``auc``, ``eer``,
        ``cllr_cal``, ``at_bound`` (share of the scored pairs), ``outside`` and
        ``outside_same`` (shares capped ``outside_calibration``, of all / same-person pairs),
        ``cllr_by_database`` (list).
    """
    lr, same = entry["log10_lr"], entry["same"]
    scored = np.isfinite(lr)
    out = performance(lr, same)
    out["auc"] = roc_auc(lr, same)
    out["eer"] = equal_error_rate(lr, same)
    out["cllr_cal"] = out["cllr"] - out["cllr_min"]
    out["at_bound"] = float(entry["at_bound"][scored].mean()) if scored.any() else float("nan")
    out["outside"] = float(entry["outside"][scored].mean()) if scored.any() else float("nan")
    same_scored = scored & same
    out["outside_same"] = (float(entry["outside"][same_scored].mean()) if same_scored.any()
                           else float("nan"))
    by_db = []
    for db in sorted(set(entry["database"])):
        sel = entry["database"] == db
        by_db.append(performance(lr[sel], same[sel])["cllr"])
    out["cllr_by_database"] = by_db
    return out


#: The criteria of the generated held-out validation: ``(characteristic, metric, decision
#: kind, test, criterion text)``; the decision kind ``single`` is each of the frontal and the
#: lateral photo, ``pair`` the frontal + lateral decision.
GENERATED_CRITERIA = (
    ("accuracy", "cllr", "pair", lambda v: v <= 0.3, "Cllr <= 0.3"),
    ("discrimination", "auc", "pair", lambda v: v >= 0.98, "AUC >= 0.98"),
    ("discrimination", "auc", "single", lambda v: v >= 0.95, "AUC >= 0.95"),
    ("discrimination", "eer", "pair", lambda v: v <= 0.05, "EER <= 5 %"),
    ("calibration", "cllr_cal", "pair", lambda v: v <= 0.1, "Cllr - Cllr_min <= 0.1"),
    ("calibration", "misleading_same", "pair", lambda v: v <= 0.05, "misleading same <= 5 %"),
    ("calibration", "misleading_diff", "pair", lambda v: v <= 0.05, "misleading diff <= 5 %"),
    ("robustness", "cllr_worst_database", "pair", lambda v: v <= 0.4,
     "every held-out seed's Cllr <= 0.4"),
    ("validity range", "outside_same", "pair", lambda v: v <= 0.05,
     "same-person pairs outside the calibration <= 5 %"),
)


def criteria_rows(by_decision, criteria=GENERATED_CRITERIA):
    """The validation table's rows: ``(characteristic, decision label, metric, value,
    criterion, passed)`` for each criterion and each decision of its kind in
    ``by_decision`` (``{(method, variant, decision): figures}``)."""
    rows = []
    for characteristic, metric, kind, test, text in criteria:
        for (method, variant, decision), fig in sorted(by_decision.items()):
            is_pair = decision == "pair_sum"
            if (kind == "pair") != is_pair or decision not in ("frontal", "lateral", "pair_sum"):
                continue
            value = (max(fig["cllr_by_database"]) if metric == "cllr_worst_database"
                     else fig[metric])
            label = f"{method} {variant} {'frontal + lateral' if is_pair else decision}".replace(
                "  ", " ")
            rows.append((characteristic, label, metric, float(value), text,
                         bool(np.isfinite(value) and test(value))))
    return rows
