"""Moved to :mod:`lilium.imaging.raster` (the pixels layer); this module keeps old imports
(``from lilium.fitness.raster import mesh_edge_topology``) working. Import from there."""

from ..imaging.raster import (  # noqa: F401
    Crossings,
    EdgeTopology,
    check_faces,
    check_topology,
    contour_edges,
    face_orientations,
    mesh_edge_topology,
    mesh_mask,
    rasterise_union,
    scan_crossings,
    skull_raster,
    winding_intervals,
)
