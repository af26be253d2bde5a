"""Hostile but realistic inputs (issue 28): JSON booleans as coordinates, absurd priors and
depth tables, deep JSON, unknown keys; each a one-line error naming the file or option and the
fix (exit 2), or a warning, never a silently wrong answer."""

import json

import pytest

from cli_helpers import _edit_json, _one_line_error, _run, _sfo

# -- JSON booleans are not numbers -----------------------------------------------------------


@pytest.mark.parametrize(
    "where, change, needles",
    [
        (
            "photo",
            lambda d: d["landmarks"].update(nasion=[True, False]),
            ["photo.json", "'nasion' must have 2 numeric coordinates", "true/false"],
        ),
        (
            "photo",
            lambda d: d["landmarks"].update(nasion=["599.5", "449.5"]),
            ["photo.json", "'nasion' must have 2 numeric coordinates"],
        ),
        (
            "photo",
            lambda d: d["priors"].update(head_tolerance_deg=True),
            ["photo.json", "priors.head_tolerance_deg"],
        ),
        (
            "photo",
            lambda d: d["priors"].update(
                head_rotation_skull2cam=[[True, False, False], [False, True, False], [0, 0, 1]]
            ),
            ["photo.json", "head_rotation_skull2cam must be a 3x3 matrix of numbers"],
        ),
        (
            "skull",
            lambda d: d["landmarks"].update(nasion=[True, False, True]),
            ["cranial_landmarks.json", "'nasion' must have 3 numeric coordinates"],
        ),
    ],
)
def test_json_booleans_are_not_coordinates(case, tmp_path, capsys, where, change, needles):
    subject_dir, photo_dir = case
    path = photo_dir / "photo.json" if where == "photo" else subject_dir / "cranial_landmarks.json"
    _edit_json(path, change)
    _one_line_error(capsys, _sfo(case, tmp_path / "out", "--method", "posest-sfo"), *needles)


def test_json_booleans_in_a_face_curve(case, tmp_path, capsys):
    _, photo_dir = case
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": [[True, 1], [500, 600]]}))
    _one_line_error(
        capsys,
        _sfo(case, tmp_path / "out", "--method", "posest-sfo"),
        "face_curve.json",
        "chin_jaw must be a list of at least two [u, v] points (numbers",
    )


# -- JSON that is not a Lilium file ----------------------------------------------------------


def test_deeply_nested_json_names_the_file(case, tmp_path, capsys):
    _, photo_dir = case
    (photo_dir / "photo.json").write_text("[" * 100_000 + "]" * 100_000)
    _one_line_error(
        capsys,
        _sfo(case, tmp_path / "out", "--method", "posest-sfo"),
        "photo.json: JSON nested deeper than 64 levels",
    )


def test_deeply_nested_landmarks_file(case, tmp_path, capsys):
    deep = tmp_path / "deep.json"
    deep.write_text('{"landmarks": ' + "[" * 200 + "]" * 200 + "}")
    _one_line_error(
        capsys,
        ["case", "--skull", case[0], "--landmarks", deep, "--photo", case[1], "--out", tmp_path],
        "deep.json: JSON nested deeper than 64 levels",
    )


def test_photo_json_holding_a_list(case, tmp_path, capsys):
    _, photo_dir = case
    (photo_dir / "photo.json").write_text("[1, 2, 3]")
    _one_line_error(
        capsys,
        _sfo(case, tmp_path / "out", "--method", "posest-sfo"),
        "photo.json: must be a JSON object",
        "got a JSON array",
    )


# -- physical ranges of priors and depth tables ------------------------------------------------


@pytest.mark.parametrize(
    "key, value, needles",
    [
        ("focal_px", [1e300, 1e301], ["priors.focal_px = [1e+300, 1e+301] px", "10-1000000 px"]),
        ("focal_px", [1e-9, 2e-9], ["priors.focal_px = [1e-09, 2e-09] px", "10-1000000 px"]),
        ("scd_mm", [1e6, 2e6], ["priors.scd_mm = [1000000, 2000000] mm", "50-100000 mm"]),
    ],
)
def test_priors_outside_their_physical_range(case, tmp_path, capsys, key, value, needles):
    _, photo_dir = case
    _edit_json(photo_dir / "photo.json", lambda d: d["priors"].update({key: value}))
    _one_line_error(
        capsys, _sfo(case, tmp_path / "out", "--method", "posest-sfo"), "photo.json", *needles
    )


