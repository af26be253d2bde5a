"""Run the paper's protocol (docs/method/evaluation.md): enumerate the SFOs, run them, store each at
once.

Tasks: every photo x every skull x every method, for each experiment:

- A, B: POSEST-SFO once (deterministic), each Lilium variant ``repetitions`` times (seeds
  ``seed + r``), with the skull's own soft-tissue axes (``axes_set`` 0);
- C: for each perturbed axis set ``k = 1..axes_sets`` (``axes_C<k>.json`` of the *tested*
  skull): POSEST-SFO once, each Lilium variant ``runs_per_axes_set`` times.

A joint method (``lilium-joint``, :mod:`lilium.experiments.joint_tasks`) runs once per
subject's frontal + lateral photo pair and skull, and stores one row per photo.

The worker (:func:`run_task`) reads the case (cached per process, :mod:`.task_io`), runs the
method and scores it: the ranking score, the BPE for positive pairs (photo of this skull's
subject) and the projected-skull pixels outside the face mask (implausible SFOs). The parent
writes each row to the :class:`~lilium.experiments.store.ResultStore` as it arrives, so a
killed run loses only the SFOs in flight; a rerun skips the stored keys.

Before the first SFO the run checks the dataset (:mod:`lilium.experiments.dataset`: the
index, every file the tasks read, the fingerprint the database keeps) and takes the database's
lock (:class:`~lilium.io.locks.RunLock`): a second run on the same database refuses at
once.

Executors: a local process pool (default, all cores) or a Dask distributed cluster
(``scheduler="tcp://host:8786"``); the dataset folder must then be readable by every worker at
the same path (a shared file system). Local workers end when the parent process dies, however
it dies (:func:`lilium.workers.exit_with_parent`); a Dask cluster is reached before
anything else, and a cluster without workers ends the run (:mod:`lilium.experiments.executors`).
"""

import os
import socket
import sqlite3
import time
from dataclasses import dataclass, replace
from pathlib import Path

from ..io.locks import RunLock
from ..optimisation.de import DEOptions
from .dataset import check_index, check_task_files, dataset_fingerprint
from .executors import connect_scheduler, dask_results, local_results
from .joint_tasks import JOINT_METHODS, partner_tasks, photo_pairs, run_joint_task
from .store import KEY_COLUMNS, ResultStore, database_error
from .task_io import (
    facial_truth,
    result_columns,
    score_result,
    skull_topology,
    task_photo,
    task_skull,
)


@dataclass(frozen=True)
class Task:
    """One SFO of the protocol (picklable; paths are absolute so Dask workers can read them).

    Attributes
    ----------
    experiment, method, variant : str
    axes_set : int
        0 = the skull's own axes; ``k`` = ``axes_C<k>.json``.
    repetition, seed : int
    photo, subject : str
        Photo id and tested skull (subject) id.
    true_subject, view : str
        The photo's subject and view.
    subject_dir, photo_dir : str
    axes_file : str or None
    de : DEOptions
    joint_with : tuple of (str, str, str)
        A joint task's other photos, ``(photo id, view, photo_dir)`` each (``photo`` is the
        pair's frontal photo); empty for a single-photo SFO.
    """

    experiment: str
    method: str
    variant: str
    axes_set: int
    repetition: int
    seed: int
    photo: str
    subject: str
    true_subject: str
    view: str
    subject_dir: str
    photo_dir: str
    axes_file: str | None
    de: DEOptions
    joint_with: tuple = ()

    @property
    def key(self):
        return tuple(getattr(self, c) for c in KEY_COLUMNS)


# -- dataset ----------------------------------------------------------------------------------
def load_dataset(cfg, workers=1, log=print):
    """Read ``dataset.json`` of ``cfg.dataset.path``, generating the dataset first if allowed.

    Returns
    -------
    root : Path
        Absolute dataset folder.
    index : dict
        The dataset index (see :mod:`lilium.synthetic.dataset`).
    """
    from ..io.jsonio import read_json

    root = Path(cfg.dataset.path).resolve()
    if root.exists() and not root.is_dir():
        raise ValueError(
            f"{root}: dataset.path is a file, not a folder; set dataset.path in the config to "
            "the dataset folder (or to a new folder to generate it)"
        )
    index_path = root / "dataset.json"
    if not index_path.is_file():
        if not cfg.dataset.generate:
            why = "not found"
            if any((root / name).exists() for name in ("subjects", "photos")):
                why = "not found: an unfinished dataset (lilium synth writes dataset.json last)"
            raise ValueError(
                f"{index_path}: dataset index {why}; generate the dataset (lilium synth) or set "
                "dataset.generate = true in the config"
            )
        from ..synthetic.dataset import generate_dataset

        log(
            f"generating the dataset: {cfg.dataset.subjects} subjects x "
            f"{2 * cfg.dataset.photos} photos -> {root}"
        )
        generate_dataset(
            root,
            cfg.dataset.subjects,
            cfg.dataset.photos,
            seed=cfg.dataset.seed,
            experiments=("A", "B", "C"),
            workers=max(1, min(workers, cfg.dataset.subjects)),
            no_mandible_share=cfg.dataset.no_mandible_share,
            drop_landmark_rate=cfg.dataset.drop_landmark_rate,
        )
    index = read_json(index_path)
    check_index(index, index_path)
    return root, index


