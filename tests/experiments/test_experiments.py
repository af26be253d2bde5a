"""Experiment runner: config, task enumeration, SQLite store, resume after a kill, Dask."""

import csv
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lilium.cli.main import main
from lilium.experiments.config import (
    ALL_METHODS,
    PRESETS,
    config_from_dict,
    load_config,
    method_label,
    parse_methods,
)
from lilium.experiments.runner import enumerate_tasks, load_dataset, run_experiment
from lilium.experiments.store import KEY_COLUMNS, ResultStore
from standin_case import toy_dataset

#: Tiny protocol: 2 toy subjects x (1 frontal + 1 lateral) photos, POSEST-SFO and Lilium base.
TINY = """
name = "tiny"
methods = ["posest-sfo", "lilium:base"]
experiments = {experiments}
repetitions = 1
axes_sets = {axes_sets}
runs_per_axes_set = 1
workers = 1
db = "results.sqlite"

[dataset]
path = "{dataset}"
generate = false

[de]
population = 5
generations = 2
max_seconds = 5
"""


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("experiment-ds")
    toy_dataset(out)
    return out


def write_config(folder, dataset, experiments=("A", "B", "C"), axes_sets=1):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "tiny.toml"
    path.write_text(
        TINY.format(dataset=dataset, experiments=list(experiments), axes_sets=axes_sets).replace(
            "'", '"'
        )
    )
    return path


def n_expected(n_photos, n_skulls, cfg):
    """SFO count of the protocol from its definition (docs/method/evaluation.md)."""
    n_lilium = sum(1 for m, _ in cfg.methods if m == "lilium")
    n_posest = len(cfg.methods) - n_lilium
    per_pair = {
        "A": n_posest + n_lilium * cfg.repetitions,
        "B": n_posest + n_lilium * cfg.repetitions,
        "C": cfg.axes_sets * (n_posest + n_lilium * cfg.runs_per_axes_set),
    }
    return n_photos * n_skulls * sum(per_pair[e] for e in cfg.experiments)


def db_keys(db):
    with sqlite3.connect(db) as conn:
        return conn.execute(f"SELECT {', '.join(KEY_COLUMNS)} FROM sfo").fetchall()


# -- config ---------------------------------------------------------------------------------------
def test_presets_and_methods():
    quick, paper = PRESETS["quick"], PRESETS["paper"]
    assert quick.methods == ALL_METHODS and quick.experiments == ("A", "B", "C")
    assert (quick.dataset.subjects, 2 * quick.dataset.photos) == (5, 4)
    assert (paper.dataset.subjects, 2 * paper.dataset.photos) == (17, 60)
    assert (paper.repetitions, paper.axes_sets, paper.runs_per_axes_set) == (5, 5, 5)
    assert (paper.de.population_size, paper.de.max_generations, paper.de.max_seconds) == (
        30,
        750,
        500,
    )
    assert load_config("quick") == PRESETS["quick"]
    assert parse_methods(["lilium"]) == ALL_METHODS[1:]
    assert parse_methods(["lilium:skof+pll", "posest-sfo"]) == (
        ("lilium", "skof+pll"),
        ("posest-sfo", ""),
    )
    assert method_label("lilium", "skof+pll") == "Lilium+P_skof+P_pll"
    with pytest.raises(ValueError, match="unknown method 'lilium:foo'"):
        parse_methods(["lilium:foo"])


