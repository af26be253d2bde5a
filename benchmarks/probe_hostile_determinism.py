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

docs/method.md ("Known limits") says the stored cohort terms (``cohort_mean``, ``cohort_sd``)
depend a little on which skull a worker scored first; they are left out of the row comparisons
above and measured by one probe of their own (``det known limit: ...``), which passes while they
stay within the documented bound (0.015 at most) and every other stored value is equal. The
LR-based report files (``calibration.csv``, ``tippett.png``, the LR rows of
``identification.csv``) read those terms, so the cross-schedule report probes leave them out.

Budgets: 3 subjects x (2 frontal + 2 lateral) photos of Exp. A, POSEST-SFO and
Lilium+P_skof+P_pll at DE 5 x 2 with 2 repetitions (36 + 72 SFOs a run, about 15 s on 2 cores);
no wall-clock cap on the DE (``max_seconds = 0``), so the machine's load cannot cut a run short.
The dataset and a reference run (1 worker, its own process) are made once per campaign under
the work folder (``det-cache/``); the databases of the probes' runs are kept there too, for
the report and calibrate probes that compare them. ::

    python benchmarks/probe_hostile_determinism.py --work /tmp/probesD [--only SUBSTRING]

prints one line per probe (``--verbose``: with what was measured), the counts per verdict, and
exits 1 when a probe did not pass.
"""

import atexit
import collections
import csv
import hashlib
import json
import math
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

from probe_hostile import Probe, Workspace, _then
from probe_hostile_casework import _quiet_main
from probe_hostile_runs import _in

ROOT = Path(__file__).resolve().parents[1]

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

#: The identification terms docs/method.md "Known limits" says depend on the first skull a
#: worker scored against a photo.
COHORT_TERMS = ("cohort_mean", "cohort_sd")

#: Their documented spread between two runs of identical SFOs (docs/method.md: "0.015 at most").
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
    from lilium.experiments import calibrate, runner

    calibrate._COHORT_TERMS.clear()
    runner._skull.cache_clear()
    runner._photo.cache_clear()
    runner._facial_truth.cache_clear()
    runner._TOPOLOGIES.clear()


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
        env = {k: v for k, v in os.environ.items() if k != "LILIUM_DEBUG"}
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
            env=env,
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


# -- comparisons ------------------------------------------------------------------------------


def _load(db):
    conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    conn.row_factory = sqlite3.Row
    try:
        rows = [dict(r) for r in conn.execute("SELECT * FROM sfo ORDER BY id")]
    finally:
        conn.close()
    from lilium.experiments.store import KEY_COLUMNS

    out = {}
    for r in rows:
        r["result"] = json.loads(r["result"]) if r["result"] else None
        out[tuple(r[c] for c in KEY_COLUMNS)] = r
    return out


def _rel(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        scale = max(abs(a), abs(b))
        return abs(a - b) / scale if scale else 0.0
    return math.inf


def _walk(a, b, path, found):
    """Append ``(path, a, b)`` of every leaf where ``a`` and ``b`` differ."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            _walk(a.get(k), b.get(k), f"{path}.{k}", found)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _walk(x, y, f"{path}[{i}]", found)
    elif a != b and not (isinstance(a, float) and isinstance(b, float) and a != a and b != b):
        found.append((path, a, b))