def enumerate_tasks(cfg, root, index):
    """Every SFO of the protocol, ordered so that consecutive tasks share their case.

    Parameters
    ----------
    cfg : ExperimentConfig
    root : Path
        Dataset folder.
    index : dict
        ``dataset.json``.

    Returns
    -------
    list of Task
    """
    root = Path(root)
    check_index(index, root / "dataset.json")
    subjects = index["subjects"]
    pairs = photo_pairs(index)
    if not pairs and any(m in JOINT_METHODS for m, _ in cfg.methods):
        raise ValueError(
            f"{root / 'dataset.json'}: a joint method needs subjects with a frontal and a "
            "lateral photo, the dataset has none; generate both views (lilium synth)"
        )
    tasks = []
    for exp in cfg.experiments:
        for photo in index["photos"]:
            if exp not in photo["paths"]:
                raise ValueError(
                    f"{root / 'dataset.json'}: photo {photo['id']} has no experiment {exp} "
                    "folder; regenerate the dataset with all of A, B, C"
                )
        if exp == "C":
            axes_sets = range(1, cfg.axes_sets + 1)
            runs = cfg.runs_per_axes_set
        else:
            axes_sets, runs = (0,), cfg.repetitions
        for k in axes_sets:
            for photo in index["photos"]:
                for subject in subjects:
                    axes_file = None
                    if k:
                        names = subject.get("axes_C", [])
                        if len(names) < k:
                            raise ValueError(
                                f"subject {subject['id']} has {len(names)} perturbed axis sets "
                                f"but the config asks for axes_sets = {cfg.axes_sets}"
                            )
                        axes_file = str(root / subject["path"] / names[k - 1])
                    for method, variant in cfg.methods:
                        partners = ()
                        if method in JOINT_METHODS:  # one task per pair, led by its frontal
                            if photo["id"] not in pairs:
                                continue
                            other = pairs[photo["id"]]
                            partners = (
                                (other["id"], other["view"], str(root / other["paths"][exp])),
                            )
                        reps = [0] if method == "posest-sfo" else range(runs)
                        for r in reps:
                            tasks.append(
                                Task(
                                    experiment=exp,
                                    method=method,
                                    variant=variant,
                                    axes_set=k,
                                    repetition=r,
                                    seed=0 if method == "posest-sfo" else cfg.seed + r,
                                    photo=photo["id"],
                                    subject=subject["id"],
                                    true_subject=photo["subject"],
                                    view=photo["view"],
                                    subject_dir=str(root / subject["path"]),
                                    photo_dir=str(root / photo["paths"][exp]),
                                    axes_file=axes_file,
                                    de=cfg.de,
                                    joint_with=partners,
                                )
                            )
    return tasks


# -- worker -------------------------------------------------------------------------------------
def _run_method(task, skull, photo):
    """Run the task's SFO; its docs/checks.md warnings land in the row's ``result`` JSON.

    The left/right checks run first (:func:`lilium.methods.run_sfo`); a broken rule is a
    ``ValueError`` naming the subject's or the photo's landmark file (an error row).
    """
    from ..methods import SfoOptions, run_sfo

    skull = replace(skull, landmarks_file=str(Path(task.subject_dir) / "cranial_landmarks.json"))
    photo = replace(photo, landmarks_file=str(Path(task.photo_dir) / "photo.json"))
    options = SfoOptions(variant=task.variant or None, de=task.de)
    return run_sfo(task.method, skull, photo, options, task.seed)


