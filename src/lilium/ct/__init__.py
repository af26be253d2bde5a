"""CT volumes: readers (DICOM, NRRD, NIfTI, MetaImage, raw) and the volume -> mesh pipeline."""

from .importer import import_ct, read_landmark_file
from .mesh import volume_to_mesh
from .readers import (
    read_dicom,
    read_metaimage,
    read_nifti,
    read_nrrd,
    read_raw,
    read_volume,
)
from .volume import Volume

__all__ = [
    "Volume",
    "import_ct",
    "read_dicom",
    "read_landmark_file",
    "read_metaimage",
    "read_nifti",
    "read_nrrd",
    "read_raw",
    "read_volume",
    "volume_to_mesh",
]
