"""The paper's tables and plots from an experiment database (docs/method/evaluation.md).

Definitions (decisions the paper leaves open are marked *):

- A *run* of a method is one repetition: ``(axes_set, repetition)``; POSEST-SFO has one run in
  A and B and one per axis set in C; each Lilium variant ``repetitions`` runs in A and B and
  ``axes_sets x runs_per_axes_set`` in C.
- **Rank** of one photo in one run: the true skull's rank among the scores of the photo against
  every skull of the experiment (1 = best, ties share the mean rank, a failed SFO ranks last).
  A photo whose SFOs are not all stored yet is left out. **Mean rank** = mean over the photos of
  a view, then mean (and sd) over runs.
- **BPE**: positive SFOs (photo of the tested skull's subject) with a camera; mean over the
  photos of a view, then over runs. *The median over all positive SFOs is given too: one
  degenerate camera can put the mean far off.
- **Wilcoxon** signed-rank test, two-sided, between every two methods of an experiment, for the
  rank (paired per photo: the photo's rank averaged over runs) and the BPE (paired per positive
  SFO, i.e. per photo: averaged over runs); frontal and lateral apart. *Bonferroni family = the
  method pairs of one (experiment, view, measure): ``p_corrected = min(1, p m)``. All-zero
  differences give p = 1.
- **Implausible SFO**: a camera under which some skull pixel lies outside the face mask. For
  each method and experiment, the worst run (highest % of implausible SFOs among the SFOs with
  a camera), with the mean % of skull pixels outside the mask among its implausible SFOs and
  how many of them were positive / negative pairs.
- **Time**: the method's own seconds per SFO (reading and scoring excluded), mean and median.
- **Terms switched off** (docs/method/lilium.md): per experiment, method and view, how many SFOs ran
  with a term switched off because its inputs were missing (``terms_off`` of the stored
  result: P_pll for a skull without its mandible, P_skof without a mask, a P_cam part without
  its prior), in all and per term. *Ranks over skulls with different terms off are biased (an
  off term is a zero), so a non-empty table qualifies every rank of its rows.
"""

import csv
import sqlite3
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..io.paths import same_file
from .config import EXPERIMENTS, VIEW_GROUPS, method_label, method_order, view_group
from .identification import (
    identification_markdown,
    identification_table,
    photo_matches,
    plot_cmc,
    write_identification,
)
from .lr_report import SCORE_FITNESS, lr_identification
from .store import ResultStore, database_error
from .terms_off import TERMS_OFF_COLUMNS, terms_off_markdown, terms_off_rows, terms_off_table


def _mean_sd(values):
    values = [v for v in values if v is not None and np.isfinite(v)]
    if not values:
        return None, None
    return float(np.mean(values)), float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


def load_rows(db):
    """Rows of the database (every column but the stored result JSON).

    The database is opened read-only (nothing is written to it, not even a WAL switch); a file
    that is not a Lilium results database, or a corrupt one, is a ``ValueError``.
    """
    db = Path(db)
    if db.is_dir():
        raise ValueError(f"{db}: is a folder; give the results database file")
    if not db.is_file():
        raise ValueError(f"{db}: database not found; run lilium experiment first")
    try:
        with ResultStore(db, read_only=True) as store:
            rows = store.rows()
    except sqlite3.DatabaseError as exc:
        raise database_error(
            db, exc, "give the database written by lilium experiment (or restore it from a copy)"
        ) from None
    if not rows:
        raise ValueError(f"{db}: the database holds no SFO yet")
    return rows


def photo_ranks(rows):
    """Rank of the true skull for every (experiment, method, run, photo) with all skulls stored.

    From :func:`identification.photo_matches`: ``rank = 1 + better + tied / 2`` (failed SFOs
    rank last, ties share the mean rank).

    Returns
    -------
    list of dict
        ``experiment, method, variant, axes_set, repetition, photo, view, rank, n_skulls``.
    """
    out = []
    for m in photo_matches(rows):
        better, tied, negatives = m.pop("better"), m.pop("tied"), m.pop("negatives")
        out.append(dict(m, rank=1.0 + better + tied / 2.0, n_skulls=negatives + 1))
    return out


def _per_run_view_means(items, value_key):
    """{(exp, method, variant): {view_group: [mean over photos, one per run]}}."""
    acc = defaultdict(lambda: defaultdict(list))
    for it in items:
        v = it[value_key]
        if v is None or not np.isfinite(v):
            continue
        run = (it["axes_set"], it["repetition"])
        acc[(it["experiment"], it["method"], it["variant"])][(view_group(it["view"]), run)].append(
            v
        )
    out = defaultdict(lambda: defaultdict(list))
    for mkey, per in acc.items():
        for (group, _run), values in sorted(per.items()):
            out[mkey][group].append(float(np.mean(values)))
    return out


