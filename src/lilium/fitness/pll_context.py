"""P_pll's fixed part for one SFO: the region's topology and the refined, indexed facial curve
(:class:`PllContext`), and its evaluation for a population of projections
(:mod:`lilium.fitness.pll` computes the terms).
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..imaging.raster import mesh_edge_topology
from ._curve_kernels import VIEW_CODES, edge_face_table
from ._pll_kernels import SIDE_CODES, population_kernel
from .curves import MAX_WINDOW_PX, check_view, detect_curves_batch, refine_curve
from .pll import PLL_NO_CURVE, FaceCurveIndex, PllTerms, _failed, face_curve_index, pll_terms_batch


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

    def terms_cameras(self, vertices_mm, cameras, span_mm=None):
        """:meth:`terms_batch` of the region's vertices projected by a population's cameras.

        Compiled, the projection, the curves and the terms run in one call
        (:func:`~lilium.fitness._pll_kernels.population_kernel`, the same kernels in the same
        order as :meth:`terms_batch`: the same numbers, without the glue between them).

        Parameters
        ----------
        vertices_mm : ndarray of shape (K, 3)
            The region's vertices (skull frame), indexed by :attr:`faces`.
        cameras : lilium.geometry.camera.Cameras
            ``S`` cameras.
        span_mm : ndarray of shape (2, 3), optional
            Forehead only: the cranial glabella and metopion.
        """
        S = len(cameras)
        if not (jit.compiled() and S and self.topology.n_faces and len(self.face_curve)):
            uv = cameras.project(vertices_mm)
            span_v = None if span_mm is None else cameras.project(span_mm)[..., 1]
            return self.terms_batch(uv, span_v)
        index = self.face_index
        if index is None:
            index = face_curve_index(self.face_curve)
        edge_face, edge_dir = (
            edge_face_table(self.topology) if self.edge_faces is None else self.edge_faces
        )
        height, width = (-1, -1) if self.image_shape is None else self.image_shape
        c = np.asarray(cameras.principal_point_px, dtype=float)
        has_ends = index.ends is not None
        return PllTerms(
            *population_kernel(
                np.ascontiguousarray(vertices_mm, dtype=float),
                np.zeros((2, 3)) if span_mm is None else np.ascontiguousarray(span_mm, dtype=float),
                span_mm is not None,
                np.ascontiguousarray(cameras.R, dtype=float),
                np.ascontiguousarray(cameras.t, dtype=float),
                np.ascontiguousarray(cameras.focal_px, dtype=float),
                float(c[0]),
                float(c[1]),
                int(height),
                int(width),
                MAX_WINDOW_PX,
                self.topology.corners,
                edge_face,
                edge_dir,
                self.topology.edges_a,
                self.topology.edges_b,
                VIEW_CODES[self.view],
                np.ascontiguousarray(index.curve, dtype=float),
                np.array(index.ends, float) if has_ends else np.zeros((4, 2)),
                has_ends,
                np.ascontiguousarray(index.table, np.int64),
                int(index.origin[0]),
                int(index.origin[1]),
                SIDE_CODES[self.view],
                PLL_NO_CURVE,
            )
        )

    def evaluate_batch(self, region_uv, span_v=None):
        """Totals ``(S,)`` for a population: ``region_uv`` (S, K, 2), ``span_v`` (S, 2) or None."""
        return self.terms_batch(region_uv, span_v).total

    def evaluate(self, region_uv, span_v=None):
        """Scalar :class:`PllTerms` of one projection ``(K, 2)`` (``span_v``: (2,) or None)."""
        region_uv = np.asarray(region_uv, dtype=float)[None]
        span_v = None if span_v is None else np.asarray(span_v, dtype=float).reshape(1, 2)
        return self.terms_batch(region_uv, span_v).member(0)
