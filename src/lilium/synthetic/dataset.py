"""Generate a synthetic evaluation dataset on disk (docs/method/evaluation.md and docs/contract.md).

Layout under ``out_dir``::

    dataset.json                      index (subjects, photos, ranges, noise, seed)
    subjects/<sid>/                   the subject folder (``subjects.write_subject``)
    subjects/<sid>/axes_C<k>.json     k = 1..5: perturbed soft-tissue axes of profile C,
                                      ``{"axes": {...}}`` like soft_tissue_axes.json
    photos/<exp>/<pid>/               exp in A, B, C; pid = <sid>_f<kk> (frontal) or <sid>_l<kk>
        image.png, face_mask.png      rendered once per pid (the mask as a 1-bit PNG); B/C hold
                                      hard links to A's files
                                      (copies where links are not possible)
        photo.json, face_curve.json

``dataset.json`` is removed first and written last: a folder without it is an unfinished
dataset (a run killed mid-way), which ``lilium experiment`` refuses (or generates again, with
``dataset.generate = true``), also when an older complete dataset lay there before. A write the
system refuses is an ``OSError`` naming the file (or the subject folder) it was writing.

Every subject ``k`` draws from its own child of ``np.random.SeedSequence(seed)``, so the output
does not depend on the number of worker processes or their scheduling. The photos of experiments
A, B and C share their camera and render; B and C share their noisy landmarks too (C differs from
B only in the soft-tissue axes given to the methods, listed in ``photo.json`` as
``"soft_tissue_axes_sets"``, file names relative to the *tested* skull's subject folder).

Incomplete cases (:mod:`lilium.synthetic.incomplete`; default none): ``no_mandible_share`` of
the subjects have a skull without the mandible (subject entry ``"mandible": false``), and
``drop_landmark_rate`` leaves visible landmarks of the photos unmarked (photo entry
``"unmarked_landmarks"``); ``dataset.json`` then records both under ``"incomplete"``. With the
defaults nothing changes, file for file.
"""

import os
import shutil
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from pathlib import Path

import cv2
import numpy as np

from ..io import jsonio
from ..io.locks import RunLock
from ..io.paths import naming_errors
from ..io.results import write_png
from ..softtissue.landmarks import CORRESPONDENCES
from ..workers import quiet_interrupts, starting_workers
from . import incomplete as _incomplete
from . import noise as _noise
from . import photos as _photos
from .head import prepare_head


def subject_ids(n_subjects):
    """``["s01", "s02", ...]`` (at least two digits)."""
    width = max(2, len(str(n_subjects)))
    return [f"s{k + 1:0{width}d}" for k in range(n_subjects)]


def photo_id(subject_id, view, k):
    """``<sid>_f<kk>`` for frontal photos, ``<sid>_l<kk>`` for lateral ones."""
    return f"{subject_id}_{'f' if view == 'frontal' else 'l'}{k:02d}"


def _link_or_copy(src, dst):
    dst = Path(dst)
    if dst.exists():
        dst.unlink()
    try:
        os.link(src, dst)
    except OSError:
        with naming_errors(dst):
            shutil.copyfile(src, dst)


def write_photo_folders(
    photos_root, pid, subject_id, photo, experiments, noisy_uv, axes_files, unmarked=()
):
    """Write one photo's folders, one per experiment; returns ``{exp: relative path}``.

    ``unmarked``: visible landmarks left out of ``photo.json`` (and the face curve with them
    when one bounds it, :func:`lilium.synthetic.incomplete.curve_kept`).
    """
    photos_root = Path(photos_root)
    first = None
    paths = {}
    curve = {k: np.asarray(v).tolist() for k, v in photo.face_curve.items()}
    if not _incomplete.curve_kept(photo.camera.view, unmarked):
        curve = {}
    for exp in experiments:
        folder = photos_root / exp / pid
        folder.mkdir(parents=True, exist_ok=True)
        if first is None:
            write_png(folder / "image.png", photo.image)
            write_png(
                folder / "face_mask.png", photo.face_mask.astype(np.uint8) * 255, bilevel=True
            )
            first = folder
        else:
            _link_or_copy(first / "image.png", folder / "image.png")
            _link_or_copy(first / "face_mask.png", folder / "face_mask.png")
        extra = {"soft_tissue_axes_sets": list(axes_files)} if exp == "C" else None
        record = _photos.photo_record(
            photo,
            subject_id,
            noise=exp,
            landmarks_uv=None if exp == "A" else noisy_uv,
            extra=extra,
            unmarked=unmarked,
        )
        jsonio.write_json(folder / "photo.json", record)
        if curve:
            jsonio.write_json(folder / "face_curve.json", curve)
        else:  # one left by an older dataset in this folder would be read as this photo's
            (folder / "face_curve.json").unlink(missing_ok=True)
        paths[exp] = f"photos/{exp}/{pid}"
    return paths


