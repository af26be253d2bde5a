"""The identification terms and score of one SFO result, single or joint
(docs/method/identification.md).

:func:`identification_terms` turns a skull, the photo(s) and the camera(s) and soft tissue an
SFO found into the terms of :mod:`lilium.identification.terms`; :func:`nll_score` adds them up
unweighted (the score before calibration); the calibrated log10 LR is
:meth:`lilium.identification.calibration.Calibration.log10_lr`.
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..evaluation.metrics import face_mask_2d, implausible_sfo, outside_depth_px
from ..geometry.camera import Camera
from ..imaging.raster import mesh_mask
from ..methods.lilium_terms import PllTerm, TermOff
from ..methods.pairs import correspondences
from ..methods.prior_checks import scd_point_mm
from ..softtissue.depths import depth_stats
from ..softtissue.landmarks import CRANIAL_TO_FACIAL
from .cohort import centred_cohort_terms, cohort_terms, refit_views, skull_cohort_terms
from .terms import (
    REFERENCE_TERMS,
    TERM_NAMES,
    eye_corner_px,
    landmark_chi2,
    landmark_worst,
    make_view,
    prior_excess,
    soft_tissue_z2,
    worst_landmark,
)


def _soft_tissue_term(skull, facial_landmarks_mm, depth_table):
    names = [
        c
        for c, f in CRANIAL_TO_FACIAL.items()
        if c in skull.landmarks_mm and f in facial_landmarks_mm and c in skull.axes
    ]
    if not names:
        return None
    stats = [depth_stats(c, depth_table) for c in names]
    return soft_tissue_z2(
        np.array([facial_landmarks_mm[CRANIAL_TO_FACIAL[c]] for c in names], float),
        np.array([skull.landmarks_mm[c] for c in names], float),
        np.array([skull.axes[c] for c in names], float),
        np.array([s.mean_mm for s in stats]),
        np.array([s.sd_mm for s in stats]),
    )


def pll_face(skull, photo, camera, eye_px):
    """P_pll of one photo under one camera in face-size units (None when P_pll cannot apply)."""
    try:
        term = PllTerm(skull, photo, camera.principal_point_px)
    except TermOff:
        return None
    if not (np.isfinite(eye_px) and eye_px > 0):
        return None
    return float(term(camera.as_batch())[0]) / eye_px


def outside_fraction(skull, photo, camera):
    """The share of the skull's pixels outside the photo's head mask under one camera (None
    when the photo has no mask; :attr:`HeadOverlap.outside_fraction`)."""
    overlap = head_overlap(skull, photo, camera)
    return None if overlap is None else overlap.outside_fraction


#: "Skull outside the head" counts the skull's pixels more than this share of the eye-corner
#: distance (:data:`OUTSIDE_BAND_MIN_PX` at least) outside the head mask
#: (:func:`skull_beyond_head`): a pixel or two at the mask's edge is raster and mask noise, not
#: a skull that leaves the head. 1 % is about 0.9 mm at the face, a third of the thinnest soft
#: tissue at the head's outline. Measured on true pairs of the headsq CT
#: (docs/method/identification.md,
#: "Skull outside the head"): Lilium's skulls lie wholly inside the head; POSEST-SFO's failed
#: lateral cameras put 44-25,000 pixels beyond the band, 2-185 % of the eye-corner distance deep.
OUTSIDE_BAND_EYE = 0.01

#: The band's floor, pixels: the raster's and the mask edge's own noise.
OUTSIDE_BAND_MIN_PX = 2.0


@dataclass(frozen=True, eq=False)
class HeadOverlap:
    """The skull's raster under one camera against the photo's head mask: one raster for the
    term ``outside_fraction`` and the rule "skull outside the head" (:meth:`beyond`).

    Attributes
    ----------
    skull_mask : ndarray of shape (H, W), bool
        The projected skull (:func:`lilium.imaging.raster.mesh_mask`).
    face_mask : ndarray of shape (H, W), bool
        The photo's head mask.
    eye_px : float
        The eye-corner distance in pixels at the skull's landmarks (the face-size unit; NaN for
        a degenerate camera).
    """

    skull_mask: np.ndarray
    face_mask: np.ndarray
    eye_px: float

    @property
    def skull_px(self):
        """The skull's pixels."""
        return int(np.count_nonzero(self.skull_mask))

    @property
    def outside_fraction(self):
        """The share of the skull's pixels outside the mask (1 for a skull of no pixel;
        :func:`lilium.evaluation.metrics.implausible_sfo`'s counts)."""
        counts = implausible_sfo(self.skull_mask, self.face_mask)
        return counts.outside_px / counts.skull_px if counts.skull_px else 1.0

    @cached_property
    def depths_px(self):
        """Per skull pixel outside the mask, its distance (pixels) to the nearest mask pixel
        (:func:`lilium.evaluation.metrics.outside_depth_px`), shape (M,); computed once."""
        return outside_depth_px(self.skull_mask, self.face_mask)

    def beyond(self):
        """``(beyond_px, skull_px, band_px)``: the skull's pixels more than ``band_px``
        (:func:`outside_band_px`) outside the mask, of its ``skull_px``."""
        band = outside_band_px(self.eye_px)
        return int(np.count_nonzero(self.depths_px > band)), self.skull_px, band


