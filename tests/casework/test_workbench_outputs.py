"""The workbench page beside every result: ``lilium sfo``, each SFO of ``lilium case`` (and
its examiner's camera), a joint SFO's photos, ``lilium lineup``; linked from the report; none
for a failed SFO."""

import json

from cli_helpers import _run, _sfo
from lilium.methods import posest_sfo
from lilium.pose.posest import failure


def test_sfo_writes_the_workbench(case, tmp_path, capsys):
    out = tmp_path / "sfo"
    assert _run(_sfo(case, out), capsys)[0] == 0
    page = (out / "workbench.html").read_text()
    camera = json.loads((out / "result.json").read_text())["camera"]
    assert repr(camera["focal_px"])[:8] in page  # the page starts at the result's camera


def test_case_and_lineup_link_their_workbenches(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    out = tmp_path / "case"
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--method", "posest-sfo",
            "--out", out]
    assert _run(argv, capsys)[0] == 0
    rel = f"{photo_dir.name}/posest-sfo/workbench.html"
    assert (out / rel).is_file()
    assert f'href="{rel}"' in (out / "report.html").read_text()
    (out / rel).unlink()  # a stored result without its page (an older Lilium) gets it back
    assert _run(argv, capsys)[0] == 0
    assert (out / rel).is_file()
    lineup = tmp_path / "lineup"
    argv = ["lineup", "--no-progress", "--skull", subject_dir, "--method", "posest-sfo",
            "--candidate", "A", photo_dir, "--out", lineup]
    assert _run(argv, capsys)[0] == 0
    assert list(lineup.rglob("workbench.html"))


def test_a_failed_sfo_has_no_workbench(case, tmp_path, capsys, monkeypatch):
    """A failed SFO's folder keeps no page of an earlier run."""
    out = tmp_path / "sfo"
    assert _run(_sfo(case, out), capsys)[0] == 0
    assert (out / "workbench.html").is_file()
    monkeypatch.setattr(posest_sfo, "posest", lambda *a, **k: failure("no real sample"))
    assert _run(_sfo(case, out), capsys)[0] == 1
    assert json.loads((out / "result.json").read_text())["camera"] is None
    assert not (out / "workbench.html").exists()
