"""Identification metrics of an experiment (docs/method/evaluation.md): rank-1 rate, CMC, ROC AUC.

For one photo in one run of a method the true skull's score is compared with the scores of the
photo against every other skull of the experiment (lower is better; a failed SFO scores worse
than every camera, and two failed SFOs tie). With ``b`` negatives strictly better than the true
skull, ``k`` tied with it and ``n`` negatives in all:

- **rank** = ``1 + b + k / 2`` (ties share the mean rank, as in the tables);
- **CMC(r)**, the cumulative match curve, = the probability that the true skull is among the
  ``r`` best when ties are broken at random: ``clip((r - b) / (k + 1), 0, 1)``. So a photo whose
  true skull ties for first with one other counts 0.5 at rank 1 and 1 at rank 2;
- **rank-1 rate** = CMC(1);
- **ROC AUC** of the positive score against the negatives of the same photo, a tie counting
  0.5: ``(n - b - k / 2) / n``, i.e. ``1 - (rank - 1) / n``; 1 = the true skull beats every
  other, 0.5 = chance.

Each is the mean over the photo-runs of a (method, experiment, view group): every photo of the
view in every run of the method, a photo whose SFOs are not all stored yet left out. The view
groups are frontal and lateral (left and right together), as in the tables.
"""

import csv
import math
from collections import defaultdict
from pathlib import Path

import numpy as np

from .config import EXPERIMENTS, VIEW_GROUPS, method_label, method_order, view_group


def ranking_score(row):
    """The score a stored SFO ranks by: its ``score``, or +inf when it failed (ranks last)."""
    if row["success"] and row["score"] is not None and np.isfinite(row["score"]):
        return float(row["score"])
    return math.inf


def complete_photo_runs(rows, score):
    """The photo-runs whose SFOs against every skull of their experiment are stored.

    Parameters
    ----------
    rows : list of dict
        Database rows (``experiment, method, variant, axes_set, repetition, photo, view,
        subject, true_subject, success, score``).
    score : callable
        ``score(row) -> float``: the ranking score of one SFO (failures mapped as the caller
        ranks them).

    Yields
    ------
    key : tuple
        ``(experiment, method, variant, axes_set, repetition, photo)``, in sorted order.
    view, true_subject : str
    scores : dict of str -> float
        Per tested skull; includes the true skull.
    """
    skulls = defaultdict(set)
    groups = defaultdict(dict)
    meta = {}
    for r in rows:
        skulls[r["experiment"]].add(r["subject"])
        key = (r["experiment"], r["method"], r["variant"], r["axes_set"], r["repetition"])
        key = key + (r["photo"],)
        groups[key][r["subject"]] = score(r)
        meta[key] = (r["view"], r["true_subject"])
    for key, scores in sorted(groups.items()):
        view, true = meta[key]
        if set(scores) == skulls[key[0]] and true in scores:
            yield key, view, true, scores


def photo_matches(rows):
    """Counts of negatives better than / tied with the true skull, per photo-run.

    Parameters
    ----------
    rows : list of dict
        Database rows (``experiment, method, variant, axes_set, repetition, photo, view,
        subject, true_subject, success, score``).

    Returns
    -------
    list of dict
        ``experiment, method, variant, axes_set, repetition, photo, view, better, tied,
        negatives`` (ints), for every photo-run whose SFOs against every skull of the
        experiment are stored and include the true skull.
    """
    out = []
    for key, view, true, scores in complete_photo_runs(rows, ranking_score):
        target = scores[true]
        negatives = [s for name, s in scores.items() if name != true]
        exp, method, variant, axes_set, rep, photo = key
        out.append(
            dict(
                experiment=exp,
                method=method,
                variant=variant,
                axes_set=axes_set,
                repetition=rep,
                photo=photo,
                view=view,
                better=sum(1 for s in negatives if s < target),
                tied=sum(1 for s in negatives if s == target),
                negatives=len(negatives),
            )
        )
    return out


