"""Lilium's image penalties for a population of cameras: P_skof and P_pll.

Glue between an SFO case (skull, photo) and the pure fitness functions of :mod:`lilium.fitness`:
each term is prepared once per SFO (regions, facial curve, mask index, mesh topology) and then
evaluated for a whole population of cameras ``(R (S, 3, 3), t (S, 3), focal_px (S,))``.

P_skof counts the outside pixels of the full-resolution skull, exactly: the compiled count
(:func:`lilium.fitness.skof.skull_outside_pixels_cameras`) projects and rasterises only the
clusters of faces that can reach a non-face pixel under each camera.
"""

import numpy as np

from ..fitness.curves import face_curve_from_mask, missing_curve_bounds
from ..fitness.pll_context import PllContext
from ..fitness.regions import anatomical_frame, chin_jaw_region, forehead_region
from ..fitness.skof import prepare_skof, skof_penalty, skull_outside_pixels_cameras
from ..geometry.mesh import decimate
from ..softtissue.landmarks import MANDIBLE_LANDMARKS
from .working_level import WorkingPll, WorkingSkof


class SkofTerm:
    """P_skof = 100 x (projected skull pixels outside the face mask), for a population.

    Exact for the skull as given: every face of the full-resolution mesh counts (no
    decimation; earlier versions rasterised a 5,000-face copy, whose best cameras could leave
    pixels of the real skull outside the mask).

    Parameters
    ----------
    skull : Skull
    photo : Photo
        Must have a face mask.
    centre : ndarray of shape (2,)
        Principal point (pixels).
    """

    def __init__(self, skull, photo, centre):
        reason = skof_off_reason(photo)
        if reason:
            raise TermOff(reason)
        self.context = prepare_skof(skull.faces, photo.face_mask, skull.vertices_mm)
        self.centre = centre

    def outside_pixels(self, cameras):
        """Skull pixels outside the face mask under ``cameras`` (:class:`Cameras`), ``(S,)`` int."""
        return skull_outside_pixels_cameras(
            self.context, cameras.R, cameras.t, cameras.focal_px, self.centre
        )

    def __call__(self, cameras):
        return skof_penalty(self.outside_pixels(cameras)).astype(float)


class TermOff(ValueError):
    """A fitness term cannot apply to this skull and photo: its inputs are missing.

    Not an error of the SFO (docs/method/lilium.md, "When a term cannot apply"): :func:`image_terms`
    switches the term off and keeps the message as the reason (``SfoResult.terms_off``).
    """


#: Cranial landmarks that cut the skull's P_pll region: the chin-jaw (frontal views) and the
#: forehead (lateral views).
PLL_SKULL_LANDMARKS = {
    "frontal": ("infradentale", "mental_foramen_l", "mental_foramen_r"),
    "lateral": ("glabella", "metopion"),
}


def _region_name(view):
    return "chin-jaw" if view == "frontal" else "forehead"


def pll_skull_landmarks(view):
    """The cranial landmarks P_pll needs on the skull in ``view`` (:data:`PLL_SKULL_LANDMARKS`)."""
    return PLL_SKULL_LANDMARKS["frontal" if view == "frontal" else "lateral"]


def skof_off_reason(photo):
    """Why P_skof cannot apply to ``photo`` ("" when it can): it needs the face mask."""
    if photo.face_mask is None:
        return f"photo {photo.id!r} has no face mask (face_mask.png or --mask)"
    return ""


def pll_off_reason(skull, photo):
    """Why P_pll cannot apply ("" when the landmarks and curve inputs it needs are there).

    The cheap checks only (no mesh work): the cranial landmarks that cut the skull's region;
    a facial curve (``face_curve.json``, or the face mask with the landmarks that bound the
    curve on it). :class:`PllTerm` finds the rest (an empty region or curve).
    """
    view, region = photo.view, _region_name(photo.view)
    missing = [n for n in pll_skull_landmarks(view) if n not in skull.landmarks_mm]
    if missing:
        absent = ""
        if view == "frontal" and "infradentale" in missing:
            if not any(n in skull.landmarks_mm for n in MANDIBLE_LANDMARKS):
                absent = " (no mandible?)"
            elif "located" in skull.landmark_sources.values():  # lilium skull's, unreviewed
                absent = " (lilium skull's template points: used once confirmed in its review.html)"
        return (
            f"skull {skull.id!r} has no {', '.join(missing)}{absent} in its cranial landmarks, "
            f"which cut the {region} region"
        )
    if photo.face_curve_uv is not None:
        return ""
    if photo.face_mask is None:
        return (
            f"photo {photo.id!r} has neither face_curve.json nor a face mask for the {region} curve"
        )
    unmarked = missing_curve_bounds(view, photo.landmarks_uv)
    if unmarked:
        return (
            f"photo {photo.id!r} has no {', '.join(unmarked)} to bound the {region} curve on the "
            "face mask (mark it, or give face_curve.json)"
        )
    return ""