def _row_differences(ref, mine, skip_terms=COHORT_TERMS):
    """``{field: [(key, a, b), ...]}`` of every stored value that differs between two
    databases' rows of one key (timing aside, ``skip_terms`` of the identification terms
    aside), plus ``"missing"`` / ``"extra"`` keys."""
    out = collections.defaultdict(list)
    for key in sorted(set(ref) - set(mine)):
        out["missing"].append((key, None, None))
    for key in sorted(set(mine) - set(ref)):
        out["extra"].append((key, None, None))
    for key in sorted(set(ref) & set(mine)):
        a, b = ref[key], mine[key]
        for col in a:
            if col in TIMING_COLUMNS or col == "result":
                continue
            if a[col] != b[col]:
                out[col].append((key, a[col], b[col]))
        ra, rb = dict(a["result"] or {}), dict(b["result"] or {})
        for r in (ra, rb):
            for k in TIMING_KEYS:
                r.pop(k, None)
            terms = r.get("identification_terms")
            if isinstance(terms, dict):
                r["identification_terms"] = {t: v for t, v in terms.items() if t not in skip_terms}
        found = []
        _walk(ra, rb, "result", found)
        for path, x, y in found:
            field = path.split("[")[0]
            field = (
                ".".join(field.split(".")[:3])
                if "identification_terms" in field
                else ".".join(field.split(".")[:2])
            )
            out[field].append((key, x, y))
    return dict(out)


def _describe(diffs, n_rows):
    parts = []
    for field, items in sorted(diffs.items(), key=lambda kv: -len(kv[1])):
        key, a, b = items[0]
        rel = max((_rel(x, y) for _, x, y in items), default=0.0)
        tag = f", max rel. diff {rel:.2g}" if math.isfinite(rel) else ""
        parts.append(
            f"{field} on {len(items)}/{n_rows} rows{tag} (e.g. {_short(key)}: "
            f"{_val(a)} vs {_val(b)})"
        )
    return "; ".join(parts[:4]) + (f"; +{len(parts) - 4} more fields" if len(parts) > 4 else "")


def _short(key):
    exp, method, variant, _axes, rep, _seed, photo, subject = key
    return f"{method}{':' + variant if variant else ''} rep {rep} {photo} x {subject}"


def _val(v):
    text = json.dumps(v) if not isinstance(v, str) else v
    return text if len(text) <= 60 else text[:57] + "..."


def _same_rows(kind, compare_to=_ref_db):
    """Check: ``out/r.sqlite`` holds the reference run's rows, key by key, every stored value
    equal (timing and the known cohort terms aside); the database is kept as run ``kind``."""

    def check(ws):
        _keep(ws, kind)
        ref, mine = _load(compare_to(ws)), _load(ws.out / "r.sqlite")
        diffs = _row_differences(ref, mine)
        cohort = _row_differences(ref, mine, skip_terms=())
        n_cohort = sum(len(v) for k, v in cohort.items() if k.endswith(COHORT_TERMS))
        MEASURED[ws.root.name] = (
            f"{len(mine)} rows; cohort terms differ on {n_cohort} "
            "row-terms (known limit, not compared)"
        )
        return f"differs from the reference run: {_describe(diffs, len(ref))}" if diffs else None

    return check


def _cohort_known_limit(ws):
    """Check: the run's rows equal the reference's except the cohort terms (docs/method.md
    "Known limits"); how much those differ is kept (:data:`MEASURED`), with a note where it
    is more than :data:`COHORT_BOUND`, the largest difference the docs measured."""
    ref, mine = _load(_ref_db(ws)), _load(ws.out / "r.sqlite")
    _keep(ws, "subjects reversed, 2 workers")
    other = _row_differences(ref, mine)
    if other:
        return f"beside the cohort terms: {_describe(other, len(ref))}"
    all_diffs = _row_differences(ref, mine, skip_terms=())
    lines, worst = [], 0.0
    for term in COHORT_TERMS:
        items = all_diffs.get(f"result.identification_terms.{term}", [])
        d = sorted(abs(a - b) for _, a, b in items if a is not None and b is not None)
        spread = [
            r["result"]["identification_terms"][term]
            for r in ref.values()
            if r["result"]
            and isinstance(r["result"].get("identification_terms"), dict)
            and r["result"]["identification_terms"].get(term) is not None
        ]
        photos = {k[6] for k, _, _ in items}
        if d:
            worst = max(worst, d[-1])
            lines.append(
                f"{term}: {len(d)}/{len(ref)} rows ({len(photos)} of "
                f"{len({k[6] for k in ref})} photos) differ, median |d| {d[len(d) // 2]:.2g}, "
                f"max {d[-1]:.2g} (range over rows {min(spread):.3g}..{max(spread):.3g})"
            )
        else:
            lines.append(f"{term}: equal on every row")
    if worst > COHORT_BOUND:
        lines.append(
            f"up to {worst:.3g}: more than the {COHORT_BOUND} docs/method.md "
            "measured on the joint database"
        )
    MEASURED[ws.root.name] = "; ".join(lines)
    return None


