"""Crashes, interrupts, resumes and concurrency of the long runs (issue 28): ``lilium
experiment``, ``lineup``, ``case`` (several photos, ``--joint``), ``synth`` and ``calibrate``.

Two kinds of probes:

- :func:`resume_probes`, here, checked by ``test_hostile_resume.py``: a run is resumed
  after what a crash leaves behind (a ``result.json`` cut in the middle, an ``overlay.png`` of 0
  bytes or missing, a WAL left over, a stale lock file) or after its inputs changed (a photo's
  landmarks, the skull's landmarks, the DE budget, the experiments). A resumed run must end as
  an uninterrupted run of the same command would (its outputs are compared with a fresh run's
  in another folder), or refuse in one line; silently keeping a stale result is ``silently
  wrong``.
- the subprocess scenarios of ``hostile_scenarios.py``, run by ``test_hostile_resume.py``
  (``python -m pytest -m slow tests/acceptance/test_hostile_resume.py [-k TEXT]``):
  subprocesses killed with SIGKILL mid-run and rerun, interrupted with SIGINT (Ctrl-C: one
  line, no traceback, also from worker processes), two runs on one ``--out`` or ``--db`` at
  once, and a file-size limit (``ulimit -f``) while writing. One line per scenario: ``pass``
  or ``defect`` and why.

Budgets: POSEST-SFO, or Lilium with DE 5 x 2 (in-process) and 8 x 40 (to be killed mid-run).
"""

import json
import shutil
import sqlite3
from pathlib import Path

from hostile_casework import TINY, _quiet_main, _second_photo
from hostile_fixtures import SFO_FIELDS, _png_ok, _results, _sfo_fields
from hostile_machinery import Probe
from hostile_runs import BASE, _config, _exp, _in, _prior_run, _stored, _then

# -- comparing a resumed run with a fresh one ---------------------------------------------------

def _same_as_fresh(argv_at):
    """Check: the outputs of the resumed run equal those of the same command run afresh into
    ``<probe>/fresh`` (``argv_at(ws, out)`` the command with its ``--out``)."""

    def check(ws):
        fresh = ws.root / "fresh"
        code = _quiet_main(argv_at(ws, fresh))
        if code != 0:
            return f"the fresh run failed ({code})"
        mine, theirs = _results(ws.out), _results(fresh)
        for rel, path in theirs.items():
            if rel not in mine:
                return f"{rel} missing"
            a, b = _sfo_fields(mine[rel]), _sfo_fields(path)
            if a != b:
                diff = [k for k in SFO_FIELDS if a[k] != b[k]]
                return f"{rel}: stale result kept ({', '.join(diff)} differ from a fresh run)"
        return None

    return check


# -- lineup ---------------------------------------------------------------------------------

A_DIR = "A/standin_frontal"


def _lineup_at(method="posest-sfo", extra=()):
    def argv_at(ws, out):
        return ["lineup", "--no-progress", "--skull", ws.skull, "--out", out, "--method", method,
                "--candidate", "A", ws.photo, "--candidate", "B", _in(ws, "photos", "p2"),
                *extra]
    return argv_at


def _prior(argv_at, *changes):
    """Set-up: the second photo, a finished run of ``argv_at`` into ``out/``, then
    ``changes``."""

    def setup(ws):
        _second_photo()(ws)
        assert _quiet_main(argv_at(ws, ws.out)) == 0, "the prior run failed"
        for change in changes:
            change(ws)

    return setup


def _move_photo_landmark(ws):
    path = ws.photo / "photo.json"
    data = json.loads(path.read_text())
    name = sorted(data["landmarks"])[0]
    u, v = data["landmarks"][name][:2]
    data["landmarks"][name] = [u + 25.0, v + 25.0]
    path.write_text(json.dumps(data))


def _move_skull_landmark(ws):
    path = ws.skull / "cranial_landmarks.json"
    data = json.loads(path.read_text())
    table = data["landmarks"] if "landmarks" in data else data
    name = sorted(table)[0]
    table[name] = [float(x) + 4.0 for x in table[name]]
    path.write_text(json.dumps(data))


def _lilium_folder(ws, tag="lilium-skof+pll"):
    return ws.out / A_DIR / tag


def _cut(rel, keep=0.5):
    def change(ws):
        path = ws.out / rel
        data = path.read_bytes()
        path.write_bytes(data[: int(len(data) * keep)])
    return change


def _remove(rel):
    return lambda ws: (ws.out / rel).unlink()


