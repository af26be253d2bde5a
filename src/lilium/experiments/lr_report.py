"""Files of the identification's calibration (docs/method/identification.md): ``calibration.json``,
``calibration.csv`` (Cllr, Cllr_min, rates of misleading evidence and of wrong conclusions per
decision), the Tippett plot, and the ranking of every photo's skulls by the cross-validated
log10 LR beside the ranking by the methods' own scores (``identification.csv``).

Used by ``lilium calibrate`` (:func:`calibrate_databases`) and ``lilium report``
(:func:`lr_identification`).
"""

import csv
import json
import textwrap
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..io.calibration import write_calibration
from .calibrate import (
    check_databases,
    database_decisions,
    fit_models,
    performance_table,
    validate,
)
from .config import method_label
from .identification import identification_table

#: Label of the two rankings in ``identification.csv``.
SCORE_FITNESS = "method's own score"
SCORE_LR = "identification log10 LR (cross-validated)"

#: Decision -> the view its ranking is reported under (a pair ranks by its frontal photo).
DECISION_VIEW = {"frontal": "frontal", "lateral": "lateral", "pair": "frontal+lateral",
                 "pair_sum": "frontal+lateral", "joint": "frontal+lateral"}


def decision_label(method, variant, decision):
    """Table label of a decision: the method's, with how photos are combined."""
    label = method_label(method, variant)
    return {
        "pair": f"{label}, separate SFOs, shared soft tissue",
        "pair_sum": f"{label}, separate SFOs, LRs added and calibrated",
    }.get(decision, label)


#: The cross-validated error rates each fitted model's provenance carries (beside its Cllr),
#: the known error rates a case's report states next to its conclusion.
CV_RATES = ("misleading_same", "misleading_diff", "wrong_conclusion_same",
            "wrong_conclusion_diff")


#: Weight of the tie-break in :func:`ranking_rows`: far below any difference of two LRs that
#: are not equal, so it only orders LRs tied at the calibration's bound.
TIE_BREAK = 1e-9


def ranking_rows(pairs, log10_lr, view, tie_break=None):
    """Rows for :func:`lilium.experiments.identification.identification_table` that rank each
    photo's skulls by ``-log10 LR`` (a failed SFO ranks last); a pair ranks by its frontal
    photo, so ``view`` is that of the decision's photo. ``tie_break`` (P,), optional: what
    orders LRs tied at the calibration's bound (the views' log10 LRs added, before their
    model clipped them; higher ranks first), as ``lilium lineup`` breaks such ties first."""
    if tie_break is None:
        tie_break = np.zeros(len(log10_lr))
    out = []
    for p, v, t in zip(pairs, log10_lr, np.nan_to_num(tie_break), strict=True):
        ok = bool(np.isfinite(v))
        out.append(
            dict(
                experiment=p["run"][1],
                method="lr",
                variant="",
                axes_set=p["run"][4],
                repetition=(p["run"][0], p["run"][5]),
                photo=p["photo"],
                view=view,
                subject=p["skull"],
                true_subject=p["person"],
                success=ok,
                score=-float(v) - TIE_BREAK * float(t) if ok else None,
            )
        )
    return out


def lr_identification_table(decision_pairs, validated):
    """Rank-1 rate, mean rank and ROC AUC of every decision ranked by its cross-validated
    log10 LR: rows like :func:`~lilium.experiments.identification.identification_table`'s,
    with ``score`` = :data:`SCORE_LR`. A photo is ranked among the skulls of its own database;
    the figures of several databases are averaged over their photos."""
    table = []
    for key in sorted(validated):
        method, variant, decision = key
        view = "lateral" if decision == "lateral" else "frontal"
        rows = ranking_rows(
            decision_pairs[key], validated[key]["log10_lr"], view, validated[key].get("added")
        )
        parts = []
        for db in sorted({p["run"][0] for p in decision_pairs[key]}):
            mine = [r for r, p in zip(rows, decision_pairs[key], strict=True) if p["run"][0] == db]
            parts += identification_table(mine)
        if not parts:
            continue
        weights = np.array([t["photo_runs"] for t in parts], float)
        merged = dict(parts[0])
        for name in ("rank1_rate", "mean_rank", "auc"):
            known = [
                (t[name], w) for t, w in zip(parts, weights, strict=True) if t[name] is not None
            ]
            merged[name] = (
                float(np.average([v for v, _ in known], weights=[w for _, w in known]))
                if known
                else None
            )
        merged.update(
            photo_runs=int(weights.sum()),
            runs=sum(t["runs"] for t in parts),
            method=decision_label(method, variant, decision),
            view=DECISION_VIEW[decision],
            score=SCORE_LR,
        )
        table.append(merged)
    return table