def cmc_values(better, tied, max_rank):
    """CMC of one photo-run at ranks ``1..max_rank`` (random tie-breaking).

    Parameters
    ----------
    better, tied : int
        Negatives strictly better than / tied with the true skull.
    max_rank : int

    Returns
    -------
    ndarray of shape (max_rank,)

    Examples
    --------
    >>> cmc_values(0, 1, 3).tolist()
    [0.5, 1.0, 1.0]
    """
    r = np.arange(1, max_rank + 1, dtype=float)
    return np.clip((r - better) / (tied + 1.0), 0.0, 1.0)


def _grouped(matches):
    groups = defaultdict(list)
    for m in matches:
        groups[(m["experiment"], m["method"], m["variant"], view_group(m["view"]))].append(m)
    return groups


def _order(keys):
    """Keys sorted by experiment, then the protocol's method order, then view."""
    out = []
    for exp in EXPERIMENTS:
        present = {(m, v) for (e, m, v, _) in keys if e == exp}
        for method, variant in method_order(present):
            out += [
                (exp, method, variant, view)
                for view in VIEW_GROUPS
                if (exp, method, variant, view) in keys
            ]
    return out


def identification_table(rows):
    """Rank-1 rate, mean rank and ROC AUC per method, experiment and view group.

    Returns
    -------
    list of dict
        ``method, experiment, view, rank1_rate, mean_rank, auc, photo_runs, runs, skulls``.
    """
    groups = _grouped(photo_matches(rows))
    table = []
    for key in _order(set(groups)):
        exp, method, variant, view = key
        items = groups[key]
        b = np.array([m["better"] for m in items], dtype=float)
        k = np.array([m["tied"] for m in items], dtype=float)
        n = np.array([m["negatives"] for m in items], dtype=float)
        rank = 1.0 + b + k / 2.0
        auc = np.where(n > 0, (n - b - k / 2.0) / np.maximum(n, 1.0), np.nan)
        table.append(
            {
                "method": method_label(method, variant),
                "experiment": exp,
                "view": view,
                "rank1_rate": float(np.mean(np.clip((1.0 - b) / (k + 1.0), 0.0, 1.0))),
                "mean_rank": float(np.mean(rank)),
                "auc": float(np.nanmean(auc)) if np.any(n > 0) else None,
                "photo_runs": len(items),
                "runs": len({(m["axes_set"], m["repetition"]) for m in items}),
                "skulls": int(n.max()) + 1,
            }
        )
    return table


def cmc_table(rows):
    """The cumulative match curves: one row per method, experiment, view group and rank.

    Returns
    -------
    list of dict
        ``method, experiment, view, rank, rate`` with ``rank`` = 1 .. number of skulls.
    """
    groups = _grouped(photo_matches(rows))
    table = []
    for key in _order(set(groups)):
        exp, method, variant, view = key
        items = groups[key]
        max_rank = max(m["negatives"] for m in items) + 1
        curve = np.mean([cmc_values(m["better"], m["tied"], max_rank) for m in items], axis=0)
        label = method_label(method, variant)
        table += [
            {"method": label, "experiment": exp, "view": view, "rank": r + 1, "rate": float(c)}
            for r, c in enumerate(curve)
        ]
    return table


#: The CMC plot's y label for :func:`cmc_table`'s curves.
CMC_YLABEL = "share of photos with the true skull in the r best"

#: Line style and marker of each view group in :func:`plot_cmc` (``"all"``: views pooled).
_VIEW_STYLES = (("frontal", "-", "o"), ("lateral", "--", "s"), ("all", "-.", "D"))


