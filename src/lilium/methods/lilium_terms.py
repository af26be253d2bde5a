"""Lilium's image penalties for a population of cameras: P_skof and P_pll.

Glue between an SFO case (skull, photo) and the pure fitness functions of :mod:`lilium.fitness`:
each term is prepared once per SFO (regions, facial curve, mask index, mesh topology) and then
evaluated for a whole population of cameras ``(R (S, 3, 3), t (S, 3), focal_px (S,))``.

P_skof counts the outside pixels of the full-resolution skull, exactly: the compiled count
(:func:`lilium.fitness.skof.skull_outside_pixels_cameras`) projects and rasterises only the
clusters of faces that can reach a non-face pixel under each camera.
"""

import numpy as np

from ..fitness.curves import face_curve_from_mask
from ..fitness.pll import PllContext
from ..fitness.regions import anatomical_frame, chin_jaw_region, forehead_region
from ..fitness.skof import prepare_skof, skof_penalty, skull_outside_pixels_cameras

#: Cranial landmarks the P_pll region needs, per view kind.
PLL_LANDMARKS = {
    "frontal": ("infradentale", "mental_foramen_l", "mental_foramen_r"),
    "lateral": ("glabella", "metopion"),
}


def _pll_landmarks_missing(skull, view):
    need = PLL_LANDMARKS["frontal" if view == "frontal" else "lateral"]
    return [n for n in need if n not in skull.landmarks_mm]


def missing_inputs(skull, photo, variant):
    """What a Lilium variant needs and this skull and photo lack.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    variant : str
        A key of :data:`lilium.methods.lilium.VARIANTS`.

    Returns
    -------
    list of str
        Plain-words descriptions (empty when the variant can run).
    """
    from .lilium import VARIANTS  # the one table (that module imports this one)

    use_skof, use_pll = VARIANTS[variant]
    missing = []
    if use_skof and photo.face_mask is None:
        missing.append("a face mask (face_mask.png in a photo folder, --mask or <stem>_mask.png)")
    if use_pll:
        if photo.face_curve_uv is None and photo.face_mask is None:
            missing.append(
                "a face curve or a face mask (face_curve.json / --face-curve / "
                "<stem>_face_curve.json, or a mask to derive it from)"
            )
        lm = _pll_landmarks_missing(skull, photo.view)
        if lm:
            missing.append(f"the cranial landmarks {', '.join(lm)}")
    return missing


def runnable_variants(skull, photo):
    """The Lilium variants this skull and photo have every input for, in table order."""
    from .lilium import VARIANTS

    return tuple(v for v in VARIANTS if not missing_inputs(skull, photo, v))


def _missing_message(skull, photo, what, missing, exclude):
    others = [v for v in runnable_variants(skull, photo) if v not in exclude]
    suggest = (
        f"or run --variant {' or --variant '.join(others)}, which these inputs allow"
        if others
        else "no Lilium variant runs without them (POSEST-SFO does: --method posest-sfo)"
    )
    return (
        f"skull {skull.id!r}, photo {photo.id!r}: {what} {'; and '.join(missing)}; add what "
        f"is missing, {suggest}"
    )


def check_variant_inputs(skull, photo, variant):
    """Raise a ``ValueError`` when ``variant`` lacks an input, suggesting variants that run.

    The suggestion is checked against what is there (mask, curve, mandible or forehead
    landmarks), so it never proposes a variant that would fail in turn.
    """
    missing = missing_inputs(skull, photo, variant)
    if missing:
        what = f"Lilium variant {variant!r} needs"
        raise ValueError(_missing_message(skull, photo, what, missing, (variant,)))


def _check_term_inputs(skull, photo, term):
    """As :func:`check_variant_inputs` for every variant using ``term`` (``skof``/``pll``)."""
    from .lilium import VARIANTS

    missing = missing_inputs(skull, photo, term)
    if missing:
        index = ("skof", "pll").index(term)
        using = [v for v, terms in VARIANTS.items() if terms[index]]
        what = f"the {term} variants ({', '.join(using)}) need"
        raise ValueError(_missing_message(skull, photo, what, missing, using))


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
        _check_term_inputs(skull, photo, "skof")
        self.context = prepare_skof(skull.faces, photo.face_mask, skull.vertices_mm)
        self.centre = centre

    def outside_pixels(self, cameras):
        """Skull pixels outside the face mask under ``cameras`` (:class:`Cameras`), ``(S,)`` int."""
        return skull_outside_pixels_cameras(
            self.context, cameras.R, cameras.t, cameras.focal_px, self.centre
        )

    def __call__(self, cameras):
        return skof_penalty(self.outside_pixels(cameras)).astype(float)


class PllTerm:
    """P_pll between the skull's and the face's chin-jaw (frontal) or forehead (lateral) curves.

    The skull region is cut once per SFO (:mod:`lilium.fitness.regions`); the facial curve is the
    photo's ``face_curve.json`` or, when absent, derived from the face mask and landmarks.

    Raises
    ------
    ValueError
        A landmark the region or the facial curve needs is missing, or neither a face curve
        nor a mask is given.
    """

    def __init__(self, skull, photo, centre):
        view = photo.view
        lm = skull.landmarks_mm
        _check_term_inputs(skull, photo, "pll")
        frame = anatomical_frame(lm)
        if view == "frontal":
            region = chin_jaw_region(skull.vertices_mm, skull.faces, lm, frame)
        else:
            region = forehead_region(skull.vertices_mm, skull.faces, lm, frame)
        if photo.face_curve_uv is not None:
            face_curve = photo.face_curve_uv
        else:  # check_variant_inputs: a mask is there
            face_curve = face_curve_from_mask(photo.face_mask, view, photo.landmarks_uv)
        if len(face_curve) < 2:
            raise ValueError(
                f"photo {photo.id!r}: the facial {'chin-jaw' if view == 'frontal' else 'forehead'}"
                " curve is empty; check face_mask.png and the landmarks, or give face_curve.json"
            )
        self.region_vertices_mm = skull.vertices_mm[region.vertex_index]
        self.context = PllContext.build(
            region.faces, face_curve, view, image_shape=photo.image_size_wh[::-1]
        )
        self.span_mm = None if view == "frontal" else np.array([lm["glabella"], lm["metopion"]])
        self.centre = centre

    def __call__(self, cameras):
        """P_pll under ``cameras`` (:class:`Cameras`), ``(S,)``."""
        uv = cameras.project(self.region_vertices_mm)
        span_v = None if self.span_mm is None else cameras.project(self.span_mm)[..., 1]
        return self.context.evaluate_batch(uv, span_v)

    def curves(self, camera):
        """Skull and face curves ``(K, 2)``, ``(M, 2)`` under one :class:`Camera` (overlays)."""
        uv = camera.project(self.region_vertices_mm)
        span_v = None if self.span_mm is None else camera.project(self.span_mm)[:, 1]
        return self.context.skull_curve(uv, span_v), self.context.face_curve