def test_toml_overrides_and_errors(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(
        'preset = "quick"\nrepetitions = 3\ndb = "x.sqlite"\n[de]\ngenerations = 7\n'
        "max_seconds = 0\n[dataset]\npath = 'data'\n"
    )
    cfg = load_config(path)
    assert cfg.repetitions == 3 and cfg.axes_sets == PRESETS["quick"].axes_sets
    assert cfg.de.max_generations == 7 and cfg.de.max_seconds is None
    assert cfg.de.population_size == PRESETS["quick"].de.population_size
    assert cfg.db == tmp_path / "x.sqlite" and cfg.dataset.path == tmp_path / "data"
    with pytest.raises(ValueError, match="unknown key"):
        config_from_dict({"repetition": 2})
    with pytest.raises(ValueError, match="unknown experiment"):
        config_from_dict({"experiments": ["D"]})
    with pytest.raises(ValueError, match=r"repetitions must be an integer in \[1, 1000\], got 0"):
        config_from_dict({"repetitions": 0})
    with pytest.raises(ValueError, match="config file not found"):
        load_config(tmp_path / "missing.toml")


# -- tasks and store --------------------------------------------------------------------------
def test_enumerate_tasks_counts_and_keys():
    index = {
        "subjects": [{"id": s, "path": f"subjects/{s}", "axes_C": ["a1", "a2"]} for s in "xyz"],
        "photos": [
            {"id": f"{s}_f", "subject": s, "view": "frontal", "paths": {e: e for e in "ABC"}}
            for s in "xy"
        ],
    }
    cfg = config_from_dict({"repetitions": 3, "axes_sets": 2, "runs_per_axes_set": 2})
    tasks = enumerate_tasks(cfg, "/data", index)
    assert len(tasks) == n_expected(2, 3, cfg) == 2 * 3 * (13 + 13 + 2 * 9)
    assert len({t.key for t in tasks}) == len(tasks)
    posest_c = [t for t in tasks if t.experiment == "C" and t.method == "posest-sfo"]
    assert len(posest_c) == 2 * 3 * 2 and {t.axes_set for t in posest_c} == {1, 2}
    assert {t.axes_file for t in posest_c if t.subject == "z"} == {
        "/data/subjects/z/a1",
        "/data/subjects/z/a2",
    }
    assert {t.seed for t in tasks if t.method == "lilium" and t.experiment == "A"} == {0, 1, 2}
    with pytest.raises(ValueError, match="perturbed axis sets"):
        enumerate_tasks(config_from_dict({"axes_sets": 3}), "/data", index)


def test_store_ignores_duplicates_and_checks_settings(tmp_path):
    row = dict(zip(KEY_COLUMNS, ("A", "lilium", "base", 0, 0, 0, "p", "s"), strict=True))
    with ResultStore(tmp_path / "r.sqlite") as store:
        assert store.conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert store.insert({**row, "score": 1.0}) is True
        assert store.insert({**row, "score": 2.0}) is False
        assert store.count() == 1 and store.rows()[0]["score"] == 1.0
        store.check_fingerprint("abc")
        store.check_fingerprint("abc")
        with pytest.raises(ValueError, match="holds results of other"):
            store.check_fingerprint("def")


def test_missing_dataset_is_an_error(tmp_path):
    cfg = config_from_dict({"dataset": {"path": "nowhere", "generate": False}}, tmp_path)
    with pytest.raises(ValueError, match="dataset index not found"):
        load_dataset(cfg)


# -- runs ---------------------------------------------------------------------------------------
def test_run_resume_and_report_cli(dataset, tmp_path):
    config = write_config(tmp_path / "run", dataset)
    db = tmp_path / "run" / "results.sqlite"
    assert main(["experiment", str(config), "--no-progress"]) == 0
    cfg = load_config(config)
    total = n_expected(4, 2, cfg)
    rows = ResultStore(db).rows()
    assert len(rows) == total == 48
    positives = [r for r in rows if r["positive"] and r["success"]]
    assert positives and all(r["bpe_mm"] is not None and r["bpe_mm"] >= 0 for r in positives)
    assert all(r["bpe_mm"] is None for r in rows if not r["positive"])
    scored = [r for r in rows if r["success"]]
    assert all(r["skull_px"] > 0 and 0 <= r["percent_outside"] <= 100 for r in scored)
    # docs/checks.md in every row's result JSON: warnings, priors and their source, landmark
    # error; the generated photos have every prior, so no missing-prior warning.
    for r in ResultStore(db).rows(["success", "result"]):
        if not r["success"]:
            continue
        stored = json.loads(r["result"])
        assert stored["priors"]["focal_px"]["source"] == "photo.json"
        assert stored["landmark_error"]["mean_mm"] > 0
        codes = {w["code"] for w in stored["warnings"]}
        assert not codes & {"no_focal_prior", "no_scd_prior"}
    # Resume: nothing left to do, nothing duplicated.
    summary = run_experiment(cfg, progress=False, log=lambda *_: None)
    assert (summary.already_done, summary.stored, summary.complete) == (total, 0, True)
    assert len(db_keys(db)) == total
    out = tmp_path / "report"
    assert main(["report", str(db), "--out", str(out)]) == 0
    for name in ("report.md", "summary.csv", "wilcoxon.csv", "implausible.csv", "bpe.png",
                 "calibration.csv", "tippett.png"):
        assert (out / name).is_file(), name
    assert "POSEST-SFO" in (out / "report.md").read_text()
    # Identification (docs/method/identification.md): every SFO's terms stored by the runner; the
    # ranking by each
    # method's own score beside the ranking by the identification LR.
    stored = [json.loads(r["result"]) for r in ResultStore(db).rows(["success", "result"])
              if r["success"]]
    assert all(s["identification_terms"]["landmark_chi2"] > 0 for s in stored)
    with (out / "identification.csv").open() as fh:
        scores = {row["score"] for row in csv.DictReader(fh)}
    assert scores == {"method's own score", "identification log10 LR (cross-validated)"}
    # Two subjects are too few to calibrate: lilium calibrate says so and writes no model.
    cal = tmp_path / "cal"
    assert main(["calibrate", str(db), "--out", str(cal)]) == 0
    assert json.loads((cal / "calibration.json").read_text())["models"] == {}


def test_kill_and_resume(dataset, tmp_path):
    """SIGKILL a running ``lilium experiment`` (2 worker processes), rerun, check the rows."""
    config = write_config(tmp_path / "kill", dataset, axes_sets=2)
    db = tmp_path / "kill" / "results.sqlite"
    total = n_expected(4, 2, load_config(config))
    cmd = [sys.executable, "-m", "lilium", "experiment", str(config), "--workers", "2"]
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = subprocess.Popen(
        cmd + ["--no-progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        start_new_session=True,
    )
    stored = 0
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if db.is_file():
                try:
                    stored = len(db_keys(db))
                except sqlite3.OperationalError:
                    stored = 0
                if stored >= 10:
                    break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)  # the run and its worker processes
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    after_kill = len(db_keys(db))
    assert 10 <= after_kill < total
    done = subprocess.run(cmd + ["--no-progress"], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    keys = db_keys(db)
    assert len(keys) == total and len(set(keys)) == total
    assert f"{after_kill} already in" in done.stdout


def test_dask_local_cluster(dataset, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    config = write_config(tmp_path / "dask", dataset, experiments=("A",))
    cfg = load_config(config)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        summary = run_experiment(
            cfg, scheduler=cluster.scheduler_address, progress=False, log=lambda *_: None
        )
    assert summary.complete and summary.stored == n_expected(4, 2, cfg) == 16
    keys = db_keys(Path(cfg.db))
    assert len(set(keys)) == len(keys) == 16


def test_scheduler_that_refuses_fails_fast_before_the_database(dataset, tmp_path, capsys):
    pytest.importorskip("dask.distributed")
    config = write_config(tmp_path / "refused", dataset, experiments=("A",))
    db = tmp_path / "refused" / "r.sqlite"
    start = time.monotonic()
    code = main(["experiment", str(config), "--db", str(db), "--scheduler", "tcp://127.0.0.1:1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "--scheduler tcp://127.0.0.1:1: no Dask scheduler there" in err[0]
    assert "dask scheduler" in err[0] and "disk space" not in err[0]
    assert time.monotonic() - start < 15
    assert not db.exists() and not list(db.parent.glob("r.sqlite*"))


def test_dask_cluster_without_workers_ends_the_run(dataset, tmp_path, capsys, monkeypatch):
    """No worker at all: the run says so within the stated time and exits (exit 2)."""
    distributed = pytest.importorskip("dask.distributed")
    from lilium.experiments import executors

    monkeypatch.setattr(executors, "NO_WORKER_TIMEOUT_S", 1.0)
    config = write_config(tmp_path / "none", dataset, experiments=("A",))
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        code = main(
            ["experiment", str(config), "--no-progress", "--scheduler"]
            + [cluster.scheduler_address]
        )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "has had no worker for 1 s, with 8 SFOs waiting" in err[0]
    assert "run the same command again to resume" in err[0]


@pytest.mark.slow
def test_dask_cluster_that_loses_every_worker(dataset, tmp_path, capsys, monkeypatch):
    """Every worker gone: the run says so, keeps what is stored and exits; a rerun resumes."""
    distributed = pytest.importorskip("dask.distributed")
    import threading

    from lilium.experiments import executors

    monkeypatch.setattr(executors, "NO_WORKER_TIMEOUT_S", 1.0)
    config = write_config(tmp_path / "lost", dataset, experiments=("A",))
    db = Path(load_config(config).db)
    argv = ["experiment", str(config), "--no-progress", "--scheduler"]
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:

        def kill_workers_after_the_first_rows():
            while not (db.exists() and _count_rows(db) >= 2):
                time.sleep(0.1)
            cluster.scale(0)

        killer = threading.Thread(target=kill_workers_after_the_first_rows, daemon=True)
        killer.start()
        code = main(argv + [cluster.scheduler_address])
        killer.join(timeout=30)
    err = capsys.readouterr().err
    assert code == 2, err
    assert "has had no worker for 1 s" in err and "run the same command again to resume" in err
    stored = _count_rows(db)
    assert 2 <= stored < 16
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        assert main(argv + [cluster.scheduler_address]) == 0
    assert f"{stored} already in" in capsys.readouterr().out
    assert len(set(db_keys(db))) == 16


def _count_rows(db):
    try:
        with sqlite3.connect(db) as conn:
            return conn.execute("SELECT COUNT(*) FROM sfo").fetchone()[0]
    except sqlite3.Error:
        return 0
