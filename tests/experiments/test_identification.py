"""Identification metrics (rank-1 rate, mean rank, ROC AUC, CMC) on hand-made rows."""

import csv

import numpy as np
import pytest

from lilium.experiments.identification import (
    cmc_table,
    cmc_values,
    identification_table,
    photo_matches,
)
from lilium.experiments.report import photo_ranks, write_report
from lilium.experiments.store import ResultStore
from report_rows import report_row as _row

SKULLS = ("s1", "s2", "s3", "s4")
P1 = ("p1", "s1", "frontal")
P2 = ("p2", "s2", "frontal")
P3 = ("p3", "s3", "lateral_left")
P4 = ("p4", "s4", "lateral_right")

#: POSEST-SFO scores per photo and skull (None = failed SFO). By hand (lower is better):
#: p1: true best -> better 0, tied 0: rank 1, CMC 1 1 1 1, AUC 1.
#: p2: s1 better, s3 tied -> rank 2.5, CMC 0 .5 1 1, AUC (3 - 1 - .5) / 3 = .5.
#: p3: the true SFO fails, the others not -> rank 4, CMC 0 0 0 1, AUC 0.
#: p4: s1 ties, s2 and s3 fail -> rank 1.5, CMC .5 1 1 1, AUC (3 - .5) / 3 = 5/6.
SCORES = {
    P1: {"s1": 1.0, "s2": 2.0, "s3": 3.0, "s4": 4.0},
    P2: {"s1": 1.0, "s2": 2.0, "s3": 2.0, "s4": 5.0},
    P3: {"s1": 1.0, "s2": 2.0, "s3": None, "s4": 3.0},
    P4: {"s1": 1.0, "s2": None, "s3": None, "s4": 1.0},
}


def make_rows():
    rows = []
    for photo, scores in SCORES.items():
        for skull, score in scores.items():
            rows.append(_row("posest-sfo", "", 0, photo, skull, score))
    # Lilium base, two runs on p1: rep 0 true best (rank 1), rep 1 true worst (rank 4).
    for rep, true_score in ((0, 0.5), (1, 9.0)):
        for skull in SKULLS:
            rows.append(
                _row("lilium", "base", rep, P1, skull, true_score if skull == "s1" else 2.0)
            )
    # An incomplete photo (two skulls of four stored): left out.
    for skull in ("s1", "s2"):
        rows.append(_row("posest-sfo", "", 0, ("p5", "s1", "frontal"), skull, 1.0))
    return rows


def by_key(table):
    return {(r["method"], r["view"]): r for r in table}


def test_identification_table_by_hand():
    table = by_key(identification_table(make_rows()))
    assert set(table) == {
        ("POSEST-SFO", "frontal"),
        ("POSEST-SFO", "lateral"),
        ("Lilium", "frontal"),
    }
    front, lat = table[("POSEST-SFO", "frontal")], table[("POSEST-SFO", "lateral")]
    assert front["rank1_rate"] == pytest.approx(0.5)
    assert front["mean_rank"] == pytest.approx(1.75)
    assert front["auc"] == pytest.approx(0.75)
    assert front["photo_runs"] == 2 and front["skulls"] == 4 and front["experiment"] == "A"
    assert lat["rank1_rate"] == pytest.approx(0.25)
    assert lat["mean_rank"] == pytest.approx(2.75)
    assert lat["auc"] == pytest.approx((0.0 + 5.0 / 6.0) / 2.0)
    lil = table[("Lilium", "frontal")]
    assert (lil["rank1_rate"], lil["mean_rank"], lil["auc"]) == pytest.approx((0.5, 2.5, 0.5))
    assert lil["runs"] == 2 and lil["photo_runs"] == 2


def test_mean_rank_agrees_with_the_rank_table():
    rows = make_rows()
    ranks = [r for r in photo_ranks(rows) if r["method"] == "posest-sfo"]
    matches = [m for m in photo_matches(rows) if m["method"] == "posest-sfo"]
    assert [r["photo"] for r in ranks] == [m["photo"] for m in matches] == ["p1", "p2", "p3", "p4"]
    for r, m in zip(ranks, matches, strict=True):
        assert r["rank"] == 1 + m["better"] + m["tied"] / 2


def test_cmc_by_hand():
    assert cmc_values(0, 0, 4).tolist() == [1.0, 1.0, 1.0, 1.0]
    assert cmc_values(1, 1, 4).tolist() == [0.0, 0.5, 1.0, 1.0]
    assert cmc_values(3, 0, 4).tolist() == [0.0, 0.0, 0.0, 1.0]
    curves = {}
    for c in cmc_table(make_rows()):
        curves.setdefault((c["method"], c["view"]), []).append((c["rank"], c["rate"]))
    assert curves[("POSEST-SFO", "frontal")] == [(1, 0.5), (2, 0.75), (3, 1.0), (4, 1.0)]
    assert curves[("POSEST-SFO", "lateral")] == [(1, 0.25), (2, 0.5), (3, 0.5), (4, 1.0)]
    # CMC(1) is the rank-1 rate; the CMC never decreases and ends at 1.
    rates = np.array([r for _, r in curves[("Lilium", "frontal")]])
    assert rates[0] == 0.5 and np.all(np.diff(rates) >= 0) and rates[-1] == 1.0


def test_report_writes_identification_csv_and_cmc_plot(tmp_path):
    db = tmp_path / "r.sqlite"
    with ResultStore(db) as store:
        for row in make_rows():
            assert store.insert(row)
    paths = write_report(db, tmp_path / "out")
    with paths["identification"].open() as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0])[:6] == ["method", "experiment", "view", "rank1_rate", "mean_rank", "auc"]
    front = next(r for r in table if r["method"] == "POSEST-SFO" and r["view"] == "frontal")
    assert float(front["auc"]) == pytest.approx(0.75)
    assert paths["cmc_plot"].read_bytes()[:4] == b"\x89PNG"
    assert paths["cmc"].is_file()
    assert "## Identification" in paths["markdown"].read_text()


def test_medium_preset():
    from lilium.experiments.config import PRESETS, load_config

    medium = load_config("medium")
    assert medium == PRESETS["medium"]
    assert medium.experiments == ("C",) and medium.dataset.subjects >= 10
    assert 2 * medium.dataset.photos == 4
    assert medium.methods == (("posest-sfo", ""), ("lilium", "skof+pll"))
    assert (medium.axes_sets, medium.runs_per_axes_set) == (1, 1)
    assert (medium.de.population_size, medium.de.max_generations) == (30, 750)
