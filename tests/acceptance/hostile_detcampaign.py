"""The campaign the determinism probes (``hostile_determinism.py``) share: its experiment
and dataset, the columns and keys that say when rather than what, the dataset and reference
run made once, and the set-ups that copy, reorder, cut short or schedule otherwise a run.

Budgets: 3 subjects x (2 frontal + 2 lateral) photos of Exp. A, POSEST-SFO and
Lilium+P_skof+P_pll at DE 5 x 2 with 2 repetitions (36 + 72 SFOs a run, about 15 s on 2 cores);
no wall-clock cap on the DE (``max_seconds = 0``), so the machine's load cannot cut a run short.
The dataset and a reference run (1 worker, its own process) are made once per campaign under
the work folder (``det-cache/``); the databases of the probes' runs are kept there too, for
the report and calibrate probes that compare them.
"""

import atexit
import hashlib
import json
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

from hostile_casework import _quiet_main
from hostile_machinery import _lilium_env
from hostile_runs import _in

#: The campaign's experiment: 3 subjects x 4 photos x 3 skulls, POSEST-SFO once and
#: Lilium+P_skof+P_pll twice per pair (108 SFOs), no wall-clock cap.
CONFIG = """name = "det"
methods = ["posest-sfo", "lilium:skof+pll"]
experiments = ["A"]
repetitions = 2
workers = 1
db = "results.sqlite"
[dataset]
path = "{data}"
generate = false
[de]
population = 5
generations = 2
max_seconds = 0
"""

#: ``lilium synth`` of the campaign's dataset (``--out`` appended).
SYNTH = (
    "synth",
    "--subjects",
    "3",
    "--photos",
    "2",
    "--seed",
    "0",
    "--experiments",
    "A",
    "--no-progress",
)

#: Stored columns that say when, where and how fast, not what.
TIMING_COLUMNS = {"id", "seconds", "task_seconds", "worker", "finished_at"}

#: ``result`` JSON keys of the same kind.
TIMING_KEYS = {"seconds"}

#: The identification terms docs/method/identification.md says depend on the first skull a
#: worker scored against a photo.
COHORT_TERMS = ("cohort_mean", "cohort_sd")

#: Their documented spread between two runs of identical SFOs (docs/method/identification.md: "0.015
#: at most").
COHORT_BOUND = 0.015

#: ``summary.csv`` columns of time per SFO.
TIMING_CSV = {"seconds_mean", "seconds_median"}

#: What each probe measured (printed by ``--verbose``, and for the known-limit probe always).
MEASURED = {}


# -- the campaign's cache ---------------------------------------------------------------------


def _cache(ws, *parts):
    path = ws.root.parent.joinpath("det-cache", *parts)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _fresh_state():
    """Empty the per-process caches of the experiment's worker code, so that an in-process run
    on 1 worker (which runs its SFOs in this process) starts as a new ``lilium`` process does:
    the cohort terms, skulls, photos and edge topologies of an earlier probe are not reused."""
    from lilium.experiments import calibrate, task_io

    calibrate._COHORT_TERMS.clear()
    task_io.clear_caches()


def _dataset_ref(ws):
    """The campaign's dataset (``lilium synth --workers 1``, made once)."""
    path = _cache(ws, "dataset")
    if not (path / "dataset.json").is_file():
        shutil.rmtree(path, ignore_errors=True)
        assert _quiet_main([*SYNTH, "--workers", "1", "--out", path]) == 0, "synth failed"
    return path


def _ref_db(ws):
    """The reference run: ``lilium experiment`` on 1 worker, in a process of its own."""
    db = _cache(ws, "ref", "r.sqlite")
    if not db.is_file():
        data = _dataset_ref(ws)
        cfg = db.parent / "c.toml"
        cfg.write_text(CONFIG.format(data=data.as_posix()))
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "lilium",
                "experiment",
                str(cfg),
                "--no-progress",
                "--db",
                str(db),
                "--workers",
                "1",
            ],
            cwd=db.parent,
            env=_lilium_env(),
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert proc.returncode == 0, f"the reference run failed: {proc.stderr[-300:]}"
    return db


def _keep(ws, kind):
    """Keep the probe's database ``out/r.sqlite`` as the campaign's run ``kind``."""
    src = ws.out / "r.sqlite"
    if src.is_file():
        dst = _cache(ws, "runs", kind, "r.sqlite")
        _copy_db(src, dst)


