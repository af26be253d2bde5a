"""The consistency rules (docs/checks.md) over a whole generated dataset (``check_rules.py``):
no generated case trips a rule, neither its true camera nor POSEST-SFO's."""

import pytest
from check_rules import main

pytestmark = pytest.mark.slow


def test_no_generated_case_trips_a_rule(tmp_path, capsys):
    from lilium.synthetic.dataset import generate_dataset

    data = tmp_path / "rules-ds"
    generate_dataset(data, 3, 2, seed=0, experiments=("A", "B", "C"), workers=2)
    code = main([str(data)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert " error: " not in out, out
