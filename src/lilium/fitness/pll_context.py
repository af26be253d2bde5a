"""P_pll's fixed part for one SFO: the region's topology and the refined, indexed facial curve
(:class:`PllContext`), and its evaluation for a population of projections
(:mod:`lilium.fitness.pll` computes the terms).
"""

from dataclasses import dataclass

import numpy as np

from ..imaging.raster import mesh_edge_topology
from ._curve_kernels import edge_face_table
from .curves import check_view, detect_curves_batch, refine_curve
from .pll import FaceCurveIndex, _failed, face_curve_index, pll_terms_batch


@dataclass(frozen=True)
class PllContext:
    """What P_pll needs that is fixed during one SFO: the region and the facial curve.

    Attributes
    ----------
    faces : ndarray of shape (G, 3)
        The region's faces, indexing the region's own vertices.
    topology : EdgeTopology
    face_curve : ndarray of shape (M, 2)
    view : str
    image_shape : (int, int) or None
    face_index : FaceCurveIndex or None
        Built from ``face_curve`` when None.
    edge_faces : tuple or None
        The faces of every edge of ``topology`` (``edge_face_table``, for the compiled curve
        detection); computed at each call when None.
    """

    faces: np.ndarray
    topology: object
    face_curve: np.ndarray
    view: str
    image_shape: tuple | None = None
    face_index: FaceCurveIndex | None = None
    edge_faces: tuple | None = None

    @classmethod
    def build(cls, region_faces, face_curve, view, image_shape=None, ordered=True, face_index=None):
        """From a region's faces ``(G, 3)`` and a facial curve ``(M, 2)`` (refined here).

        ``face_index``: the :class:`FaceCurveIndex` of an already refined facial curve, reused
        (``face_curve`` is then ignored: the index's own curve is the facial curve).
        """
        check_view(view)
        if face_index is None:
            face_index = face_curve_index(refine_curve(face_curve, view, ordered=ordered))
        topology = mesh_edge_topology(region_faces)
        return cls(
            np.asarray(region_faces),
            topology,
            face_index.curve,
            view,
            None if image_shape is None else tuple(image_shape),
            face_index,
            edge_face_table(topology),
        )

    def skull_curves(self, region_uv, span_v=None):
        """The skull curves (:class:`CurveBatch`) of ``region_uv`` (S, K, 2), ``span_v`` (S, 2)."""
        return detect_curves_batch(
            region_uv,
            self.view,
            topology=self.topology,
            span_v=span_v,
            image_shape=self.image_shape,
            edge_faces=self.edge_faces,
        )

    def skull_curve(self, region_uv, span_v=None):
        """The skull curve ``(N, 2)`` of one projection ``(K, 2)`` (``span_v``: (2,) or None)."""
        region_uv = np.asarray(region_uv, dtype=float)[None]
        span_v = None if span_v is None else np.asarray(span_v, dtype=float).reshape(1, 2)
        return self.skull_curves(region_uv, span_v).curve(0)

    def terms_batch(self, region_uv, span_v=None):
        """:class:`PllTerms` (fields of shape (S,)) of a population's projections.

        Parameters
        ----------
        region_uv : array_like of shape (S, K, 2)
            The region's projected vertices, one row per member.
        span_v : array_like of shape (S, 2), optional
            Forehead only: the v of the projected cranial glabella and metopion.
        """
        region_uv = np.asarray(region_uv, dtype=float)
        if region_uv.ndim != 3 or region_uv.shape[-1] != 2:
            raise ValueError(f"region_uv must have shape (S, K, 2), got {region_uv.shape}")
        if len(self.face_curve) == 0:
            return _failed(len(region_uv))
        index = (
            self.face_index if self.face_index is not None else face_curve_index(self.face_curve)
        )
        return pll_terms_batch(self.skull_curves(region_uv, span_v), index, self.view)

    def evaluate_batch(self, region_uv, span_v=None):
        """Totals ``(S,)`` for a population: ``region_uv`` (S, K, 2), ``span_v`` (S, 2) or None."""
        return self.terms_batch(region_uv, span_v).total

    def evaluate(self, region_uv, span_v=None):
        """Scalar :class:`PllTerms` of one projection ``(K, 2)`` (``span_v``: (2,) or None)."""
        region_uv = np.asarray(region_uv, dtype=float)[None]
        span_v = None if span_v is None else np.asarray(span_v, dtype=float).reshape(1, 2)
        return self.terms_batch(region_uv, span_v).member(0)
