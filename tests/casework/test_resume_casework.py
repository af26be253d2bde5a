"""Resumes of ``lilium lineup`` and ``lilium case`` (single and ``--joint``): a stored SFO is
reused only for the same inputs and options (its ``inputs_sha256``) and only whole with its
overlay; a reused SFO gives the report a fresh run gives; one run at a time on an ``--out``.
"""

import json
import re
import shutil

import numpy as np
import pytest

import lilium.casework.case as case_module
import lilium.casework.joint_case as joint_case
import lilium.casework.lineup as lineup_module
from cli_helpers import _edit_json, _one_line_error, _run
from lilium.casework.folders import FINGERPRINT_KEY, output_lock, sfo_fingerprint
from lilium.casework.inputs import load_photos, load_skull
from lilium.casework.request import PhotoSource, PriorOverrides, SkullSource
from lilium.io.results import png_readable, write_png, write_result
from lilium.methods.options import SfoOptions
from lilium.methods.registry import run_sfo
from standin_case import scaled_photo

#: Lilium's smallest budget that runs (fast tests).
TINY = ("--generations", "2", "--population", "5")


def _lineup(case, out, method="posest-sfo", *extra):
    subject_dir, photo_dir = case
    return ["lineup", "--no-progress", "--skull", subject_dir, "--candidate", "A", photo_dir,
            "--method", method, "--out", out, *extra]


def _stored(out, case, tag="posest-sfo"):
    return out / "A" / case[1].name / tag / "result.json"


def _count_sfos(monkeypatch):
    """Count the single SFOs run (not read back) from now on."""
    runs = []

    def counted(method, skull, photo, *args):
        runs.append(photo.id)
        return run_sfo(method, skull, photo, *args)

    monkeypatch.setattr(case_module, "run_sfo", counted)
    monkeypatch.setattr(lineup_module, "run_sfo", counted)
    return runs


# -- D1: the input fingerprint -------------------------------------------------------------------


def _fingerprint(case, options=SfoOptions(), seed=0, **priors):
    subject_dir, photo_dir = case
    skull, skull_inputs = load_skull(SkullSource(subject_dir))
    (record,) = load_photos([PhotoSource(photo_dir)], PriorOverrides(**priors))
    return sfo_fingerprint(
        "lilium", options, seed, skull, skull_inputs, [record.photo], [record.inputs]
    )


def test_the_fingerprint_follows_files_options_seed_and_priors_not_the_path(case, tmp_path):
    subject_dir, photo_dir = case
    first = _fingerprint(case)
    assert re.fullmatch("[0-9a-f]{64}", first)
    assert _fingerprint(case) == first
    moved = [shutil.copytree(d, tmp_path / "moved" / d.name) for d in case]
    assert _fingerprint(moved) == first  # the same bytes, named the same, elsewhere
    assert _fingerprint(case, SfoOptions().with_de(max_generations=3)) != first
    assert _fingerprint(case, SfoOptions().with_de(population_size=7)) != first
    assert _fingerprint(case, SfoOptions().with_de(max_seconds=9.0)) != first
    assert _fingerprint(case, SfoOptions(variant="base")) != first
    assert _fingerprint(case, seed=1) != first
    assert _fingerprint(case, focal_px=(900.0, 1100.0)) != first
    assert _fingerprint(case, scd_mm=(900.0, 1100.0)) != first
    mask = photo_dir / "face_mask.png"
    mask.write_bytes(mask.read_bytes() + b"\0")
    assert _fingerprint(case) != first


def test_a_lineup_resumed_under_other_options_runs_its_sfos_again(case, tmp_path, capsys, monkeypatch):  # noqa: E501
    out = tmp_path / "out"
    assert _run(_lineup(case, out, "lilium", *TINY), capsys)[0] == 0
    stored = _stored(out, case, "lilium-skof+pll")
    assert re.fullmatch("[0-9a-f]{64}", json.loads(stored.read_text())[FINGERPRINT_KEY])
    runs = _count_sfos(monkeypatch)
    code, stdout, _ = _run(_lineup(case, out, "lilium", *TINY), capsys)
    assert code == 0 and runs == [] and "reusing the stored result" in stdout
    code, stdout, _ = _run(_lineup(case, out, "lilium", "--generations", "3", "--population", "5"), capsys)  # noqa: E501
    assert code == 0 and len(runs) == 1
    assert "running the SFO again" in stdout and "other inputs or options" in stdout
    assert json.loads(stored.read_text())["generations"] == 3


