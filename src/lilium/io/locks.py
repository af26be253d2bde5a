"""Locks that keep a second run off what a run writes (a results database, an output folder)."""

import os
import time
from pathlib import Path


class RunLock:
    """An exclusive lock on what one run writes: a results database (one ``lilium experiment``
    at a time) or an output folder (one ``lilium case`` or ``lineup``).

    ``fcntl.flock`` on a lock file, taken without waiting. The kernel drops the lock when its
    process ends, however it ends, so a crashed or killed run leaves no stale lock; the file,
    which names the owner's PID and start time, is removed on release. Where ``fcntl`` does not
    exist (Windows) no lock is taken.

    Parameters
    ----------
    target : str or Path
        What is locked, as the messages name it: a database (the lock file ``<db>.lock`` beside
        it, its folder must exist) or an existing output folder (``<folder>/.lilium-run.lock``).
    command : str
        The command that holds it, for the messages (``lilium experiment``).
    option : str
        The option that names ``target``, for the fix (``--db``, ``--out``).

    Raises
    ------
    ValueError
        The lock file cannot be made, or another process holds the lock (its PID is in the
        message).
    """

    def __init__(self, target, command="lilium experiment", option="--db"):
        self.target = Path(target)
        self.command, self.option = command, option
        if self.target.is_dir():
            self.path = self.target / ".lilium-run.lock"
        else:
            self.path = self.target.with_name(self.target.name + ".lock")
        self.fd = None

    def acquire(self):
        try:
            import fcntl
        except ImportError:  # pragma: no cover - Windows
            return self
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise ValueError(
                    f"{self.path}: cannot create the lock file ({exc.strerror}); give "
                    f"{self.option} in a writable folder"
                ) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                owner = os.pread(fd, 200, 0).decode(errors="replace").strip() or "another process"
                os.close(fd)
                raise ValueError(
                    f"{self.target}: in use by another {self.command} ({owner}); wait for it to "
                    f"finish, stop it, or give another {self.option}"
                ) from None
            # The holder before us may have removed the file after we opened it: retry then.
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        stamp = time.strftime("%Y-%m-%d %H:%M:%S")
        try:  # only what a refused second run names; a full disk must not stop this one here
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"pid {os.getpid()} on {os.uname().nodename}, since {stamp}".encode(), 0)
        except OSError:
            pass
        self.fd = fd
        return self

    def release(self):
        if self.fd is None:
            return
        try:
            os.unlink(self.path)  # while still holding the lock, see acquire()
        except FileNotFoundError:
            pass
        os.close(self.fd)
        self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()
