"""Worker processes of a local pool (``lilium synth``'s and the experiments'): they do not
outlive the run that started them, and a Ctrl-C ends them without a word.

Ctrl-C reaches every process of the terminal's process group: the pool's workers too. Python
turns it into a KeyboardInterrupt that a worker prints as a traceback when it lands outside a
task (starting up, importing, waiting for work), under the parent's one-line "interrupted". So
the parent starts its workers with SIGINT blocked (:func:`starting_workers`, around the calls
that may start one; a blocked signal waits, it is not lost), and each worker, first thing
(:func:`quiet_interrupts`, in the pool's initializer), restores SIGINT's default action, which
ends a process without a word, and unblocks it (a parent that ignores SIGINT, started in the
background, has workers that ignore it too). The parent, which holds the results, reports
the interrupt and stops the pool.
"""

import contextlib
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


@contextlib.contextmanager
def starting_workers():
    """Block SIGINT in this thread for the block: a worker process started in it (a pool's
    ``submit`` may start one) inherits the blocked signal and sees no Ctrl-C before its
    initializer calls :func:`quiet_interrupts`. A Ctrl-C meanwhile waits, then arrives."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - Windows
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def quiet_interrupts():
    """In a worker process: a Ctrl-C ends it at once without a traceback (SIGINT's default
    action; one that arrived while it started, blocked by :func:`starting_workers`, now).

    A worker whose parent ignores SIGINT (a run started with ``&`` by a shell script: a
    non-interactive shell's background jobs ignore it) inherits that and keeps ignoring it: a
    SIGINT sent to the whole process group would otherwise end the workers under a parent that
    goes on, which then finds its pool broken."""
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
