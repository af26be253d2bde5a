"""The dataset of an experiment: its index checked, its files checked, its fingerprint.

Three checks run before the first SFO, so that a run either starts on a sound dataset or does
not start at all:

- :func:`check_index`: ``dataset.json`` has the shape :mod:`lilium.synthetic.dataset` writes;
  ids are unique (a repeated id would make two SFOs share a database key, and one of them would
  be dropped), every photo's subject is among the subjects (a rank is the rank of the true
  skull), and every path is relative and stays inside the dataset folder (no absolute path, no
  ``..``; a symbolic link inside the folder is the dataset owner's choice and is followed).
- :func:`check_task_files`: every folder and file the tasks will read exists: the subject
  folders with a skull mesh, the perturbed axis sets ``axes_C<k>.json`` of Exp. C (without
  them an SFO would silently use the skull's default axes), the photo folders with their
  ``photo.json``.
- :func:`dataset_fingerprint`: a SHA-256 of ``dataset.json`` (without its ``seconds`` timing
  fields, so that regenerating the same dataset gives the same fingerprint) and of the content
  of every regular file in every subject and photo folder ``dataset.json`` lists (hard links
  hashed once), whatever the config selects: the experiments, methods or axis sets of a config
  may change between runs on one database, the dataset may not. The results database keeps it;
  resuming against a dataset with another fingerprint (the same ids from another seed, a file
  edited by hand) is refused. Databases written before whole-dataset fingerprints keep the
  fingerprint of the folders their tasks read (``tasks=``): the runner accepts that one too,
  once, and then records the whole-dataset one
  (:func:`lilium.experiments.runner.check_dataset_fingerprint`). Cost, measured on the layout of
  the paper's dataset (17 subjects x 60 photos x 3 experiments: 12,428 files, 205 MB on disk,
  images hard-linked across A/B/C as the generator makes them): 0.56 to 0.62 s with a warm file
  cache, against 23 s to enumerate its 2,548,980 tasks (docs/experiments.md).
"""

import hashlib
import json
import os
from pathlib import Path, PurePosixPath, PureWindowsPath

#: Views a photo entry may name (docs/contract.md).
VIEWS = ("frontal", "lateral_left", "lateral_right")

#: Skull mesh file names a subject folder must hold one of (``lilium.casework.build.read_skull``).
SKULL_MESHES = ("skull.ply", "skull.obj", "skull.stl")

#: Read size when hashing files.
_CHUNK = 1 << 20


def _entry(kind, k, entry):
    name = entry.get("id") if isinstance(entry, dict) else None
    return f"{kind}[{k}]" + (f" ({name})" if isinstance(name, str) else "")


def inside_path(value, where):
    """Check a path of ``dataset.json``: a relative path that stays inside its folder.

    Parameters
    ----------
    value : str
    where : str
        The file and entry, for the message.

    Returns
    -------
    str
        ``value`` unchanged.
    """
    if not isinstance(value, str) or not value.strip() or "\0" in value:
        raise ValueError(f"{where} must be a non-empty relative path, got {value!r}")
    posix, windows = PurePosixPath(value), PureWindowsPath(value)
    if posix.is_absolute() or windows.is_absolute() or windows.drive or value.startswith("\\"):
        raise ValueError(
            f"{where} = {value!r} is an absolute path; paths in dataset.json must be relative "
            "to the dataset folder"
        )
    if ".." in windows.parts:
        raise ValueError(
            f"{where} = {value!r} leaves the dataset folder ('..'); paths in dataset.json must "
            "stay inside the dataset folder"
        )
    return value


def _str(value, where):
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"{where} must be a non-empty string, got {value!r}")
    return value


def check_index(index, index_path="dataset.json"):
    """Check the structure of a dataset index (see the module docstring).

    Parameters
    ----------
    index : dict
        The parsed ``dataset.json``.
    index_path : str or Path
        Its path, for the messages.

    Raises
    ------
    ValueError
        Naming the file and the entry (``photos[3] (s02_f01).paths.B``) and the fix.
    """
    where = str(index_path)
    if not isinstance(index, dict):
        raise ValueError(f"{where}: not a dataset index (an object with subjects and photos)")
    for key in ("subjects", "photos"):
        if not isinstance(index.get(key), list) or not index[key]:
            raise ValueError(f"{where}: {key} must be a non-empty list")
    subject_ids = set()
    for k, subject in enumerate(index["subjects"]):
        name = f"{where}: {_entry('subjects', k, subject)}"
        if not isinstance(subject, dict):
            raise ValueError(f"{name} must be an object with id and path")
        sid = _str(subject.get("id"), f"{name}.id")
        if sid in subject_ids:
            raise ValueError(f"{name}.id {sid!r} is repeated; subject ids must be unique")
        subject_ids.add(sid)
        inside_path(subject.get("path"), f"{name}.path")
        axes = subject.get("axes_C", [])
        if not isinstance(axes, list):
            raise ValueError(f"{name}.axes_C must be a list of file names")
        for j, file_name in enumerate(axes):
            inside_path(file_name, f"{name}.axes_C[{j}]")
    photo_ids = set()
    for k, photo in enumerate(index["photos"]):
        name = f"{where}: {_entry('photos', k, photo)}"
        if not isinstance(photo, dict):
            raise ValueError(f"{name} must be an object with id, subject, view and paths")
        pid = _str(photo.get("id"), f"{name}.id")
        if pid in photo_ids:
            raise ValueError(f"{name}.id {pid!r} is repeated; photo ids must be unique")
        photo_ids.add(pid)
        subject = photo.get("subject")
        if subject not in subject_ids:
            raise ValueError(
                f"{name}.subject {subject!r} is not among the subjects; every photo's own skull "
                "must be in the dataset (its rank is the rank of the true skull)"
            )
        if photo.get("view") not in VIEWS:
            raise ValueError(f"{name}.view must be one of {', '.join(VIEWS)}")
        paths = photo.get("paths")
        if not isinstance(paths, dict) or not paths:
            raise ValueError(f"{name}.paths must be an object {{experiment: folder}}")
        for exp, folder in paths.items():
            inside_path(folder, f"{name}.paths.{exp}")


