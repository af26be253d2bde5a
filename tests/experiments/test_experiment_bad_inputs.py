"""``lilium experiment`` and ``lilium report`` on bad input: one-line errors, nothing silently
wrong, nothing written elsewhere, no orphaned worker processes, one run per database."""

import hashlib
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from test_experiments import db_keys, write_config

from lilium.cli.main import main
from lilium.experiments.config import MAX_SEED, config_from_dict, load_config
from lilium.experiments.dataset import check_index
from lilium.experiments.runner import Task, run_task
from lilium.experiments.store import KEY_COLUMNS, ResultStore
from lilium.io.locks import RunLock
from lilium.optimisation.de import DEOptions
from standin_case import toy_dataset


def _generate(out, seed):
    toy_dataset(out, seed)
    return out


@pytest.fixture(scope="module")
def datasets(tmp_path_factory):
    """Two toy datasets with the same ids from different seeds."""
    root = tmp_path_factory.mktemp("hardening-ds")
    return _generate(root / "seed3", 3), _generate(root / "seed4", 4)


def run_cli(capsys, argv):
    """``main(argv)`` -> (exit status, stderr); the stderr of an error is one line."""
    status = main(argv)
    err = capsys.readouterr().err
    if status == 2:
        assert len(err.strip().splitlines()) == 1, err
    return status, err


def file_digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# -- config
@pytest.mark.parametrize(
    "toml, key",
    [
        ("seed = 9223372036854775807", r"seed must be an integer in \[0, 4294967295\]"),
        ("seed = -1", r"seed must be an integer in \[0, 4294967295\]"),
        ("seed = 1.5", r"seed must be an integer"),
        (
            f"seed = {MAX_SEED}\nrepetitions = 2\nruns_per_axes_set = 1",
            r"seed = 4294967295 with 2 runs gives seeds up to 4294967296, above 4294967295",
        ),
        ("[dataset]\nseed = -3", r"dataset.seed must be an integer"),
        ("[dataset]\nsubjects = 1000000", r"dataset.subjects must be an integer in \[1, 1000\]"),
        ("[dataset]\npath = ''", r"dataset.path must be a non-empty path string"),
        ("workers = 100000", r"workers must be an integer in \[0, 256\]"),
        ("repetitions = 10000000000", r"repetitions must be an integer in \[1, 1000\]"),
        ("axes_sets = true", r"axes_sets must be an integer"),
        ("[de]\npopulation = 3", r"de.population must be an integer in \[4, 10000\]"),
        ("[de]\npopulation = 100000000", r"de.population must be an integer in \[4, 10000\]"),
        ("[de]\ngenerations = 0", r"de.generations must be an integer"),
        ("[de]\nmax_seconds = nan", r"de.max_seconds must be a finite number >= 0"),
        ("[de]\nmax_seconds = -1", r"de.max_seconds must be a finite number >= 0"),
        ("[de]\nmax_seconds = inf", r"de.max_seconds must be a finite number >= 0"),
        ("preset = ['quick']", r"unknown preset \['quick'\]"),
        ("name = 5", r"name must be a non-empty one-line string"),
        ('name = "a\\nb"', r"name must be a non-empty one-line string"),
        ("db = 5", r"db must be a non-empty path string"),
    ],
)
def test_config_values_out_of_range_name_their_key(tmp_path, capsys, toml, key):
    path = tmp_path / "bad.toml"
    path.write_text(toml + "\n")
    with pytest.raises(ValueError, match=key):
        load_config(path)
    status, err = run_cli(capsys, ["experiment", str(path), "--no-progress"])
    assert status == 2 and str(path) in err and "Traceback" not in err


def test_config_file_that_is_not_text(tmp_path, capsys):
    path = tmp_path / "binary.toml"
    path.write_bytes(b"\xff\xfe\x00 seed = 1")
    status, err = run_cli(capsys, ["experiment", str(path)])
    assert status == 2 and "not valid TOML" in err
    status, err = run_cli(capsys, ["experiment", "quick", "--workers", "100000"])
    assert status == 2 and "--workers" in err


def test_largest_seed_is_accepted():
    cfg = config_from_dict({"seed": MAX_SEED - 4, "repetitions": 5, "runs_per_axes_set": 5})
    assert cfg.seed == MAX_SEED - 4