def _csv_rows(path, skip_columns=(), keep=None):
    with Path(path).open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    out = []
    for r in rows:
        if keep is not None and not keep(r):
            continue
        out.append({k: v for k, v in r.items() if k not in skip_columns})
    return out


def _fitness_rows(r):
    return "log10 LR" not in (r.get("score") or "")


#: The report's files that read neither the clock nor the identification LR, and how to read
#: them: ``(skip_columns, keep)`` for a CSV, None for bytes.
FITNESS_FILES = {
    "summary.csv": (TIMING_CSV, None),
    "ranks.csv": ((), None),
    "wilcoxon.csv": ((), None),
    "implausible.csv": ((), None),
    "terms_off.csv": ((), None),
    "identification.csv": ((), _fitness_rows),
    "cmc.csv": ((), None),
    "rank_distribution.png": None,
    "bpe.png": None,
    "cmc.png": None,
}


#: Every file of a report but ``report.md`` (it shows the time per SFO), and ``summary.csv``
#: without the time per SFO.
ALL_BUT_TIME = {
    **FITNESS_FILES,
    "identification.csv": ((), None),
    "calibration.csv": ((), None),
    "tippett.png": None,
}


def _compare_files(a_dir, b_dir, files=None, json_skip=()):
    """Differences between two output folders: every file byte for byte (``files`` None), or
    the files of ``files`` as it says; a ``.json`` compared parsed, without the keys named in
    ``json_skip`` (at any depth)."""
    a_dir, b_dir = Path(a_dir), Path(b_dir)
    names = (
        sorted(files)
        if files is not None
        else sorted({p.name for p in a_dir.iterdir()} | {p.name for p in b_dir.iterdir()})
    )
    problems = []
    for name in names:
        a, b = a_dir / name, b_dir / name
        if not a.is_file() or not b.is_file():
            problems.append(f"{name} only in {'the first' if a.is_file() else 'the second'}")
            continue
        how = files.get(name) if files is not None else None
        if name.endswith(".csv"):
            skip, keep = how if how else ((), None)
            ra, rb = _csv_rows(a, skip, keep), _csv_rows(b, skip, keep)
            if ra != rb:
                problems.append(f"{name}: {_csv_diff(ra, rb)}")
        elif name.endswith(".json"):
            ja = _without(json.loads(a.read_text()), json_skip)
            jb = _without(json.loads(b.read_text()), json_skip)
            found = []
            _walk(ja, jb, name, found)
            if found:
                rel, p, x, y = max(((_rel(x, y), p, x, y) for p, x, y in found), key=_first)
                problems.append(
                    f"{name}: {len(found)} values differ (largest rel. diff "
                    f"{rel:.2g}: {p}: {_val(x)} vs {_val(y)})"
                )
        elif name == "report.md":  # the same but for the database's path it names
            la, lb = (_without_database(p.read_text()) for p in (a, b))
            if la != lb:
                problems.append(f"{name}: lines differ")
        elif a.read_bytes() != b.read_bytes():
            problems.append(f"{name}: bytes differ")
    return problems


def _without_database(text):
    return [line for line in text.splitlines() if not line.startswith("Database: ")]


def _first(item):
    return item[0]


