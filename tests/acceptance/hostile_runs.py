"""Hostile-input probes of the protocol's runs, tested (issue 28):
``lilium experiment`` (config types, unknown keys, counts, methods, the dataset path, a resume
against another config's database, ``--workers 0``, ``--scheduler``), ``lilium report`` (a
folder that is no database, joint-only rows, one photo only, ``--out`` the database's folder)
and ``lilium demo`` (``--out``, ``--seed``, ``--variant``).

A dataset of one subject (a frontal and a lateral photo) is generated once per campaign under
the work folder and copied into each probe's ``in/data``; the databases are written under the
probe's ``out/`` (its ``--db``), so a run writes nowhere else. Budgets: POSEST-SFO or DE 5 x 2.
"""

import os
import shutil
import sqlite3

from hostile_machinery import Probe, _then, _write

#: One subject, a frontal and a lateral photo, POSEST-SFO, Exp. A: 2 SFOs, a few seconds.
BASE = """name = "runs"
methods = ["posest-sfo"]
experiments = ["A"]
repetitions = 1
workers = 1
db = "results.sqlite"
[dataset]
path = "data"
generate = false
subjects = 1
photos = 1
[de]
population = 5
generations = 2
"""


def _in(ws, *parts):
    return ws.root.joinpath("in", *parts)


def _dataset(ws):
    """Set-up: ``in/data``, a copy of the campaign's one-subject dataset (made once)."""
    cache = ws.root.parent / "runs-dataset"
    if not (cache / "dataset.json").is_file():
        from lilium.synthetic.dataset import generate_dataset

        shutil.rmtree(cache, ignore_errors=True)
        generate_dataset(cache, 1, 1, seed=0, experiments=("A", "B", "C"), workers=1)
    shutil.copytree(cache, _in(ws, "data"))


def _config(text, name="c.toml", data=True):
    def setup(ws):
        if data:
            _dataset(ws)
        _in(ws, name).write_text(text)

    return setup


def _exp(*extra, name="c.toml"):
    return lambda ws: [
        "experiment",
        _in(ws, name),
        "--no-progress",
        "--db",
        ws.out / "r.sqlite",
        *extra,
    ]


def _rows(ws):
    """Rows stored in ``out/r.sqlite``, or 0."""
    path = ws.out / "r.sqlite"
    if not path.is_file():
        return 0
    conn = sqlite3.connect(path)
    try:
        return conn.execute("SELECT COUNT(*) FROM sfo").fetchone()[0]
    finally:
        conn.close()


def _stored(n):
    return lambda ws: None if _rows(ws) == n else f"{_rows(ws)} rows stored, not {n}"


def _prior_run(text):
    """Set-up: ``out/r.sqlite`` written by a run of the config ``text`` (another config)."""

    def setup(ws):
        from hostile_casework import _quiet_main

        _in(ws, "prior.toml").write_text(text)
        ws.out.mkdir(exist_ok=True)
        code = _quiet_main(
            ["experiment", _in(ws, "prior.toml"), "--no-progress", "--db", ws.out / "r.sqlite"]
        )
        assert code == 0, "the prior run failed"

    return setup


def _report_db(where="in", change=None):
    """Set-up: ``<where>/r.sqlite`` holding ``change(rows)`` of the report tests' rows."""

    def setup(ws):
        from lilium.experiments.store import ResultStore
        from report_rows import make_rows

        folder = ws.root / where
        folder.mkdir(exist_ok=True)
        rows = make_rows()
        with ResultStore(folder / "r.sqlite") as store:
            for row in change(rows) if change else rows:
                store.insert(row)

    return setup


def _joint_only(rows):
    out = [r for r in rows if r["method"] == "lilium"]
    for r in out:
        r["method"] = "lilium-joint"
    return out


def _one_photo(rows):
    return [r for r in rows if r["photo"] == "s1_f"]


