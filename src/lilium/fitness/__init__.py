"""Fitness terms of SPEC section 5, as pure functions over arrays (no file I/O).

- :mod:`lilium.fitness.camera_penalty`  P_cam over a population (focal, SCD, head prior)
- :mod:`lilium.fitness.skof`            P_skof = 100 |S \\ F| (S from :mod:`lilium.imaging.raster`)
- :mod:`lilium.fitness.regions`         forehead / chin-jaw mesh regions, Frankfurt frame
- :mod:`lilium.fitness.curves`          contour detection and refinement
- :mod:`lilium.fitness.pll`             P_pll = Delta_d + P_conv + P_int
"""

from ..imaging.raster import EdgeTopology, mesh_edge_topology
from .camera_penalty import (
    CameraPriors,
    camera_penalty,
    camera_penalty_from_priors,
    head_deviation_deg,
)
from .curves import (
    detect_curve,
    face_curve_from_mask,
    join_fragments,
    order_points,
    refine_curve,
)
from .pll import (
    PllContext,
    PllTerms,
    convergence_penalty,
    intersection_count,
    pair_curves,
    pll_penalty,
    pll_terms,
    trim_curves,
)
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
    "EdgeTopology",
    "FaceMaskIndex",
    "PllContext",
    "PllTerms",
    "Region",
    "SkofContext",
    "anatomical_frame",
    "camera_penalty",
    "camera_penalty_from_priors",
    "chin_jaw_region",
    "convergence_penalty",
    "detect_curve",
    "face_chin_jaw_region",
    "face_curve_from_mask",
    "face_mask_index",
    "forehead_region",
    "head_deviation_deg",
    "intersection_count",
    "join_fragments",
    "mesh_edge_topology",
    "order_points",
    "pair_curves",
    "pll_penalty",
    "pll_terms",
    "prepare_skof",
    "refine_curve",
    "skof_penalty",
    "skull_outside_pixels",
    "skull_outside_pixels_batch",
    "skull_raster",
    "submesh",
    "trim_curves",
]
