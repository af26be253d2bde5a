"""SFO-like PnP+f problems from the project's generator (used by ``bench_posest.py --sfo``).

One problem is exactly what POSEST-SFO hands POSEST for a positive pair of Exp. C: the photo's
visible 2D landmarks moved by up to +-5 px per coordinate, and 3D points = the subject's cranial
landmarks pushed by the population *mean* depth along the subject's first perturbed axes set
(``axes_C1``: each true soft-tissue direction turned by up to 30 degrees). The truth is the photo
camera and the subject's true facial landmarks; an estimate is scored by BPE (mm) over every
facial landmark, visible or not, at its noise-free image point (docs/method/evaluation.md).

The seeds follow :func:`lilium.synthetic.dataset.generate_dataset` (one
:class:`numpy.random.SeedSequence` child per subject, split into subject / axes / photos; one
child per photo, split into camera / landmark noise), so ``sfo_problems(n, k, seed)`` are the
positive Exp. C pairs (axes set C1) of ``lilium synth --subjects n --photos k --seed seed``.
"""

from dataclasses import dataclass

import numpy as np

from lilium.evaluation.metrics import back_projection_error
from lilium.geometry import Camera
from lilium.inputs import Photo, Skull
from lilium.methods.pairs import correspondences
from lilium.methods.posest_sfo import mean_depth_landmarks
from lilium.synthetic import noise as _noise
from lilium.synthetic import photos as _photos
from lilium.synthetic.dataset import subject_ids
from lilium.synthetic.head import prepare_head
from lilium.synthetic.subjects import MANDIBLE_LANDMARKS, make_subject


@dataclass(frozen=True)
class SfoProblem:
    """One positive-pair POSEST-SFO problem and its ground truth.

    Attributes
    ----------
    photo_id : str
    view : {"frontal", "lateral"}
    image_size_wh : (int, int)
    uv_px : ndarray of shape (N, 2)
        Given (noisy) image points of the visible landmarks with a cranial counterpart.
    points_mm : ndarray of shape (N, 3)
        Cranial landmark + mean depth x perturbed axis (skull frame).
    facial_true_mm : ndarray of shape (L, 3)
        Every true facial landmark.
    uv_true_px : ndarray of shape (L, 2)
        Their noise-free image points.
    camera : Camera
        The true camera.
    """

    photo_id: str
    view: str
    image_size_wh: tuple
    uv_px: np.ndarray
    points_mm: np.ndarray
    facial_true_mm: np.ndarray
    uv_true_px: np.ndarray
    camera: Camera

    @property
    def principal_point_px(self):
        return self.camera.principal_point_px

    @property
    def spread_px(self):
        """RMS distance (px) of the given image points from their centroid."""
        d = self.uv_px - self.uv_px.mean(axis=0)
        return float(np.sqrt(np.mean(np.sum(d**2, axis=1))))

    def bpe_mm(self, camera):
        """BPE (mm) of an estimated camera; ``nan`` for None."""
        if camera is None:
            return np.nan
        return back_projection_error(self.facial_true_mm, self.uv_true_px, camera)


def sfo_problems(n_subjects, n_photos, seed=0, axes_set=1, mandible=True, views=None):
    """The positive Exp. C POSEST-SFO problems of a generated dataset, in memory.

    Parameters
    ----------
    n_subjects : int
    n_photos : int
        Frontal photos per subject; as many lateral (alternating left, right).
    seed : int
    axes_set : int
        Which of the five perturbed axes sets (1-based) the methods are given.
    mandible : bool
        False: every skull without its mandible (the problems of ``lilium synth
        --no-mandible-share 1``: the same photos, the :data:`MANDIBLE_LANDMARKS` absent from the
        skull, so they pair with nothing; POSEST never sees the mesh).
    views : collection of {"frontal", "lateral"}, optional
        Only these views (default both).

    Returns
    -------
    list of SfoProblem
    """
    problems = []
    ids = subject_ids(n_subjects)
    for sid, seq in zip(ids, np.random.SeedSequence(seed).spawn(n_subjects), strict=True):
        subject_seq, axes_seq, photos_seq = seq.spawn(3)
        subject = make_subject(sid, np.random.default_rng(subject_seq))
        sets = _noise.perturbed_axes_sets(subject.soft_tissue_axes, np.random.default_rng(axes_seq))
        cranial = dict(subject.cranial_landmarks)
        if not mandible:
            cranial = {k: v for k, v in cranial.items() if k not in MANDIBLE_LANDMARKS}
        skull = Skull(
            id=sid,
            vertices_mm=subject.skull_vertices_mm,
            faces=subject.skull_faces,
            landmarks_mm=cranial,
            axes=sets[axes_set - 1],
        )
        names = sorted(subject.facial_landmarks)
        facial_true = np.array([subject.facial_landmarks[n] for n in names])
        head = prepare_head(subject)
        kinds = _photos.photo_views(n_photos)
        for k, (view, pseq) in enumerate(zip(kinds, photos_seq.spawn(len(kinds)), strict=True)):
            if views is not None and ("frontal" if view == "frontal" else "lateral") not in views:
                continue
            camera_seq, noise_seq = pseq.spawn(2)
            photo = _photos.make_photo(head, view, np.random.default_rng(camera_seq))
            noisy = _noise.perturb_landmarks(photo.landmarks_uv, np.random.default_rng(noise_seq))
            given = Photo(
                id=f"{sid}_{k}",
                image_size_wh=photo.camera.image_size_wh,
                view=view,
                landmarks_uv={n: noisy[n] for n in photo.visible},
            )
            corr = correspondences(skull, given)
            problems.append(
                SfoProblem(
                    photo_id=given.id,
                    view="frontal" if view == "frontal" else "lateral",
                    image_size_wh=photo.camera.image_size_wh,
                    uv_px=corr.uv_px,
                    points_mm=mean_depth_landmarks(corr),
                    facial_true_mm=facial_true,
                    uv_true_px=np.array([photo.landmarks_uv[n] for n in names]),
                    camera=photo.camera.camera,
                )
            )
    return problems
