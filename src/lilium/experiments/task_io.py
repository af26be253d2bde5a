"""What an experiment's worker reads and stores for one task, single or joint: the skull, the
photo and the truth it reads (cached per worker process, so a worker that runs many SFOs on
one skull reads it once) and the columns of the database row it writes. Shared by
:mod:`lilium.experiments.runner` and :mod:`lilium.experiments.joint_tasks`."""

import functools
import json
import os

import numpy as np

#: Cached cases per worker process (skulls are a few MB each).
SKULL_CACHE = 48
PHOTO_CACHE = 256

#: Keys of the SFO result dictionary that are not stored (long, and not needed by the report).
_DROPPED_RESULT_KEYS = ("history", "genes")


@functools.lru_cache(maxsize=SKULL_CACHE)
def task_skull(subject_dir, axes_file):
    """A subject's skull with one axes file (``None``: its own axes), cached per process."""
    from ..casework.build import read_skull

    if axes_file is not None and not os.path.isfile(axes_file):
        # Checked before the run too; a file gone since is an error row, never a success with
        # the skull's default axes.
        raise ValueError(f"{axes_file}: perturbed soft-tissue axes not found")
    return read_skull(subject_dir, axes_path=axes_file)


_topologies = {}


def skull_topology(subject_dir, skull):
    """Edge topology of a subject's skull mesh (the same for every axis set)."""
    from ..imaging.raster import mesh_edge_topology

    if subject_dir not in _topologies:
        if len(_topologies) >= SKULL_CACHE:
            _topologies.pop(next(iter(_topologies)))
        _topologies[subject_dir] = mesh_edge_topology(skull.faces)
    return _topologies[subject_dir]


@functools.lru_cache(maxsize=SKULL_CACHE)
def facial_truth(subject_dir):
    """A subject's true 3D facial landmarks (the BPE's reference), cached per process."""
    from ..io.truth import read_facial_landmarks

    return read_facial_landmarks(subject_dir)


@functools.lru_cache(maxsize=PHOTO_CACHE)
def task_photo(photo_dir):
    """The photo and its :class:`~lilium.io.truth.GroundTruth` (without the 3D landmarks),
    cached per process."""
    from ..casework.build import read_photo
    from ..io.truth import read_ground_truth

    return read_photo(photo_dir, load_image=False), read_ground_truth(photo_dir)


def _finite(value):
    return float(value) if value is not None and np.isfinite(value) else None


def score_result(result, skull, photo, truth=None, topology=None):
    """Evaluation columns of one SFO (:func:`lilium.evaluation.score`).

    Parameters
    ----------
    result : SfoResult
    skull : Skull
    photo : Photo
    truth : GroundTruth, optional
        With the tested skull's 3D facial landmarks for a positive pair (BPE); None or without
        them for a negative pair.
    topology : EdgeTopology, optional
        Of the skull mesh (cached by the caller).

    Returns
    -------
    dict
        ``bpe_mm``, ``skull_px``, ``outside_px``, ``percent_outside`` (None where not defined).
    """
    from ..evaluation import score

    s = score(result, truth, skull, photo.face_mask, topology)
    imp = s.implausible
    return {
        "bpe_mm": _finite(s.bpe_mm),
        "skull_px": imp.skull_px if imp else None,
        "outside_px": imp.outside_px if imp else None,
        "percent_outside": imp.percent_outside if imp else None,
    }


def result_columns(single, score, run):
    """The stored columns of one photo's SFO result.

    Parameters
    ----------
    single : SfoResult
        The photo's result (terms, camera, ``result.json``).
    score : float or None
        Its ranking score (a joint SFO's: the joint fitness).
    run : SfoResult or JointSfoResult
        The run that produced it (its time, generations and error).
    """
    data = single.to_dict()
    for key in _DROPPED_RESULT_KEYS:
        data.pop(key, None)
    return dict(
        success=int(bool(single)),
        score=_finite(score),
        mse_pix=_finite(single.terms.get("mse_pix")),
        p_cam=_finite(single.terms.get("p_cam")),
        p_skof=_finite(single.terms.get("p_skof")),
        p_pll=_finite(single.terms.get("p_pll")),
        focal_px=_finite(single.camera.focal_px) if single else None,
        seconds=float(run.seconds),
        generations=run.extra.get("generations"),
        error=single.error or run.error or None,
        result=json.dumps(data),
    )


def clear_caches():
    """Forget every cached case of this process (a run in this process then reads its inputs
    afresh, as a new worker would)."""
    task_skull.cache_clear()
    task_photo.cache_clear()
    facial_truth.cache_clear()
    _topologies.clear()