@pytest.mark.parametrize("change", ["photo landmark", "cranial landmark", "image"])
def test_a_lineup_resumed_over_changed_inputs_runs_its_sfo_again(case, tmp_path, capsys, change):
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    assert _run(_lineup(case, out), capsys)[0] == 0
    before = json.loads(_stored(out, case).read_text())
    if change == "photo landmark":
        name = sorted(json.loads((photo_dir / "photo.json").read_text())["landmarks"])[0]
        _edit_json(photo_dir / "photo.json", lambda d: d["landmarks"][name].__setitem__(0, d["landmarks"][name][0] + 25.0))  # noqa: E501
    elif change == "cranial landmark":
        path = subject_dir / "cranial_landmarks.json"
        table = json.loads(path.read_text())
        table = table.get("landmarks", table)
        name = sorted(table)[0]

        def move(data):
            lms = data.get("landmarks", data)
            lms[name] = [float(x) + 4.0 for x in lms[name]]

        _edit_json(path, move)
    else:  # another photo under the same folder name
        other = scaled_photo(photo_dir, tmp_path / "half", 0.5)
        shutil.rmtree(photo_dir)
        shutil.copytree(other, photo_dir)
    assert _run(_lineup(case, out), capsys)[0] == 0
    after = json.loads(_stored(out, case).read_text())
    assert after[FINGERPRINT_KEY] != before[FINGERPRINT_KEY]
    assert after["camera"] != before["camera"]


# -- D2: result.json last, only with its whole overlay --------------------------------------------


def test_write_result_writes_result_json_only_after_its_overlay(tmp_path, monkeypatch):
    from lilium.io import results

    class Result:
        def to_dict(self):
            return {"method": "posest-sfo"}

    folder = tmp_path / "sfo"
    write_result(folder, Result(), np.zeros((4, 5, 3), np.uint8))
    assert png_readable(folder / "overlay.png") and (folder / "result.json").is_file()

    def full(path, data):
        raise OSError(27, "File too large")  # what a file-size limit gives: no file name

    monkeypatch.setattr(results, "_write_bytes", full)
    with pytest.raises(OSError) as caught:
        write_result(folder, Result(), np.zeros((4, 5, 3), np.uint8))
    assert caught.value.filename == str(folder / "overlay.png")
    assert not (folder / "result.json").exists()  # the earlier one too: it is not this overlay's
    # Neither the earlier overlay (another camera's) nor a temporary file is left.
    assert list(folder.iterdir()) == []
    monkeypatch.undo()
    write_png(folder / "overlay.png", np.zeros((4, 5, 3), np.uint8))
    monkeypatch.setattr(results, "_write_bytes", full)
    with pytest.raises(OSError):
        write_png(folder / "overlay.png", np.ones((4, 5, 3), np.uint8))
    assert [p.name for p in folder.iterdir()] == ["overlay.png"]  # no temporary file left
    assert png_readable(folder / "overlay.png")  # the earlier one, whole (atomic replace)


