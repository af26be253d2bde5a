"""Joint SFOs in the experiment protocol: each subject's frontal + lateral photo pair against
every skull (docs/method/joint.md), scored like the single-photo methods.

A joint method is named ``<method>-joint`` (``lilium-joint``) in a config's ``methods``
(``"lilium-joint:skof+pll"``). Its photos: each subject's frontal photos and lateral photos,
each in id order, paired by position (the k-th frontal with the k-th lateral; photos left
over run in no joint task). A joint task runs one joint SFO of the pair against one skull and
stores **one row per photo**, with that photo's id and view, so every table of ``lilium
report`` reads it like a single-photo method:

- ``score`` is the joint fitness (the ranking score, the same on both rows), so the frontal and
  the lateral rank of a pair are the pair's rank;
- ``bpe_mm``, ``mse_pix`` .. ``p_pll``, ``focal_px``, the skull pixels outside the face are the
  photo's own, under its camera;
- ``seconds`` is the joint SFO's time (both photos), ``result`` the photo's part of the joint
  result (with ``joint_photos`` and ``joint_fitness``).

The task's key is its frontal row's; the rows are stored lateral first, so a run killed between
the two writes reruns the task (``INSERT OR IGNORE`` keeps the row already there).
"""

import time
from dataclasses import replace
from pathlib import Path

from .task_io import (
    facial_truth,
    result_columns,
    score_result,
    skull_topology,
    task_photo,
    task_skull,
)

#: Joint methods of a config: name -> the registry method it runs jointly.
JOINT_METHODS = {"lilium-joint": "lilium"}


def photo_pairs(index):
    """``{frontal photo id: lateral photo entry}`` of each subject's photo pairs.

    Parameters
    ----------
    index : dict
        ``dataset.json``.

    Returns
    -------
    dict of str -> dict
    """
    by_subject = {}
    for photo in index["photos"]:
        group = "frontal" if photo["view"] == "frontal" else "lateral"
        by_subject.setdefault(photo["subject"], {"frontal": [], "lateral": []})[group].append(photo)
    pairs = {}
    for views in by_subject.values():
        frontal = sorted(views["frontal"], key=lambda p: p["id"])
        lateral = sorted(views["lateral"], key=lambda p: p["id"])
        for f, lat in zip(frontal, lateral, strict=False):
            pairs[f["id"]] = lat
    return pairs


def partner_tasks(tasks):
    """Each joint task's other photos as tasks of their own (for the file checks)."""
    return [
        replace(t, photo=pid, view=view, photo_dir=folder, joint_with=())
        for t in tasks
        for pid, view, folder in t.joint_with
    ]


def run_joint_task(task):
    """Run one joint task and score each photo; returns the rows (lateral first).

    An invalid case (a ``ValueError``) is an error row per photo.
    """
    import os
    import socket

    from ..methods import SfoOptions, run_joint_sfo
    from .calibrate import TERMS_KEY, with_terms
    from .store import KEY_COLUMNS

    start = time.perf_counter()
    members = [(task.photo, task.view, task.photo_dir), *task.joint_with]
    base = {c: getattr(task, c) for c in KEY_COLUMNS}
    common = dict(
        true_subject=task.true_subject,
        positive=int(task.subject == task.true_subject),
        worker=f"{socket.gethostname()}:{os.getpid()}",
    )
    rows = [base | common | {"photo": pid, "view": view} for pid, view, _ in members]
    try:
        skull = task_skull(task.subject_dir, task.axes_file)
        skull = replace(
            skull, landmarks_file=str(Path(task.subject_dir) / "cranial_landmarks.json")
        )
        cases = [task_photo(folder) for _, _, folder in members]
        photos = [
            replace(photo, landmarks_file=str(Path(folder) / "photo.json"))
            for (photo, _), (_, _, folder) in zip(cases, members, strict=True)
        ]
        options = SfoOptions(variant=task.variant or None, de=task.de)
        result = run_joint_sfo(JOINT_METHODS[task.method], skull, photos, options, task.seed)
    except ValueError as exc:
        for row in rows:
            row.update(success=0, error=str(exc), task_seconds=time.perf_counter() - start)
            row["finished_at"] = time.time()
        return rows[::-1]
    topology = skull_topology(task.subject_dir, skull)
    for row, single, photo, (_, truth) in zip(rows, result.photos, photos, cases, strict=True):
        if row["positive"]:
            truth = replace(truth, facial_landmarks_mm=facial_truth(task.subject_dir))
        row.update(score_result(single, skull, photo, truth, topology))
        row.update(result_columns(single, result.fitness if result else None, result))
        with_terms(row, skull, [photo], [single], result.facial_landmarks_mm, [row])
        row.update(task_seconds=time.perf_counter() - start, finished_at=time.time())
    # The joint decision's terms (both photos, one soft tissue), on the frontal row.
    with_terms(rows[0], skull, photos, list(result.photos), result.facial_landmarks_mm, rows,
               key=TERMS_KEY + "_joint")
    return rows[::-1]
