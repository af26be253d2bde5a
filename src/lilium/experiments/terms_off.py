"""How many SFOs of an experiment ran with a term switched off (docs/method/lilium.md).

A term whose inputs are missing for a skull or photo (P_pll for a skull without its mandible,
P_skof without a face mask, a P_cam part without its prior) is switched off for that SFO and
named in its result's ``terms_off``. An off term counts zero, so ranks over skulls with
different terms off are biased: the experiment report says how many SFOs ran so, per
experiment, method and view (``terms_off.csv`` and a section of ``report.md``).
"""

import json
import sqlite3
from collections import defaultdict
from pathlib import Path

from .config import EXPERIMENTS, VIEW_GROUPS, method_label, method_order, view_group
from .store import ResultStore, database_error

#: The columns of ``terms_off.csv`` (then ``off_<term>`` for each term switched off somewhere).
TERMS_OFF_COLUMNS = ("experiment", "method", "view", "sfos", "with_term_off")


def terms_off_rows(db):
    """``experiment, method, variant, view, terms_off`` of every stored SFO (read-only)."""
    columns = ["experiment", "method", "variant", "view", "result"]
    try:
        with ResultStore(Path(db), read_only=True) as store:
            rows = store.rows(columns)
    except sqlite3.DatabaseError as exc:
        raise database_error(db, exc) from None
    for r in rows:
        try:
            stored = json.loads(r.pop("result") or "{}")
        except json.JSONDecodeError:
            stored = {}
        r["terms_off"] = sorted(stored.get("terms_off") or {}) if isinstance(stored, dict) else []
    return rows


def terms_off_table(rows):
    """SFOs that ran with a term switched off, per experiment, method and view.

    Parameters
    ----------
    rows : list of dict
        :func:`terms_off_rows`.

    Returns
    -------
    list of dict
        ``experiment, method, view, sfos, with_term_off`` and ``off_<term>`` for every term
        switched off somewhere; only the (experiment, method) pairs with some term off.
    """
    terms = sorted({t for r in rows for t in r["terms_off"]})
    groups = defaultdict(list)
    for r in rows:
        groups[(r["experiment"], r["method"], r["variant"], view_group(r["view"]))].append(r)
    out = []
    for exp in EXPERIMENTS:
        pairs = {(m, v) for (e, m, v, _) in groups if e == exp}
        for method, variant in method_order(pairs):
            if not any(
                r["terms_off"]
                for g in VIEW_GROUPS
                for r in groups.get((exp, method, variant, g), [])
            ):
                continue
            for view in VIEW_GROUPS:
                group = groups.get((exp, method, variant, view), [])
                if not group:
                    continue
                row = {
                    "experiment": exp,
                    "method": method_label(method, variant),
                    "view": view,
                    "sfos": len(group),
                    "with_term_off": sum(1 for r in group if r["terms_off"]),
                }
                row.update({f"off_{t}": sum(t in r["terms_off"] for r in group) for t in terms})
                out.append(row)
    return out


def terms_off_markdown(table):
    """The ``report.md`` section of :func:`terms_off_table`."""
    parts = ["\n\n## SFOs that ran with a term switched off\n"]
    if table:
        keys = [k for k in table[0] if k.startswith("off_")]
        parts.append(
            "A term whose inputs are missing is switched off for that SFO: it "
            "counts zero, so ranks over skulls with different terms off are biased.\n"
        )
        lines = [
            [t["experiment"], t["method"], t["view"], t["sfos"], t["with_term_off"]]
            + [t[k] for k in keys]
            for t in table
        ]
        header = ["exp", "method", "view", "SFOs", "with a term off"]
        header += [f"{k[4:]} off" for k in keys]
        parts.append("| " + " | ".join(header) + " |\n|" + "---|" * len(header))
        parts += ["| " + " | ".join(str(c) for c in line) + " |" for line in lines]
    else:
        parts.append("None: every SFO ran with every term its variant asks for.")
    return "\n".join(parts)
