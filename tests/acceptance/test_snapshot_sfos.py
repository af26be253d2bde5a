"""Same seeds, same numbers: the result.json of POSEST-SFO and every Lilium variant on
generated Exp. C photos (``snapshot_sfos.py``) against the snapshot in
``data/sfo_snapshot.json``. To record a new one after a change that is meant to move the
numbers (and say so in the commit)::

    cd tests/acceptance && python snapshot_sfos.py --out /tmp/snap --save data/sfo_snapshot.json
"""

import json
from pathlib import Path

import pytest
from snapshot_sfos import differences, run_all

pytestmark = pytest.mark.slow

SNAPSHOT = Path(__file__).parent / "data" / "sfo_snapshot.json"

#: Relative tolerance of a numeric field: the seeded runs repeat bit for bit on one machine;
#: another CPU or BLAS may round differently.
RTOL = 1e-6


def test_seeded_sfos_match_the_snapshot(tmp_path):
    before = json.loads(SNAPSHOT.read_text())
    after = run_all(tmp_path, generations=40, population=12)
    assert sorted(after) == sorted(before)
    diffs = list(differences(before, after, RTOL))
    shown = "\n".join(f"{where}: {b!r} -> {a!r}" for where, b, a in diffs[:20])
    assert not diffs, f"{len(diffs)} field(s) differ (rtol {RTOL:g}):\n{shown}"