def summary_table(rows, ranks):
    """Mean rank, BPE and time per experiment and method (frontal/lateral apart).

    Returns
    -------
    list of dict
    """
    positives = [r for r in rows if r["positive"] and r["success"] and r["bpe_mm"] is not None]
    rank_runs = _per_run_view_means(ranks, "rank")
    bpe_runs = _per_run_view_means(positives, "bpe_mm")
    by_method = defaultdict(list)
    for r in rows:
        by_method[(r["experiment"], r["method"], r["variant"])].append(r)
    table = []
    for exp in EXPERIMENTS:
        pairs = {(m, v) for (e, m, v) in by_method if e == exp}
        for method, variant in method_order(pairs):
            key = (exp, method, variant)
            group = by_method[key]
            row = {
                "experiment": exp,
                "method": method_label(method, variant),
                "runs": len({(r["axes_set"], r["repetition"]) for r in group}),
                "sfos": len(group),
                "failed": sum(1 for r in group if not r["success"]),
            }
            for view in VIEW_GROUPS:
                row[f"rank_{view}"], row[f"rank_{view}_sd"] = _mean_sd(rank_runs[key][view])
                row[f"bpe_{view}_mm"], row[f"bpe_{view}_sd"] = _mean_sd(bpe_runs[key][view])
                bpes = [
                    r["bpe_mm"]
                    for r in positives
                    if (r["experiment"], r["method"], r["variant"]) == key
                    and view_group(r["view"]) == view
                ]
                row[f"bpe_{view}_median_mm"] = float(np.median(bpes)) if bpes else None
            seconds = [r["seconds"] for r in group if r["seconds"] is not None]
            row["seconds_mean"] = float(np.mean(seconds)) if seconds else None
            row["seconds_median"] = float(np.median(seconds)) if seconds else None
            table.append(row)
    return table


def _photo_values(items, value_key):
    """{(exp, view_group, method, variant): {photo: mean over runs}}."""
    acc = defaultdict(lambda: defaultdict(list))
    for it in items:
        v = it[value_key]
        if v is None or not np.isfinite(v):
            continue
        key = (it["experiment"], view_group(it["view"]), it["method"], it["variant"])
        acc[key][it["photo"]].append(v)
    return {k: {p: float(np.mean(v)) for p, v in per.items()} for k, per in acc.items()}


def wilcoxon_pair(x, y):
    """Two-sided Wilcoxon signed-rank test of paired samples; (statistic, p) (p = 1 if equal)."""
    from scipy.stats import wilcoxon

    d = np.asarray(x, float) - np.asarray(y, float)
    if len(d) == 0:
        return None, None
    if np.all(d == 0):
        return 0.0, 1.0
    res = wilcoxon(x, y, alternative="two-sided")
    return float(res.statistic), float(res.pvalue)


def wilcoxon_table(rows, ranks):
    """Pairwise Wilcoxon tests with Bonferroni correction (see the module docstring)."""
    positives = [r for r in rows if r["positive"] and r["success"] and r["bpe_mm"] is not None]
    values = {"rank": _photo_values(ranks, "rank"), "bpe": _photo_values(positives, "bpe_mm")}
    out = []
    for measure, table in values.items():
        families = defaultdict(list)
        for exp, view, method, variant in table:
            families[(exp, view)].append((method, variant))
        for exp in EXPERIMENTS:
            for view in VIEW_GROUPS:
                methods = method_order(set(families.get((exp, view), [])))
                tests = []
                for i, a in enumerate(methods):
                    for b in methods[i + 1 :]:
                        va, vb = table[(exp, view, *a)], table[(exp, view, *b)]
                        common = sorted(set(va) & set(vb))
                        x = [va[p] for p in common]
                        y = [vb[p] for p in common]
                        stat, p = wilcoxon_pair(x, y)
                        if p is None:
                            continue
                        tests.append(
                            {
                                "experiment": exp,
                                "view": view,
                                "measure": measure,
                                "method_a": method_label(*a),
                                "method_b": method_label(*b),
                                "n": len(common),
                                "mean_a": float(np.mean(x)),
                                "mean_b": float(np.mean(y)),
                                "statistic": stat,
                                "p": p,
                            }
                        )
                for t in tests:
                    t["p_bonferroni"] = min(1.0, t["p"] * len(tests))
                    t["tests_in_family"] = len(tests)
                out.extend(tests)
    return out


