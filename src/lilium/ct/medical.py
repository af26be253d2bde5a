"""Readers through the optional packages: DICOM series (``pydicom``) and NIfTI (``nibabel``).

Both give a :class:`~lilium.ct.volume.Volume` with its patient frame named: DICOM's is LPS,
NIfTI's RAS (see :mod:`lilium.ct.frame`). Every failure of the package on a corrupt or truncated
file becomes a one-line ``ValueError`` naming the file.
"""

import contextlib
import logging
from pathlib import Path

import numpy as np

from .decode import check_voxel_count
from .volume import Volume


class _Collect(logging.Handler):
    def __init__(self):
        super().__init__()
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


@contextlib.contextmanager
def _nibabel_messages():
    """nibabel's own log lines (e.g. "pixdim[1,2,3] should be non-zero; setting 0 dims to 1"),
    kept off stderr and handed to the caller, which turns them into errors or header notes."""
    loggers = [logging.getLogger(name) for name in ("nibabel", "nibabel.global")]
    saved = [(lg.handlers[:], lg.propagate) for lg in loggers]
    handler = _Collect()
    for lg in loggers:  # nibabel.global has its own stderr handler
        lg.handlers, lg.propagate = [handler], False
    try:
        yield handler.messages
    finally:
        for lg, (handlers, propagate) in zip(loggers, saved, strict=True):
            lg.handlers, lg.propagate = handlers, propagate


def read_nifti(path, spacing_given=False):
    """A NIfTI-1/2 volume (needs the optional package ``nibabel``).

    The voxel-to-world affine (the sform when its code is set, else the qform: nibabel's
    ``image.affine``) gives origin, spacing and direction in the RAS+ world, mm; the array
    (i, j, k) is transposed to ``[k, j, i]``. With both codes 0 the file states no orientation
    (``space_known`` False). A zero voxel size (``pixdim``) is an error unless
    ``spacing_given`` (``--spacing``): nibabel would take it as 1 mm.
    """
    try:
        import nibabel
    except ImportError as exc:
        raise ValueError(
            f"{path}: reading NIfTI needs the optional package nibabel (pip install nibabel)"
        ) from exc
    try:
        with _nibabel_messages() as messages:
            image = nibabel.load(str(path))
            check_voxel_count(image.shape[:3], str(path))
            data = np.asarray(image.dataobj)
        header = image.header
        known = int(header["sform_code"]) > 0 or int(header["qform_code"]) > 0
    except ValueError as exc:
        if str(exc).startswith(str(path)):
            raise
        raise ValueError(
            f"{path}: cannot read the NIfTI file ({_one_line(exc)}); export it again"
        ) from exc
    except Exception as exc:  # nibabel raises several kinds for corrupt or truncated files
        raise ValueError(
            f"{path}: cannot read the NIfTI file ({_one_line(exc)}); the file is truncated or "
            "corrupt, export it again"
        ) from exc
    if any("setting 0 dims to 1" in m for m in messages) and not spacing_given:
        raise ValueError(
            f"{path}: the voxel size (pixdim) is 0, so the file does not say how large its voxels "
            "are; give it with --spacing X,Y,Z (mm)"
        )
    notes = tuple(f"nibabel: {m}" for m in messages if "setting 0 dims to 1" not in m)
    if data.ndim == 4 and data.shape[3] == 1:
        data = data[..., 0]
    if data.ndim != 3:
        raise ValueError(f"{path}: expected a 3D NIfTI volume, got shape {data.shape}")
    affine = np.asarray(image.affine, float)
    cols = affine[:3, :3]
    spacing = np.linalg.norm(cols, axis=0)
    if not np.all(np.isfinite(affine)) or np.any(spacing <= 0):
        raise ValueError(f"{path}: the NIfTI affine (qform/sform) is singular or not finite")
    return Volume(
        np.ascontiguousarray(data.transpose(2, 1, 0)),
        spacing,
        affine[:3, 3],
        cols / spacing,
        str(path),
        space="ras",
        space_known=known,
        notes=notes,
    )


def _is_dicom_file(path):
    """Whether a file has DICOM's ``DICM`` marker at byte 128 (or a DICOM suffix)."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(132)
    except OSError:
        return False
    return head[128:132] == b"DICM" or path.suffix.lower() in (".dcm", ".dicom", ".ima")


def _is_image_storage(ds):
    """Whether a dataset's SOP class is an image storage (so it must hold pixel data)."""
    uid = getattr(getattr(ds, "file_meta", None), "MediaStorageSOPClassUID", None)
    uid = uid or getattr(ds, "SOPClassUID", None)
    return uid is not None and "Image Storage" in str(getattr(uid, "name", ""))


def _one_line(exc):
    """An exception's text on one line (messages of the packages may span several)."""
    return " ".join(f"{type(exc).__name__}: {exc}".split())


def _check_same_grid(slices, iop, pixel_spacing):
    """Refuse a series whose slices differ in ``ImageOrientationPatient`` or ``PixelSpacing``:
    the volume takes both from the first slice, so another slice's would be silently wrong."""
    for f, ds in slices[1:]:
        for tag, first in (("ImageOrientationPatient", iop), ("PixelSpacing", pixel_spacing)):
            try:
                value = np.array(getattr(ds, tag), float).reshape(np.shape(first))
            except (TypeError, ValueError):
                value = None
            if value is None or not np.allclose(value, first, atol=1e-4, rtol=1e-3):
                raise ValueError(
                    f"{f}: {tag} differs from the series' first slice {slices[0][0].name} "
                    f"({list(np.round(first, 4))}); the slices are not one volume: remove the "
                    "odd slice or export the series again (resampled to one grid)"
                )


