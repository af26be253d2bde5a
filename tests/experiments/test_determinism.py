"""What a report or a calibration computes from stored SFOs does not depend on the order the
rows were stored in or the databases are given in (tests/acceptance/hostile_determinism.py)."""

import json
import sqlite3

import numpy as np
import pytest

from standin_case import terms_database


def _reinserted(src, dst, order):
    """``src``'s rows stored again in ``dst`` in another insertion order."""
    from lilium.experiments.store import COLUMNS, ResultStore

    with ResultStore(src, read_only=True) as store:
        rows = store.rows(list(COLUMNS))
    with ResultStore(dst) as store:
        for k in order(len(rows)):
            store.insert(rows[k])
    return dst


def test_rows_come_in_key_order_whatever_the_insertion(tmp_path):
    from lilium.experiments.store import ResultStore, task_key

    a = terms_database(tmp_path / "a.sqlite", n_subjects=4)
    b = _reinserted(a, tmp_path / "b.sqlite", lambda n: np.random.default_rng(1).permutation(n))
    with sqlite3.connect(b) as conn:  # stored in another order indeed
        first = conn.execute("SELECT photo, subject FROM sfo ORDER BY id LIMIT 3").fetchall()
    with ResultStore(a, read_only=True) as sa, ResultStore(b, read_only=True) as sb:
        ra, rb = sa.rows(), sb.rows()
    assert [task_key(r) for r in ra] == [task_key(r) for r in rb]
    assert [task_key(r) for r in ra] == sorted(task_key(r) for r in ra)
    assert first != [(r["photo"], r["subject"]) for r in ra[:3]]


def test_pav_pools_tied_scores():
    from lilium.identification.calibration import pav_log10_lr

    scores = np.array([-1.0, 0.5, 0.5, 0.5, 0.5, 2.0, -0.3, 0.5])
    same = np.array([0, 1, 0, 0, 1, 1, 0, 0], bool)
    lr = pav_log10_lr(scores, same)
    for perm in (np.arange(8)[::-1], np.random.default_rng(0).permutation(8)):
        np.testing.assert_allclose(pav_log10_lr(scores[perm], same[perm]), lr[perm])
    tied = lr[scores == 0.5]
    assert np.ptp(tied) == 0  # one LR for every pair of one score
    # the tie's LR is its share of same-person pairs (2 of 5) against the prior odds (3 / 5)
    assert tied[0] == pytest.approx(np.log10((2 / 5) / (3 / 5)) - np.log10(3 / 5))


def test_calibration_does_not_depend_on_the_order_of_rows_or_databases(tmp_path):
    from lilium.experiments.calibrate import database_decisions

    a = terms_database(tmp_path / "a.sqlite", n_subjects=4, seed=0)
    b = terms_database(tmp_path / "b.sqlite", n_subjects=4, seed=1)
    b2 = _reinserted(b, tmp_path / "b2.sqlite", lambda n: range(n - 1, -1, -1))

    def pooled(dbs):
        decisions, _ = database_decisions(dbs, log=lambda *_: None)
        return {
            key: sorted(json.dumps(p, sort_keys=True, default=str) for p in pairs)
            for key, pairs in decisions.items()
        }

    reference = pooled([a, b])
    assert pooled([b, a]) == reference
    assert pooled([a, b2]) == reference