def check_task_files(tasks):
    """Check that every folder and file the tasks read exists, before the first SFO.

    Parameters
    ----------
    tasks : list of Task

    Raises
    ------
    ValueError
        Naming the first missing file, what needs it and how many are missing in all.
    """
    missing = {}

    def need(path, what, fix, test=os.path.isfile):
        if path not in missing and not test(path):
            missing[path] = (what, fix)

    seen = set()
    for task in tasks:
        case = (task.subject_dir, task.photo_dir, task.axes_file)
        if case in seen:
            continue
        seen.add(case)
        need(task.subject_dir, "subject folder", "regenerate the dataset", os.path.isdir)
        if task.subject_dir not in missing and not any(
            os.path.isfile(os.path.join(task.subject_dir, m)) for m in SKULL_MESHES
        ):
            missing[os.path.join(task.subject_dir, SKULL_MESHES[0])] = (
                "skull mesh",
                "put the skull mesh there or regenerate the dataset",
            )
        if task.axes_file is not None:
            need(
                task.axes_file,
                f"perturbed soft-tissue axes (Exp. C, axis set {task.axes_set})",
                "regenerate the dataset with experiment C, or lower axes_sets",
            )
        need(
            task.photo_dir,
            f"photo folder (Exp. {task.experiment})",
            "regenerate the dataset",
            os.path.isdir,
        )
        if task.photo_dir not in missing:
            need(os.path.join(task.photo_dir, "photo.json"), "photo.json", "regenerate the dataset")
    if missing:
        path, (what, fix) = next(iter(missing.items()))
        more = f" ({len(missing) - 1} more files missing)" if len(missing) > 1 else ""
        raise ValueError(f"{path}: {what} not found{more}; {fix}; no SFO was run")


def _canonical_index(index):
    """``dataset.json`` without its timing fields (``seconds``), as canonical JSON bytes."""
    index = {k: v for k, v in index.items() if k != "seconds"}
    index["subjects"] = [
        {k: v for k, v in s.items() if k != "seconds"} if isinstance(s, dict) else s
        for s in index.get("subjects", [])
    ]
    return json.dumps(index, sort_keys=True, separators=(",", ":")).encode()


def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def dataset_folders(root, index):
    """Every subject and photo folder ``dataset.json`` lists, as absolute paths (sorted).

    Parameters
    ----------
    root : Path
        The dataset folder.
    index : dict
        Its checked ``dataset.json`` (:func:`check_index`).

    Returns
    -------
    list of str
    """
    root = Path(root)
    folders = {str(root / s["path"]) for s in index["subjects"]}
    folders |= {str(root / path) for p in index["photos"] for path in p["paths"].values()}
    return sorted(folders)


def dataset_fingerprint(root, index, tasks=None):
    """SHA-256 (hex, 16 digits) of a dataset (see the module docstring).

    Parameters
    ----------
    root : Path
        The dataset folder.
    index : dict
        Its ``dataset.json``.
    tasks : list of Task, optional
        Hash only the folders these tasks read: the fingerprint that databases written before
        whole-dataset fingerprints keep (it changed with the config's experiments). Default:
        every folder of :func:`dataset_folders`; a listed folder that does not exist (one a
        config does not use, deleted to save space) is hashed as missing.

    Returns
    -------
    str
        Independent of where the dataset folder lies (paths are hashed relative to it).
    """
    root = Path(root)
    if tasks is None:
        folders = dataset_folders(root, index)
    else:
        folders = sorted({t.subject_dir for t in tasks} | {t.photo_dir for t in tasks})
    h = hashlib.sha256(_canonical_index(index))
    by_inode = {}
    for folder in folders:
        if tasks is None and not os.path.isdir(folder):
            h.update(f"\n{Path(folder).relative_to(root).as_posix()}\0missing".encode())
            continue
        with os.scandir(folder) as entries:
            files = sorted(
                (e for e in entries if not e.name.startswith(".") and e.is_file()),
                key=lambda e: e.name,
            )
        for entry in files:
            st = entry.stat()
            inode = (st.st_dev, st.st_ino)
            if inode not in by_inode:
                by_inode[inode] = _file_digest(entry.path)
            rel = Path(entry.path).relative_to(root).as_posix()
            h.update(f"\n{rel}\0{by_inode[inode]}".encode())
    return h.hexdigest()[:16]
