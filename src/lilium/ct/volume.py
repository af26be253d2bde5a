"""A CT volume: a voxel array with its spacing, origin and axis directions.

Convention, written once. ``data`` is indexed ``[k, j, i]`` = ``[slice, row, column]`` (the
(Z, Y, X) order of DICOM series, NRRD/MetaImage files read in C order and most viewers). The voxel
``(i, j, k)`` (column, row, slice) sits at the point

    ``p_mm = origin_mm + direction @ ((i, j, k) * spacing_mm)``

of the volume frame (the scanner's patient frame for DICOM/NIfTI, the file's ``space`` for NRRD),
so ``spacing_mm`` and ``origin_mm`` are in (x, y, z) order and the columns of ``direction`` are the
unit directions of the i, j, k index axes. :func:`~lilium.ct.mesh.volume_to_mesh` returns meshes in
this frame, in mm; ``space`` names it (``"LPS"``, ``"RAS"``, an NRRD space such as
``"3D-left-handed"``, or None when the file names none) and :mod:`lilium.ct.frame` maps it to the
one right-handed patient frame (LPS) that ``lilium import-ct`` writes.
"""

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Volume:
    """A 3D scalar image (CT numbers in Hounsfield units or scanner units).

    Attributes
    ----------
    data : ndarray of shape (Z, Y, X)
        Voxel values, indexed ``[slice, row, column]``.
    spacing_mm : ndarray of shape (3,)
        Voxel size along the column, row and slice axes (x, y, z order), mm.
    origin_mm : ndarray of shape (3,)
        Position of voxel ``(0, 0, 0)``, mm.
    direction : ndarray of shape (3, 3)
        Columns: unit directions of the column, row and slice axes in the volume frame.
    source : str
        Where the volume came from (for messages).
    space : str or None
        The frame of ``p_mm`` (see :func:`lilium.ct.frame.space_to_lps`): ``"LPS"`` for DICOM
        and MetaImage, ``"RAS"`` for NIfTI, the ``space`` field of an NRRD header; None when the
        file names no frame (raw data, NRRD without ``space``).
    space_known : bool
        Whether the file states the patient's anatomical axes (DICOM, NIfTI with a qform/sform
        code, NRRD with an anatomical space, MetaImage with a TransformMatrix or
        AnatomicalOrientation).
    units : {"HU", None}
        ``"HU"`` where the file says so (DICOM after the rescale); None: to be detected.
    notes : tuple of str
        Header observations the importer reports as warnings (e.g. a MetaImage
        ``AnatomicalOrientation`` that contradicts its ``TransformMatrix``).
    """

    data: np.ndarray
    spacing_mm: np.ndarray
    origin_mm: np.ndarray = field(default_factory=lambda: np.zeros(3))
    direction: np.ndarray = field(default_factory=lambda: np.eye(3))
    source: str = "volume"
    space: str | None = None
    space_known: bool = False
    units: str | None = None
    notes: tuple = ()

    def __post_init__(self):
        data = np.asarray(self.data)
        if data.ndim != 3:
            raise ValueError(
                f"{self.source}: a volume needs 3 dimensions (slices, rows, columns), got shape "
                f"{data.shape}"
            )
        if min(data.shape) < 2:
            raise ValueError(
                f"{self.source}: every volume dimension needs at least 2 voxels, got {data.shape}"
            )
        object.__setattr__(self, "data", data)
        object.__setattr__(self, "spacing_mm", check_spacing(self.spacing_mm, source=self.source))
        origin = np.asarray(self.origin_mm, dtype=float).reshape(-1)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise ValueError(f"{self.source}: origin must be 3 finite numbers, got {origin}")
        object.__setattr__(self, "origin_mm", origin)
        direction = np.asarray(self.direction, dtype=float)
        if direction.shape != (3, 3) or not np.all(np.isfinite(direction)):
            raise ValueError(f"{self.source}: direction must be a finite 3x3 matrix")
        norms = np.linalg.norm(direction, axis=0)
        if np.any(norms < 1e-9) or abs(np.linalg.det(direction / norms)) < 1e-6:
            raise ValueError(f"{self.source}: direction matrix is singular; check the header")
        object.__setattr__(self, "direction", direction / norms)

    @property
    def shape_zyx(self):
        return self.data.shape

    def index_to_mm(self, ijk):
        """Volume-frame points (mm) of voxel indices ``(i, j, k)`` (column, row, slice).

        Parameters
        ----------
        ijk : array_like of shape (N, 3)

        Returns
        -------
        ndarray of shape (N, 3)
        """
        ijk = np.asarray(ijk, dtype=float)
        return self.origin_mm + (ijk * self.spacing_mm) @ self.direction.T

    def extent_mm(self):
        """Size of the volume along its three axes, (x, y, z) order, mm."""
        return (np.array(self.data.shape[::-1]) - 1) * self.spacing_mm


#: Physical range of a CT voxel's side (mm): a micro-CT's 0.01 mm to a 20 mm scout. Outside it
#: the number is a unit or typing error (1e-9 mm makes a flat skull, 0 is "unknown").
VOXEL_SIZE_RANGE_MM = (0.01, 20.0)


def check_spacing(spacing, source="volume"):
    """Validate a voxel spacing of 3 numbers (x, y, z order, mm) in :data:`VOXEL_SIZE_RANGE_MM`
    and return it."""
    spacing = np.asarray(spacing, dtype=float).reshape(-1)
    lo, hi = VOXEL_SIZE_RANGE_MM
    if spacing.shape != (3,) or not np.all(np.isfinite(spacing)) or np.any(spacing <= 0):
        raise ValueError(
            f"{source}: spacing must be 3 positive numbers in mm (x, y, z), got "
            f"{np.asarray(spacing).tolist()}"
        )
    if np.any(spacing < lo) or np.any(spacing > hi):
        raise ValueError(
            f"{source}: voxel size {', '.join(f'{v:g}' for v in spacing)} mm (x, y, z) is "
            f"outside the {lo:g}-{hi:g} mm of a CT voxel; give the size in mm (--spacing X,Y,Z)"
        )
    return spacing
