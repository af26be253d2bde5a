"""The comparisons of the determinism probes (``hostile_determinism.py``): the stored
rows of two databases key by key (every stored value, the timing columns and the cohort terms
aside; the cohort terms measured apart, against docs/method/identification.md's bound), two report
or
calibration folders file by file (CSV cell by cell, JSON parsed, some keys or columns left
out), and two datasets file by file; each as a probe's ``check``.
"""

import collections
import csv
import hashlib
import json
import math
import re
import sqlite3
from pathlib import Path

from hostile_detcampaign import (
    COHORT_BOUND,
    COHORT_TERMS,
    MEASURED,
    TIMING_COLUMNS,
    TIMING_CSV,
    TIMING_KEYS,
    _dataset_ref,
    _keep,
    _ref_db,
)
from hostile_runs import _in

# -- comparisons ------------------------------------------------------------------------------


#: The campaign's dataset and its copies (``det-cache/dataset``, ``det-cache/data/<kind>``) in a
#: stored message (a warning naming a photo's file): each run names the copy it ran on.
_DATASET_COPY = re.compile(r"det-cache/(?:dataset|data/[^/]+)/")


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
        text = _DATASET_COPY.sub("det-cache/<dataset>/", r["result"]) if r["result"] else None
        r["result"] = json.loads(text) if text else None
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
    """Check: the run's rows equal the reference's except the cohort terms
    (docs/method/identification.md
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
            f"up to {worst:.3g}: more than the {COHORT_BOUND} docs/method/identification.md "
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

