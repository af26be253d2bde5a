"""``lilium synth``'s experiment letters and contact sheet, checked before anything is generated:
each bad value ends in one error line that names the option."""

import numpy as np
import pytest

from lilium.cli.main import main


def _error(capsys, argv):
    assert main([str(a) for a in argv]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(lines) == 1 and ": error:" in lines[0], lines
    return lines[0]


@pytest.mark.parametrize(
    ("letters", "said"),
    [("X", "'X' is not an experiment"), (",", "at least one"), ("A,a", "A is given twice")],
)
def test_synth_experiments_are_checked_before_generating(tmp_path, capsys, letters, said):
    argv = ["synth", "--out", tmp_path / "d", "--subjects", "1", "--photos", "1", "--workers", "1"]
    line = _error(capsys, [*argv, "--no-progress", "--experiments", letters])
    assert "--experiments" in line and said in line
    assert not (tmp_path / "d").exists()


@pytest.mark.parametrize("sheet", ["folder", "sheet.txt"])
def test_synth_contact_sheet_is_checked_before_generating(tmp_path, capsys, sheet):
    (tmp_path / "folder").mkdir()
    argv = ["synth", "--out", tmp_path / "d", "--subjects", "1", "--photos", "1", "--workers", "1"]
    line = _error(capsys, [*argv, "--no-progress", "--contact-sheet", tmp_path / sheet])
    assert "--contact-sheet" in line and ".png" in line
    assert not (tmp_path / "d" / "dataset.json").exists()


def test_synth_experiment_letters_parse():
    from lilium.cli.synth import experiment_list

    assert experiment_list(" b, a ") == ("B", "A")
    assert np.array_equal(experiment_list("A,B,C"), ("A", "B", "C"))