# -- dataset index
def _index():
    return {
        "subjects": [{"id": s, "path": f"subjects/{s}", "axes_C": ["axes_C1.json"]} for s in "xy"],
        "photos": [
            {"id": f"{s}_f", "subject": s, "view": "frontal", "paths": {"A": f"photos/A/{s}_f"}}
            for s in "xy"
        ],
    }


@pytest.mark.parametrize(
    "edit, match",
    [
        (lambda i: i["subjects"][1].update(path="../elsewhere"), r"subjects\[1\] \(y\)\.path"),
        (lambda i: i["subjects"][0].update(path="/etc"), r"subjects\[0\] \(x\)\.path .*absolute"),
        (lambda i: i["subjects"][0].update(path="C:\\data\\x"), r"absolute"),
        (
            lambda i: i["subjects"][0].update(axes_C=["../../../etc/passwd"]),
            r"subjects\[0\] \(x\)\.axes_C\[0\] .*leaves the dataset folder",
        ),
        (
            lambda i: i["photos"][1]["paths"].update(A="photos/../../y"),
            r"photos\[1\] \(y_f\)\.paths\.A .*leaves the dataset folder",
        ),
        (lambda i: i["photos"][1].update(id="x_f"), r"photos\[1\] \(x_f\)\.id 'x_f' is repeated"),
        (lambda i: i["subjects"][1].update(id="x"), r"subjects\[1\] \(x\)\.id 'x' is repeated"),
        (lambda i: i["photos"][0].update(subject="z"), r"subject 'z' is not among the subjects"),
        (lambda i: i["photos"][0].update(view="top"), r"view must be one of"),
        (lambda i: i.update(photos=[]), r"photos must be a non-empty list"),
    ],
)
def test_index_entries_are_checked(edit, match):
    index = _index()
    check_index(index)
    edit(index)
    with pytest.raises(ValueError, match=match):
        check_index(index, "dataset.json")


def _copy(dataset, tmp_path):
    out = tmp_path / "dataset"
    shutil.copytree(dataset, out)
    return out


def test_dataset_path_outside_is_refused_by_the_cli(datasets, tmp_path, capsys):
    data = _copy(datasets[0], tmp_path)
    index = json.loads((data / "dataset.json").read_text())
    index["photos"][0]["paths"]["B"] = str(data / index["photos"][0]["paths"]["B"])
    (data / "dataset.json").write_text(json.dumps(index))
    config = write_config(tmp_path / "run", data)
    status, err = run_cli(capsys, ["experiment", str(config), "--no-progress"])
    assert status == 2 and "dataset.json: photos[0]" in err and "paths.B" in err
    assert "absolute path" in err
    assert not (tmp_path / "run" / "results.sqlite").exists()


# -- files checked before the first SFO
def test_missing_axes_file_stops_the_run_before_it_starts(datasets, tmp_path, capsys):
    data = _copy(datasets[0], tmp_path)
    (data / "subjects" / "s02" / "axes_C2.json").unlink()
    config = write_config(tmp_path / "run", data, axes_sets=2)
    status, err = run_cli(capsys, ["experiment", str(config), "--no-progress"])
    assert status == 2
    assert "s02/axes_C2.json: perturbed soft-tissue axes (Exp. C, axis set 2) not found" in err
    assert "no SFO was run" in err
    assert not (tmp_path / "run" / "results.sqlite").exists()
    (data / "photos" / "B" / "s01_f00" / "photo.json").unlink()
    status, err = run_cli(capsys, ["experiment", str(config), "--no-progress"])
    assert status == 2 and "1 more files missing" in err


def test_axes_file_gone_during_the_run_is_an_error_row(datasets):
    data = datasets[0]
    task = Task(
        experiment="C",
        method="posest-sfo",
        variant="",
        axes_set=9,
        repetition=0,
        seed=0,
        photo="s01_f00",
        subject="s01",
        true_subject="s01",
        view="frontal",
        subject_dir=str(data / "subjects" / "s01"),
        photo_dir=str(data / "photos" / "C" / "s01_f00"),
        axes_file=str(data / "subjects" / "s01" / "axes_C9.json"),
        de=DEOptions(),
    )
    row = run_task(task)
    assert row["success"] == 0 and "axes_C9.json" in row["error"]
    assert row.get("score") is None