def implausible_table(rows):
    """Worst-run implausible SFOs per experiment and method."""
    runs = defaultdict(lambda: defaultdict(list))
    for r in rows:
        if r["success"] and r["outside_px"] is not None:
            runs[(r["experiment"], r["method"], r["variant"])][
                (r["axes_set"], r["repetition"])
            ].append(r)
    out = []
    for exp in EXPERIMENTS:
        pairs = {(m, v) for (e, m, v) in runs if e == exp}
        for method, variant in method_order(pairs):
            per_run = runs[(exp, method, variant)]
            stats = []
            for run, group in sorted(per_run.items()):
                bad = [r for r in group if r["outside_px"] > 0]
                stats.append(
                    {
                        "run": run,
                        "sfos": len(group),
                        "percent": 100.0 * len(bad) / len(group),
                        "positive": sum(1 for r in bad if r["positive"]),
                        "negative": sum(1 for r in bad if not r["positive"]),
                        "mean_percent_outside": float(np.mean([r["percent_outside"] for r in bad]))
                        if bad
                        else None,
                    }
                )
            worst = max(stats, key=lambda s: s["percent"])
            out.append(
                {
                    "experiment": exp,
                    "method": method_label(method, variant),
                    "runs": len(stats),
                    "worst_run": f"axes {worst['run'][0]} rep {worst['run'][1]}",
                    "sfos": worst["sfos"],
                    "implausible_percent": worst["percent"],
                    "implausible_positive": worst["positive"],
                    "implausible_negative": worst["negative"],
                    "mean_percent_outside": worst["mean_percent_outside"],
                    "implausible_percent_mean_over_runs": float(
                        np.mean([s["percent"] for s in stats])
                    ),
                }
            )
    return out


# -- output -----------------------------------------------------------------------------------
def _fmt(value, digits=3):
    if value is None:
        return "-"
    if isinstance(value, float):
        if not np.isfinite(value):
            return "-"
        if value != 0 and (abs(value) >= 1e5 or abs(value) < 10**-(digits)):
            return f"{value:.{digits}g}" if abs(value) < 1e5 else f"{value:.3e}"
        return f"{value:.{digits}f}"
    return str(value)


def _pm(mean, sd, digits=3):
    if mean is None:
        return "-"
    return f"{_fmt(mean, digits)} ± {_fmt(sd, digits)}" if sd else _fmt(mean, digits)


def _markdown_table(header, lines):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in line) + " |" for line in lines]
    return "\n".join(out)


def write_csv(path, table, columns=()):
    path = Path(path)
    keys = list(table[0]) if table else list(columns)  # an empty table keeps its header
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys)
        writer.writeheader()
        writer.writerows(table)
    return path


def rank_distribution(ranks):
    """Cumulative rank distribution: per experiment and method, the fraction of photo-runs
    (both views) whose true skull ranks r or better (``rank`` of :func:`photo_ranks`: ties at
    their mean rank), r = 1 .. the experiment's number of skulls.

    Returns
    -------
    list of dict
        ``method`` (its label), ``experiment``, ``view`` (``"all"``), ``rank``, ``rate``: the
        rows of :func:`~lilium.experiments.identification.plot_cmc`.
    """
    out = []
    for exp in EXPERIMENTS:
        items = [r for r in ranks if r["experiment"] == exp]
        k = max((r["n_skulls"] for r in items), default=1)
        for method, variant in method_order({(r["method"], r["variant"]) for r in items}):
            values = np.array(
                [r["rank"] for r in items if (r["method"], r["variant"]) == (method, variant)]
            )
            label = method_label(method, variant)
            row = {"method": label, "experiment": exp, "view": "all"}
            out += [row | {"rank": g, "rate": float((values <= g).mean())} for g in range(1, k + 1)]
    return out


def plot_rank_distribution(ranks, path):
    """The cumulative rank distribution (:func:`rank_distribution`), drawn by
    :func:`~lilium.experiments.identification.plot_cmc`."""
    return plot_cmc(
        rank_distribution(ranks), path, ylabel="fraction of photos (all runs) with rank <= r"
    )


