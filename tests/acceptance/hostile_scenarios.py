"""The subprocess scenarios of the resume campaign (issue 28), run by ``test_hostile_resume.py``
(``python -m pytest -m slow tests/acceptance/test_hostile_resume.py -k scenario``): ``lilium
experiment``, ``lineup``, ``case`` (several photos, ``--joint``), ``synth`` and ``calibrate`` run as
subprocesses, killed with SIGKILL mid-run and rerun (the rerun must end as an uninterrupted
run), interrupted with SIGINT (Ctrl-C: one line, no traceback, also from worker processes), two
runs on one ``--out`` or ``--db`` at once, and a file-size limit (``ulimit -f``) while writing.

:class:`Scenarios` holds them (each method returns None, a pass, or why it is a defect) and
:data:`SCENARIOS` names them in the order they run. Budgets: Lilium with DE 8 x 40 for runs to
be killed mid-run.
"""

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

from hostile_fixtures import _png_ok, _results, _sfo_fields
from hostile_machinery import _lilium_env

ROOT = Path(__file__).resolve().parents[2]

PY = sys.executable


def _lilium(args, cwd, limit_fsize=None):
    pre = None
    if limit_fsize is not None:
        import resource

        def pre():
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_fsize, limit_fsize))
    return subprocess.Popen([PY, "-m", "lilium", *map(str, args)], cwd=cwd, env=_lilium_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=pre)


def _wait_for(proc, cond, timeout=120):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            if cond():
                return True
        except (OSError, sqlite3.Error, ValueError):
            pass
        time.sleep(0.05)
    return False


def _finish(proc, timeout=300):
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        return "hang", out, err
    return proc.returncode, out, err