def _pll_inputs(skull, photo, cut=None):
    """P_pll's inputs for ``photo``, found once: the skull's region of its view, cut from the
    full mesh (``cut`` when given: a region already cut from this skull for another photo of
    the same view), and the photo's facial curve (``face_curve.json``, else from the face mask).

    Parameters
    ----------
    skull : Skull
    photo : Photo
    cut : (ndarray of shape (K, 3), ndarray of shape (G, 3)), optional
        A region cut already (millimetres, faces): only the facial curve is found.

    Returns
    -------
    cut : (ndarray of shape (K, 3), ndarray of shape (G, 3))
        The region's vertices (millimetres) and faces.
    face_curve : ndarray of shape (M, 2)
        The facial curve (pixels).

    Raises
    ------
    TermOff
        P_pll cannot apply (:func:`pll_off_reason`; the skull's landmarks cannot orient the
        head; the region holds no triangle; the facial curve is empty); the message says why.
    """
    view, region_name = photo.view, _region_name(photo.view)
    if cut is None:
        reason = pll_off_reason(skull, photo)
        if reason:
            raise TermOff(reason)
        lm = skull.landmarks_mm
        try:
            frame = anatomical_frame(lm)
        except ValueError as exc:
            raise TermOff(f"skull {skull.id!r}: {exc}") from None
        region_of = chin_jaw_region if view == "frontal" else forehead_region
        region = region_of(skull.vertices_mm, skull.faces, lm, frame)
        if len(region.faces) == 0:
            raise TermOff(
                f"skull {skull.id!r}: the {region_name} region between its landmarks holds no "
                "triangle of the mesh (check the landmarks against skull.ply)"
            )
        cut = skull.vertices_mm[region.vertex_index], region.faces
    face_curve = photo.face_curve_uv
    if face_curve is None:
        face_curve = face_curve_from_mask(photo.face_mask, view, photo.landmarks_uv)
    if len(face_curve) < 2:
        raise TermOff(
            f"photo {photo.id!r}: the facial {region_name} curve is empty (check "
            "face_mask.png and the landmarks, or give face_curve.json)"
        )
    return cut, face_curve


class PllTerm:
    """P_pll between the skull's and the face's chin-jaw (frontal) or forehead (lateral) curves.

    The skull region is cut once per SFO (:mod:`lilium.fitness.regions`); the facial curve is the
    photo's ``face_curve.json`` or, when absent, derived from the face mask and landmarks.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    centre : ndarray of shape (2,)
        Principal point (pixels).
    region_fraction : float
        Keep about this fraction of the region's faces (quadric decimation; the DE's working
        level, :mod:`lilium.methods.working_level`); 1 = the region as cut.
    reuse : PllTerm, optional
        A term built on the same skull (the DE's working term, for the result's full-level
        P_pll): its region cut is reused, and so is its facial curve when it was built for this
        very ``photo`` (the working level kept the photo's resolution).

    Raises
    ------
    TermOff
        P_pll cannot apply (:func:`pll_off_reason`; the skull's region or the facial curve is
        empty; the skull's landmarks cannot orient the head); the message says why.
    """

    def __init__(self, skull, photo, centre, region_fraction=1.0, reuse=None):
        view, lm = photo.view, skull.landmarks_mm
        if reuse is not None and reuse.photo is photo:  # the working term's curve and index
            self.cut, face_curve, face_index = reuse.cut, None, reuse.context.face_index
        else:
            self.cut, face_curve = _pll_inputs(skull, photo, None if reuse is None else reuse.cut)
            face_index = None
        vertices_mm, faces = self.cut
        if region_fraction < 1.0 and len(faces) * region_fraction >= 4:
            vertices_mm, faces = decimate(vertices_mm, faces, len(faces) * region_fraction)
        self.photo = photo
        self.region_vertices_mm = vertices_mm
        self.context = PllContext.build(
            faces, face_curve, view, image_shape=photo.image_size_wh[::-1], face_index=face_index
        )
        self.span_mm = None if view == "frontal" else np.array([lm["glabella"], lm["metopion"]])
        self.centre = centre

    def __call__(self, cameras):
        """P_pll under ``cameras`` (:class:`Cameras`), ``(S,)``."""
        return self.parts(cameras).total

    def parts(self, cameras):
        """:class:`~lilium.fitness.pll.PllTerms` (fields ``(S,)``) under ``cameras``."""
        return self.context.terms_cameras(self.region_vertices_mm, cameras, self.span_mm)

    def curves(self, camera):
        """Skull and face curves ``(K, 2)``, ``(M, 2)`` under one :class:`Camera` (overlays)."""
        uv = camera.project(self.region_vertices_mm)
        span_v = None if self.span_mm is None else camera.project(self.span_mm)[:, 1]
        return self.context.skull_curve(uv, span_v), self.context.face_curve


