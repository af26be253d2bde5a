"""Fitness terms of docs/method/lilium.md, as pure functions over arrays (no file I/O).

- :mod:`lilium.fitness.camera_penalty`  P_cam over a population (focal, SCD, head prior)
- :mod:`lilium.fitness.skof`            P_skof = 100 |S \\ F| (S from :mod:`lilium.imaging.raster`)
- :mod:`lilium.fitness.regions`         forehead / chin-jaw mesh regions, Frankfurt frame
- :mod:`lilium.fitness.curves`          skull-curve detection (a population at once), facial curves
- :mod:`lilium.fitness.pll`             P_pll = Delta_d + P_conv + P_int (a population at once)
"""

from ..imaging.raster import EdgeTopology, mesh_edge_topology
from .camera_penalty import (
    CameraPriors,
    camera_penalty,
    camera_penalty_from_priors,
    head_deviation_deg,
)
from .curves import (
    CurveBatch,
    detect_curves_batch,
    face_curve_from_mask,
    join_fragments,
    join_fragments_batch,
    order_points,
    refine_curve,
)
from .pll import (
    FaceCurveIndex,
    PairBatch,
    PllTerms,
    convergence_penalties,
    face_curve_index,
    pair_curves_batch,
    pll_penalty,
    pll_terms_batch,
    terms_from_pairs,
    trim_curves_batch,
    wrong_side,
)
from .pll_context import PllContext
from .regions import (
    AnatomicalFrame,
    Region,
    anatomical_frame,
    chin_jaw_region,
    face_chin_jaw_region,
    forehead_region,
    submesh,
)
from .skof import (
    FaceMaskIndex,
    SkofContext,
    face_mask_index,
    prepare_skof,
    skof_penalty,
    skull_outside_pixels,
    skull_outside_pixels_batch,
    skull_raster,
)

__all__ = [
    "AnatomicalFrame",
    "CameraPriors",
    "CurveBatch",
    "EdgeTopology",
    "FaceCurveIndex",
    "FaceMaskIndex",
    "PairBatch",
    "PllContext",
    "PllTerms",
    "Region",
    "SkofContext",
    "anatomical_frame",
    "camera_penalty",
    "camera_penalty_from_priors",
    "chin_jaw_region",
    "convergence_penalties",
    "detect_curves_batch",
    "face_chin_jaw_region",
    "face_curve_from_mask",
    "face_curve_index",
    "face_mask_index",
    "forehead_region",
    "head_deviation_deg",
    "join_fragments",
    "join_fragments_batch",
    "mesh_edge_topology",
    "order_points",
    "pair_curves_batch",
    "pll_penalty",
    "pll_terms_batch",
    "prepare_skof",
    "refine_curve",
    "skof_penalty",
    "skull_outside_pixels",
    "skull_outside_pixels_batch",
    "skull_raster",
    "submesh",
    "terms_from_pairs",
    "trim_curves_batch",
    "wrong_side",
]