def head_overlap(skull, photo, camera):
    """The :class:`HeadOverlap` of the skull under one camera (None when the photo has no
    mask)."""
    if photo.face_mask is None:
        return None
    face_mask = face_mask_2d(photo.face_mask) != 0
    height, width = face_mask.shape
    eye_px = eye_corner_px(camera, np.array(list(skull.landmarks_mm.values()), float))
    skull_mask = mesh_mask(skull.vertices_mm, skull.faces, camera, (width, height)) != 0
    return HeadOverlap(skull_mask, face_mask, float(eye_px))


def outside_depths(skull, photo, camera):
    """How far outside the head mask each of the skull's pixels outside it lies, under one
    camera (None when the photo has no mask).

    Returns
    -------
    depth_px : ndarray of shape (M,)
        Per skull pixel outside the mask, its distance (pixels) to the nearest mask pixel
        (:func:`lilium.evaluation.metrics.outside_depth_px`).
    skull_px : int
    eye_px : float
        The eye-corner distance in pixels (the face-size unit; NaN for a degenerate camera).
    """
    overlap = head_overlap(skull, photo, camera)
    if overlap is None:
        return None
    return overlap.depths_px, overlap.skull_px, overlap.eye_px


def skull_beyond_head(skull, photo, camera):
    """The skull's pixels beyond the head mask's edge band under one camera.

    Returns
    -------
    beyond_px : int
        Skull pixels more than ``band_px`` outside the mask.
    skull_px : int
    band_px : float
        ``max(OUTSIDE_BAND_MIN_PX, OUTSIDE_BAND_EYE * eye-corner distance in pixels)``.

    None when the photo has no mask.
    """
    overlap = head_overlap(skull, photo, camera)
    return None if overlap is None else overlap.beyond()


def outside_band_px(eye_px):
    """The head mask's edge band, pixels: ``max(OUTSIDE_BAND_MIN_PX, OUTSIDE_BAND_EYE *
    eye_px)``, the floor alone for a non-finite ``eye_px``."""
    if not np.isfinite(eye_px):
        return OUTSIDE_BAND_MIN_PX
    return float(max(OUTSIDE_BAND_MIN_PX, OUTSIDE_BAND_EYE * eye_px))


def refit_terms(skull, photos, views):
    """``landmark_refit`` and ``outside_refit``: the candidate's landmark term and outside
    fraction (mean over the photos with a mask) under cameras refitted to the landmarks alone
    (:func:`lilium.identification.cohort.refit_views`)."""
    refitted = refit_views(views)
    outside = [outside_fraction(skull, photo, view.camera)
               for photo, view in zip(photos, refitted, strict=True)]
    outside = [o for o in outside if o is not None]
    return float(landmark_chi2(refitted)[0]), (float(np.mean(outside)) if outside else None)


