"""Volume to triangle mesh: iso-surface, then the mesh operations of :mod:`lilium.geometry.mesh`.

The pipeline shared by the CT importer and the synthetic subject generator: marching cubes
(``skimage.measure.marching_cubes``) on a volume padded by one voxel of background so that a
structure touching the border still gives a closed surface, optionally keeping only the largest
connected component and decimating to a target number of faces (quadric decimation through the
optional ``fast-simplification`` package).
"""

import numpy as np

from ..geometry.mesh import compact, decimate, keep_largest_component
from .volume import Volume, check_spacing


def _parse_crop(crop, shape_zyx, source):
    """Slices ``(k, j, i)`` of a crop given as ``((i0, i1), (j0, j1), (k0, k1))``."""
    if crop is None:
        return (slice(None),) * 3
    try:
        bounds = np.asarray(crop, dtype=float).reshape(3, 2)
    except ValueError as exc:
        raise ValueError(
            f"{source}: crop must be ((i0, i1), (j0, j1), (k0, k1)) voxel index ranges "
            f"(column, row, slice), got {crop!r}"
        ) from exc
    slices = []
    for (lo, hi), n, axis in zip(bounds, shape_zyx[::-1], "ijk", strict=True):
        lo, hi = int(max(lo, 0)), int(min(hi, n))
        if hi - lo < 2:
            raise ValueError(
                f"{source}: crop range of index {axis} is empty or thinner than 2 voxels "
                f"(volume has {n} along it); widen the crop"
            )
        slices.append(slice(lo, hi))
    return tuple(slices[::-1])


def volume_to_mesh(
    volume,
    iso,
    spacing=None,
    largest_component=True,
    crop=None,
    target_faces=None,
    origin=None,
):
    """Iso-surface of a volume as a triangle mesh in mm.

    The inside of the surface is where the volume is *above* ``iso`` (bone and skin in CT);
    face normals (right-hand winding) point outwards.

    Parameters
    ----------
    volume : Volume or ndarray of shape (Z, Y, X)
        A :class:`~lilium.ct.volume.Volume`, or a bare array indexed ``[slice, row, column]``.
    iso : float
        Iso-value (same units as the volume).
    spacing : array_like of shape (3,), optional
        Voxel size (x, y, z order), mm; needed for a bare array (default 1 mm), ignored for a
        ``Volume``.
    largest_component : bool
        Keep only the connected component with the most faces.
    crop : ((i0, i1), (j0, j1), (k0, k1)), optional
        Voxel index ranges (column, row, slice; end exclusive) to keep before extraction.
    target_faces : int, optional
        Decimate to about this many faces (quadric decimation, ``fast-simplification``).
    origin : array_like of shape (3,), optional
        Position of voxel (0, 0, 0) for a bare array (default 0).

    Returns
    -------
    vertices_mm : ndarray of shape (V, 3)
        Volume-frame points (see :mod:`lilium.ct.volume`).
    faces : ndarray of shape (F, 3), int

    Raises
    ------
    ValueError
        If the iso-value is outside the range of the (cropped) volume, so no surface exists.
    """
    from skimage.measure import marching_cubes

    if not isinstance(volume, Volume):
        volume = Volume(
            np.asarray(volume),
            check_spacing((1.0, 1.0, 1.0) if spacing is None else spacing),
            np.zeros(3) if origin is None else origin,
            source="array",
        )
    data = volume.data[_parse_crop(crop, volume.data.shape, volume.source)]
    start = np.zeros(3)
    if crop is not None:
        sl = _parse_crop(crop, volume.data.shape, volume.source)
        start = np.array([s.start or 0 for s in sl[::-1]], dtype=float)
    data = np.asarray(data, dtype=np.float32)
    lo, hi = float(np.nanmin(data)), float(np.nanmax(data))
    if not lo < iso < hi:
        raise ValueError(
            f"{volume.source}: iso-value {iso:g} is outside the volume's range [{lo:g}, {hi:g}], "
            "so there is no surface; pick a level inside it (--bone-iso, --skin-iso; defaults "
            "bone 300 HU or 1150 scanner units, skin -400 HU or 500, see lilium.ct.checks)"
        )
    background = min(lo, iso) - 1.0
    padded = np.pad(np.nan_to_num(data, nan=background), 1, constant_values=background)
    verts_kji, faces, _, _ = marching_cubes(
        padded, level=iso, gradient_direction="descent", allow_degenerate=False
    )
    faces = faces.astype(np.int64)
    ijk = verts_kji[:, ::-1] - 1.0 + start
    vertices = volume.index_to_mm(ijk)
    # skimage's winding is outward in (k, j, i) coordinates; reversing the axis order to
    # (i, j, k) mirrors it, and a left-handed direction matrix mirrors it back.
    if np.linalg.det(volume.direction) < 0:
        faces = faces[:, ::-1]
    if largest_component:
        vertices, faces = keep_largest_component(vertices, faces)
    else:
        vertices, faces = compact(vertices, faces)
    if target_faces is not None:
        vertices, faces = decimate(vertices, faces, target_faces)
    return vertices, faces