def run_task(task):
    """Run one SFO and score it; returns the database row (a dict).

    An invalid case (a ``ValueError``: too few landmarks, no face mask for P_skof, ...) is a
    finished SFO with its ``error``; any other exception propagates (the task is not stored and
    a rerun tries it again). A joint task returns a list of rows, one per photo
    (:func:`~lilium.experiments.joint_tasks.run_joint_task`).
    """
    if task.joint_with:
        return run_joint_task(task)
    start = time.perf_counter()
    row = {c: getattr(task, c) for c in KEY_COLUMNS}
    row.update(
        view=task.view,
        true_subject=task.true_subject,
        positive=int(task.subject == task.true_subject),
        worker=f"{socket.gethostname()}:{os.getpid()}",
    )
    try:
        skull = task_skull(task.subject_dir, task.axes_file)
        photo, truth = task_photo(task.photo_dir)
        result = _run_method(task, skull, photo)
    except ValueError as exc:
        row.update(success=0, error=str(exc), task_seconds=time.perf_counter() - start)
        row["finished_at"] = time.time()
        return row
    if row["positive"]:
        truth = replace(truth, facial_landmarks_mm=facial_truth(task.subject_dir))
    row.update(score_result(result, skull, photo, truth, skull_topology(task.subject_dir, skull)))
    row.update(result_columns(result, result.fitness, result))
    from .calibrate import with_terms

    with_terms(row, skull, [photo], [result], result.facial_landmarks_mm, [row])
    row.update(task_seconds=time.perf_counter() - start, finished_at=time.time())
    return row


# -- driver -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RunSummary:
    """What a call of :func:`run_experiment` did.

    Attributes
    ----------
    total : int
        SFOs of the protocol.
    already_done : int
        Found in the database at the start.
    stored : int
        Written by this call.
    errors : list of (key, str)
        Tasks that raised (not stored; a rerun tries them again).
    seconds : float
    db : Path
    """

    total: int
    already_done: int
    stored: int
    errors: list
    seconds: float
    db: Path

    @property
    def complete(self):
        return self.already_done + self.stored == self.total


def run_experiment(cfg, scheduler=None, workers=None, db=None, progress=True, log=print):
    """Run (or resume) the protocol of ``cfg``.

    Before the first SFO: takes the database's lock (a second run on it is refused), reads and
    checks the dataset (generating it if allowed), checks every file the tasks read, and checks
    the database's fingerprints of the settings and of the dataset (a resume against other
    settings or another dataset is refused).

    Parameters
    ----------
    cfg : ExperimentConfig
    scheduler : str or dask.distributed.Client, optional
        Run on this Dask cluster instead of the local process pool.
    workers : int, optional
        Local processes (default ``cfg.workers``; 0 = all cores).
    db : path, optional
        Results database (default ``cfg.db``).
    progress : bool
        Show a tqdm progress bar (SFOs done, rate, ETA) on stderr.
    log : callable
        Receives one-line messages.

    Returns
    -------
    RunSummary

    Raises
    ------
    ValueError
        Any of the checks above, or a corrupt or foreign database, with the file and the fix.
    """
    start = time.perf_counter()
    workers = workers if workers is not None else cfg.workers
    workers = workers or os.cpu_count() or 1
    db = Path(db or cfg.db)
    if db.is_dir():
        raise ValueError(f"{db}: is a folder; give the results database file (--db)")
    if isinstance(scheduler, str):  # reached first: a wrong address fails before any file
        client = connect_scheduler(scheduler)
        try:
            return run_experiment(cfg, client, workers, db, progress, log)
        finally:
            client.close()
    try:
        db.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(
            f"{db}: cannot create its folder {db.parent} ({exc.strerror}); give another --db"
        ) from None
    with RunLock(db):
        root, index = load_dataset(cfg, workers=workers, log=log)
        tasks = enumerate_tasks(cfg, root, index)
        check_task_files(tasks + partner_tasks(tasks))
        fingerprint = dataset_fingerprint(root, index)
        try:
            with ResultStore(db) as store:
                store.check_fingerprint(cfg.fingerprint(), what="other DE settings or seeds")
                check_dataset_fingerprint(store, root, index, tasks, fingerprint, log)
                config = {"name": cfg.name, "dataset": str(root), "de": vars(cfg.de)}
                store.set_meta("config", config)
                return _run(cfg, store, tasks, scheduler, workers, progress, log, start)
        except sqlite3.DatabaseError as exc:
            raise database_error(db, exc) from None