def _default_subject_api():
    # Imported lazily: the procedural generator is a separate module.
    from .subjects import make_subject, write_subject

    return make_subject, write_subject


def _generate_subject(task):
    """Worker: make, write and photograph one subject. Returns its index entries."""
    (out_dir, subject_id, seed_seq, n_photos, experiments, ranges, factory, writer) = task[:8]
    mandible, drop_rate = task[8:] if len(task) > 8 else (True, 0.0)
    cv2.setNumThreads(1)
    start = time.perf_counter()
    if factory is None or writer is None:
        default_factory, default_writer = _default_subject_api()
        factory = factory or default_factory
        writer = writer or default_writer
    out_dir = Path(out_dir)
    subject_seq, axes_seq, photos_seq = seed_seq.spawn(3)
    subject_rng = np.random.default_rng(subject_seq)
    if mandible:
        subject = factory(subject_id, subject_rng)
    else:  # the same person, the skull without its mandible
        subject = factory(subject_id, subject_rng, mandible=False)
    on_skull = getattr(subject, "cranial_landmarks", None)
    subject_dir = out_dir / "subjects" / subject_id
    with naming_errors(subject_dir):
        writer(subject_dir, subject)

    axes_files = []
    if "C" in experiments:
        axes = getattr(subject, "soft_tissue_axes", None) or {}
        sets = _noise.perturbed_axes_sets(axes, np.random.default_rng(axes_seq))
        for k, axes_set in enumerate(sets, start=1):
            name = f"axes_C{k}.json"
            if on_skull is not None:  # drawn for every axis, written for the skull's landmarks
                axes_set = {c: v for c, v in axes_set.items() if c in on_skull}
            jsonio.write_json(subject_dir / name, {"axes": axes_set})
            axes_files.append(name)

    head = prepare_head(subject)
    views = _photos.photo_views(n_photos)
    photo_seqs = photos_seq.spawn(len(views))
    counters = {"frontal": 0, "lateral": 0}
    entries = []
    pairable = {f for c, f in CORRESPONDENCES if on_skull is None or c in on_skull}
    for view, seq in zip(views, photo_seqs, strict=True):
        camera_seq, noise_seq = seq.spawn(2)
        key = "frontal" if view == "frontal" else "lateral"
        pid = photo_id(subject_id, view, counters[key])
        counters[key] += 1
        photo = _photos.make_photo(head, view, np.random.default_rng(camera_seq), ranges)
        noisy = _noise.perturb_landmarks(photo.landmarks_uv, np.random.default_rng(noise_seq))
        unmarked = ()
        if drop_rate > 0:  # a third stream of the photo: the first two are as without it
            unmarked = _incomplete.unmarked_landmarks(
                photo.visible, pairable, drop_rate, np.random.default_rng(seq.spawn(1)[0])
            )
        paths = write_photo_folders(
            out_dir / "photos", pid, subject_id, photo, experiments, noisy, axes_files, unmarked
        )
        entry = {
            "id": pid,
            "subject": subject_id,
            "view": view,
            "image_size": list(photo.camera.image_size_wh),
            "n_visible_landmarks": len(photo.visible),
            "paths": paths,
        }
        if unmarked:
            entry["unmarked_landmarks"] = list(unmarked)
        entries.append(entry)
    subject_entry = {
        "id": subject_id,
        "path": f"subjects/{subject_id}",
        "axes_C": axes_files,
        "seconds": time.perf_counter() - start,
    }
    if not mandible:
        subject_entry["mandible"] = False
    return subject_entry, entries


def _unindex(out_dir):
    """Remove ``out_dir/dataset.json`` before anything else is written.

    ``dataset.json`` is written last, so a folder without it is an unfinished dataset, which
    ``lilium experiment`` refuses (or generates again with ``dataset.generate = true``). Left in
    place while a new dataset is written over an older one, a run killed mid-way would leave
    the old index beside new files: a mixed dataset that looks complete.
    """
    (out_dir / "dataset.json").unlink(missing_ok=True)