def terms_and_overlaps(
    skull, photos, cameras, facial_landmarks_mm, depth_table=None, image=None, cohort=None,
    cohort_cache=None,
):
    """The identification terms of one SFO result, and the skull's overlap with each photo's
    head mask they read (:func:`identification_terms` without the overlaps).

    Parameters
    ----------
    skull : Skull
    photos : sequence of Photo
        One photo (a single SFO) or several (a joint SFO, or separate SFOs of one person
        combined: their soft tissue is shared in the landmark term).
    cameras : sequence of Camera
        The SFO's camera for each photo.
    facial_landmarks_mm : dict of str -> array_like of shape (3,)
        The soft tissue the SFO found (facial points, skull frame); for separate SFOs any one
        of them, or None to leave ``soft_tissue_z2`` out.
    depth_table : dict, optional
    image : sequence of (float or None, float or None) or None, optional
        Per photo, ``(outside_fraction, pll_face)`` already known (e.g. from the photo's own
        SFO when several are combined); computed for a photo whose entry is None, or for every
        photo when not given.
    cohort : Cohort, optional
        Other people's skulls and faces (:mod:`lilium.identification.cohort`): without it
        the cohort terms (``cohort_mean``, ``cohort_sd``, ``skull_mean``, ``skull_sd``) are
        None.
    cohort_cache : dict, optional
        Cohort terms already computed, by the photos' landmarks (names and positions): the
        cohort terms describe the photos, so scoring many skulls against one photo computes
        them once (the first skull's camera starts the cohort's fits).

    Returns
    -------
    terms : dict
        ``{name: float or None}`` for every name of :data:`TERM_NAMES`, plus ``"nll"`` (the
        landmarks' negative log-likelihood in nats) and ``"landmarks"`` (pairs used).
    overlaps : list of HeadOverlap or None
        Per photo, the skull's raster under its camera against the head mask (None where the
        photo has no mask or its ``image`` terms were given): ``outside_fraction`` is read from
        it, and the rule "skull outside the head" (:meth:`HeadOverlap.beyond`) can read the
        same raster.
    """
    views = views_of(skull, photos, cameras, depth_table)
    outside, pll, excess, overlaps = [], [], [], []
    for k, (photo, camera, view) in enumerate(zip(photos, cameras, views, strict=True)):
        overlap = None
        if image is not None and image[k] is not None:
            o, p = image[k]
        else:
            overlap = head_overlap(skull, photo, camera)
            o = None if overlap is None else overlap.outside_fraction
            p = pll_face(skull, photo, camera, eye_corner_px(camera, view.cranial_mm))
        overlaps.append(overlap)
        outside.append(o)
        pll.append(p)
        point = scd_point_mm(facial_landmarks_mm) if facial_landmarks_mm else view.cranial_mm[0]
        excess.append(prior_excess(camera, photo.priors, point))
    chi2, nll = landmark_chi2(views)
    cohort_mean = cohort_sd = None
    if cohort is not None and np.isfinite(chi2):
        key = tuple((v.names, v.uv_px.tobytes()) for v in views)
        cache = {} if cohort_cache is None else cohort_cache
        if key not in cache:
            cache[key] = cohort_terms(views, cohort)
        cohort_mean, cohort_sd = cache[key]
    skull_mean = skull_sd = centred_mean = centred_sd = None
    if cohort is not None and np.isfinite(chi2):
        skull_mean, skull_sd = skull_cohort_terms(views, cohort)
        centred_mean, centred_sd = centred_cohort_terms(views, cohort)
    refit = outside_refit = None
    if np.isfinite(chi2):
        refit, outside_refit = refit_terms(skull, photos, views)
    st = _soft_tissue_term(skull, facial_landmarks_mm or {}, depth_table)

    def mean(values):
        values = [v for v in values if v is not None]
        return float(np.mean(values)) if values else None

    out = dict(
        landmark_chi2=chi2,
        soft_tissue_z2=st,
        outside_fraction=mean(outside),
        pll_face=mean(pll),
        prior_excess=(
            float(np.sum([e for e in excess if e is not None]))
            if any(e is not None for e in excess)
            else None
        ),
        cohort_mean=cohort_mean,
        cohort_sd=cohort_sd,
        skull_mean=skull_mean,
        skull_sd=skull_sd,
        landmark_refit=refit,
        outside_refit=outside_refit,
        landmark_worst=landmark_worst(views),
        centred_mean=centred_mean,
        centred_sd=centred_sd,
    )
    assert tuple(out) == TERM_NAMES
    out["nll"] = nll
    out["landmarks"] = int(sum(len(v.names) for v in views))
    return out, overlaps