def _copy_db(src, dst):
    """A copy of a closed database (its WAL merged first, so one file holds every row)."""
    conn = sqlite3.connect(src)
    try:
        conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    finally:
        conn.close()
    Path(dst).parent.mkdir(parents=True, exist_ok=True)
    for suffix in ("-wal", "-shm"):
        Path(str(dst) + suffix).unlink(missing_ok=True)
    shutil.copy(src, dst)
    conn = sqlite3.connect(dst)  # a copy in rollback mode: read-only readers need no -wal
    try:
        conn.execute("PRAGMA journal_mode=DELETE")
    finally:
        conn.close()
    return Path(dst)


# -- set-ups ----------------------------------------------------------------------------------


def _dataset(change=None, kind="copy"):
    """Set-up: ``det-cache/data/<kind>``, a copy of the campaign's dataset, its
    ``dataset.json`` changed by ``change(index)``; ``in/c.toml`` the campaign's config on it;
    the in-process caches emptied. The copy stays for the campaign: the database keeps its
    path, where ``lilium report`` and ``lilium calibrate`` read the pairs' inputs."""

    def setup(ws):
        src = _dataset_ref(ws)
        data = _cache(ws, "data", kind.replace(" ", "-"))
        shutil.rmtree(data, ignore_errors=True)
        shutil.copytree(src, data)
        if change is not None:
            path = data / "dataset.json"
            index = json.loads(path.read_text())
            change(index)
            path.write_text(json.dumps(index, indent=2))
        _in(ws, "c.toml").write_text(CONFIG.format(data=data.as_posix()))
        _fresh_state()

    return setup


def _reverse(key):
    def change(index):
        index[key] = index[key][::-1]

    return change


def _interrupted(keep, kind):
    """Set-up: ``out/r.sqlite``, the reference database with only the rows ``keep(id, n)``
    (what a run killed part way leaves), and the dataset copied."""

    def setup(ws):
        _dataset(kind=kind)(ws)
        db = _copy_db(_ref_db(ws), ws.out / "r.sqlite")
        conn = sqlite3.connect(db)
        with conn:
            ids = [r[0] for r in conn.execute("SELECT id FROM sfo ORDER BY id")]
            gone = [(i,) for i in ids if not keep(i, len(ids))]
            conn.executemany("DELETE FROM sfo WHERE id = ?", gone)
        conn.close()
        MEASURED.setdefault("_removed", {})[ws.root.name] = len(gone)

    return setup


_CLUSTERS = []


def _close_clusters():
    while _CLUSTERS:
        client, cluster = _CLUSTERS.pop()
        for thing in (client, cluster):
            try:
                thing.close()
            except Exception:  # noqa: BLE001, S110 - closing at the end, whatever its state
                pass


atexit.register(_close_clusters)


def _dask_cluster(ws):
    """Set-up: a Dask local cluster of 2 worker processes of one thread each (its address in
    ``in/scheduler.txt``), closed by the probe's check or at exit."""
    import logging

    from dask.distributed import Client, LocalCluster

    _dataset(kind="dask")(ws)
    cluster = LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    client = Client(cluster)  # keeps the workers warm until the run has connected its own
    _CLUSTERS.append((client, cluster))
    _in(ws, "scheduler.txt").write_text(cluster.scheduler_address)


def _permuted(src, dst, how="hash"):
    """A copy of a database with its rows stored in another order (``hash``: by a hash of
    their key; ``reverse``); the ``meta`` table as it was."""
    _copy_db(src, dst)
    conn = sqlite3.connect(dst)
    cols = [r[1] for r in conn.execute("PRAGMA table_info(sfo)") if r[1] != "id"]
    rows = conn.execute(f"SELECT {', '.join(cols)} FROM sfo ORDER BY id").fetchall()
    if how == "reverse":
        rows = rows[::-1]
    else:
        rows.sort(key=lambda r: hashlib.sha256(repr(r[:8]).encode()).hexdigest())
    with conn:
        conn.execute("DELETE FROM sfo")
        conn.executemany(
            f"INSERT INTO sfo ({', '.join(cols)}) VALUES ({', '.join('?' * len(cols))})", rows
        )
    conn.execute("VACUUM")
    conn.close()
    return Path(dst)


def _db_in(where, source, permute=None):
    """Set-up: ``in/<where>/r.sqlite``, a copy of ``source(ws)`` (rows ``permute``d)."""

    def setup(ws):
        dst = _in(ws, where, "r.sqlite")
        if permute:
            _permuted(source(ws), dst, permute)
        else:
            _copy_db(source(ws), dst)

    return setup


def _prior(argv, into):
    """Set-up: the command ``argv(ws, out)`` run first into ``in/<into>`` (the run to compare
    with)."""

    def setup(ws):
        assert _quiet_main(argv(ws, _in(ws, into))) == 0, f"the first run ({into}) failed"

    return setup