#: Labels of the P_cam parts a missing prior switches off (keys of ``terms_off``).
PRIOR_TERMS = {
    "p_cam_focal": "focal length",
    "p_cam_scd": "subject-to-camera distance",
    "p_cam_head": "head orientation",
}


def prior_terms_off(priors):
    """The P_cam parts without their prior: ``{key of PRIOR_TERMS: reason}``.

    Parameters
    ----------
    priors : lilium.fitness.camera_penalty.Priors
    """
    off = {}
    if priors.focal_px is None:
        off["p_cam_focal"] = "no focal prior (focal_px in photo.json, --focal-px or EXIF)"
    if priors.scd_mm is None:
        off["p_cam_scd"] = "no subject-to-camera distance prior (scd_mm in photo.json or --scd-mm)"
    if not priors.uses_head:
        off["p_cam_head"] = (
            "no head orientation prior (head_rotation_skull2cam and head_tolerance_deg in "
            "photo.json)"
        )
    return off


def image_terms(skull, photo, centre, use_skof, use_pll, level=None):
    """The image penalties an SFO asks for, each built or switched off.

    An asked-for term whose inputs are missing (:class:`TermOff`) is switched off, not an
    error (docs/method/lilium.md): the SFO runs with the other terms. With a working ``level``
    (:mod:`lilium.methods.working_level`) the terms are built on its skull and photo and take
    full-resolution cameras (their values in full-resolution units).

    Parameters
    ----------
    skull : Skull
    photo : Photo
    centre : ndarray of shape (2,)
        Principal point (pixels).
    use_skof, use_pll : bool
        Whether the variant asks for P_skof / P_pll.
    level : WorkingLevel, optional
        None or a full level: the terms at the photo's resolution on the full mesh.

    Returns
    -------
    skof : SkofTerm, WorkingSkof or None
    pll : PllTerm, WorkingPll or None
    terms_off : dict of str -> str
        ``{"p_skof": why, "p_pll": why}`` for the asked-for terms that cannot apply.
    """
    skof = pll = None
    off = {}
    working = level is not None and not level.is_full
    if use_skof:
        off["p_skof"] = skof_off_reason(photo)
        if not off["p_skof"] and working:
            skof = WorkingSkof(SkofTerm(level.skull, level.photo, level.centre(centre)), level)
        elif not off["p_skof"]:
            skof = SkofTerm(skull, photo, centre)
    if use_pll:
        try:
            if working:  # the region cut from the full mesh, then decimated
                term = PllTerm(skull, level.photo, level.centre(centre), level.pll_fraction)
                pll = WorkingPll(term, level)
            else:
                pll = PllTerm(skull, photo, centre)
        except TermOff as exc:
            off["p_pll"] = str(exc)
    return skof, pll, {k: v for k, v in off.items() if v}


def planned_terms_off(skull, photo, variant_terms):
    """What an SFO of ``photo`` will switch off, before it runs (the case's check).

    P_pll's region is cut and its facial curve found (what can switch it off), not the term
    built (its topology and curve index are the SFO's work); P_skof's mask is checked.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    variant_terms : (bool, bool)
        ``(use_skof, use_pll)`` of the variant.

    Returns
    -------
    dict of str -> str
        Term -> reason, the image terms first, then the P_cam parts (:func:`prior_terms_off`).
    """
    use_skof, use_pll = variant_terms
    priors_off = prior_terms_off(photo.priors)
    off = {}
    if use_skof and skof_off_reason(photo):
        off["p_skof"] = skof_off_reason(photo)
    if use_pll:
        try:
            _pll_inputs(skull, photo)
        except TermOff as exc:
            off["p_pll"] = str(exc)
    return {**off, **priors_off}


def full_image_terms(skull, photo, camera, use_skof, use_pll, working_pll=None):
    """P_skof and P_pll of one camera at the photo's resolution on the full mesh.

    What an SFO's result reports when its DE ran at a working level
    (:mod:`lilium.methods.working_level`): the exact terms of the best camera.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    camera : Camera
    use_skof, use_pll : bool
        Which terms to compute (those that ran in the DE).
    working_pll : PllTerm, optional
        The DE's working P_pll term: its region cut (and facial curve, at the same resolution)
        is reused.

    Returns
    -------
    terms : dict of str -> float
        ``p_skof`` and/or ``p_pll`` (those asked for).
    outside : ImplausibleSFO or None
        The skull pixels outside the face mask (:func:`lilium.evaluation.metrics.outside_face`),
        when P_skof was asked for.
    """
    from ..evaluation.metrics import outside_face

    terms, outside = {}, None
    if use_skof:
        outside = outside_face(camera, skull.vertices_mm, skull.faces, photo.face_mask)
        terms["p_skof"] = float(skof_penalty(outside.outside_px))
    if use_pll:
        pll = PllTerm(skull, photo, camera.principal_point_px, reuse=working_pll)
        terms["p_pll"] = float(pll(camera.as_batch())[0])
    return terms, outside