def read_dicom(path):
    """A DICOM series: every image file of a folder with the same series (needs ``pydicom``).

    Slices are ordered by their position along the slice normal; ``RescaleSlope`` and
    ``RescaleIntercept`` are applied (Hounsfield units for CT). Origin, direction and spacing come
    from ``ImagePositionPatient``, ``ImageOrientationPatient``, ``PixelSpacing`` and the slice
    positions (patient frame LPS, mm). Files without the DICOM marker are skipped (notes,
    DICOMDIR-less folders); a DICOM file that cannot be read or whose pixel data cannot be decoded
    (truncated, or compressed without a decoder) is an error naming it.
    """
    try:
        import pydicom
        from pydicom.errors import InvalidDicomError
    except ImportError as exc:
        raise ValueError(
            f"{path}: reading DICOM needs the optional package pydicom (pip install pydicom)"
        ) from exc
    path = Path(path)
    files = sorted(p for p in path.iterdir() if p.is_file()) if path.is_dir() else [path]
    slices = []
    for f in files:
        marked = _is_dicom_file(f)
        try:
            ds = pydicom.dcmread(str(f), force=False)
        except InvalidDicomError as exc:
            if marked:
                raise ValueError(
                    f"{f}: not a readable DICOM file ({_one_line(exc)}); remove it or export again"
                ) from exc
            continue
        except Exception as exc:  # pydicom raises many kinds on truncated headers
            if not marked:
                continue
            raise ValueError(
                f"{f}: cannot read the DICOM file ({_one_line(exc)}); it is "
                "truncated or corrupt: remove it or export the series again"
            ) from exc
        if "PixelData" in ds:
            slices.append((f, ds))
        elif _is_image_storage(ds):  # pydicom stops quietly at the end of a truncated file
            raise ValueError(
                f"{f}: a DICOM image without pixel data (the file is truncated); remove it or "
                "export the series again"
            )
    if not slices:
        raise ValueError(f"{path}: no DICOM image with pixel data found")
    series = {getattr(ds, "SeriesInstanceUID", None) for _, ds in slices}
    if len(series) > 1:
        raise ValueError(f"{path}: holds {len(series)} DICOM series; put one series per folder")
    for f, ds in slices:
        for tag in ("ImagePositionPatient", "ImageOrientationPatient", "PixelSpacing"):
            if tag not in ds:
                raise ValueError(f"{f}: DICOM slice lacks {tag}; cannot build a volume")
        if int(getattr(ds, "NumberOfFrames", 1) or 1) > 1:
            raise ValueError(
                f"{f}: a multi-frame DICOM image is not supported; export one file per slice"
            )
    try:
        iop = np.array(slices[0][1].ImageOrientationPatient, float).reshape(6)
        positions = np.array([np.array(ds.ImagePositionPatient, float) for _, ds in slices])
        row_spacing, col_spacing = (float(v) for v in slices[0][1].PixelSpacing)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"{slices[0][0]}: ImageOrientationPatient (6 numbers), ImagePositionPatient (3) or "
            f"PixelSpacing (2) is malformed ({exc})"
        ) from exc
    _check_same_grid(slices, iop, (row_spacing, col_spacing))
    row_dir, col_dir = iop[:3], iop[3:]
    normal = np.cross(row_dir, col_dir)
    if np.linalg.norm(normal) < 1e-6 or positions.shape[1:] != (3,):
        raise ValueError(f"{slices[0][0]}: ImageOrientationPatient has parallel row and column")
    order = np.argsort(positions @ normal)
    slices = [slices[i] for i in order]
    positions = positions[order]
    dz = np.diff(positions @ normal)
    if len(slices) > 1 and np.any(np.abs(dz) < 1e-6):
        raise ValueError(f"{path}: two DICOM slices share a position; remove duplicates")
    if len(slices) > 1 and np.ptp(dz) > 0.01 * np.abs(dz).mean() + 1e-3:
        raise ValueError(f"{path}: DICOM slices are not evenly spaced; resample the series")
    first = slices[0][1]
    slice_spacing = (
        float(np.mean(dz)) if len(slices) > 1 else float(getattr(first, "SliceThickness", 1.0))
    )
    shapes = {(int(ds.Rows), int(ds.Columns)) for _, ds in slices}
    if len(shapes) > 1:
        raise ValueError(f"{path}: DICOM slices differ in size {sorted(shapes)}")
    check_voxel_count((len(slices), *shapes.pop()), str(path))
    planes = []
    for f, ds in slices:
        try:
            pixels = ds.pixel_array
        except Exception as exc:  # truncated data, missing decoder, bad attributes
            raise ValueError(
                f"{f}: cannot decode the pixel data ({_one_line(exc)}); the file is "
                "truncated or compressed without a decoder (pip install pylibjpeg): export the "
                "series again, uncompressed"
            ) from exc
        planes.append(
            pixels.astype(np.float32) * float(getattr(ds, "RescaleSlope", 1.0) or 1.0)
            + float(getattr(ds, "RescaleIntercept", 0.0) or 0.0)
        )
    data = np.stack(planes)
    # PixelSpacing = (between rows, between columns); columns advance along row_dir.
    spacing = np.array([col_spacing, row_spacing, abs(slice_spacing)])
    direction = np.column_stack([row_dir, col_dir, normal])
    modality = str(getattr(first, "Modality", "")).upper()
    hounsfield = modality == "CT" or "RescaleIntercept" in first
    return Volume(
        data,
        spacing,
        positions[0],
        direction,
        str(path),
        space="lps",
        space_known=True,
        units="HU" if hounsfield else None,
    )