@pytest.mark.parametrize(
    "option, values, needle",
    [
        ("--focal-px", ["1e-9", "2e-9"], "command line: --focal-px = [1e-09, 2e-09] px"),
        ("--scd-mm", ["1", "2"], "command line: --scd-mm = [1, 2] mm lies outside"),
    ],
)
def test_command_line_priors_outside_their_range(case, tmp_path, capsys, option, values, needle):
    argv = ["case", "--skull", case[0], "--photo", case[1], "--out", tmp_path, option, *values]
    _one_line_error(capsys, argv, needle, "physical range")


def test_depth_table_beyond_soft_tissue(case, tmp_path, capsys):
    table = tmp_path / "depths.csv"
    table.write_text("landmark,mean,sd,min,max\nnasion,6,1,0,1e9\n")
    argv = _sfo(case, tmp_path / "out", "--method", "posest-sfo", "--depth-table", table)
    _one_line_error(capsys, argv, "depths.csv: landmark 'nasion' has max=1e+09 mm", "100 mm")


def test_depth_table_short_row(case, tmp_path, capsys):
    table = tmp_path / "depths.csv"
    table.write_text("landmark,mean,sd,min,max\nnasion,6\n")
    argv = _sfo(case, tmp_path / "out", "--method", "posest-sfo", "--depth-table", table)
    _one_line_error(capsys, argv, "depths.csv: line 2: mean, sd, min and max must be numbers")


# -- input ignored without a word -----------------------------------------------------------


def test_unknown_keys_of_photo_json_are_warned_about(case, tmp_path, capsys):
    _, photo_dir = case

    def change(d):
        d["priors"]["focal_pxx"] = d["priors"].pop("focal_px")
        d["veiw"] = "frontal"

    _edit_json(photo_dir / "photo.json", change)
    code, _, err = _run(_sfo(case, tmp_path / "out", "--method", "posest-sfo"), capsys)
    assert code == 0, err
    assert (
        "key priors.focal_pxx is not read by Lilium (ignored); did you mean priors.focal_px?" in err
    )
    assert "key veiw is not read by Lilium (ignored); did you mean view?" in err
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert [w["code"] for w in result["warnings"]].count("unknown_key") == 2


# -- messages --------------------------------------------------------------------------------


def test_focal_cap_message_does_not_contradict_itself(case):
    from dataclasses import replace

    from lilium.casework.build import read_photo
    from lilium.inputs import Priors
    from lilium.methods.posest_sfo import focal_cap_message

    _, photo_dir = case
    photo = read_photo(photo_dir, load_image=False)
    low = focal_cap_message(replace(photo, priors=Priors(focal_px=(4350.0, 4808.0))))
    assert "capped at 10000 px (focal prior" not in low
    assert "above 10000 px" in low and "far beyond the focal prior 4350-4808 px" in low
    high = focal_cap_message(replace(photo, priors=Priors(focal_px=(31000.0, 35000.0))))
    assert "capped at 70000 px (twice the focal prior's upper bound" in high


# -- the face curve: work bounded by the photo, not the file ------------------------------------


def test_zig_zag_face_curve_is_refused_at_once(case, tmp_path, capsys):
    _, photo_dir = case
    n = 5_000
    zig = [[100 + 1000 * k / n, 100 if k % 2 else 800] for k in range(n)]
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": zig}))
    _one_line_error(
        capsys,
        _sfo(case, tmp_path / "out", "--method", "posest-sfo"),
        "face_curve.json: chin_jaw is 3499300 px long",
        "perimeter (4200 px)",
        "give the outline once",
    )


def test_dense_face_curve_is_resampled_to_pixels(case):
    import numpy as np

    from lilium.io.curves import read_face_curve

    _, photo_dir = case
    t = np.linspace(0, np.pi, 5_000)
    dense = np.c_[600 + 400 * np.cos(t), 500 + 300 * np.sin(t)]
    path = photo_dir / "face_curve.json"
    path.write_text(json.dumps({"chin_jaw": dense.tolist()}))
    curve = read_face_curve(path, "frontal", (1200, 900))
    # One point per pixel step along the half ellipse: between its Chebyshev length,
    # 2 (300 sin t0 + 400 cos t0) = 1000, and its Manhattan length, 800 + 2 * 300 = 1400.
    assert 1000 <= len(curve) <= 1401
    assert np.array_equal(curve, np.rint(curve))
    assert np.abs(np.diff(curve, axis=0)).max() == 1  # 8-connected, no repeats
    assert np.all(np.abs(np.diff(curve, axis=0)).sum(axis=1) > 0)


# -- the command line --------------------------------------------------------------------------


def test_population_beyond_memory_names_the_option(case, tmp_path, capsys):
    argv = _sfo(case, tmp_path / "out", "--method", "lilium", "--population", "100000000")
    line = _one_line_error(capsys, argv, "argument --population", "from 4 to 10000")
    assert "out of memory" not in line and "downscale" not in line