def plot_tippett(validated, path):
    """Tippett plot: per decision, the share of same-person pairs with log10 LR >= x (solid)
    and of different-person pairs with log10 LR >= x (dashed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = sorted(validated)
    cols = min(max(len(keys), 1), 4)
    rows = -(-max(len(keys), 1) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.6 * rows), squeeze=False)
    for ax in axes.ravel()[len(keys):]:
        ax.set_visible(False)
    for ax, key in zip(axes.ravel(), keys, strict=False):
        lr = validated[key]["log10_lr"]
        same = validated[key]["same"]
        ok = np.isfinite(lr)
        lo, hi = (np.min(lr[ok]) - 0.2, np.max(lr[ok]) + 0.2) if ok.any() else (-3, 3)
        grid = np.linspace(lo, hi, 400)
        for mask, style, label in ((same, "-", "same person"), (~same, "--", "different")):
            values = lr[ok & mask]
            if len(values):
                ax.plot(grid, [(values >= g).mean() for g in grid], style, label=label)
        ax.axvline(0.0, color="grey", lw=0.8)
        perf = validated[key]["performance"]
        ax.set_title(
            f"{textwrap.fill(decision_label(*key), 50)}\n{key[2]}: Cllr {perf['cllr']:.2f} "
            f"(min {perf['cllr_min']:.2f})",
            fontsize=8,
        )
        ax.set_xlabel("log10 LR")
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("share of pairs with log10 LR >= x")
    if axes[0][0].get_lines()[1:]:  # more than the line at 0
        axes[0][0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def write_calibration_csv(path, validated):
    table = performance_table(validated)
    for t in table:
        t["label"] = decision_label(t["method"], t["variant"], t["decision"])
    keys = ["label", "method", "variant", "decision", "cllr", "cllr_min", "misleading_same",
            "misleading_diff", "wrong_conclusion_same", "wrong_conclusion_diff", "n_same",
            "n_diff", "failed"]
    with Path(path).open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(table)
    return Path(path)


def validated_with_labels(decision_pairs, folds=5):
    validated = validate(decision_pairs, folds)
    for key, v in validated.items():
        v["same"] = np.array([p["same"] for p in decision_pairs[key]], bool)
    return validated


def lr_identification(dbs, out_dir, dataset=None, log=print):
    """``calibration.csv``, ``tippett.png`` and the LR ranking rows of databases.

    Returns
    -------
    paths : dict of str -> Path
    table : list of dict
        :func:`lr_identification_table`.
    decision_pairs, validated : dict
    """
    out_dir = Path(out_dir)
    decision_pairs, _ = database_decisions(dbs, dataset, log=log)
    validated = validated_with_labels(decision_pairs)
    paths = {
        "calibration_csv": write_calibration_csv(out_dir / "calibration.csv", validated),
        "tippett": plot_tippett(validated, out_dir / "tippett.png"),
    }
    return paths, lr_identification_table(decision_pairs, validated), decision_pairs, validated


def database_provenance(db):
    """What a calibration says of one database it was fitted on: its experiment's name, DE
    budget and dataset (generator seed and subjects, when ``dataset.json`` is there)."""
    from .store import ResultStore

    with ResultStore(db, read_only=True) as store:
        config = store.get_meta("config") or {}
    out = {"database": Path(db).name, "experiment": config.get("name"), "de": config.get("de")}
    index = Path(str(config.get("dataset", ""))) / "dataset.json"
    if index.is_file():
        data = json.loads(index.read_text())
        out.update(dataset_seed=data.get("seed"), subjects=len(data.get("subjects", [])),
                   photos=len(data.get("photos", [])))
    return out


def calibrate_databases(dbs, out_dir, dataset=None, log=print):
    """``lilium calibrate``: fit every decision's model on all pairs of the databases and
    write ``calibration.json`` beside the cross-validated ``calibration.csv`` and Tippett plot.

    Returns
    -------
    paths : dict of str -> Path
    table, decision_pairs, validated
        As :func:`lr_identification`.
    """
    check_databases(dbs, out_dir, dataset)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths, table, decision_pairs, validated = lr_identification(dbs, out_dir, dataset, log)
    provenance = {
        "fitted": time.strftime("%Y-%m-%d"),
        "lilium": __version__,
        "databases": [database_provenance(db) for db in dbs],
        "model": "logistic regression on the identification terms (lilium.identification)",
    }
    models = fit_models(decision_pairs, provenance, log, validated)
    for key, model in models.items():
        perf = validated[tuple(key.split("/"))]["performance"]
        model.provenance.update(
            pairs_same=model.n_same,
            pairs_different=model.n_diff,
            cv_cllr=round(perf["cllr"], 4),
            cv_cllr_min=round(perf["cllr_min"], 4),
            **{f"cv_{name}": round(perf[name], 4) for name in CV_RATES},
        )
    paths["calibration.json"] = out_dir / "calibration.json"
    write_calibration(paths["calibration.json"], models, provenance)
    return paths, table, decision_pairs, validated