def _without(node, names):
    """A JSON value without the keys ``names``, at any depth."""
    if isinstance(node, dict):
        return {k: _without(v, names) for k, v in node.items() if k not in names}
    if isinstance(node, list):
        return [_without(v, names) for v in node]
    return node


def _csv_diff(ra, rb):
    if len(ra) != len(rb):
        return f"{len(ra)} vs {len(rb)} rows"
    cells = []
    for i, (x, y) in enumerate(zip(ra, rb, strict=True)):
        for k in x:
            if x[k] != y.get(k):
                cells.append((i, k, x[k], y.get(k)))
    rel = []
    for _, _, x, y in cells:
        try:
            rel.append(_rel(float(x), float(y)))
        except (TypeError, ValueError):
            rel.append(math.inf)
    i, k, x, y = cells[rel.index(max(rel))]
    label = ", ".join(str(v) for v in list(ra[i].values())[:3])
    return (
        f"{len(cells)} cells differ (largest rel. diff {max(rel):.2g}: row {i + 1} "
        f"[{label}] {k}: {x} vs {y})"
    )


def _same_outputs(first, files=None, json_skip=()):
    """Check: ``out/`` holds what the first run wrote into ``in/<first>``."""

    def check(ws):
        problems = _compare_files(_in(ws, first), ws.out, files, json_skip)
        return "; ".join(problems[:4]) if problems else None

    return check


def _digest(folder, only=None):
    """``{relative path: sha256}`` of a dataset folder (``dataset.json`` without its timing
    fields); ``only(rel)`` keeps some files."""
    out = {}
    for p in sorted(Path(folder).rglob("*")):
        if not p.is_file():
            continue
        rel = p.relative_to(folder).as_posix()
        if only is not None and not only(rel):
            continue
        data = p.read_bytes()
        if p.name == "dataset.json":
            d = json.loads(data)
            d.pop("seconds", None)
            for s in d.get("subjects", []):
                s.pop("seconds", None)
            data = json.dumps(d, sort_keys=True).encode()
        out[rel] = hashlib.sha256(data).hexdigest()
    return out


def _same_dataset(only=None):
    """Check: ``out/`` holds the campaign's dataset file for file (``only``: those files)."""

    def check(ws):
        a, b = _digest(_dataset_ref(ws), only), _digest(ws.out, only)
        if not a:
            return "nothing compared"
        missing = sorted(set(a) - set(b))
        differ = [k for k in sorted(set(a) & set(b)) if a[k] != b[k]]
        if missing or differ:
            return (
                f"{len(differ)} of {len(a)} files differ from the first synth run "
                f"({differ[:3]}), {len(missing)} missing ({missing[:3]})"
            )
        MEASURED[ws.root.name] = f"{len(a)} files identical"
        return None

    return check


def _first_subjects(rel):
    """The files of the campaign's 3 subjects and their photos (not ``dataset.json``)."""
    parts = rel.split("/")
    if parts[0] == "subjects":
        return parts[1] in ("s01", "s02", "s03")
    if parts[0] == "photos":
        return parts[2][:3] in ("s01", "s02", "s03")
    return False


def _resumed_nothing(ws):
    """Check: the resume on the regenerated dataset ran no SFO and left the rows as they
    were."""
    return _same_rows("regenerated dataset")(ws)


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


def _measured(probe, ws, verdict, verbose):
    """What a probe measured: always for the known limit, for every probe with --verbose."""
    measured = MEASURED.get(ws.root.name)
    return f" -- {measured}" if measured and (verbose or "known limit" in probe.name) else ""


def main(argv=None):
    """Run this group alone (the same verdicts as ``probe_hostile.py``)."""
    from probe_hostile import run_group

    return run_group(
        determinism_probes,
        "determinism",
        __doc__,
        argv,
        limit_s=120,
        base=lambda folder: folder.mkdir(parents=True),  # the probes bring their own inputs
        note=_measured,
        hooks={"after": _close_clusters},
    )


if __name__ == "__main__":
    sys.exit(main())
