"""Landmark catalogue, population depth table and soft-tissue cones."""

from .cones import ConeSet, decode, encode_depth_only, hybrid_genes, make_cones, midsagittal_plane
from .depths import BUILTIN_DEPTHS, DepthStats, check_depth_table, depth_stats
from .landmarks import (
    CORRESPONDENCES,
    CRANIAL_NAMES,
    CRANIAL_TO_FACIAL,
    EXTRA_CRANIAL,
    EXTRA_FACIAL,
    FACIAL_NAMES,
    FACIAL_TO_CRANIAL,
    bilateral_pairs,
    twin,
)
from .normals import landmark_normals, surface_normals_at

__all__ = [
    "BUILTIN_DEPTHS",
    "CORRESPONDENCES",
    "CRANIAL_NAMES",
    "CRANIAL_TO_FACIAL",
    "ConeSet",
    "DepthStats",
    "EXTRA_CRANIAL",
    "EXTRA_FACIAL",
    "FACIAL_NAMES",
    "FACIAL_TO_CRANIAL",
    "bilateral_pairs",
    "check_depth_table",
    "decode",
    "depth_stats",
    "encode_depth_only",
    "hybrid_genes",
    "landmark_normals",
    "make_cones",
    "midsagittal_plane",
    "surface_normals_at",
    "twin",
]
