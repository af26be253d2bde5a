"""Where the experiment runner's SFOs run: a local process pool or a Dask cluster.

Each executor yields ``(task, row or exception)`` as tasks finish; the runner stores each row at
once, so whatever stops a run (Ctrl-C, a lost cluster) keeps what is stored and a rerun resumes.
A Dask cluster is reached before anything else happens (:func:`connect_scheduler`: a wrong
address fails in seconds, before the database is made), and a cluster that has lost every
worker ends the run with a message (:class:`NoWorkersLeft`) instead of waiting for ever.
"""

import os
import socket
import time
from urllib.parse import urlsplit

from ..workers import exit_with_parent, quiet_interrupts, starting_workers

#: Tasks in flight per worker (keeps workers busy without queueing the whole run).
IN_FLIGHT_PER_WORKER = 3

#: Environment variables that pin numerical libraries to one thread per worker process.
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

#: Seconds to reach a Dask scheduler before giving up.
CONNECT_TIMEOUT_S = 10.0

#: Seconds a Dask cluster may have no worker at all before the run stops (workers that restart
#: come back within it; a cluster whose workers are all gone never does).
NO_WORKER_TIMEOUT_S = 60.0

#: How often (seconds) a Dask run checks for finished tasks and for workers.
POLL_S = 0.2


class NoWorkersLeft(ValueError):
    """The Dask cluster has had no worker for :data:`NO_WORKER_TIMEOUT_S` seconds."""


def init_worker(parent_pid=None):
    """Worker set-up: one OpenCV thread; with ``parent_pid`` (a pool's process), no library
    warnings on the console (as in ``lilium``'s own process, unless ``LILIUM_DEBUG`` is set)
    and exit when the parent dies."""
    import warnings

    import cv2

    if parent_pid is not None and os.environ.get("LILIUM_DEBUG", "") in ("", "0"):
        warnings.simplefilter("ignore")  # a pool's process (serial runs: lilium.cli.main's)

    cv2.setNumThreads(1)
    if parent_pid is not None:
        quiet_interrupts()
        exit_with_parent(parent_pid)


def local_results(tasks, workers, run):
    """Yield ``(task, run(task) or exception)`` from a local process pool (serial when
    ``workers`` is 1)."""
    if workers <= 1:
        init_worker()
        for task in tasks:
            try:
                yield task, run(task)
            except Exception as exc:  # noqa: BLE001 - reported by the parent, retried on rerun
                yield task, exc
        return

    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    saved = {v: os.environ.get(v) for v in THREAD_VARS}
    for v in THREAD_VARS:  # inherited by the spawned workers
        os.environ.setdefault(v, "1")
    try:
        pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=init_worker,
            initargs=(os.getpid(),),
        )
    finally:
        for v, value in saved.items():
            if value is None:
                os.environ.pop(v, None)
            else:
                os.environ[v] = value
    todo = iter(tasks)
    pending = {}
    try:

        def fill():
            while len(pending) < IN_FLIGHT_PER_WORKER * workers:
                task = next(todo, None)
                if task is None:
                    return
                with starting_workers():
                    pending[pool.submit(run, task)] = task

        fill()
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                task = pending.pop(future)
                try:
                    outcome = future.result()
                except Exception as exc:  # noqa: BLE001
                    outcome = exc
                yield task, outcome
            fill()
    except BaseException:
        # Interrupted (Ctrl-C, or the consumer stopped): do not wait for long SFOs in flight.
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def _refused(address):
    """Why nothing listens at a ``tcp://host:port`` address (None when something does, or
    for other address kinds, which Dask itself then tries)."""
    try:
        parts = urlsplit(address if "://" in address else f"tcp://{address}")
        if parts.scheme not in ("tcp", "tls") or parts.hostname is None:
            return None
        port = parts.port or 8786
    except ValueError:
        return "not an address of the form tcp://host:port"
    try:
        with socket.create_connection((parts.hostname, port), timeout=CONNECT_TIMEOUT_S):
            return None
    except OSError as exc:
        return exc.strerror or type(exc).__name__


def connect_scheduler(address):
    """A ``dask.distributed.Client`` on the scheduler at ``address``, within seconds.

    Raises
    ------
    ValueError
        Naming ``--scheduler``: dask.distributed missing, nothing listening at the address
        (a refused connection fails at once), or no scheduler answering within
        :data:`CONNECT_TIMEOUT_S` seconds.
    """
    try:
        from dask.distributed import Client
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ValueError(
            "--scheduler needs dask.distributed; install it with pip install 'dask[distributed]'"
        ) from exc
    fix = (
        "start one (dask scheduler) and its workers, or check the address, or leave "
        "--scheduler out to run on this machine"
    )
    reason = _refused(str(address))
    if reason is not None:
        raise ValueError(f"--scheduler {address}: no Dask scheduler there ({reason}); {fix}")
    try:
        return Client(address, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ValueError(
            f"--scheduler {address}: no Dask scheduler answered within "
            f"{CONNECT_TIMEOUT_S:g} s ({detail}); {fix}"
        ) from None


def dask_results(tasks, client, run, no_worker_timeout_s=None):
    """Yield ``(task, run(task) or exception)`` from a Dask cluster (``client``).

    Raises
    ------
    NoWorkersLeft
        When the cluster has had no worker for ``no_worker_timeout_s`` seconds (default
        :data:`NO_WORKER_TIMEOUT_S`) while tasks were waiting; what was yielded before is kept
        by the caller, and the tasks in flight are cancelled.
    """
    from dask.distributed import as_completed

    limit = NO_WORKER_TIMEOUT_S if no_worker_timeout_s is None else no_worker_timeout_s
    todo = iter(tasks)
    pending = {}
    queue = as_completed()
    try:

        def fill():
            threads = sum(client.nthreads().values()) or 1
            while len(pending) < max(8, IN_FLIGHT_PER_WORKER * threads):
                task = next(todo, None)
                if task is None:
                    return
                future = client.submit(run, task, pure=False)
                pending[future.key] = task
                queue.add(future)

        fill()
        alone_since = None
        while pending:
            if not queue.has_ready():
                if client.nthreads():
                    alone_since = None
                elif alone_since is None:
                    alone_since = time.monotonic()
                elif time.monotonic() - alone_since > limit:
                    raise NoWorkersLeft(
                        f"the Dask cluster at {client.scheduler.address} has had no worker for "
                        f"{limit:g} s, with {len(pending)} SFOs waiting; the SFOs finished so "
                        "far are stored: start workers (dask worker ADDRESS) and run the same "
                        "command again to resume"
                    )
                time.sleep(POLL_S)
                continue
            future = next(queue)
            task = pending.pop(future.key)
            try:
                outcome = future.result()
            except Exception as exc:  # noqa: BLE001 - a failed or cancelled task, retried on rerun
                outcome = exc
            future.release()
            yield task, outcome
            fill()
    finally:
        for future in list(queue.futures):
            future.cancel()