def test_view_given_for_a_photo_folder_is_not_ignored(case, tmp_path, capsys):
    argv = ["case", "--skull", case[0], "--photo", case[1], "--out", tmp_path / "out"]
    _one_line_error(
        capsys,
        argv + ["--view", "lateral_left"],
        "photo.json: view is 'frontal' but --view says 'lateral_left'",
        "edit it there",
    )


def test_garbage_mesh_names_the_format(case, tmp_path, capsys):
    subject_dir, _ = case
    (subject_dir / "skull.ply").write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\nx y z\n"
    )
    _one_line_error(
        capsys,
        _sfo(case, tmp_path / "out", "--method", "posest-sfo"),
        "skull.ply: not a readable PLY triangle mesh",
        "export the skull surface again as PLY",
    )


def test_library_warnings_stay_off_the_console(case, tmp_path, capsys, monkeypatch):
    import warnings

    from lilium.casework import inputs

    read_photo = inputs.read_photo

    def noisy(*args, **kwargs):
        warnings.warn("All-NaN slice encountered", RuntimeWarning, stacklevel=1)
        return read_photo(*args, **kwargs)

    monkeypatch.setattr(inputs, "read_photo", noisy)
    monkeypatch.delenv("LILIUM_DEBUG")
    code, _, err = _run(_sfo(case, tmp_path / "out", "--method", "posest-sfo"), capsys)
    assert code == 0, err
    assert "All-NaN" not in err and "RuntimeWarning" not in err


# -- result databases ----------------------------------------------------------------------------


@pytest.fixture
def report_db(tmp_path):
    from lilium.experiments.store import ResultStore
    from report_rows import make_rows

    path = tmp_path / "results.sqlite"
    with ResultStore(path) as store:
        for row in make_rows():
            assert store.insert(row)
    return path


def test_text_in_the_score_column_names_the_database(report_db, tmp_path, capsys):
    import sqlite3

    with sqlite3.connect(report_db) as conn:
        conn.execute("UPDATE sfo SET score = 'abc' WHERE id = 3")
    line = _one_line_error(capsys, ["report", report_db, "--out", tmp_path / "rep"], report_db)
    assert "row 3 holds 'abc' in the numeric column score" in line
    assert "internal error" not in line


def test_terms_off_csv_has_its_header_when_nothing_was_off(report_db, tmp_path, capsys):
    code, _, err = _run(["report", report_db, "--out", tmp_path / "rep"], capsys)
    assert code == 0, err
    header = (tmp_path / "rep" / "terms_off.csv").read_text().splitlines()
    assert header == ["experiment,method,view,sfos,with_term_off"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--subjects", "100000000"], "argument --subjects: must be an integer from 1 to 1000"),
        (["--photos", "0"], "argument --photos: must be an integer from 1 to 1000"),
        (["--workers", "-3"], "argument --workers: must be an integer from 0 to 256"),
        (["--seed", "-1"], "argument --seed"),
    ],
)
def test_synth_counts_are_bounded(tmp_path, capsys, args, needle):
    _one_line_error(capsys, ["synth", "--out", tmp_path / "ds", *args], needle)
    assert not (tmp_path / "ds").exists()


@pytest.mark.parametrize(
    "args, needle",
    [(["--seed", "-1"], "argument --seed: must be an integer from 0"), (["--out", None], "--out")],
)
def test_demo_options_name_themselves(case, tmp_path, capsys, args, needle):
    args = [str(case[0] / "skull.ply") if a is None else a for a in args]
    line = _one_line_error(capsys, ["demo", *args], needle)
    assert "Not a directory" not in line and "non-negative integer" not in line


def test_report_says_on_the_console_when_the_lr_is_not_computed(tmp_path, capsys):
    """Rows without stored terms whose dataset has moved: the report is written, and the
    console (not only report.md) says the LR is missing and how to give the dataset; a
    --dataset that is no dataset is a one-line error."""
    import json

    from lilium.experiments.store import ResultStore
    from standin_case import terms_database

    db = terms_database(
        tmp_path / "r.sqlite", result=lambda k, data: json.dumps({"camera": data["camera"]})
    )
    with ResultStore(db) as store:
        store.set_meta("config", {"dataset": str(tmp_path / "moved")})
    code, _, err = _run(["report", db, "--out", tmp_path / "rep"], capsys)
    assert code == 0, err
    assert "Identification LR not computed" in (tmp_path / "rep" / "report.md").read_text()
    assert "lilium report: warning: identification LR not computed" in err
    assert "give --dataset DIR" in err
    _one_line_error(
        capsys,
        ["report", db, "--out", tmp_path / "rep2", "--dataset", tmp_path / "moved"],
        "--dataset",
        "give the dataset folder lilium synth wrote",
    )
