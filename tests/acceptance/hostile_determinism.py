"""Determinism and equivalence probes of the protocol's pipeline (``lilium synth`` ->
``lilium experiment`` -> ``lilium report`` / ``lilium calibrate``): each probe runs one command
whose outputs must equal those of another run of the same work, scheduled otherwise, and its
``check`` compares the two.

What must not change the stored results (per SFO row: the camera, fitness, terms, estimated
landmarks, warnings, identification terms; the timing columns and the worker's name aside):

- ``lilium experiment`` on 1 worker twice (into another dataset folder), on 2 workers, on a Dask
  local cluster (2 one-thread worker processes), killed part way (rows removed from the
  database) and resumed on 1 or 2 workers, and on the dataset with its subjects, or its photos,
  listed in another order in ``dataset.json``;
- ``lilium synth`` twice with one seed, with ``--workers 2``, with one more subject (the first
  subjects' files), and the dataset fingerprint of a regenerated dataset (a resume accepts it);
- ``lilium report`` twice on one database, on the same rows stored in another order, and on
  the databases of the runs above (the tables that do not read the identification LR, timing
  columns aside);
- ``lilium calibrate`` twice on one database, on the same rows stored in another order, and
  on two databases given in the other order.

docs/method/identification.md (cohorts) says the stored cohort terms (``cohort_mean``,
``cohort_sd``)
depend a little on which skull a worker scored first; they are left out of the row comparisons
above and measured by one probe of their own (``det known limit: ...``), which passes while they
stay within the documented bound (0.015 at most) and every other stored value is equal. The
LR-based report files (``calibration.csv``, ``tippett.png``, the LR rows of
``identification.csv``) read those terms, so the cross-schedule report probes leave them out.

Budgets: 3 subjects x (2 frontal + 2 lateral) photos of Exp. A, POSEST-SFO and
Lilium+P_skof+P_pll at DE 5 x 2 with 2 repetitions (36 + 72 SFOs a run); the campaign (its
experiment, dataset and reference run, made once under ``det-cache/``, and the set-ups) is in
``hostile_detcampaign.py``, the comparisons of rows, report files and datasets in
``hostile_detcompare.py``; this module holds the probes, their command lines and the runs
later probes compare. ::

    python -m pytest -m slow tests/acceptance/test_hostile_determinism.py [-k TEXT]

"""

import shutil
from pathlib import Path

from hostile_casework import _quiet_main
from hostile_detcampaign import (
    CONFIG,
    SYNTH,
    _cache,
    _close_clusters,
    _copy_db,
    _dask_cluster,
    _dataset,
    _dataset_ref,
    _db_in,
    _fresh_state,
    _interrupted,
    _keep,
    _prior,
    _ref_db,
    _reverse,
)
from hostile_detcompare import (
    ALL_BUT_TIME,
    FITNESS_FILES,
    _cohort_known_limit,
    _first_subjects,
    _resumed_nothing,
    _same_dataset,
    _same_outputs,
    _same_rows,
)
from hostile_machinery import Probe, Workspace, _then
from hostile_runs import _in

ROOT = Path(__file__).resolve().parents[2]


# -- command lines ------------------------------------------------------------------------------


def _exp(*extra):
    return lambda ws: [
        "experiment",
        _in(ws, "c.toml"),
        "--no-progress",
        "--db",
        ws.out / "r.sqlite",
        *extra,
    ]


def _exp_dask(ws):
    address = _in(ws, "scheduler.txt").read_text().strip()
    return [*_exp("--scheduler", address)(ws)]


def _dask_check(ws):
    try:
        return _same_rows("dask")(ws)
    finally:
        _close_clusters()


def _report(where):
    return lambda ws, out=None: ["report", _in(ws, where, "r.sqlite"), "--out", out or ws.out]


def _calibrate(*wheres):
    return lambda ws, out=None: [
        "calibrate",
        *(_in(ws, w, "r.sqlite") for w in wheres),
        "--out",
        out or ws.out,
    ]


def _at(argv):
    """``argv(ws, out)`` as a probe's command line (``--out`` = ``out/``)."""
    return lambda ws: argv(ws, ws.out)