# -- the dataset fingerprint
def test_resume_against_another_dataset_is_refused(datasets, tmp_path, capsys):
    seed3, seed4 = datasets
    run = tmp_path / "run"
    config = write_config(run, seed3, experiments=("A",))
    assert run_cli(capsys, ["experiment", str(config), "--no-progress"])[0] == 0
    n_rows = len(db_keys(run / "results.sqlite"))
    # The same ids from another seed, into the same database: refused, nothing added.
    config = write_config(run, seed4, experiments=("A",))
    status, err = run_cli(capsys, ["experiment", str(config), "--no-progress"])
    assert status == 2 and "holds results of another dataset" in err
    assert "give a new --db for this dataset" in err and str(seed3) in err
    assert len(db_keys(run / "results.sqlite")) == n_rows
    # A file edited by hand counts as another dataset too; the original resumes.
    data = _copy(seed3, tmp_path)
    photo_json = data / "photos" / "A" / "s01_f00" / "photo.json"
    photo = json.loads(photo_json.read_text())
    photo["landmarks"]["nasion"][0] += 1.0
    photo_json.write_text(json.dumps(photo))
    config = write_config(run, data, experiments=("A",))
    assert run_cli(capsys, ["experiment", str(config), "--no-progress"])[0] == 2
    config = write_config(run, seed3, experiments=("A",))
    assert run_cli(capsys, ["experiment", str(config), "--no-progress"])[0] == 0
    assert len(db_keys(run / "results.sqlite")) == n_rows == 16


def test_fingerprint_ignores_timing_and_location(datasets, tmp_path):
    from lilium.experiments.dataset import dataset_fingerprint
    from lilium.experiments.runner import enumerate_tasks, load_dataset

    def fingerprint(folder):
        cfg = config_from_dict({"dataset": {"path": str(folder), "generate": False}})
        root, index = load_dataset(cfg)
        return dataset_fingerprint(root, index, enumerate_tasks(cfg, root, index))

    moved = _copy(datasets[0], tmp_path)
    index = json.loads((moved / "dataset.json").read_text())
    index["seconds"] += 12.5
    (moved / "dataset.json").write_text(json.dumps(index))
    assert fingerprint(moved) == fingerprint(datasets[0]) != fingerprint(datasets[1])


# -- foreign, corrupt and truncated databases
def _foreign_db(path):
    conn = sqlite3.connect(path)
    conn.execute("CREATE TABLE patients (name TEXT)")
    conn.execute("INSERT INTO patients VALUES ('x')")
    conn.commit()
    conn.close()
    return path


def test_report_and_experiment_leave_a_foreign_database_untouched(datasets, tmp_path, capsys):
    foreign = _foreign_db(tmp_path / "other.sqlite")
    before = file_digest(foreign)
    status, err = run_cli(capsys, ["report", str(foreign), "--out", str(tmp_path / "rep")])
    assert status == 2 and "not a Lilium results database" in err
    config = write_config(tmp_path / "run", datasets[0], experiments=("A",))
    status, err = run_cli(
        capsys, ["experiment", str(config), "--db", str(foreign), "--no-progress"]
    )
    assert status == 2 and "not a Lilium results database" in err and "--db" in err
    assert file_digest(foreign) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.sqlite", "run"]
    with sqlite3.connect(foreign) as conn:
        assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "delete"


def _results_db(path, n=2000):
    with ResultStore(path) as store:
        for k in range(n):
            key = ("A", "lilium", "base", 0, 0, 0, f"p{k}", "s")
            store.insert({**dict(zip(KEY_COLUMNS, key, strict=True)), "result": "x" * 200})
    return path


def test_report_opens_read_only(tmp_path, capsys):
    db = _results_db(tmp_path / "r.sqlite", n=3)
    before = file_digest(db)
    assert main(["report", str(db), "--out", str(tmp_path / "rep")]) == 0
    assert file_digest(db) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.sqlite", "rep"]