def _overlays_ok(ws):
    for result in _results(ws.out).values():
        problem = _png_ok(result.parent / "overlay.png")
        if problem:
            return f"{result.parent.relative_to(ws.out)}: {problem} after the resume"
    return None


# -- case -------------------------------------------------------------------------------------


def _case_at(joint=False):
    def argv_at(ws, out):
        return ["case", "--skull", ws.skull, "--photo", ws.photo, "--photo",
                _in(ws, "photos", "p2"), "--out", out, "--method", "lilium", *TINY,
                *(["--joint"] if joint else [])]
    return argv_at


def _crash_after_first(folder_of_rest):
    """Change: what a crash after the first SFO leaves: the later SFOs' folders removed; the
    first SFO's result.json is kept aside to see whether the rerun keeps it."""

    def change(ws):
        for rel in folder_of_rest:
            shutil.rmtree(ws.out / rel, ignore_errors=True)
        (ws.out / "report.html").unlink(missing_ok=True)
        first = _results(ws.out)
        (ws.root / "kept.json").write_text(json.dumps({k: str(v) for k, v in first.items()}))
        for rel, path in first.items():
            shutil.copy(path, ws.root / (rel.replace("/", "__")))
    return change


def _first_kept(ws):
    kept = json.loads((ws.root / "kept.json").read_text())
    if not kept:
        return "set-up kept nothing"
    for rel in kept:
        before = json.loads((ws.root / rel.replace("/", "__")).read_text())
        after = json.loads((ws.out / rel).read_text())
        if before.get("seconds") != after.get("seconds"):
            return f"{rel}: the finished SFO ran again on the rerun (no resume)"
    return None


# -- experiment -------------------------------------------------------------------------------


def _leftover_wal(delete_row=True, drop_shm=False, garbage_wal=False):
    """Set-up after a prior run: the database as a process killed after writing leaves it
    (a WAL with an uncheckpointed change, its -shm), or with a garbage -wal."""

    def setup(ws):
        db = ws.out / "r.sqlite"
        if garbage_wal:
            Path(str(db) + "-wal").write_bytes(bytes(range(256)) * 40)
            return
        saved = ws.root / "copy"
        saved.mkdir()
        conn = sqlite3.connect(db)
        conn.execute("PRAGMA journal_mode=WAL")
        with conn:
            if delete_row:
                conn.execute("DELETE FROM sfo WHERE id = (SELECT MAX(id) FROM sfo)")
        for suffix in ("", "-wal", "-shm"):
            shutil.copy(str(db) + suffix, saved / ("r.sqlite" + suffix))
        conn.close()
        for suffix in ("", "-wal", "-shm"):
            Path(str(db) + suffix).unlink(missing_ok=True)
            if not (drop_shm and suffix == "-shm"):
                shutil.copy(saved / ("r.sqlite" + suffix), str(db) + suffix)

    return setup


def _stale_lock(ws):
    ws.out.mkdir(exist_ok=True)
    (ws.out / "r.sqlite.lock").write_text("pid 999999 on elsewhere, since 2001-01-01 00:00:00")


def _edit_dataset_photo(ws):
    path = _in(ws, "data", "photos", "A", "s01_f00", "photo.json")
    data = json.loads(path.read_text())
    name = sorted(data["landmarks"])[0]
    data["landmarks"][name] = [float(x) + 20.0 for x in data["landmarks"][name][:2]]
    path.write_text(json.dumps(data))


def _distinct_keys(n):
    def check(ws):
        conn = sqlite3.connect(ws.out / "r.sqlite")
        try:
            rows = conn.execute("SELECT COUNT(*), COUNT(DISTINCT experiment || method || variant "
                                "|| axes_set || repetition || seed || photo || subject) "
                                "FROM sfo").fetchone()
        finally:
            conn.close()
        return None if rows == (n, n) else f"{rows[0]} rows, {rows[1]} distinct keys, not {n}"
    return check


# One probe a line: the tables read better than the formatter's 1000 lines.
# fmt: off