def generate_dataset(
    out_dir,
    n_subjects,
    n_photos,
    seed=0,
    experiments=_noise.NOISE_PROFILES,
    progress=None,
    workers=2,
    ranges=_photos.CameraRanges(),
    subject_factory=None,
    subject_writer=None,
    no_mandible_share=0.0,
    drop_landmark_rate=0.0,
):
    """Generate subjects and their photos for the experiments A/B/C; write ``dataset.json``.

    Parameters
    ----------
    out_dir : path
    n_subjects : int
    n_photos : int
        Frontal photos per subject; as many lateral ones (split left/right).
    seed : int
    experiments : sequence of {"A", "B", "C"}
    progress : callable, optional
        ``progress(done_subjects, n_subjects)`` after each subject.
    workers : int
        Processes over subjects (1 = in this process). They are spawned, so a script that
        calls this with ``workers > 1`` needs the ``if __name__ == "__main__":`` guard.
    ranges : photos.CameraRanges
    subject_factory, subject_writer : callable, optional
        ``factory(subject_id, rng) -> subject`` and ``writer(folder, subject)``; default
        ``lilium.synthetic.subjects.make_subject`` / ``write_subject``. With ``workers > 1``
        they must be picklable (module-level functions). With ``no_mandible_share > 0`` the
        factory must take ``mandible=False``.
    no_mandible_share : float
        Share of the subjects whose skull has no mandible, in [0, 1] (default 0; see
        :mod:`lilium.synthetic.incomplete`).
    drop_landmark_rate : float
        Probability that a visible landmark of a photo is left unmarked, in [0, 1) (default 0).

    Returns
    -------
    dict
        The index written to ``out_dir/dataset.json``.

    Raises
    ------
    ValueError
        A bad count or option, or another generation running in ``out_dir``
        (:class:`~lilium.io.locks.RunLock`).
    """
    experiments = tuple(_noise.check_profile(e) for e in experiments)
    drop_rate = _incomplete.check_fraction(drop_landmark_rate, "drop_landmark_rate", closed=False)
    if not experiments:
        raise ValueError("experiments is empty; give at least one of A, B, C")
    if n_subjects < 1 or n_photos < 1:
        raise ValueError(f"need n_subjects >= 1 and n_photos >= 1, got {n_subjects}, {n_photos}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with RunLock(out_dir, "lilium run", "--out"):  # two generations would mix their files
        _unindex(out_dir)
        start = time.perf_counter()
        ids = subject_ids(n_subjects)
        seqs = np.random.SeedSequence(seed).spawn(n_subjects)
        no_mandible = _incomplete.mandible_less(ids, no_mandible_share, seed)
        tasks = [
            (str(out_dir), sid, seq, n_photos, experiments, ranges, subject_factory, subject_writer)
            + (sid not in no_mandible, drop_rate)
            for sid, seq in zip(ids, seqs, strict=True)
        ]
        results = {}
        if workers <= 1:
            for task in tasks:
                results[task[1]] = _generate_subject(task)
                if progress is not None:
                    progress(len(results), n_subjects)
        else:
            # Spawned, not forked, as the experiment runner's workers: a fork after a library
            # started threads (LiteRT's, once `lilium photo` ran in this process) deadlocked.
            with ProcessPoolExecutor(
                max_workers=workers, mp_context=get_context("spawn"), initializer=quiet_interrupts
            ) as pool:
                with starting_workers():  # a Ctrl-C ends the workers without tracebacks
                    futures = {pool.submit(_generate_subject, t): t[1] for t in tasks}
                for future in as_completed(futures):
                    results[futures[future]] = future.result()
                    if progress is not None:
                        progress(len(results), n_subjects)

        subjects, photos = [], []
        for sid in ids:
            subject_entry, entries = results[sid]
            subjects.append(subject_entry)
            photos.extend(entries)
        index = {
            "format": "lilium-synthetic-dataset",
            "version": 1,
            "seed": seed,
            "n_subjects": n_subjects,
            "n_photos_per_view": n_photos,
            "experiments": list(experiments),
            "camera_ranges": ranges.as_dict(),
            "min_visible_landmarks": _photos.MIN_VISIBLE_LANDMARKS,
            "priors": {
                "focal_fraction": _photos.PRIOR_FOCAL_FRACTION,
                "scd_fraction": _photos.PRIOR_SCD_FRACTION,
                "head_rotation": "true rotation",
                "head_tolerance_deg": _photos.PRIOR_HEAD_TOLERANCE_DEG,
            },
            "noise": {
                "landmark_px": _noise.LANDMARK_NOISE_PX,
                "axis_deg": _noise.AXIS_NOISE_DEG,
                "n_axes_sets": _noise.N_AXES_SETS,
            },
            "subjects": subjects,
            "photos": photos,
            "seconds": time.perf_counter() - start,
        }
        if no_mandible or drop_rate:  # only then: complete datasets stay as they were
            index["incomplete"] = {
                "no_mandible_share": float(no_mandible_share),
                "subjects_without_mandible": sorted(no_mandible),
                "drop_landmark_rate": drop_rate,
            }
        jsonio.write_json(out_dir / "dataset.json", index)
        return index