def plot_bpe(rows, path):
    """BPE of the positive SFOs per method, one panel per experiment (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pos = [r for r in rows if r["positive"] and r["success"] and r["bpe_mm"] is not None]
    exps = [e for e in EXPERIMENTS if any(r["experiment"] == e for r in pos)] or ["A"]
    fig, axes = plt.subplots(1, len(exps), figsize=(4.5 * len(exps), 4.2), squeeze=False)
    for ax, exp in zip(axes[0], exps, strict=True):
        items = [r for r in pos if r["experiment"] == exp]
        pairs = method_order({(r["method"], r["variant"]) for r in items})
        data = [
            [max(r["bpe_mm"], 1e-3) for r in items if (r["method"], r["variant"]) == p]
            for p in pairs
        ]
        if data:
            ax.boxplot(data, showfliers=True)
            ax.set_xticks(range(1, len(pairs) + 1), [method_label(*p) for p in pairs])
            ax.tick_params(axis="x", rotation=35, labelsize=8)
            ax.set_yscale("log")
        ax.set_title(f"Exp. {exp}")
        ax.grid(alpha=0.3, axis="y")
    axes[0][0].set_ylabel("BPE (mm), positive SFOs")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def markdown_report(db, summary, tests, implausible, n_rows, terms_off=()):
    parts = [f"# Lilium experiment report\n\nDatabase: `{db}` ({n_rows} SFOs).\n"]
    parts.append("## Mean rank of the true skull and BPE (mm)\n")
    parts.append(
        "Mean over the photos of a view, then mean ± sd over runs; failed SFOs rank last. "
        "BPE over positive SFOs with a camera; median over all of them in brackets.\n"
    )
    lines = []
    for s in summary:
        lines.append(
            [
                s["experiment"],
                s["method"],
                s["runs"],
                s["sfos"],
                s["failed"],
                _pm(s["rank_frontal"], s["rank_frontal_sd"]),
                _pm(s["rank_lateral"], s["rank_lateral_sd"]),
                f"{_pm(s['bpe_frontal_mm'], s['bpe_frontal_sd'])} "
                f"({_fmt(s['bpe_frontal_median_mm'])})",
                f"{_pm(s['bpe_lateral_mm'], s['bpe_lateral_sd'])} "
                f"({_fmt(s['bpe_lateral_median_mm'])})",
                _fmt(s["seconds_mean"], 3),
            ]
        )
    parts.append(
        _markdown_table(
            [
                "exp",
                "method",
                "runs",
                "SFOs",
                "failed",
                "rank frontal",
                "rank lateral",
                "BPE frontal (median)",
                "BPE lateral (median)",
                "s / SFO",
            ],
            lines,
        )
    )
    parts.append("\n\n## Time per SFO (s, the method alone; mean / median)\n")
    exps = [e for e in EXPERIMENTS if any(s["experiment"] == e for s in summary)]
    methods = list(dict.fromkeys(s["method"] for s in summary))
    lookup = {(s["experiment"], s["method"]): s for s in summary}
    lines = []
    for m in methods:
        line = [m]
        for e in exps:
            s = lookup.get((e, m))
            line.append(f"{_fmt(s['seconds_mean'])} / {_fmt(s['seconds_median'])}" if s else "-")
        lines.append(line)
    parts.append(_markdown_table(["method"] + [f"Exp. {e}" for e in exps], lines))
    parts.append(
        "\n\n## Wilcoxon signed-rank tests (two-sided, Bonferroni-corrected)\n\n"
        "Rank: paired per photo (mean over runs); BPE: paired per positive SFO (mean over "
        "runs). The Bonferroni family is the method pairs of one experiment, view and "
        "measure.\n"
    )
    lines = [
        [
            t["experiment"],
            t["view"],
            t["measure"],
            t["method_a"],
            t["method_b"],
            t["n"],
            _fmt(t["mean_a"]),
            _fmt(t["mean_b"]),
            _fmt(t["p"], 4),
            _fmt(t["p_bonferroni"], 4),
        ]
        for t in tests
    ]
    parts.append(
        _markdown_table(
            ["exp", "view", "measure", "A", "B", "n", "mean A", "mean B", "p", "p (Bonf.)"],
            lines,
        )
    )
    parts.append(
        "\n\n## Implausible SFOs (skull pixels outside the face mask), worst run\n\n"
        "Among the SFOs with a camera of the worst run: % implausible, how many were positive "
        "/ negative pairs, and the mean % of skull pixels outside the mask among them.\n"
    )
    lines = [
        [
            i["experiment"],
            i["method"],
            i["worst_run"],
            i["sfos"],
            _fmt(i["implausible_percent"], 2),
            i["implausible_positive"],
            i["implausible_negative"],
            _fmt(i["mean_percent_outside"], 2),
            _fmt(i["implausible_percent_mean_over_runs"], 2),
        ]
        for i in implausible
    ]
    parts.append(
        _markdown_table(
            [
                "exp",
                "method",
                "worst run",
                "SFOs",
                "% implausible",
                "positive",
                "negative",
                "mean % outside",
                "% implausible (mean of runs)",
            ],
            lines,
        )
    )
    parts.append(terms_off_markdown(terms_off))
    parts.append("\n\n## Plots\n\n![rank distribution](rank_distribution.png)\n\n![BPE](bpe.png)\n")
    return "\n".join(parts)


#: The write test :func:`write_report` makes (and removes) in its folder.
WRITE_TEST = ".lilium-write-test"

#: Every file :func:`write_report` writes in its folder (the LR files only when a calibration
#: can be cross-validated).
REPORT_FILES = (
    *("report.md", "summary.csv", "wilcoxon.csv", "implausible.csv", "terms_off.csv"),
    *("ranks.csv", "rank_distribution.png", "bpe.png", "identification.csv", "cmc.csv"),
    *("cmc.png", "calibration.csv", "tippett.png", WRITE_TEST),
)


def check_database_not_output(db, out_dir):
    """Refuse, before anything is written, a database that a report file in ``out_dir`` would
    overwrite (``lilium report in/summary.csv --out in``).

    Raises
    ------
    ValueError
        Naming ``--out``, the file and the database, and the fix.
    """
    db, out_dir = Path(db), Path(out_dir)
    for name in REPORT_FILES:
        if same_file(out_dir / name, db):
            raise ValueError(
                f"--out {out_dir}: lilium report writes {name} there, over the database {db}; "
                "give another --out"
            )


def write_report(db, out_dir, dataset=None, log=None):
    """Write ``report.md``, the CSV tables and the PNG plots (:data:`REPORT_FILES`) to
    ``out_dir``; a database one of them would overwrite is refused first.

    ``dataset``: the dataset folder when it moved since the database was written (its rows
    without stored terms need it for the identification LR); ``log`` receives one line when
    the LR could not be computed (the report says so too).

    Returns
    -------
    dict of str -> Path
    """
    rows = load_rows(db)
    out_dir = Path(out_dir)
    check_database_not_output(db, out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise ValueError(f"--out {out_dir}: is a file, not a folder; give a folder for the report")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        probe = out_dir / WRITE_TEST
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise ValueError(
            f"--out {out_dir}: cannot write there ({exc.strerror}); give a writable folder"
        ) from None
    ranks = photo_ranks(rows)
    summary = summary_table(rows, ranks)
    tests = wilcoxon_table(rows, ranks)
    implausible = implausible_table(rows)
    terms_off = terms_off_table(terms_off_rows(db))
    paths = {
        "summary": write_csv(out_dir / "summary.csv", summary),
        "wilcoxon": write_csv(out_dir / "wilcoxon.csv", tests),
        "implausible": write_csv(out_dir / "implausible.csv", implausible),
        "terms_off": write_csv(out_dir / "terms_off.csv", terms_off, TERMS_OFF_COLUMNS),
        "ranks": write_csv(out_dir / "ranks.csv", ranks),
        "rank_plot": plot_rank_distribution(ranks, out_dir / "rank_distribution.png"),
        "bpe_plot": plot_bpe(rows, out_dir / "bpe.png"),
    }
    identification = identification_table(rows)
    for t in identification:
        t["score"] = SCORE_FITNESS
    lr_note = ""
    try:
        lr_paths, lr_table, _, _ = lr_identification(
            [db], out_dir, dataset=dataset, log=lambda line: None
        )
        paths.update(lr_paths)
        identification += lr_table
        lr_note = (
            "\n\nRanked by the identification log10 LR: each pair scored by "
            "a calibration that never saw its subject (cross-validated); Cllr, Cllr_min, "
            "the rates of misleading evidence and of conclusions that support the wrong "
            "proposition in calibration.csv, the Tippett plot:\n\n"
            "![Tippett plot](tippett.png)\n"
        )
    except (ValueError, OSError) as exc:
        lr_note = f"\n\nIdentification LR not computed: {exc}.\n"
        if log is not None:
            log(f"identification LR not computed: {exc}")
    paths.update(write_identification(rows, identification, out_dir))
    md = out_dir / "report.md"
    md.write_text(
        markdown_report(db, summary, tests, implausible, len(rows), terms_off)
        + identification_markdown(identification)
        + lr_note
        + "\n"
    )
    paths["markdown"] = md
    return paths
