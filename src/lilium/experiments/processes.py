"""Worker processes that do not outlive the run that started them."""

import os
import signal
import sys
import threading
import time

#: Seconds between two checks of a worker's watchdog that its parent process is alive.
PARENT_CHECK_SECONDS = 0.5


def exit_with_parent(parent_pid):
    """End this worker process when the process ``parent_pid`` (its parent) dies.

    On Linux the kernel sends SIGKILL on the parent's death (``prctl(PR_SET_PDEATHSIG)``);
    everywhere a daemon thread checks every :data:`PARENT_CHECK_SECONDS` that the parent is still
    the parent (an orphan is adopted by another process) and exits at once otherwise. A worker
    holds nothing to clean up: only the parent writes the database.

    Call it in the pool's initializer. ``PR_SET_PDEATHSIG`` fires when the *thread* that started
    the worker ends; the runner's pool starts its workers from the thread that runs the
    experiment, which outlives them.

    Parameters
    ----------
    parent_pid : int
        ``os.getpid()`` of the parent, passed in by it (``initargs``).
    """
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover - no prctl: the watchdog remains
            pass
    if os.getppid() != parent_pid:  # the parent died before the line above
        os._exit(1)

    def watch():
        while True:
            time.sleep(PARENT_CHECK_SECONDS)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="lilium-parent-watchdog", daemon=True).start()
