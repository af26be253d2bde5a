"""Report tables on a hand-made results database with known answers."""

import numpy as np
import pytest
from scipy.stats import wilcoxon

from lilium.experiments.report import (
    implausible_table,
    load_rows,
    photo_ranks,
    summary_table,
    wilcoxon_pair,
    wilcoxon_table,
    write_report,
)
from lilium.experiments.store import ResultStore
from report_rows import make_rows


@pytest.fixture
def db(tmp_path):
    path = tmp_path / "r.sqlite"
    with ResultStore(path) as store:
        for row in make_rows():
            assert store.insert(row)
    return path


def test_ranks_and_summary(db):
    rows = load_rows(db)
    ranks = photo_ranks(rows)
    assert len(ranks) == 6 * 4  # 4 complete runs (posest, base x 2, pll); base rep 2 left out
    by = {(r["method"], r["variant"], r["repetition"], r["photo"]): r["rank"] for r in ranks}
    assert by[("posest-sfo", "", 0, "s1_f")] == 1.0
    assert by[("lilium", "base", 0, "s2_l")] == 1.5
    assert by[("lilium", "base", 1, "s3_f")] == 3.0
    assert by[("lilium", "pll", 0, "s1_f")] == 3.0  # failed true SFO ranks last
    assert by[("lilium", "pll", 0, "s1_l")] == 1.0
    table = {s["method"]: s for s in summary_table(rows, ranks)}
    assert table["POSEST-SFO"]["rank_frontal"] == 1.0
    base = table["Lilium"]
    assert base["runs"] == 3 and base["rank_frontal"] == pytest.approx(2.25)
    assert base["rank_frontal_sd"] == pytest.approx(np.std([1.5, 3.0], ddof=1))
    # BPE per run: rep 0 = 2, rep 1 = 4, rep 2 (one photo) = 2 -> mean of run means.
    assert base["bpe_frontal_mm"] == pytest.approx(8 / 3)
    assert table["Lilium+P_pll"]["rank_frontal"] == 3.0
    assert table["Lilium+P_pll"]["rank_lateral"] == 1.0
    assert table["Lilium+P_pll"]["bpe_frontal_mm"] is None
    assert table["Lilium+P_pll"]["failed"] == 3
    assert table["POSEST-SFO"]["seconds_mean"] == pytest.approx(0.01)


def test_wilcoxon_bonferroni(db):
    rows = load_rows(db)
    tests = wilcoxon_table(rows, photo_ranks(rows))
    rank_frontal = [t for t in tests if t["measure"] == "rank" and t["view"] == "frontal"]
    assert len(rank_frontal) == 3 and all(t["tests_in_family"] == 3 for t in rank_frontal)
    t = next(t for t in rank_frontal if (t["method_a"], t["method_b"]) == ("POSEST-SFO", "Lilium"))
    assert t["n"] == 3 and t["mean_a"] == 1.0 and t["mean_b"] == pytest.approx(2.25)
    expected = wilcoxon([1.0] * 3, [2.25] * 3, alternative="two-sided").pvalue
    assert t["p"] == pytest.approx(expected)
    assert t["p_bonferroni"] == pytest.approx(min(1.0, 3 * expected))
    # BPE pairs only photos where both methods have a positive SFO with a camera.
    bpe = [t for t in tests if t["measure"] == "bpe" and t["view"] == "frontal"]
    assert {(t["method_a"], t["method_b"]) for t in bpe} == {("POSEST-SFO", "Lilium")}
    assert wilcoxon_pair([1.0, 2.0], [1.0, 2.0]) == (0.0, 1.0)


def test_implausible_worst_run(db):
    table = {i["method"]: i for i in implausible_table(load_rows(db))}
    posest = table["POSEST-SFO"]
    assert posest["implausible_percent"] == pytest.approx(100 * 2 / 18)
    assert (posest["implausible_positive"], posest["implausible_negative"]) == (1, 1)
    assert posest["mean_percent_outside"] == pytest.approx(15.0)
    base = table["Lilium"]
    assert base["worst_run"] == "axes 0 rep 1" and base["runs"] == 3
    assert (base["implausible_positive"], base["implausible_negative"]) == (0, 3)
    assert base["mean_percent_outside"] == pytest.approx(30.0)
    assert table["Lilium+P_pll"]["implausible_percent"] == 0.0


def test_write_report(db, tmp_path):
    paths = write_report(db, tmp_path / "out")
    for key in ("markdown", "summary", "wilcoxon", "implausible", "rank_plot", "bpe_plot"):
        assert paths[key].is_file() and paths[key].stat().st_size > 0
    text = paths["markdown"].read_text()
    assert "| A | Lilium | 3 |" in text and "Bonferroni" in text
    assert paths["rank_plot"].read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="database not found"):
        load_rows(tmp_path / "none.sqlite")
