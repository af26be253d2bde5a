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
        if photo.face_mask is None:
            raise ValueError(
                f"photo {photo.id!r} has no face_mask.png; the skof variants need the face mask "
                "(or use the base or pll variant)"
            )
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
        need = (
            ("infradentale", "mental_foramen_l", "mental_foramen_r")
            if view == "frontal"
            else ("glabella", "metopion")
        )
        missing = [n for n in need if n not in lm]
        if missing:
            raise ValueError(
                f"skull {skull.id!r}: the pll variants need the cranial landmarks "
                f"{', '.join(missing)} (in cranial_landmarks.json) to cut the "
                f"{'chin-jaw' if view == 'frontal' else 'forehead'} region"
            )
        frame = anatomical_frame(lm)
        if view == "frontal":
            region = chin_jaw_region(skull.vertices_mm, skull.faces, lm, frame)
        else:
            region = forehead_region(skull.vertices_mm, skull.faces, lm, frame)
        if photo.face_curve_uv is not None:
            face_curve = photo.face_curve_uv
        elif photo.face_mask is not None:
            face_curve = face_curve_from_mask(photo.face_mask, view, photo.landmarks_uv)
        else:
            raise ValueError(
                f"photo {photo.id!r} has neither face_curve.json nor face_mask.png; the pll "
                "variants need one of them"
            )
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