def identification_terms(
    skull, photos, cameras, facial_landmarks_mm, depth_table=None, image=None, cohort=None,
    cohort_cache=None,
):
    """The identification terms of one SFO result: :func:`terms_and_overlaps`' ``terms``
    (same parameters)."""
    return terms_and_overlaps(
        skull, photos, cameras, facial_landmarks_mm, depth_table, image, cohort, cohort_cache
    )[0]


#: The terms added last, in the order they came: stored terms lacking only these are
#: completed (:func:`with_late_terms`), not computed again.
LATE_TERMS = ("skull_mean", "skull_sd", "landmark_refit", "outside_refit", "landmark_worst",
              "centred_mean", "centred_sd")


def with_late_terms(terms, skull, photos, cameras, depth_table=None, cohort=None):
    """Terms stored by an older version, completed: each of :data:`LATE_TERMS` they lack
    computed (``skull_mean`` and ``skull_sd`` by
    :func:`lilium.identification.cohort.skull_cohort_terms`, ``landmark_refit`` and
    ``outside_refit`` by :func:`refit_terms`, ``landmark_worst`` by
    :func:`lilium.identification.terms.landmark_worst`, ``centred_mean`` and ``centred_sd``
    by :func:`lilium.identification.cohort.centred_cohort_terms`), every other term kept as
    stored (arguments as in :func:`identification_terms`)."""
    out = dict(terms)
    missing = [n for n in LATE_TERMS if n not in terms]
    if not missing:
        return out
    for name in missing:
        out[name] = None
    if not np.isfinite(terms.get("landmark_chi2") or np.nan):
        return out
    views = views_of(skull, photos, cameras, depth_table)
    if cohort is not None and {"skull_mean", "skull_sd"} & set(missing):
        out["skull_mean"], out["skull_sd"] = skull_cohort_terms(views, cohort)
    if {"landmark_refit", "outside_refit"} & set(missing):
        out["landmark_refit"], out["outside_refit"] = refit_terms(skull, photos, views)
    if "landmark_worst" in missing:
        out["landmark_worst"] = landmark_worst(views)
    if cohort is not None and {"centred_mean", "centred_sd"} & set(missing):
        out["centred_mean"], out["centred_sd"] = centred_cohort_terms(views, cohort)
    return out


def views_of(skull, photos, cameras, depth_table=None):
    """The :class:`~lilium.identification.terms.View` of each photo under its camera."""
    return [
        make_view(camera, correspondences(skull, photo), photo.landmark_sources, depth_table)
        for photo, camera in zip(photos, cameras, strict=True)
    ]


def worst_landmark_of(skull, photos, cameras):
    """The photo landmark that fits worst under the cameras (its facial name, the photos'
    landmarks taken together as in ``landmark_worst``) and its misfit per coordinate; ``(None,
    inf)`` when a landmark lies behind a camera (:func:`lilium.identification.terms.
    worst_landmark`). A case names it: one misplaced landmark lowers the LR."""
    name, misfit = worst_landmark(views_of(skull, photos, cameras))
    return (None if name is None else CRANIAL_TO_FACIAL[name]), misfit


def nll_score(terms):
    """The unweighted identification score (lower = more likely the same person): the
    landmarks' chi^2 per coordinate plus the other terms of the skull as they are (a None
    counts 0; the reference terms are left out: they say how to read the others)."""
    return float(sum(terms[k] or 0.0 for k in TERM_NAMES if k not in REFERENCE_TERMS))


def cameras_of(result):
    """The cameras of a ``result.json`` dictionary, single or joint (None for a failed one)."""
    if result.get("joint"):
        return [Camera.from_dict(p["camera"]) if p.get("camera") else None
                for p in result["photos"]]
    return [Camera.from_dict(result["camera"]) if result.get("camera") else None]

