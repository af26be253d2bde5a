"""SQLite results store: one row per finished SFO, committed at once (WAL mode).

The key ``(experiment, method, variant, axes_set, repetition, seed, photo, subject)`` is UNIQUE
and rows are written with ``INSERT OR IGNORE``: a run killed at any moment loses only the SFOs
in flight, and running it again skips every key already stored, so nothing is duplicated.

Conventions of the key: ``variant`` is ``""`` for POSEST-SFO; ``axes_set`` is 0 for the
subject's own soft-tissue axes (Exps. A, B) and ``k`` for ``axes_C<k>.json`` (Exp. C);
``repetition`` is the 0-based Lilium run (0 for POSEST-SFO, which is deterministic).

A file that is not a Lilium results database is refused and left untouched; ``lilium report``
opens the database read-only. :class:`RunLock` keeps a second ``lilium experiment`` off a
database that one is using.
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
    "result": "TEXT",  # the result.json dictionary (docs/contract.md) (without the fitness history)
}

COLUMNS = KEY_COLUMNS + tuple(VALUE_COLUMNS)

#: Columns that hold numbers (SQLite would store text in them too).
_NUMERIC_COLUMNS = {"axes_set", "repetition", "seed"} | {
    c for c, kind in VALUE_COLUMNS.items() if kind in ("REAL", "INTEGER")
}

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


#: ``meta`` row that marks a database as Lilium's (older databases are known by their table).
FORMAT = "lilium-experiment-results"


#: SQLite result codes (extended names) of a write the system refused: the disk is full, or a
#: file-size limit (``ulimit -f``) was reached. The database stays intact (SQLite rolls the
#: transaction back), so these are not a damaged database.
WRITE_REFUSED = frozenset(
    {
        "SQLITE_FULL",
        "SQLITE_IOERR",
        "SQLITE_IOERR_WRITE",
        "SQLITE_IOERR_FSYNC",
        "SQLITE_IOERR_DIR_FSYNC",
        "SQLITE_IOERR_TRUNCATE",
        "SQLITE_IOERR_SHMSIZE",
    }
)


def write_refused(exc):
    """Whether a ``sqlite3.Error`` is a write the system refused (see :data:`WRITE_REFUSED`)."""
    return getattr(exc, "sqlite_errorname", None) in WRITE_REFUSED


def database_error(path, exc, fix="give another --db (or restore the file from a copy)"):
    """The ``ValueError`` for a ``sqlite3.DatabaseError`` on the results database ``path``.

    A write the system refused (:func:`write_refused`) says so and that the run resumes; any
    other error says the file cannot be used, with ``fix``.
    """
    if write_refused(exc):
        return ValueError(
            f"{path}: could not write (disk full or a file-size limit; {exc}); the stored SFOs "
            "are kept: free space and run the same command again to resume"
        )
    return ValueError(
        f"{path}: cannot use this results database ({exc}): it is corrupt, truncated, not "
        f"writable or not a Lilium results database; {fix}"
    )


class ResultStore:
    """The results database (open with ``ResultStore(path)``; a context manager).

    Parameters
    ----------
    path : str or Path
        Created with its parent folders when missing (unless ``read_only``).
    read_only : bool
        Open an existing database read-only (a ``file:...?mode=ro`` URI): nothing is created,
        written or switched to WAL (``lilium report``).

    Raises
    ------
    ValueError
        The file is not a SQLite database, is corrupt, or is a SQLite database of something
        else (its tables are left untouched).
    """

    def __init__(self, path, read_only=False):
        self.path = Path(path)
        self.read_only = read_only
        self._fix = (
            "give the database written by lilium experiment (or restore it from a copy)"
            if read_only
            else "give another --db (or restore the file from a copy)"
        )
        if self.path.is_dir():
            raise ValueError(f"{self.path}: is a folder; give the results database file (--db)")
        try:
            if read_only:
                if not self.path.is_file():
                    raise ValueError(
                        f"{self.path}: database not found; run lilium experiment first"
                    )
                uri = self.path.resolve().as_uri() + "?mode=ro"
                if not self.path.with_name(self.path.name + "-wal").exists():
                    # No writer at work (a closed WAL database has no -wal file): read it as
                    # immutable, so that not even the -shm/-wal side files are created.
                    uri += "&immutable=1"
                self.conn = sqlite3.connect(uri, uri=True, timeout=60.0)
            else:
                try:
                    self.path.parent.mkdir(parents=True, exist_ok=True)
                except OSError as exc:
                    raise ValueError(
                        f"{self.path}: cannot create its folder {self.path.parent} "
                        f"({exc.strerror}); give another --db"
                    ) from None
                self.conn = sqlite3.connect(self.path, timeout=60.0)
        except sqlite3.DatabaseError as exc:
            raise database_error(self.path, exc, self._fix) from None
        try:
            self._open()
        except sqlite3.DatabaseError as exc:
            self.conn.close()
            raise database_error(self.path, exc, self._fix) from None
        except ValueError:
            self.conn.close()
            raise

    def _open(self):
        tables = {
            r[0] for r in self.conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")
        }
        if tables:
            self._check_schema(tables)
        elif self.read_only:
            raise ValueError(
                f"{self.path}: an empty database, not a Lilium results database; give the "
                "database written by lilium experiment"
            )
        if self.read_only:
            return
        self.conn.execute("PRAGMA journal_mode=WAL")
        # In WAL mode NORMAL survives a killed process (only a power cut may lose the last rows).
        self.conn.execute("PRAGMA synchronous=NORMAL")
        self.conn.executescript(_SCHEMA)
        self.conn.commit()
        if self.get_meta("format") is None:
            self.set_meta("format", FORMAT)

    def _check_schema(self, tables):
        """Refuse a SQLite file that is not a Lilium results database (touching nothing)."""
        columns = set()
        if "sfo" in tables:
            columns = {r[1] for r in self.conn.execute("PRAGMA table_info(sfo)")}
        if "sfo" not in tables or "meta" not in tables or not set(COLUMNS) <= columns:
            lacking = ["table meta"] if "meta" not in tables else []
            lacking += sorted(set(COLUMNS) - columns) if "sfo" in tables else ["table sfo"]
            raise ValueError(
                f"{self.path}: a SQLite database but not a Lilium results database (it lacks "
                f"{', '.join(lacking[:3])}{', ...' if len(lacking) > 3 else ''}); it was left "
                "untouched: "
                + (
                    "give the database written by lilium experiment"
                    if self.read_only
                    else "give a new file for the results (--db)"
                )
            )

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

    def check_fingerprint(self, fingerprint, what="other settings", key="fingerprint", fix=None):
        """Record ``fingerprint`` in a new database, or check that it matches the stored one.

        Parameters
        ----------
        fingerprint : str
        what : str
            What a mismatch means, for the message ("other DE settings or seeds").
        key : str
            ``meta`` key it is kept under.
        fix : str, optional
            How to fix a mismatch (default: resume with the same config or another --db).
        """
        stored = self.get_meta(key)
        if stored is None:
            self.set_meta(key, fingerprint)
        elif stored != fingerprint:
            fix = fix or "resume with the same config or give another database (--db)"
            raise ValueError(
                f"{self.path}: this database holds results of {what} (fingerprint "
                f"{stored}, now {fingerprint}); {fix}"
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

    def rows(self, columns=None, with_id=False):
        """All rows as dicts (``columns`` default: every column but ``result``), in the order
        of their key (:data:`KEY_COLUMNS`), not of their insertion: which worker finished
        first, a resume or a Dask run must not change what a report or a calibration pairs
        and sums. ``with_id``: each dict also holds the row's ``id`` (what messages name)."""
        columns = list(columns or [c for c in COLUMNS if c != "result"])
        order = ", ".join(KEY_COLUMNS)
        cur = self.conn.execute(f"SELECT id, {', '.join(columns)} FROM sfo ORDER BY {order}")
        fetched = cur.fetchall()
        rows = [dict(zip(columns, r[1:], strict=True)) for r in fetched]
        numeric = [c for c in columns if c in _NUMERIC_COLUMNS]
        for (row_id, *_), row in zip(fetched, rows, strict=True):  # SQLite: any value anywhere
            if with_id:
                row["id"] = row_id
            for c in numeric:
                if row[c] is not None and not isinstance(row[c], (int, float)):
                    raise ValueError(
                        f"{self.path}: row {row_id} holds {str(row[c])[:40]!r} in the numeric "
                        f"column {c}; the database was edited or damaged: restore it, or delete "
                        "that row (lilium experiment then runs its SFO again)"
                    )
        return rows


def task_key(row):
    """The key tuple of a row or task dict."""
    return tuple(row[c] for c in KEY_COLUMNS)