def plot_cmc(cmc, path, ylabel=CMC_YLABEL):
    """Cumulative match curves, one panel per experiment: frontal solid, lateral dashed, both
    views pooled (view ``"all"``) dash-dotted. The experiment report's two cumulative rank plots
    (``cmc.png``, and ``rank_distribution.png`` of :mod:`lilium.experiments.report`) both use it.

    The curve is defined at the integer ranks (markers); each method is shifted by a few
    hundredths of a rank so that equal curves stay visible.

    Parameters
    ----------
    cmc : list of dict
        ``method`` (its label), ``experiment``, ``view``, ``rank``, ``rate``, as
        :func:`cmc_table` gives them.
    path : path of the PNG to write
    ylabel : str
        What the rate is.

    Returns
    -------
    Path
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    exps = [e for e in EXPERIMENTS if any(c["experiment"] == e for c in cmc)] or ["A"]
    fig, axes = plt.subplots(1, len(exps), figsize=(4.8 * len(exps), 4.0), squeeze=False)
    for ax, exp in zip(axes[0], exps, strict=True):
        items = [c for c in cmc if c["experiment"] == exp]
        methods = list(dict.fromkeys(c["method"] for c in items))
        colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        max_rank = max((c["rank"] for c in items), default=1)
        for i, method in enumerate(methods):
            for view, style, marker in _VIEW_STYLES:
                curve = [c for c in items if c["method"] == method and c["view"] == view]
                if not curve:
                    continue
                ax.plot(
                    [c["rank"] + 0.04 * (i - (len(methods) - 1) / 2) for c in curve],
                    [c["rate"] for c in curve],
                    linestyle=style,
                    marker=marker,
                    markersize=4,
                    color=colours[i % len(colours)],
                    label=f"{method}, {view}",
                )
        ax.set_title(f"Exp. {exp}: cumulative match curve")
        ax.set_xlabel("rank r")
        ax.set_xlim(0.5, max_rank + 0.5)
        ax.set_ylim(0.0, 1.02)
        ax.set_xticks(range(1, max_rank + 1, max(1, max_rank // 10)))
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel(ylabel)
    if axes[0][-1].get_legend_handles_labels()[0]:  # no curve, no legend (and no warning)
        axes[0][-1].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def _fmt(value):
    return "-" if value is None or not np.isfinite(value) else f"{value:.3f}"


def identification_markdown(identification):
    """The report's identification section (rank-1 rate, mean rank, ROC AUC), markdown."""
    out = [
        "\n\n## Identification\n",
        "Rank-1 rate and cumulative match curve with ties broken at random (a tie counts in "
        "part), ROC AUC of the true skull's score against the other skulls' for the same photo "
        "(a tie counts 0.5); means over the photos of a view in every run.\n",
        "| exp | method | ranked by | view | rank-1 rate | mean rank | ROC AUC | photo-runs |",
        "|---|---|---|---|---|---|---|---|",
    ]
    out += [
        f"| {i['experiment']} | {i['method']} | {i.get('score', 'score')} | {i['view']} | "
        f"{_fmt(i['rank1_rate'])} | {_fmt(i['mean_rank'])} | {_fmt(i['auc'])} | "
        f"{i['photo_runs']} |"
        for i in identification
    ]
    out.append("\n![cumulative match curve](cmc.png)\n")
    return "\n".join(out)


def _write_csv(path, table, keys):
    with Path(path).open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys)
        writer.writeheader()
        writer.writerows(table)
    return Path(path)


def write_identification(rows, identification, out_dir):
    """Write ``identification.csv``, ``cmc.csv`` and ``cmc.png`` into ``out_dir``.

    Returns
    -------
    dict of str -> Path
        ``identification``, ``cmc``, ``cmc_plot``.
    """
    out_dir = Path(out_dir)
    cmc = cmc_table(rows)
    keys = ["method", "experiment", "view", "rank1_rate", "mean_rank", "auc"]
    keys += ["photo_runs", "runs", "skulls"]
    if any("score" in t for t in identification):
        keys.append("score")
    return {
        "identification": _write_csv(out_dir / "identification.csv", identification, keys),
        "cmc": _write_csv(
            out_dir / "cmc.csv", cmc, ["method", "experiment", "view", "rank", "rate"]
        ),
        "cmc_plot": plot_cmc(cmc, out_dir / "cmc.png"),
    }
