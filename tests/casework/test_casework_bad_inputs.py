"""Hostile inputs of the newer entry points (issue 28, tests/acceptance/hostile_casework.py):
a calibration file with NaN, text or impossible counts, a results database given twice, empty,
damaged or about to be overwritten, a lineup or joint SFO given one photo twice (by path or as
a copy), and a resumed lineup under another calibration; each a one-line error naming the
file or option (exit 2), or the right answer."""

import json
import shutil

import pytest

from cli_helpers import _one_line_error, _run
from lilium.casework.lineup import check_candidates
from lilium.experiments.store import ResultStore
from lilium.identification.calibration import Calibration
from lilium.io.calibration import read_calibration, shipped_path
from lilium.io.case import check_distinct_files
from standin_case import terms_database

# -- calibration files -------------------------------------------------------------------------


def _shipped():
    return json.loads(shipped_path().read_text())


def _set(key, value, inner=None):
    def change(model):
        (model[inner] if inner else model)[key] = value

    return change


@pytest.mark.parametrize(
    "change, needle",
    [
        (_set("landmark_chi2", float("nan"), "weights"), "weights.landmark_chi2"),
        (_set("intercept", float("inf")), "intercept"),
        (_set("landmark_chi2", "-1.3", "weights"), "weights.landmark_chi2"),
        (_set("intercept", True), "intercept"),
        (_set("landmark_chi2", 0.0, "scale"), "scale.landmark_chi2"),
        (_set("n_same", 0), "n_same"),
        (_set("n_diff", 2.5), "n_diff"),
        (_set("warp", {"knots": [0.0, float("nan")], "ln_lr": [0.0, 1.0]}), "warp"),
    ],
)
def test_a_model_with_coefficients_that_are_not_finite_numbers_is_refused(change, needle):
    data = _shipped()["models"]["posest-sfo//frontal"]
    Calibration.from_dict(data)  # the shipped model reads
    change(data)
    with pytest.raises(ValueError, match=needle):
        Calibration.from_dict(data)


def test_a_calibration_file_names_itself_and_the_model(tmp_path):
    data = _shipped()
    data["models"]["lilium/skof+pll/frontal"]["weights"]["landmark_chi2"] = float("nan")
    path = tmp_path / "cal.json"
    path.write_text(json.dumps(data))  # NaN as JSON's NaN, which Python reads
    with pytest.raises(ValueError, match=r"cal\.json: model 'lilium/skof\+pll/frontal'"):
        read_calibration(path)
    path.write_text(json.dumps(dict(data, models=[1, 2])))
    with pytest.raises(ValueError, match=r'cal\.json: "models" must be an object'):
        read_calibration(path)


# -- lilium calibrate ----------------------------------------------------------------------------



def test_calibrate_refuses_a_database_twice_empty_or_under_its_outputs(tmp_path, capsys):
    db = terms_database(tmp_path / "r.sqlite")
    out = tmp_path / "out"
    _one_line_error(capsys, ["calibrate", db, tmp_path / "." / "r.sqlite", "--out", out], "twice")
    with ResultStore(tmp_path / "empty.sqlite"):
        pass
    _one_line_error(
        capsys, ["calibrate", tmp_path / "empty.sqlite", "--out", out], "empty.sqlite", "no SFO"
    )
    _one_line_error(capsys, ["calibrate", db, "--dataset", tmp_path, "--out", out], "--dataset")
    inside = shutil.copy(db, tmp_path / "calibration.csv")
    _one_line_error(capsys, ["calibrate", inside, "--out", tmp_path], "--out", "calibration.csv")
    assert (tmp_path / "calibration.csv").read_bytes() == db.read_bytes()  # left untouched
    code, stdout, err = _run(["calibrate", db, "--out", out], capsys)
    assert code == 0, err
    assert (out / "calibration.json").is_file() and "calibration:" in stdout


@pytest.mark.parametrize(
    "result, needle",
    [
        (lambda k, d: "{bad" if k == 2 else json.dumps(d), "row 3 holds a result that is not"),
        (lambda k, d: "[1, 2]" if k == 0 else json.dumps(d), "row 1 holds a result that is not"),
        (
            lambda k, d: json.dumps(d | {"identification_terms": {"landmark_chi2": "0.3"}}),
            "row 1 holds identification_terms",
        ),
        (lambda k, d: json.dumps(d | {"camera": {"focal_px": -1}}), "row 1 holds an unreadable"),
    ],
)
def test_calibrate_names_the_database_and_row_of_a_damaged_result(tmp_path, capsys, result, needle):
    db = terms_database(tmp_path / "r.sqlite", result=result)
    _one_line_error(capsys, ["calibrate", db, "--out", tmp_path / "out"], "r.sqlite", needle)


# -- the same photo twice --------------------------------------------------------------------


def test_a_copied_photo_is_the_same_photo(case, tmp_path):
    _, photo_dir = case
    copy = shutil.copytree(photo_dir, tmp_path / "copy")
    with pytest.raises(ValueError, match=r"--photo .*copy: the same image \(byte for byte\)"):
        check_distinct_files([photo_dir, copy])
    with pytest.raises(ValueError, match="--candidate B: .* is the same photo as"):
        check_candidates([("A", [photo_dir]), ("B", [photo_dir])])
    with pytest.raises(ValueError, match="--candidate A: .*copy is the same image"):
        check_candidates([("A", [photo_dir, copy])])
    with pytest.raises(ValueError, match="--candidate lineup.json: the name of the lineup's"):
        check_candidates([("lineup.json", [photo_dir])])
    with pytest.raises(ValueError, match="name is empty"):
        check_candidates([(" ", [photo_dir])])


def test_joint_sfo_refuses_a_copied_photo_folder(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    copy = shutil.copytree(photo_dir, tmp_path / "copy")
    argv = ["sfo", "--method", "lilium", "--skull", subject_dir, "--photo", photo_dir]
    argv += ["--photo", copy, "--out", tmp_path / "o"]
    _one_line_error(capsys, argv, "--photo", "copy", "byte for byte")
    assert not (tmp_path / "o").exists()


# -- lilium lineup resumed ----------------------------------------------------------------------


def test_a_resumed_lineup_identifies_again_with_this_runs_calibration(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    out = tmp_path / "lineup"
    argv = ["lineup", "--no-progress", "--skull", subject_dir, "--method", "posest-sfo"]
    argv += ["--candidate", "A", photo_dir, "--out", out]
    assert _run(argv, capsys)[0] == 0
    stored = out / "A" / photo_dir.name / "posest-sfo" / "result.json"
    first = json.loads(stored.read_text())["identification"]
    assert first["log10_lr"] is not None
    data = json.loads(stored.read_text())
    data["identification"]["log10_lr"] = "abc"  # an edited stored record is not trusted
    stored.write_text(json.dumps(data))
    assert _run(argv, capsys)[0] == 0
    ranking = json.loads((out / "lineup.json").read_text())["ranking"]
    assert ranking[0]["identification"]["log10_lr"] == pytest.approx(first["log10_lr"])
    # Another calibration, without a model for the decision: no LR, said in the result too.
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"format": "lilium-calibration", "models": {}}))
    assert _run(argv + ["--calibration", other], capsys)[0] == 0
    ranking = json.loads((out / "lineup.json").read_text())["ranking"]
    assert ranking[0]["identification"]["log10_lr"] is None
    assert json.loads(stored.read_text())["identification"]["calibration"]["file"] == str(other)