#: The runs whose databases later probes compare: how to make each (``--only``).
RUN_KINDS = {
    "2 workers": {"setup": _dataset(kind="2 workers"), "argv": _exp("--workers", "2")},
    "subjects reversed": {
        "setup": _dataset(_reverse("subjects"), "subjects reversed"),
        "argv": _exp(),
    },
    "photos reversed": {"setup": _dataset(_reverse("photos"), "photos reversed"), "argv": _exp()},
    "resumed": {"setup": _interrupted(lambda i, n: i <= n // 3, "resumed"), "argv": _exp()},
}


def _run_db(ws, kind):
    """The database of the campaign's run ``kind`` (made now, in this process, when the probe
    that makes it did not run: ``--only``)."""
    db = _cache(ws, "runs", kind, "r.sqlite")
    if db.is_file():
        return db
    maker = RUN_KINDS[kind]
    tmp = Workspace(ws.root.parent / f"det-make-{kind.replace(' ', '-')}", ws.root / "in")
    try:
        tmp.out.mkdir(exist_ok=True)
        maker["setup"](tmp)
        assert _quiet_main(maker["argv"](tmp)) == 0, f"the {kind} run failed"
        _keep(tmp, kind)
    finally:
        shutil.rmtree(tmp.root, ignore_errors=True)
    return db


def _kind_setup(kind):
    return lambda ws: RUN_KINDS[kind]["setup"](ws)


def _kind_argv(kind):
    return lambda ws: RUN_KINDS[kind]["argv"](ws)


def _regenerated(ws):
    """Set-up: ``in/data`` generated again by ``lilium synth`` with the campaign's seed (on 2
    workers), ``in/c.toml`` on it, and ``out/r.sqlite`` the reference run's database."""
    assert _quiet_main([*SYNTH, "--workers", "2", "--out", _in(ws, "data")]) == 0
    _in(ws, "c.toml").write_text(CONFIG.format(data="data"))
    ws.out.mkdir(exist_ok=True)
    _copy_db(_ref_db(ws), ws.out / "r.sqlite")
    _fresh_state()


def _grown(ws):
    """Set-up: ``out/r.sqlite`` holding a run of the campaign's config with 1 repetition (then
    resumed with 2 by the probe: what growing an experiment step by step does)."""
    _dataset(kind="grown")(ws)
    text = _in(ws, "c.toml").read_text().replace("repetitions = 2", "repetitions = 1")
    _in(ws, "prior.toml").write_text(text)
    ws.out.mkdir(exist_ok=True)
    argv = ["experiment", _in(ws, "prior.toml"), "--no-progress", "--db", ws.out / "r.sqlite"]
    assert _quiet_main(argv) == 0, "the 1-repetition run failed"
    _fresh_state()


def _run(kind):
    return lambda ws: _run_db(ws, kind)


#: ``calibration.json`` keys that say when it was fitted (at any depth).
CAL_DATE = ("fitted",)


# One probe a line: the tables read better than the formatter's 1000 lines.
# fmt: off


def determinism_probes():
    """Runs of the protocol scheduled otherwise that must store and report the same results."""
    rep_ref = _db_in("ref", _ref_db)
    same_all = _same_outputs("first")
    fit_only = _same_outputs("first", FITNESS_FILES)
    all_but_time = _same_outputs("first", ALL_BUT_TIME, json_skip=CAL_DATE)
    cal_same = _same_outputs("first", json_skip=CAL_DATE)
    cal_pair = _same_outputs("first", {"calibration.json": None, "calibration.csv": None},
                             json_skip=(*CAL_DATE, "databases"))
    synth = lambda *extra: lambda ws: [*SYNTH, "--out", ws.out, *extra]  # noqa: E731
    return [
        # lilium synth
        Probe("det synth twice, same seed", synth("--workers", "1"), "ok", (), _dataset_ref, check=_same_dataset()),  # noqa: E501
        Probe("det synth --workers 2 vs 1", synth("--workers", "2"), "ok", (), _dataset_ref, check=_same_dataset()),  # noqa: E501
        Probe("det synth one more subject keeps the first three", lambda ws: ["synth", "--subjects", "4", *SYNTH[3:], "--out", ws.out, "--workers", "2"], "ok", (), _dataset_ref, check=_same_dataset(_first_subjects)),  # noqa: E501
        Probe("det resume on the dataset regenerated with its seed", _exp(), "ok", (), _regenerated, check=_resumed_nothing),  # noqa: E501
        # lilium experiment
        Probe("det experiment 1 worker, again in another folder", _exp("--workers", "1"), "ok", (), _then(_ref_db, _dataset(kind="1 worker")), check=_same_rows("1 worker")),  # noqa: E501
        Probe("det experiment 2 workers vs 1", _kind_argv("2 workers"), "ok", (), _then(_ref_db, _kind_setup("2 workers")), check=_same_rows("2 workers")),  # noqa: E501
        Probe("det experiment Dask local cluster vs local processes", _exp_dask, "ok", (), _then(_ref_db, _dask_cluster), check=_dask_check),  # noqa: E501
        Probe("det experiment killed after a third, resumed", _kind_argv("resumed"), "ok", (), _kind_setup("resumed"), check=_same_rows("resumed")),  # noqa: E501
        Probe("det experiment in-flight rows lost, resumed on 2 workers", _exp("--workers", "2"), "ok", (), _interrupted(lambda i, n: i % 3 != 0, "resumed 2 workers"), check=_same_rows("resumed 2 workers")),  # noqa: E501
        Probe("det experiment 1 repetition, then resumed with 2", _exp(), "ok", (), _then(_ref_db, _grown), check=_same_rows("grown")),  # noqa: E501
        Probe("det experiment subjects listed in reverse", _kind_argv("subjects reversed"), "ok", (), _then(_ref_db, _kind_setup("subjects reversed")), check=_same_rows("subjects reversed")),  # noqa: E501
        Probe("det experiment photos listed in reverse", _kind_argv("photos reversed"), "ok", (), _then(_ref_db, _kind_setup("photos reversed")), check=_same_rows("photos reversed")),  # noqa: E501
        Probe("det known limit: cohort terms (subjects reversed, 2 workers)", _exp("--workers", "2"), "ok", (), _then(_ref_db, _dataset(_reverse("subjects"), "subjects reversed 2 workers")), check=_cohort_known_limit),  # noqa: E501
        # lilium report
        Probe("det report twice on one database", _at(_report("ref")), "ok", (), _then(rep_ref, _prior(_report("ref"), "first")), check=same_all),  # noqa: E501
        Probe("det report on the same rows in another order", _at(_report("perm")), "ok", (), _then(rep_ref, _db_in("perm", _ref_db, "hash"), _prior(_report("ref"), "first")), check=same_all),  # noqa: E501
        Probe("det report on the same rows in reverse order", _at(_report("perm")), "ok", (), _then(rep_ref, _db_in("perm", _ref_db, "reverse"), _prior(_report("ref"), "first")), check=same_all),  # noqa: E501
        Probe("det report photos-reversed run vs straight run", _at(_report("other")), "ok", (), _then(rep_ref, _db_in("other", _run("photos reversed")), _prior(_report("ref"), "first")), check=all_but_time),  # noqa: E501
        Probe("det report 2-worker run vs 1-worker run", _at(_report("other")), "ok", (), _then(rep_ref, _db_in("other", _run("2 workers")), _prior(_report("ref"), "first")), check=fit_only),  # noqa: E501
        Probe("det report resumed run vs straight run", _at(_report("other")), "ok", (), _then(rep_ref, _db_in("other", _run("resumed")), _prior(_report("ref"), "first")), check=fit_only),  # noqa: E501
        Probe("det report subjects-reversed run vs straight run", _at(_report("other")), "ok", (), _then(rep_ref, _db_in("other", _run("subjects reversed")), _prior(_report("ref"), "first")), check=fit_only),  # noqa: E501
        # lilium calibrate
        Probe("det calibrate twice on one database", _at(_calibrate("ref")), "ok", (), _then(rep_ref, _prior(_calibrate("ref"), "first")), check=cal_same),  # noqa: E501
        Probe("det calibrate on the same rows in another order", _at(_calibrate("perm")), "ok", (), _then(rep_ref, _db_in("perm", _ref_db, "hash"), _prior(_calibrate("ref"), "first")), check=cal_same),  # noqa: E501
        Probe("det calibrate photos-reversed run vs straight run", _at(_calibrate("other")), "ok", (), _then(rep_ref, _db_in("other", _run("photos reversed")), _prior(_calibrate("ref"), "first")), check=cal_same),  # noqa: E501
        Probe("det calibrate two databases given in the other order", _at(_calibrate("other", "ref")), "ok", (), _then(rep_ref, _db_in("other", _run("2 workers")), _prior(_calibrate("ref", "other"), "first")), check=cal_pair),  # noqa: E501
    ]


# fmt: on