def _one_line_error(code, err, cmd, word="error", names=None):
    """None when ``err`` is one ``lilium <cmd>: <word>`` line (naming ``names``, a folder a
    file of which it must name) and nothing else of note."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if "Traceback" in err or "internal error" in err:
        tb = [ln for ln in lines if ln.strip()]
        return f"traceback on stderr ({len(lines)} lines; last: {tb[-1][:120] if tb else ''})"
    ours = [ln for ln in lines if ln.startswith(f"lilium {cmd}: {word}")]
    if len(ours) != 1:
        return f"exit {code}, no one '{word}' line: {lines[-3:] if lines else 'stderr empty'}"
    extra = [ln for ln in lines if ln not in ours]
    if extra:
        return f"stray stderr lines beside the message: {extra[:2]}"
    if names is not None and str(names) not in ours[0]:
        return f"the message names no file: {ours[0]}"
    return None


def _rows(db, columns="experiment, method, variant, axes_set, repetition, seed, photo, subject"):
    conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        return conn.execute(f"SELECT {columns}, score, mse_pix, focal_px FROM sfo").fetchall()
    finally:
        conn.close()


def _count(db):
    conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1)
    try:
        return conn.execute("SELECT COUNT(*) FROM sfo").fetchone()[0]
    finally:
        conn.close()


EXP_SLOW = """name = "rz"
methods = ["posest-sfo", "lilium:base"]
experiments = ["A"]
repetitions = 2
workers = {workers}
db = "results.sqlite"
[dataset]
path = "{data}"
generate = false
[de]
population = 8
generations = 40
max_seconds = 0
"""


class Scenarios:
    """The subprocess scenarios; each method returns None (pass) or why it is a defect."""

    def __init__(self, work):
        self.work = Path(work)
        self.data = self.work / "ds"
        self.base = self.work / "base"

    def prepare(self):
        sys.path.insert(0, str(ROOT / "tests"))
        from lilium.synthetic.dataset import generate_dataset
        from standin_case import make_standin_case, scaled_photo

        if self.work.exists():
            shutil.rmtree(self.work)
        generate_dataset(self.data, 2, 1, seed=0, experiments=("A",), workers=1)
        make_standin_case(self.base, seed=0)
        scaled_photo(self.base / "photos" / "standin_frontal", self.base / "photos" / "p2", 0.5)
        scaled_photo(self.base / "photos" / "standin_frontal", self.base / "photos" / "p3", 0.9)

    def folder(self, name):
        path = self.work / name
        shutil.rmtree(path, ignore_errors=True)
        path.mkdir(parents=True)
        return path

    def config(self, where, workers=1):
        path = where / "c.toml"
        path.write_text(EXP_SLOW.format(workers=workers, data=self.data))
        return path

    # experiment ----------------------------------------------------------------------------
    def _full_db(self):
        if not hasattr(self, "_ref"):
            w = self.folder("exp-ref")
            code, _, err = _finish(_lilium(["experiment", self.config(w), "--no-progress",
                                            "--db", w / "r.sqlite"], w))
            assert code == 0, err
            self._ref = sorted(_rows(w / "r.sqlite"))
        return self._ref

    def experiment_sigkill(self):
        ref = self._full_db()
        w = self.folder("exp-kill")
        db = w / "r.sqlite"
        args = ["experiment", self.config(w, workers=2), "--no-progress", "--db", db]
        proc = _lilium(args, w)
        if not _wait_for(proc, lambda: _count(db) >= 6):
            _finish(proc)
            return "the run ended before it could be killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        kept = _count(db)
        code, out, err = _finish(_lilium(args, w))
        if code != 0:
            return f"rerun exit {code}: {err[-200:]}"
        if f"{kept} already in" not in out:
            return f"rerun did not report the {kept} stored rows: {out.splitlines()[:1]}"
        rows = sorted(_rows(db))
        if rows != ref:
            keys = [r[:8] for r in rows]
            return (f"{len(rows)} rows ({len(set(keys))} distinct keys) differ from the "
                    f"uninterrupted run's {len(ref)}")
        return None

    def experiment_sigint(self, workers):
        ref = self._full_db()
        w = self.folder(f"exp-int{workers}")
        db = w / "r.sqlite"
        args = ["experiment", self.config(w, workers=workers), "--no-progress", "--db", db]
        proc = _lilium(args, w)
        if not _wait_for(proc, lambda: _count(db) >= 4):
            _finish(proc)
            return "the run ended before it could be interrupted"
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the whole foreground group
        code, _, err = _finish(proc, 60)
        problem = _one_line_error(code, err, "experiment", "interrupted")
        if problem:
            return f"Ctrl-C: {problem}"
        code, _, err = _finish(_lilium(args, w))
        if code != 0 or sorted(_rows(db)) != ref:
            return f"rerun after Ctrl-C: exit {code}, rows differ from an uninterrupted run"
        return None

    def experiment_two_at_once(self):
        ref = self._full_db()
        w = self.folder("exp-two")
        db = w / "r.sqlite"
        args = ["experiment", self.config(w), "--no-progress", "--db", db]
        a = _lilium(args, w)
        time.sleep(0.3)
        b = _lilium(args, w)
        (ca, _, ea), (cb, _, eb) = _finish(a), _finish(b)
        if sorted((ca, cb)) != [0, 2]:
            return f"exits {ca}, {cb} (one run and one refusal expected): {ea[-150:]} {eb[-150:]}"
        refused = eb if cb == 2 else ea
        problem = _one_line_error(2, refused, "experiment")
        if problem or "in use" not in refused:
            return f"the refusal: {problem or refused.strip()}"
        if sorted(_rows(db)) != ref:
            return "the database differs from an uninterrupted run's"
        return None

    def experiment_fsize(self):
        w = self.folder("exp-fsize")
        db = w / "r.sqlite"
        args = ["experiment", self.config(w), "--no-progress", "--db", db]
        code, _, err = _finish(_lilium(args, w, limit_fsize=120_000))
        if code == 0:
            return "ran to exit 0 under a 120 kB file-size limit?"
        problem = _one_line_error(code, err, "experiment")
        if problem:
            return f"ulimit -f: {problem}"
        kept = _count(db)
        code2, _, err2 = _finish(_lilium(args, w))
        if code2 != 0 or sorted(_rows(db)) != self._full_db():
            return f"rerun without the limit: exit {code2} {err2.strip()[-200:]}"
        if not any(w in err.lower() for w in ("too large", "disk is full", "no space", "limit")):
            return (f"the run stopped after {kept} SFOs at the file-size limit (the rerun then "
                    f"resumed fine) but the message blames the database: {err.strip()[:260]}")
        return None

    def calibrate_while_writing(self):
        sys.path.insert(0, str(ROOT / "tests"))
        from standin_case import terms_database

        w = self.folder("cal-live")
        db = terms_database(w / "r.sqlite", 12)
        conn = sqlite3.connect(db)  # a writer at work: WAL with rows not checkpointed
        conn.execute("PRAGMA journal_mode=WAL")
        conn.execute("PRAGMA wal_autocheckpoint=0")
        n = conn.execute("SELECT COUNT(*) FROM sfo").fetchone()[0]
        with conn:
            conn.execute("DELETE FROM sfo WHERE id > ?", (n // 2,))
        proc = _lilium(["calibrate", db, "--out", w / "cal"], w)
        code, out, err = _finish(proc)
        conn.close()
        if code != 0:
            return f"calibrate beside a writer: exit {code}: {err.strip()[-250:]}"
        return None

    def calibrate_sigint(self):
        sys.path.insert(0, str(ROOT / "tests"))
        from standin_case import terms_database

        w = self.folder("cal-int")
        # 80 subjects: about 3 s of work, so that 1.3 s in it is still working (30 subjects
        # finished in 1.7 s on a fast machine, and a Ctrl-C in the interpreter's shutdown,
        # after the outputs, killed it with the default handler)
        db = terms_database(w / "r.sqlite", 80)
        proc = _lilium(["calibrate", db, "--out", w / "cal"], w)
        time.sleep(1.3)
        if proc.poll() is not None:
            return "finished before it could be interrupted"
        if proc.poll() is not None:
            _finish(proc)
            return "ended before it could be interrupted (give it more work)"
        os.killpg(proc.pid, signal.SIGINT)
        code, _, err = _finish(proc, 60)
        return _one_line_error(code, err, "calibrate", "interrupted")

    def startup_sigint(self):
        """Ctrl-C half a second after the start (the user saw a wrong option)."""
        w = self.folder("startup-int")
        proc = _lilium(["synth", "--out", w / "out", "--subjects", "2", "--no-progress"], w)
        time.sleep(0.4)
        if proc.poll() is not None:
            _finish(proc)
            return "ended before it could be interrupted (give it more work)"
        os.killpg(proc.pid, signal.SIGINT)
        code, _, err = _finish(proc, 60)
        return _one_line_error(code, err, "synth", "interrupted")

    # lineup -------------------------------------------------------------------------------
    def lineup_args(self, out, extra=()):
        ph = self.base / "photos"
        return ["lineup", "--no-progress", "--skull", self.base / "subjects" / "standin",
                "--candidate", "A", ph / "standin_frontal", "--candidate", "B", ph / "p3",
                "--candidate", "C", ph / "p2", "--out", out, "--method", "lilium",
                "--generations", "500", "--population", "20", "--max-seconds", "600", *extra]

    def lineup_sigkill(self):
        w = self.folder("lineup-kill")
        code, _, err = _finish(_lilium(self.lineup_args(w / "ref"), w))
        if code != 0:
            return f"uninterrupted lineup failed: {err[-200:]}"
        first = w / "out" / "A" / "standin_frontal" / "lilium-skof+pll" / "result.json"
        proc = _lilium(self.lineup_args(w / "out"), w)
        if not _wait_for(proc, (first.parent / "overlay.png").is_file):
            _finish(proc)
            return "ended before it could be killed"
        time.sleep(0.3)  # the overlay written to its end
        if proc.poll() is not None:
            return "ended before it could be killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        before = first.read_text()
        code, _, err = _finish(_lilium(self.lineup_args(w / "out"), w))
        if code != 0:
            return f"rerun: exit {code} {err[-200:]}"
        if json.loads(first.read_text())["seconds"] != json.loads(before)["seconds"]:
            return "the SFO finished before the kill ran again"
        a, b = _results(w / "out"), _results(w / "ref")
        if sorted(a) != sorted(b) or any(_sfo_fields(a[k]) != _sfo_fields(b[k]) for k in a):
            return "resumed results differ from the uninterrupted run's"
        for k in a:
            problem = _png_ok(a[k].parent / "overlay.png")
            if problem:
                return f"{k}: {problem}"
        ra = json.loads((w / "out" / "lineup.json").read_text())["ranking"]
        rb = json.loads((w / "ref" / "lineup.json").read_text())["ranking"]
        if [(e["candidate"], e["identification"].get("log10_lr")) for e in ra] != [
            (e["candidate"], e["identification"].get("log10_lr")) for e in rb
        ]:
            return "the ranking differs from the uninterrupted run's"
        return None

    def _sigint(self, args, cmd, ready, name):
        w = self.folder(name)
        proc = _lilium(args(w), w)
        if not _wait_for(proc, lambda: ready(w)):
            _finish(proc)
            return "ended before it could be interrupted"
        if proc.poll() is not None:
            _finish(proc)
            return "ended before it could be interrupted (give it more work)"
        os.killpg(proc.pid, signal.SIGINT)
        code, _, err = _finish(proc, 60)
        if code == "hang":
            return "Ctrl-C did not stop it within 60 s"
        return _one_line_error(code, err, cmd, "interrupted")

    def lineup_sigint(self):
        return self._sigint(lambda w: self.lineup_args(w / "out"), "lineup",
                            lambda w: any((w / "out").rglob("result.json")), "lineup-int")

    def lineup_two_at_once(self):
        w = self.folder("lineup-two")
        args = self.lineup_args(w / "out", ("--generations", "100"))
        a = _lilium(args, w)
        time.sleep(0.5)
        b = _lilium(args, w)
        (ca, _oa, ea), (cb, _ob, eb) = _finish(a), _finish(b)
        if ca == cb == 0:
            return ("no refusal: both runs ran every SFO into one --out (duplicated work, "
                    "each overwriting the other's files)")
        if sorted((ca, cb)) == [0, 2]:
            return _one_line_error(2, eb if cb else ea, "lineup")
        return f"exits {ca}, {cb}: {ea[-150:]} {eb[-150:]}"

    def lineup_fsize(self):
        w = self.folder("lineup-fsize")
        args = self.lineup_args(w / "out", ("--generations", "5"))
        code, _, err = _finish(_lilium(args, w, limit_fsize=60_000))
        if code == 0:
            return "exit 0 under a 60 kB file-size limit (the overlays are larger)"
        message = _one_line_error(code, err, "lineup", names=w)
        if message and "names no file" not in message:
            return f"ulimit -f: {message}"
        code, _, err = _finish(_lilium(args, w))
        if code != 0:
            return f"rerun without the limit: exit {code}: {err.strip()[-200:]}"
        for k, p in _results(w / "out").items():
            problem = _png_ok(p.parent / "overlay.png")
            if problem:
                return f"rerun without the limit kept a half-written SFO: {k}: {problem}"
        return f"ulimit -f: {message}" if message else None

    # case ---------------------------------------------------------------------------------
    def case_args(self, out, joint=False, generations=500):
        ph = self.base / "photos"
        return ["case", "--skull", self.base / "subjects" / "standin", "--photo",
                ph / "standin_frontal", "--photo", ph / "p3", "--out", out, "--method", "lilium",
                "--generations", str(generations), "--population", "20", "--max-seconds", "600",
                *(["--joint"] if joint else [])]

    def case_sigint(self, joint=False):
        # 5,000 generations: with the kernels built ahead of time a joint case of 500 ended
        # within the 2 s before the Ctrl-C.
        return self._sigint(lambda w: self.case_args(w / "out", joint, 5000), "case",
                            lambda w: time.sleep(2) is None, f"case-int{int(joint)}")

    def case_sigkill_resume(self):
        w = self.folder("case-kill")
        first = w / "out" / "standin_frontal" / "lilium-skof+pll" / "result.json"
        proc = _lilium(self.case_args(w / "out"), w)
        if not _wait_for(proc, first.is_file):
            _finish(proc)
            return "ended before it could be killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        before = json.loads(first.read_text())["seconds"]
        code, _, err = _finish(_lilium(self.case_args(w / "out"), w))
        if code != 0:
            return f"rerun exit {code}: {err[-200:]}"
        if json.loads(first.read_text())["seconds"] != before:
            return "no resume: the SFO finished before the kill ran again on the rerun"
        return None

    def case_fsize(self):
        w = self.folder("case-fsize")
        args = self.case_args(w / "out")
        args[args.index("500")] = "5"
        code, _, err = _finish(_lilium(args, w, limit_fsize=60_000))
        if code == 0:
            return "exit 0 under a 60 kB file-size limit"
        return _one_line_error(code, err, "case", names=w)

    # synth --------------------------------------------------------------------------------
    def synth_args(self, out, seed=0, workers=1):
        return ["synth", "--out", out, "--subjects", "3", "--photos", "1", "--seed", seed,
                "--workers", workers, "--no-progress", "--experiments", "A"]

    @staticmethod
    def _digest(folder):
        out = {}
        for p in sorted(Path(folder).rglob("*")):
            if p.is_file():
                data = p.read_bytes()
                if p.name == "dataset.json":
                    d = json.loads(data)
                    d.pop("seconds", None)
                    for s in d["subjects"]:
                        s.pop("seconds", None)
                    data = json.dumps(d, sort_keys=True).encode()
                out[p.relative_to(folder).as_posix()] = hashlib.sha256(data).hexdigest()
        return out

    def synth_sigkill(self):
        w = self.folder("synth-kill")
        code, _, err = _finish(_lilium(self.synth_args(w / "ref"), w))
        assert code == 0, err
        proc = _lilium(self.synth_args(w / "out"), w)
        if not _wait_for(proc, lambda: (w / "out" / "subjects" / "s02").is_dir()):
            _finish(proc)
            return "ended before it could be killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        code, _, err = _finish(_lilium(self.synth_args(w / "out"), w))
        if code != 0:
            return f"rerun exit {code}: {err[-200:]}"
        a, b = self._digest(w / "out"), self._digest(w / "ref")
        if a != b:
            diff = sorted(set(a) ^ set(b)) or [k for k in a if a[k] != b[k]]
            return f"rerun after a kill differs from an uninterrupted run: {diff[:3]}"
        return None

    def synth_killed_over_old(self):
        """synth --seed 1 over a finished --seed 0 dataset, killed mid-way: dataset.json must
        not still describe a complete dataset (lilium experiment would trust it)."""
        w = self.folder("synth-over")
        out = w / "out"
        code, _, err = _finish(_lilium(self.synth_args(out, seed=0), w))
        assert code == 0, err
        mesh = next((out / "subjects" / "s01").glob("skull*"))
        old = mesh.stat().st_mtime_ns
        proc = _lilium(self.synth_args(out, seed=1), w)
        if not _wait_for(proc, lambda: (out / "subjects" / "s02").is_dir()
                         and mesh.stat().st_mtime_ns != old):
            _finish(proc)
            return "ended before it could be killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        index = out / "dataset.json"
        if index.is_file() and json.loads(index.read_text()).get("seed") == 0:
            cfg = w / "c.toml"
            cfg.write_text(EXP_SLOW.format(workers=1, data=out).replace("generations = 40",
                                                                        "generations = 2"))
            code, _, err = _finish(_lilium(["experiment", cfg, "--no-progress", "--db",
                                            w / "r.sqlite"], w))
            return ("a killed synth --seed 1 left the old dataset.json (seed 0) beside "
                    f"subject files of seed 1; lilium experiment on it: exit {code}"
                    + (" (ran on the mixed dataset)" if code == 0 else f" {err.strip()[:120]}"))
        return None

    def synth_sigint(self, workers):
        return self._sigint(lambda w: self.synth_args(w / "out", workers=workers), "synth",
                            lambda w: (w / "out" / "subjects").is_dir(), f"synth-int{workers}")

    def synth_two_at_once(self):
        w = self.folder("synth-two")
        a = _lilium(self.synth_args(w / "out", seed=0), w)
        time.sleep(0.3)
        b = _lilium(self.synth_args(w / "out", seed=1), w)
        (ca, _, _ea), (cb, _, _eb) = _finish(a), _finish(b)
        if ca == cb == 0:
            index = json.loads((w / "out" / "dataset.json").read_text())
            ref = self.folder("synth-two-ref")
            _finish(_lilium(self.synth_args(ref / "out", seed=index["seed"]), ref))
            if self._digest(ref / "out") != self._digest(w / "out"):
                return (f"two synth (seeds 0 and 1) on one --out both exit 0; the folder is a "
                        f"mix: its dataset.json says seed {index['seed']} but the files "
                        "differ from that seed's dataset")
        return None

    def synth_fsize(self):
        w = self.folder("synth-fsize")
        code, _, err = _finish(_lilium(self.synth_args(w / "out"), w, limit_fsize=50_000))
        if code == 0:
            return "exit 0 under a 50 kB file-size limit"
        return _one_line_error(code, err, "synth", names=w)


SCENARIOS = [
    ("experiment SIGKILL mid-run, rerun", lambda s: s.experiment_sigkill()),
    ("experiment Ctrl-C (1 worker)", lambda s: s.experiment_sigint(1)),
    ("experiment Ctrl-C (2 workers)", lambda s: s.experiment_sigint(2)),
    ("experiment two runs on one --db", lambda s: s.experiment_two_at_once()),
    ("experiment ulimit -f 120 kB", lambda s: s.experiment_fsize()),
    ("lineup SIGKILL mid-run, rerun", lambda s: s.lineup_sigkill()),
    ("lineup Ctrl-C", lambda s: s.lineup_sigint()),
    ("lineup two runs on one --out", lambda s: s.lineup_two_at_once()),
    ("lineup ulimit -f 60 kB, rerun", lambda s: s.lineup_fsize()),
    ("case SIGKILL mid-run, rerun", lambda s: s.case_sigkill_resume()),
    ("case Ctrl-C", lambda s: s.case_sigint()),
    ("case --joint Ctrl-C", lambda s: s.case_sigint(joint=True)),
    ("case ulimit -f 60 kB", lambda s: s.case_fsize()),
    ("synth SIGKILL mid-run, rerun", lambda s: s.synth_sigkill()),
    ("synth --seed 1 killed over a seed-0 dataset", lambda s: s.synth_killed_over_old()),
    ("synth Ctrl-C (1 worker)", lambda s: s.synth_sigint(1)),
    ("synth Ctrl-C (2 workers)", lambda s: s.synth_sigint(2)),
    ("synth two runs on one --out", lambda s: s.synth_two_at_once()),
    ("synth ulimit -f 50 kB", lambda s: s.synth_fsize()),
    ("calibrate beside a writer of its database", lambda s: s.calibrate_while_writing()),
    ("calibrate Ctrl-C", lambda s: s.calibrate_sigint()),
    ("any command: Ctrl-C during start-up", lambda s: s.startup_sigint()),
]
