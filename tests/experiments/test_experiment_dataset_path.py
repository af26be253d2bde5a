"""Fixes found by the hostile-input probes of the runs (tests/acceptance/hostile_runs.py)."""

import pytest

from lilium.cli.main import main


@pytest.mark.parametrize("generate", ["true", "false"])
def test_experiment_dataset_path_a_file_is_one_clear_line(tmp_path, capsys, generate):
    (tmp_path / "d.txt").write_text("x")
    config = tmp_path / "c.toml"
    config.write_text(
        f'methods = ["posest-sfo"]\nexperiments = ["A"]\nrepetitions = 1\n'
        f'[dataset]\npath = "d.txt"\ngenerate = {generate}\nsubjects = 1\nphotos = 1\n'
    )
    code = main(["experiment", str(config), "--no-progress", "--db", str(tmp_path / "r.sqlite")])
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert code != 0
    assert len(err) == 1, err
    assert "d.txt" in err[0] and "dataset.path is a file, not a folder" in err[0]
    assert (tmp_path / "d.txt").read_text() == "x"