@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty"])
def test_corrupt_database_is_a_one_line_error(datasets, tmp_path, capsys, damage):
    db = _results_db(tmp_path / "r.sqlite")
    data = db.read_bytes()
    if damage == "garbage":
        db.write_bytes(b"this is not a database\n" * 100)
    elif damage == "truncated":
        db.write_bytes(data[: len(data) // 3])
    else:
        db.write_bytes(b"")
    status, err = run_cli(capsys, ["report", str(db), "--out", str(tmp_path / "rep")])
    assert status == 2 and str(db) in err
    if damage == "empty":
        assert "not a Lilium results database" in err
    else:
        assert "corrupt, truncated" in err
    if damage != "empty":  # an empty file is a new database for lilium experiment
        config = write_config(tmp_path / "run", datasets[0], experiments=("A",))
        status, err = run_cli(capsys, ["experiment", str(config), "--db", str(db), "--no-progress"])
        assert status == 2 and str(db) in err and "corrupt, truncated" in err


def test_report_out_that_is_a_file(tmp_path, capsys):
    db = _results_db(tmp_path / "r.sqlite", n=3)
    target = tmp_path / "taken.txt"
    target.write_text("keep me")
    status, err = run_cli(capsys, ["report", str(db), "--out", str(target)])
    assert status == 2 and "--out" in err and "is a file" in err
    status, err = run_cli(capsys, ["report", str(db), "--out", str(target / "sub")])
    assert status == 2 and "--out" in err and "cannot hold folders" in err
    assert target.read_text() == "keep me"
    status, err = run_cli(capsys, ["report", str(tmp_path), "--out", str(tmp_path / "rep")])
    assert status == 2 and "is a folder; give the results database file" in err


def test_db_that_is_a_folder_or_under_a_file(datasets, tmp_path, capsys):
    config = write_config(tmp_path / "run", datasets[0], experiments=("A",))
    blocker = tmp_path / "file"
    blocker.write_text("")
    for db, message in [
        (tmp_path, "is a folder"),
        (blocker / "r.sqlite", f"cannot create its folder {blocker}"),
    ]:
        argv = ["experiment", str(config), "--db", str(db), "--no-progress"]
        status, err = run_cli(capsys, argv)
        assert status == 2 and message in err and "--db" in err


# -- processes: one run per database, no orphaned workers
def test_lock_refuses_a_second_holder(tmp_path):
    db = tmp_path / "r.sqlite"
    with RunLock(db) as lock:
        assert f"pid {os.getpid()}" in lock.path.read_text()
        with pytest.raises(
            ValueError, match=rf"in use by another lilium experiment \(pid {os.getpid()}"
        ):
            RunLock(db).acquire()
    assert not lock.path.exists()
    with RunLock(db):
        pass


def _children(pid):
    """PIDs of the live (not zombie) child processes of ``pid`` (Linux /proc)."""
    out = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(entry.name))
    return out


def _alive(pid):
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_second_run_refused_and_workers_die_with_their_parent(datasets, tmp_path, capsys):
    """A running experiment holds its database: a second copy refuses at once. SIGKILL the
    first one's parent process only: its worker processes are gone within seconds."""
    config = write_config(tmp_path / "kill", datasets[0], axes_sets=2)
    db = tmp_path / "kill" / "results.sqlite"
    cmd = [sys.executable, "-m", "lilium", "experiment", str(config), "--workers", "2"]
    proc = subprocess.Popen(
        cmd + ["--no-progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 60
        workers = []
        while time.monotonic() < deadline and proc.poll() is None:
            if db.is_file():
                try:
                    if len(db_keys(db)) >= 2:
                        workers = [p for p in _children(proc.pid) if p != proc.pid]
                        if len(workers) >= 2:
                            break
                except sqlite3.OperationalError:
                    pass
            time.sleep(0.05)
        assert proc.poll() is None, "the run ended before it could be tested"
        start = time.monotonic()
        status, err = run_cli(capsys, ["experiment", str(config), "--no-progress"])
        assert status == 2 and "in use by another lilium experiment" in err
        assert f"pid {proc.pid}" in err and time.monotonic() - start < 5
        os.kill(proc.pid, signal.SIGKILL)  # the parent only
        proc.wait()
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and any(_alive(p) for p in workers):
            time.sleep(0.1)
        assert not [p for p in workers if _alive(p)], "workers outlived their parent"
    finally:
        if proc.poll() is None:
            proc.kill()
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
    # The lock of a killed run is not stale: the next run takes it and finishes.
    assert run_cli(capsys, ["experiment", str(config), "--no-progress"])[0] == 0