#: ``meta`` keys of the dataset fingerprint and of what it covers (absent: the folders the
#: database's runs read, as databases written before whole-dataset fingerprints keep it).
DATASET_FINGERPRINT_KEY = "dataset_fingerprint"
DATASET_SCOPE_KEY = "dataset_fingerprint_scope"
WHOLE_DATASET = "every folder of dataset.json"


def check_dataset_fingerprint(store, root, index, tasks, fingerprint, log=print):
    """Record the dataset's fingerprint in the database, or check it against the stored one.

    The fingerprint covers the whole dataset (:func:`.dataset.dataset_fingerprint`), so that
    the experiments of a config may be added or dropped between runs on one database.
    Decision for the databases written before (their fingerprint covers only the folders the
    tasks of their config read, and they do not mark its scope): such a fingerprint is accepted
    when it equals the one of the folders the current tasks read, and is then replaced by the
    whole-dataset one (marked), so that the next run may change the experiments. A database of
    that kind resumed with other experiments than it was made with is refused, saying to resume
    it once with its own config first. Any other mismatch is another dataset: refused.

    Parameters
    ----------
    store : ResultStore
    root : Path
        The dataset folder.
    index : dict
        Its ``dataset.json``.
    tasks : list of Task
        The run's tasks.
    fingerprint : str
        ``dataset_fingerprint(root, index)``.
    log : callable

    Raises
    ------
    ValueError
        Naming the database and the dataset folder it was made from.
    """
    db = store.path
    stored = store.get_meta(DATASET_FINGERPRINT_KEY)
    whole = store.get_meta(DATASET_SCOPE_KEY) == WHOLE_DATASET
    if stored is None and store.count():
        log(f"{db}: made before dataset fingerprints; recording the fingerprint of {root}")
    elif stored not in (None, fingerprint) and not whole:
        if stored == dataset_fingerprint(root, index, tasks + partner_tasks(tasks)):
            log(f"{db}: recording the fingerprint of the whole dataset {root}")
            store.set_meta(DATASET_FINGERPRINT_KEY, fingerprint)
    previous = store.get_meta("config")
    made_from = previous.get("dataset", "?") if isinstance(previous, dict) else "?"
    fix = (
        f"{root} is not the dataset the database was made from ({made_from}; other seed, ids or "
        "files): give a new --db for this dataset, or point dataset.path to the database's "
        "dataset"
    )
    if not whole and stored is not None:
        fix += (
            " (a database made before whole-dataset fingerprints: if the dataset is the same, "
            "resume it once with the experiments it was made with, then change them)"
        )
    store.check_fingerprint(fingerprint, "another dataset", DATASET_FINGERPRINT_KEY, fix)
    if not whole:
        store.set_meta(DATASET_SCOPE_KEY, WHOLE_DATASET)


def _run(cfg, store, tasks, scheduler, workers, progress, log, start):
    """The run itself, once every check has passed (see :func:`run_experiment`)."""
    db = store.path
    done = store.done_keys()
    todo = [t for t in tasks if t.key not in done]
    already = len(tasks) - len(todo)
    workers = max(1, min(workers, len(todo)))
    where = (
        f"Dask at {scheduler.scheduler.address}"
        if scheduler is not None
        else f"{workers} local worker(s)"
    )
    log(f"{cfg.name}: {len(tasks)} SFOs, {already} already in {db}, {len(todo)} to run on {where}")
    results = (
        dask_results(todo, scheduler, run_task)
        if scheduler is not None
        else local_results(todo, workers, run_task)
    )
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(tasks), initial=already, unit="SFO", smoothing=0.05, desc=cfg.name)
    stored, errors = 0, []
    try:
        for task, outcome in results:
            if isinstance(outcome, BaseException):
                errors.append((task.key, f"{type(outcome).__name__}: {outcome}"))
                if len(errors) <= 5:
                    log(f"SFO {task.key} raised {type(outcome).__name__}: {outcome}")
            else:  # a joint task's rows end with the one of its key (joint_tasks)
                rows = outcome if isinstance(outcome, list) else [outcome]
                stored += [store.insert(row) for row in rows][-1]
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
        close = getattr(results, "close", None)
        if close is not None:
            close()
    summary = RunSummary(len(tasks), already, stored, errors, time.perf_counter() - start, db)
    log(
        f"{cfg.name}: stored {stored} SFOs in {summary.seconds:.1f} s; "
        f"{already + stored}/{len(tasks)} done"
        + (f"; {len(errors)} raised (rerun to retry)" if errors else "")
    )
    return summary
