"""SQLite results store: one row per finished SFO, committed at once (WAL mode).

The key ``(experiment, method, variant, axes_set, repetition, seed, photo, subject)`` is UNIQUE
and rows are written with ``INSERT OR IGNORE``: a run killed at any moment loses only the SFOs
in flight, and running it again skips every key already stored, so nothing is duplicated.

Conventions of the key: ``variant`` is ``""`` for POSEST-SFO; ``axes_set`` is 0 for the
subject's own soft-tissue axes (Exps. A, B) and ``k`` for ``axes_C<k>.json`` (Exp. C);
``repetition`` is the 0-based Lilium run (0 for POSEST-SFO, which is deterministic).
"""

import json
import sqlite3
from pathlib import Path

#: Columns of the unique key, in order.
KEY_COLUMNS = (
    "experiment",
    "method",
    "variant",
    "axes_set",
    "repetition",
    "seed",
    "photo",
    "subject",
)

#: Value columns: name -> SQLite type.
VALUE_COLUMNS = {
    "view": "TEXT",  # frontal | lateral_left | lateral_right
    "true_subject": "TEXT",
    "positive": "INTEGER",  # 1 when the photo shows this skull's subject
    "success": "INTEGER",  # 1 when a camera was found
    "score": "REAL",  # ranking score, lower = better (NULL = failed, ranks last)
    "mse_pix": "REAL",
    "p_cam": "REAL",
    "p_skof": "REAL",
    "p_pll": "REAL",
    "focal_px": "REAL",
    "bpe_mm": "REAL",  # positive pairs with a camera only
    "skull_px": "INTEGER",  # |S|, projected skull pixels in the photo
    "outside_px": "INTEGER",  # |S \ F|
    "percent_outside": "REAL",  # 100 |S \ F| / |S|
    "seconds": "REAL",  # the method's own time
    "task_seconds": "REAL",  # the whole task: reading, method, metrics
    "generations": "INTEGER",
    "error": "TEXT",
    "worker": "TEXT",
    "finished_at": "REAL",  # Unix time
    "result": "TEXT",  # the SPEC result.json dictionary (without the fitness history)
}

COLUMNS = KEY_COLUMNS + tuple(VALUE_COLUMNS)

_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS sfo (
    id INTEGER PRIMARY KEY,
    experiment TEXT NOT NULL,
    method TEXT NOT NULL,
    variant TEXT NOT NULL,
    axes_set INTEGER NOT NULL,
    repetition INTEGER NOT NULL,
    seed INTEGER NOT NULL,
    photo TEXT NOT NULL,
    subject TEXT NOT NULL,
    {", ".join(f"{name} {kind}" for name, kind in VALUE_COLUMNS.items())},
    UNIQUE ({", ".join(KEY_COLUMNS)})
);
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
"""


class ResultStore:
    """The results database (open with ``ResultStore(path)``; a context manager).

    Parameters
    ----------
    path : str or Path
        Created with its parent folders when missing.
    """

    def __init__(self, path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.conn = sqlite3.connect(self.path, timeout=60.0)
        self.conn.execute("PRAGMA journal_mode=WAL")
        # In WAL mode NORMAL survives a killed process (only a power cut may lose the last rows).
        self.conn.execute("PRAGMA synchronous=NORMAL")
        self.conn.executescript(_SCHEMA)
        self.conn.commit()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        self.conn.close()

    # -- metadata -------------------------------------------------------------------------
    def get_meta(self, key):
        row = self.conn.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return None if row is None else json.loads(row[0])

    def set_meta(self, key, value):
        with self.conn:
            self.conn.execute(
                "INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", (key, json.dumps(value))
            )

    def check_fingerprint(self, fingerprint, what="settings"):
        """Record ``fingerprint`` in a new database, or check that it matches the stored one."""
        stored = self.get_meta("fingerprint")
        if stored is None:
            self.set_meta("fingerprint", fingerprint)
        elif stored != fingerprint:
            raise ValueError(
                f"{self.path}: this database holds results of other {what} (fingerprint "
                f"{stored}, the config gives {fingerprint}); resume with the same config or "
                "give another database (--db)"
            )

    # -- rows -------------------------------------------------------------------------------
    def done_keys(self):
        """The keys already stored, as a set of tuples in :data:`KEY_COLUMNS` order."""
        cur = self.conn.execute(f"SELECT {', '.join(KEY_COLUMNS)} FROM sfo")
        return set(cur.fetchall())

    def insert(self, row):
        """Store one finished SFO and commit; returns False when its key was already there."""
        values = [row.get(c) for c in COLUMNS]
        with self.conn:
            cur = self.conn.execute(
                f"INSERT OR IGNORE INTO sfo ({', '.join(COLUMNS)}) "
                f"VALUES ({', '.join('?' * len(COLUMNS))})",
                values,
            )
        return cur.rowcount == 1

    def count(self):
        return self.conn.execute("SELECT COUNT(*) FROM sfo").fetchone()[0]

    def rows(self, columns=None):
        """All rows as dicts (``columns`` default: every column but ``result``)."""
        columns = columns or [c for c in COLUMNS if c != "result"]
        cur = self.conn.execute(f"SELECT {', '.join(columns)} FROM sfo ORDER BY id")
        return [dict(zip(columns, r, strict=True)) for r in cur.fetchall()]


def task_key(row):
    """The key tuple of a row or task dict."""
    return tuple(row[c] for c in KEY_COLUMNS)