def resume_probes():
    """Resumes of ``lilium lineup``, ``case`` and ``experiment`` after a crash's leftovers or
    changed inputs."""
    post = _lineup_at()
    lil = _lineup_at("lilium", TINY)
    lil_more = _lineup_at("lilium", ("--generations", "4", "--population", "6"))
    lil_seed = _lineup_at("lilium", (*TINY, "--seed", "3"))
    run = lambda argv_at: lambda ws: argv_at(ws, ws.out)  # noqa: E731
    fresh = _same_as_fresh
    p = [
        Probe("resume lineup other --generations/--population", run(lil_more), "ok", (), _prior(lil), check=fresh(lil_more)),  # noqa: E501
        Probe("resume lineup other --seed", run(lil_seed), "ok", (), _prior(lil), check=fresh(lil_seed)),  # noqa: E501
        Probe("resume lineup photo landmark edited", run(post), "ok", (), _prior(post, _move_photo_landmark), check=fresh(post)),  # noqa: E501
        Probe("resume lineup skull landmark edited", run(post), "ok", (), _prior(post, _move_skull_landmark), check=fresh(post)),  # noqa: E501
        Probe("resume lineup result.json cut in the middle", run(post), "ok", (), _prior(post, _cut(f"{A_DIR}/posest-sfo/result.json")), check=fresh(post)),  # noqa: E501
        Probe("resume lineup overlay.png of 0 bytes", run(post), "ok", (), _prior(post, _cut(f"{A_DIR}/posest-sfo/overlay.png", 0)), check=_overlays_ok),  # noqa: E501
        Probe("resume lineup overlay.png cut in the middle", run(post), "ok", (), _prior(post, _cut(f"{A_DIR}/posest-sfo/overlay.png")), check=_overlays_ok),  # noqa: E501
        Probe("resume lineup overlay.png missing", run(post), "ok", (), _prior(post, _remove(f"{A_DIR}/posest-sfo/overlay.png")), check=_overlays_ok),  # noqa: E501
        Probe("resume lineup lineup.json cut", run(post), "ok", (), _prior(post, _cut("lineup.json")), check=lambda ws: None if json.loads((ws.out / "lineup.json").read_text())["ranking"] else "no ranking"),  # noqa: E501
        Probe("resume lineup result.json.tmp left over", run(post), "ok", (), _prior(post, lambda ws: (ws.out / A_DIR / "posest-sfo" / "result.json.tmp").write_text('{"meth')), check=fresh(post)),  # noqa: E501
        Probe("resume case after a crash mid-way", run(_case_at()), "ok", (), _prior(_case_at(), _crash_after_first(["p2"])), check=_first_kept),  # noqa: E501
        Probe("resume case --joint after a crash before the report", run(_case_at(True)), "ok", (), _prior(_case_at(True), _crash_after_first([])), check=_first_kept),  # noqa: E501
        Probe("resume case photo landmark edited", run(_case_at()), "ok", (), _prior(_case_at(), _move_photo_landmark), check=fresh(_case_at())),  # noqa: E501
        Probe("resume experiment adding experiment B", _exp(), "ok", (), _then(_config(BASE.replace('["A"]', '["A", "B"]')), _prior_run(BASE)), check=_stored(4)),  # noqa: E501
        Probe("resume experiment dropping experiment B", _exp(), "ok", (), _then(_config(BASE), _prior_run(BASE.replace('["A"]', '["A", "B"]'))), check=_stored(4)),  # noqa: E501
        Probe("resume experiment photo landmark edited", _exp(), "error", ("r.sqlite", "dataset"), _then(_config(BASE), _prior_run(BASE), _edit_dataset_photo)),  # noqa: E501
        Probe("resume experiment other max_seconds", _exp(), "error", ("r.sqlite",), _then(_config(BASE.replace("generations = 2", "generations = 2\nmax_seconds = 9")), _prior_run(BASE))),  # noqa: E501
        Probe("resume experiment WAL left by a killed run", _exp(), "ok", (), _then(_config(BASE), _prior_run(BASE), _leftover_wal()), check=_distinct_keys(2)),  # noqa: E501
        Probe("resume experiment WAL left, -shm lost", _exp(), "ok", (), _then(_config(BASE), _prior_run(BASE), _leftover_wal(drop_shm=True)), check=_distinct_keys(2)),  # noqa: E501
        Probe("resume experiment garbage -wal", _exp(), "ok", (), _then(_config(BASE), _prior_run(BASE), _leftover_wal(garbage_wal=True)), check=_distinct_keys(2)),  # noqa: E501
        Probe("resume experiment database cut in the middle", _exp(), "error", ("r.sqlite",), _then(_config(BASE), _prior_run(BASE), _cut("r.sqlite", 0.6))),  # noqa: E501
        Probe("resume experiment stale lock file", _exp(), "ok", (), _then(_config(BASE), _stale_lock), check=_distinct_keys(2)),  # noqa: E501
    ]
    return p


# fmt: on