def test_a_cut_png_is_not_readable(tmp_path):
    path = tmp_path / "o.png"
    write_png(path, np.full((40, 50, 3), 7, np.uint8))
    data = path.read_bytes()
    assert png_readable(path)
    for cut in (b"", data[: len(data) // 2]):
        path.write_bytes(cut)
        assert not png_readable(path)
    path.unlink()
    assert not png_readable(path)


@pytest.mark.parametrize("damage", ["missing", "empty", "cut"])
def test_a_lineup_resumed_without_a_whole_overlay_runs_the_sfo_again(case, tmp_path, capsys, damage):  # noqa: E501
    out = tmp_path / "out"
    assert _run(_lineup(case, out), capsys)[0] == 0
    overlay = _stored(out, case).parent / "overlay.png"
    data = overlay.read_bytes()
    if damage == "missing":
        overlay.unlink()
    else:
        overlay.write_bytes(data[: len(data) // 2] if damage == "cut" else b"")
    code, stdout, _ = _run(_lineup(case, out), capsys)
    assert code == 0 and "overlay.png is missing or incomplete" in stdout
    assert png_readable(overlay)


def test_a_file_size_limit_names_the_file(case, tmp_path, capsys, monkeypatch):
    """The first file an SFO writes (its workbench page, then its overlay) names the limit."""
    from lilium.io import results

    def full(path, data):
        raise OSError(27, "File too large")

    monkeypatch.setattr(results, "_write_bytes", full)
    monkeypatch.delenv("LILIUM_DEBUG")
    out = tmp_path / "out"
    line = _one_line_error(capsys, _lineup(case, out), "workbench.html")
    assert str(_stored(out, case).parent) in line
    assert not _stored(out, case).exists()


# -- D3: lilium case resumes ----------------------------------------------------------------------


def _case(case, tmp_path, out, *extra):
    subject_dir, photo_dir = case
    second = tmp_path / "p2"
    if not second.exists():
        scaled_photo(photo_dir, second, 0.5)
    return ["case", "--skull", subject_dir, "--photo", photo_dir, "--photo", second,
            "--method", "lilium", *TINY, "--out", out, *extra]


def _report(path):
    """The report without its date, to compare two runs."""
    return re.sub(r"\d{4}-\d\d-\d\dT[\d:+]+", "DATE", path.read_text())


def _without_seconds(path):
    return {k: v for k, v in json.loads(path.read_text()).items() if k != "seconds"}


def test_a_case_resumes_and_reports_as_a_fresh_run(case, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    argv = _case(case, tmp_path, out)
    assert _run(argv, capsys)[0] == 0
    fresh = _report(out / "report.html")
    kept = out / case[1].name / "lilium-skof+pll" / "result.json"
    lost = out / "p2" / "lilium-skof+pll" / "result.json"
    before, lost_before = kept.read_bytes(), _without_seconds(lost)
    runs = _count_sfos(monkeypatch)
    (out / "report.html").unlink()  # a crash before the report: every SFO is reused
    code, stdout, _ = _run(argv, capsys)
    assert code == 0 and runs == [] and stdout.count("(stored)") == 2
    assert _report(out / "report.html") == fresh
    shutil.rmtree(out / "p2")  # a crash before the second photo's SFO
    code, stdout, _ = _run(argv, capsys)
    assert code == 0 and runs == ["p2"]  # only the lost SFO ran again
    assert kept.read_bytes() == before
    assert _without_seconds(lost) == lost_before  # the same SFO: the same result
    report = (out / "report.html").read_text()
    for photo in (case[1].name, "p2"):
        assert f"{photo}/lilium-skof%2Bpll/overlay.png" in report


def test_a_joint_case_resumes_and_reports_as_a_fresh_run(case, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    argv = _case(case, tmp_path, out, "--joint")
    assert _run(argv, capsys)[0] == 0
    fresh = _report(out / "report.html")
    stored = out / "joint" / "lilium-skof+pll" / "result.json"
    before = stored.read_bytes()
    (out / "report.html").unlink()

    def no_rerun(*args, **kwargs):
        raise AssertionError("the stored joint SFO ran again")

    with monkeypatch.context() as patch:
        patch.setattr(joint_case, "run_joint_sfo", no_rerun)
        code, stdout, _ = _run(argv, capsys)
    assert code == 0 and "(stored)" in stdout
    assert stored.read_bytes() == before
    assert _report(out / "report.html") == fresh
    argv[argv.index("--generations") + 1] = "3"  # another budget: the joint SFO runs again
    code, stdout, _ = _run(argv, capsys)
    assert code == 0 and "running the SFO again" in stdout
    assert json.loads(stored.read_text())[FINGERPRINT_KEY] != json.loads(before)[FINGERPRINT_KEY]


# -- D10: one run at a time on an output folder ---------------------------------------------------


@pytest.mark.parametrize("command", ["lineup", "case"])
def test_a_second_run_on_one_out_is_refused(case, tmp_path, capsys, command):
    out = tmp_path / "out"
    argv = _lineup(case, out) if command == "lineup" else _case(case, tmp_path, out)
    with output_lock(out):
        line = _one_line_error(capsys, argv, str(out), "in use by another lilium run", "--out")
    assert "pid" in line
    assert not (out / "report.html").exists()
    assert _run(argv, capsys)[0] == 0  # released: the run goes ahead
    assert not any(p.name.startswith(".lilium-run") for p in out.iterdir())


def test_the_lock_removes_an_output_folder_it_made_when_the_run_left_it_empty(tmp_path):
    out = tmp_path / "new" / "out"
    with pytest.raises(ValueError, match="refused"):
        with output_lock(out):
            raise ValueError("refused")
    assert not out.exists()