def _report_ok(ws):
    md = ws.out / "report.md"
    return None if md.is_file() and md.stat().st_size else "no report.md"


def _db_intact(ws):
    from lilium.experiments.report import load_rows

    problem = _report_ok(ws)
    return problem or (None if load_rows(ws.out / "r.sqlite") else "database emptied")


def _read_only(path):
    def setup(ws):
        p = ws.root / path
        p.mkdir(parents=True, exist_ok=True)
        p.chmod(0o500)

    return setup


# One probe a line: the tables read better than the formatter's 1000 lines.
# fmt: off


def run_probes():
    """``lilium experiment``, ``lilium report`` and ``lilium demo`` (the runs)."""
    rep = lambda ws: ["report", _in(ws, "r.sqlite"), "--out", ws.out]  # noqa: E731
    demo = lambda *extra: lambda ws: ["demo", *extra]  # noqa: E731
    json_cfg = '{"name": "runs", "methods": ["posest-sfo"], "repetitions": 1}'
    p = [
        Probe("runs config JSON", _exp(name="c.json"), "error", ("c.json", "TOML"), _config(json_cfg, "c.json")),  # noqa: E501
        Probe("runs config YAML", _exp(name="c.yaml"), "error", ("c.yaml", "TOML"), _config("name: runs\nrepetitions: 1\n", "c.yaml")),  # noqa: E501
        Probe("runs repetitions a string", _exp(), "error", ("c.toml", "repetitions"), _config(BASE.replace("repetitions = 1", 'repetitions = "2"'))),  # noqa: E501
        Probe("runs repetitions a float", _exp(), "error", ("c.toml", "repetitions"), _config(BASE.replace("repetitions = 1", "repetitions = 2.0"))),  # noqa: E501
        Probe("runs unknown top key", _exp(), "error", ("c.toml", "reps"), _config(BASE.replace("workers = 1", "workers = 1\nreps = 2"))),  # noqa: E501
        Probe("runs unknown [de] key", _exp(), "error", ("c.toml", "mutation"), _config(BASE + "mutation = 0.5\n")),  # noqa: E501
        Probe("runs [dataset] not a table", _exp(), "error", ("c.toml", "dataset"), _config(BASE.split("[dataset]")[0] + 'dataset = "data"\n')),  # noqa: E501
        Probe("runs subjects -1", _exp(), "error", ("c.toml", "subjects"), _config(BASE.replace("subjects = 1", "subjects = -1"))),  # noqa: E501
        Probe("runs generations 1e12", _exp(), "error", ("c.toml", "generations"), _config(BASE.replace("generations = 2", "generations = 1000000000000"))),  # noqa: E501
        Probe("runs max_seconds nan", _exp(), "error", ("c.toml", "max_seconds"), _config(BASE + "max_seconds = nan\n")),  # noqa: E501
        Probe("runs methods a string", _exp(), "error", ("c.toml", "methods"), _config(BASE.replace('["posest-sfo"]', '"posest-sfo"'))),  # noqa: E501
        Probe("runs method lilium-joint:nope", _exp(), "error", ("c.toml", "lilium-joint:nope"), _config(BASE.replace('"posest-sfo"', '"lilium-joint:nope"'))),  # noqa: E501
        Probe("runs method a number", _exp(), "error", ("c.toml", "methods"), _config(BASE.replace('["posest-sfo"]', "[3]"))),  # noqa: E501
        Probe("runs experiments lowercase", _exp(), "error", ("c.toml", "experiment"), _config(BASE.replace('["A"]', '["a"]'))),  # noqa: E501
        Probe("runs dataset path a file", _exp(), "error", ("d.txt", "dataset.path"), _then(_write("in", "d.txt", "x"), _config(BASE.replace("generate = false", "generate = true").replace('path = "data"', 'path = "d.txt"'), data=False))),  # noqa: E501
        Probe("runs dataset path a file, no generate", _exp(), "error", ("d.txt", "dataset.path"), _then(_write("in", "d.txt", "x"), _config(BASE.replace('path = "data"', 'path = "d.txt"'), data=False))),  # noqa: E501
        Probe("runs dataset.json a folder", _exp(), "error", ("dataset.json",), _then(lambda ws: _in(ws, "d", "dataset.json").mkdir(parents=True), _config(BASE.replace('path = "data"', 'path = "d"'), data=False))),  # noqa: E501
        Probe("runs resume other seed", _exp(), "error", ("r.sqlite", "seed"), _then(_config(BASE.replace("workers = 1", "workers = 1\nseed = 7")), _prior_run(BASE))),  # noqa: E501
        Probe("runs resume other methods", _exp(), "ok", (), _then(_config(BASE.replace('"posest-sfo"', '"posest-sfo", "lilium:base"')), _prior_run(BASE)), check=_stored(4)),  # noqa: E501
        Probe("runs --workers 0", _exp("--workers", "0"), "ok", (), _config(BASE), check=_stored(2)),  # noqa: E501
        Probe("runs workers = 0 in the config", _exp(), "ok", (), _config(BASE.replace("workers = 1", "workers = 0")), check=_stored(2)),  # noqa: E501
        Probe("runs lilium-joint tiny", _exp(), "ok", (), _config(BASE.replace('"posest-sfo"', '"lilium-joint:base"')), check=_stored(2)),  # noqa: E501
        Probe("runs --scheduler not an address", _exp("--scheduler", "not an address"), "error", ("--scheduler",), _config(BASE)),  # noqa: E501
        Probe("runs --scheduler a path", _exp("--scheduler", "/tmp/sched.json"), "error", ("--scheduler",), _config(BASE)),  # noqa: E501
        Probe("runs --scheduler empty", _exp("--scheduler", ""), "error", ("--scheduler",), _config(BASE)),  # noqa: E501
        Probe("runs report a plain folder", lambda ws: ["report", _in(ws, "subjects"), "--out", ws.out], "error", ("subjects",)),  # noqa: E501
        Probe("runs report joint-only rows", rep, "ok", (), _report_db(change=_joint_only), check=_report_ok),  # noqa: E501
        Probe("runs report one photo", rep, "ok", (), _report_db(change=_one_photo), check=_report_ok),  # noqa: E501
        Probe("runs report --out the db's folder", lambda ws: ["report", ws.out / "r.sqlite", "--out", ws.out], "ok", (), _report_db("out"), check=_db_intact),  # noqa: E501
        Probe("runs report --out the db itself", lambda ws: ["report", ws.out / "r.sqlite", "--out", ws.out / "r.sqlite"], "error", ("--out",), _report_db("out")),  # noqa: E501
        Probe("runs demo --out a file", lambda ws: ["demo", "--out", _in(ws, "x.txt")], "error", ("--out",), _write("in", "x.txt", "x")),  # noqa: E501
        Probe("runs demo --out under a file", lambda ws: ["demo", "--out", _in(ws, "x.txt", "sub")], "error", ("--out",), _write("in", "x.txt", "x")),  # noqa: E501
        Probe("runs demo --seed 2^63", demo("--out", "out", "--seed", str(2**63)), "error", ("--seed",)),  # noqa: E501
        Probe("runs demo --variant empty", demo("--out", "out", "--variant", ""), "error", ("--variant",)),  # noqa: E501
        Probe("runs demo --variant lilium:base", demo("--out", "out", "--variant", "lilium:base"), "error", ("--variant",)),  # noqa: E501
    ]
    if os.geteuid() != 0:  # root writes through a read-only folder: nothing to refuse
        p.append(Probe("runs demo --out read-only parent", lambda ws: ["demo", "--out", ws.out / "ro" / "sub"], "error", ("--out",), _read_only("out/ro")))  # noqa: E501
    return p


# fmt: on
