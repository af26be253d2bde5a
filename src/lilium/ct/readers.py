"""CT volume readers: DICOM series, NRRD, NIfTI, MetaImage and headerless raw slices.

Every reader returns a :class:`~lilium.ct.volume.Volume` (data ``[slice, row, column]``, spacing
and origin in (x, y, z) order, direction columns = index axes). NRRD, MetaImage and raw files are
parsed here without extra packages; DICOM needs ``pydicom`` and NIfTI ``nibabel`` (optional,
imported only when such a file is read).
"""

import gzip
import re
import zlib
from pathlib import Path

import numpy as np

from .volume import Volume, check_spacing

#: Suffixes understood by :func:`read_volume`, per format.
NRRD_SUFFIXES = (".nrrd", ".nhdr")
NIFTI_SUFFIXES = (".nii", ".nii.gz")
META_SUFFIXES = (".mhd", ".mha")
DICOM_SUFFIXES = (".dcm", ".dicom", ".ima")


def read_volume(
    path,
    raw_shape=None,
    raw_dtype=None,
    spacing=None,
    origin=None,
    byte_order="little",
    header_bytes=0,
):
    """Read a CT volume, the format chosen from the path.

    Parameters
    ----------
    path : str, Path or sequence of them
        A ``.nrrd``/``.nhdr`` header, a ``.nii``/``.nii.gz`` file, a ``.mhd``/``.mha`` header, a
        folder of DICOM files (or one ``.dcm`` file), or headerless raw data: one file holding
        the whole volume, a list of slice files, or a glob pattern such as ``"quarter.*"``
        (slices in natural order: ``quarter.2`` before ``quarter.10``).
    raw_shape : (int, int, int), optional
        ``(slices, rows, columns)`` of raw data; with slice files, ``(rows, columns)`` suffices.
    raw_dtype : str, optional
        NumPy type of raw voxels (``int16``, ``uint16``, ``float32``, ...).
    spacing : (float, float, float), optional
        Voxel size (x, y, z) in mm: required for raw data, overrides a header's otherwise.
    origin : (float, float, float), optional
        Position of the first voxel (mm); overrides the header's.
    byte_order : {"little", "big"}
        Of raw data.
    header_bytes : int
        Bytes to skip at the start of each raw file.

    Returns
    -------
    Volume

    Raises
    ------
    ValueError
        Missing file, unknown format, or a header or size that does not fit; the message names
        the file and what to change.
    """
    paths = _expand(path)
    first = paths[0]
    name = first.name.lower()
    if raw_shape is not None or raw_dtype is not None:
        volume = read_raw(paths, raw_shape, raw_dtype, spacing, byte_order, header_bytes)
    elif len(paths) > 1:
        raise ValueError(
            f"{path}: several files matched; for raw slices give raw_shape and raw_dtype "
            "(--raw-shape, --raw-dtype), for DICOM give the folder"
        )
    elif first.is_dir() or name.endswith(DICOM_SUFFIXES):
        volume = read_dicom(first)
    elif name.endswith(NRRD_SUFFIXES):
        volume = read_nrrd(first)
    elif name.endswith(NIFTI_SUFFIXES):
        volume = read_nifti(first)
    elif name.endswith(META_SUFFIXES):
        volume = read_metaimage(first)
    else:
        raise ValueError(
            f"{first}: unknown volume format; use a DICOM folder, .nrrd/.nhdr, .nii/.nii.gz, "
            ".mhd/.mha, or raw data with raw_shape, raw_dtype and spacing"
        )
    if spacing is not None or origin is not None:
        volume = Volume(
            volume.data,
            volume.spacing_mm if spacing is None else check_spacing(spacing, str(first)),
            volume.origin_mm if origin is None else origin,
            volume.direction,
            volume.source,
        )
    return volume


def _expand(path):
    if isinstance(path, (list, tuple)):
        paths = [Path(p) for p in path]
    else:
        text = str(path)
        if any(ch in Path(text).name for ch in "*?["):
            folder = Path(text).parent
            paths = sorted(folder.glob(Path(text).name), key=_natural_key)
            if not paths:
                raise ValueError(f"{text}: no file matches the pattern")
        else:
            paths = [Path(text)]
    for p in paths:
        if not p.exists():
            raise ValueError(f"{p}: file not found")
    if not paths:
        raise ValueError("no volume file given")
    return paths


def _natural_key(path):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", str(path))]


def _dtype(name, byte_order, source):
    try:
        dt = np.dtype(name)
    except TypeError as exc:
        raise ValueError(
            f"{source}: unknown voxel type {name!r}; use int16, uint16, int32, float32, ..."
        ) from exc
    if byte_order not in ("little", "big"):
        raise ValueError(f"{source}: byte order must be 'little' or 'big', got {byte_order!r}")
    return dt.newbyteorder("<" if byte_order == "little" else ">")


# --------------------------------------------------------------------------------------------
# Raw


def read_raw(paths, shape, dtype, spacing, byte_order="little", header_bytes=0):
    """Headerless voxels: one file with the whole volume, or one file per slice.

    Parameters
    ----------
    paths : sequence of Path
    shape : (slices, rows, columns) or (rows, columns) for slice files
    dtype : str
    spacing : (float, float, float)
        Voxel size (x, y, z), mm (required: raw data carry none).
    """
    source = str(paths[0]) if len(paths) == 1 else f"{paths[0]} (+{len(paths) - 1} slices)"
    if shape is None or dtype is None or spacing is None:
        raise ValueError(
            f"{source}: raw data need raw_shape, raw_dtype and spacing "
            "(e.g. --raw-shape 93,64,64 --raw-dtype int16 --spacing 3.2,3.2,1.5)"
        )
    shape = tuple(int(n) for n in shape)
    if len(shape) == 2:
        shape = (len(paths),) + shape
    if len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"{source}: raw shape must be (slices, rows, columns), got {shape}")
    dt = _dtype(dtype, byte_order, source)
    per_file = int(np.prod(shape)) // len(paths)
    if per_file * len(paths) != int(np.prod(shape)):
        raise ValueError(
            f"{source}: {len(paths)} files cannot hold a volume of shape {shape}; "
            "the number of slice files must divide the number of slices"
        )
    chunks = []
    for p in paths:
        raw = p.read_bytes()[int(header_bytes) :]
        expected = per_file * dt.itemsize
        if len(raw) != expected:
            raise ValueError(
                f"{p}: holds {len(raw)} bytes after the header, but shape {shape} of {dt.name} "
                f"needs {expected} per file; check raw_shape, raw_dtype and header_bytes"
            )
        chunks.append(np.frombuffer(raw, dtype=dt))
    data = np.concatenate(chunks).reshape(shape).astype(dt.newbyteorder("="))
    return Volume(data, check_spacing(spacing, source), source=source)


# --------------------------------------------------------------------------------------------
# NRRD

_NRRD_TYPES = {
    "signed char": "i1",
    "int8": "i1",
    "int8_t": "i1",
    "uchar": "u1",
    "unsigned char": "u1",
    "uint8": "u1",
    "uint8_t": "u1",
    "short": "i2",
    "short int": "i2",
    "signed short": "i2",
    "signed short int": "i2",
    "int16": "i2",
    "int16_t": "i2",
    "ushort": "u2",
    "unsigned short": "u2",
    "unsigned short int": "u2",
    "uint16": "u2",
    "uint16_t": "u2",
    "int": "i4",
    "signed int": "i4",
    "int32": "i4",
    "int32_t": "i4",
    "uint": "u4",
    "unsigned int": "u4",
    "uint32": "u4",
    "uint32_t": "u4",
    "longlong": "i8",
    "long long": "i8",
    "int64": "i8",
    "int64_t": "i8",
    "ulonglong": "u8",
    "unsigned long long": "u8",
    "uint64": "u8",
    "uint64_t": "u8",
    "float": "f4",
    "double": "f8",
}


def _parse_vector(text):
    return [float(v) for v in text.strip().strip("()").split(",")]


def read_nrrd(path):
    """An NRRD volume (``.nrrd`` with attached data or ``.nhdr`` with detached data files).

    Supports encodings raw and gzip, ``spacings`` or ``space directions``, ``space origin``, and
    detached ``data file`` given as one name, a ``%d`` pattern with ``min max step``, or
    ``LIST``.
    """
    path = Path(path)
    blob = path.read_bytes()
    if not blob.startswith(b"NRRD"):
        raise ValueError(f"{path}: not an NRRD file (no 'NRRD000x' magic line)")
    end = blob.find(b"\n\n")
    header_text = blob[: end if end >= 0 else len(blob)].decode("latin-1")
    lines = header_text.splitlines()[1:]
    fields = {}
    list_files = []
    for i, line in enumerate(lines):
        if line.startswith("#") or not line.strip():
            continue
        if ":=" in line:
            continue  # key/value pairs
        if ":" not in line:
            raise ValueError(f"{path}: malformed header line {line!r}")
        key, value = line.split(":", 1)
        key, value = key.strip().lower(), value.strip()
        fields[key] = value
        if key in ("data file", "datafile") and value.upper().startswith("LIST"):
            list_files = [ln.strip() for ln in lines[i + 1 :] if ln.strip()]
            break

    def need(key):
        if key not in fields:
            raise ValueError(f"{path}: NRRD header lacks the '{key}' field")
        return fields[key]

    dim = int(need("dimension"))
    if dim != 3:
        raise ValueError(f"{path}: only 3D NRRD volumes are supported, got dimension {dim}")
    sizes = [int(v) for v in need("sizes").split()]
    type_name = need("type").lower()
    if type_name not in _NRRD_TYPES:
        raise ValueError(f"{path}: unsupported NRRD type {type_name!r}")
    encoding = need("encoding").lower()
    if encoding not in ("raw", "gzip", "gz"):
        raise ValueError(f"{path}: unsupported NRRD encoding {encoding!r}; use raw or gzip")
    endian = fields.get("endian", "little").lower()
    dt = _dtype(_NRRD_TYPES[type_name], endian, str(path))

    direction = np.eye(3)
    if "space directions" in fields:
        vecs = re.findall(r"\(([^)]*)\)", fields["space directions"])
        if len(vecs) != 3:
            raise ValueError(f"{path}: 'space directions' must give 3 vectors for a 3D volume")
        cols = np.array([_parse_vector(v) for v in vecs]).T
        spacing = np.linalg.norm(cols, axis=0)
        direction = cols / np.where(spacing > 0, spacing, 1.0)
    elif "spacings" in fields:
        spacing = np.array([float(v) for v in fields["spacings"].split()])
    else:
        spacing = np.ones(3)
    origin = np.zeros(3)
    if "space origin" in fields:
        origin = np.array(_parse_vector(fields["space origin"]))

    n_voxels = int(np.prod(sizes))
    data_file = fields.get("data file", fields.get("datafile"))
    skip = int(fields.get("byte skip", "0"))
    if data_file is None:
        payload = [blob[end + 2 :]] if end >= 0 else [b""]
    else:
        payload = [
            (path.parent / name).read_bytes() if (path.parent / name).is_file() else None
            for name in _nrrd_data_files(data_file, list_files, path)
        ]
        missing = [
            name
            for name, b in zip(_nrrd_data_files(data_file, list_files, path), payload, strict=True)
            if b is None
        ]
        if missing:
            raise ValueError(f"{path}: detached data file(s) not found: {missing[:3]}")
    chunks = []
    for b in payload:
        if encoding in ("gzip", "gz"):
            b = gzip.decompress(b)
        if skip == -1:
            b = b[len(b) - (n_voxels // len(payload)) * dt.itemsize :]
        else:
            b = b[skip:]
        chunks.append(b)
    raw = b"".join(chunks)
    if len(raw) < n_voxels * dt.itemsize:
        raise ValueError(
            f"{path}: data hold {len(raw)} bytes, sizes {sizes} of {dt.name} need "
            f"{n_voxels * dt.itemsize}; check the header's sizes, type and data file"
        )
    data = np.frombuffer(raw[: n_voxels * dt.itemsize], dtype=dt).reshape(sizes[::-1])
    return Volume(data.astype(dt.newbyteorder("=")), spacing, origin, direction, str(path))


def _nrrd_data_files(spec, list_files, path):
    if spec.upper().startswith("LIST"):
        return list_files
    parts = spec.split()
    if len(parts) >= 4 and "%" in parts[0]:
        lo, hi, step = int(parts[1]), int(parts[2]), int(parts[3])
        stop = hi + (1 if step > 0 else -1)
        return [parts[0] % i for i in range(lo, stop, step)]
    return [spec]


# --------------------------------------------------------------------------------------------
# MetaImage

_MET_TYPES = {
    "MET_CHAR": "i1",
    "MET_UCHAR": "u1",
    "MET_SHORT": "i2",
    "MET_USHORT": "u2",
    "MET_INT": "i4",
    "MET_UINT": "u4",
    "MET_LONG": "i4",
    "MET_ULONG": "u4",
    "MET_LONG_LONG": "i8",
    "MET_ULONG_LONG": "u8",
    "MET_FLOAT": "f4",
    "MET_DOUBLE": "f8",
}


def read_metaimage(path):
    """A MetaImage volume: ``.mhd`` header with a ``.raw`` file, or a single ``.mha``."""
    path = Path(path)
    blob = path.read_bytes()
    fields = {}
    offset = 0
    for raw_line in blob.split(b"\n"):
        offset += len(raw_line) + 1
        line = raw_line.decode("latin-1").strip()
        if not line:
            continue
        if "=" not in line:
            raise ValueError(f"{path}: malformed MetaImage header line {line!r}")
        key, value = (s.strip() for s in line.split("=", 1))
        fields[key] = value
        if key == "ElementDataFile":
            break
    for key in ("DimSize", "ElementType", "ElementDataFile"):
        if key not in fields:
            raise ValueError(f"{path}: MetaImage header lacks {key}")
    ndims = int(fields.get("NDims", "3"))
    sizes = [int(v) for v in fields["DimSize"].split()]
    if ndims != 3 or len(sizes) != 3:
        raise ValueError(f"{path}: only 3D MetaImage volumes are supported (NDims = 3)")
    if fields["ElementType"] not in _MET_TYPES:
        raise ValueError(f"{path}: unsupported ElementType {fields['ElementType']!r}")
    msb = fields.get("BinaryDataByteOrderMSB", fields.get("ElementByteOrderMSB", "False"))
    order = "big" if msb.lower() == "true" else "little"
    dt = _dtype(_MET_TYPES[fields["ElementType"]], order, str(path))
    spacing = [float(v) for v in fields.get("ElementSpacing", "1 1 1").split()]
    origin_text = fields.get("Offset", fields.get("Origin", fields.get("Position", "0 0 0")))
    origin = [float(v) for v in origin_text.split()]
    matrix = fields.get("TransformMatrix", fields.get("Rotation", fields.get("Orientation")))
    direction = (
        np.eye(3)
        if matrix is None
        else np.array([float(v) for v in matrix.split()]).reshape(3, 3).T
    )
    data_file = fields["ElementDataFile"]
    if data_file == "LOCAL":
        raw = blob[offset:]
    elif data_file.upper().startswith("LIST"):
        raise ValueError(f"{path}: ElementDataFile LIST is not supported; merge the slices")
    else:
        target = path.parent / data_file
        if not target.is_file():
            raise ValueError(f"{path}: data file {target} not found (ElementDataFile)")
        raw = target.read_bytes()
    if fields.get("CompressedData", "False").lower() == "true":
        raw = zlib.decompress(raw)
    n = int(np.prod(sizes)) * dt.itemsize
    if len(raw) < n:
        raise ValueError(
            f"{path}: data hold {len(raw)} bytes, DimSize {sizes} of {dt.name} needs {n}"
        )
    data = np.frombuffer(raw[:n], dtype=dt).reshape(sizes[::-1])
    return Volume(data.astype(dt.newbyteorder("=")), spacing, origin, direction, str(path))


# --------------------------------------------------------------------------------------------
# NIfTI (nibabel)


def read_nifti(path):
    """A NIfTI-1/2 volume (needs the optional package ``nibabel``).

    The voxel-to-world affine gives origin, spacing and direction (RAS+ world, mm); the array
    (i, j, k) is transposed to ``[k, j, i]``.
    """
    try:
        import nibabel
    except ImportError as exc:
        raise ValueError(
            f"{path}: reading NIfTI needs the optional package nibabel (pip install nibabel)"
        ) from exc
    try:
        image = nibabel.load(str(path))
    except Exception as exc:  # nibabel raises several kinds for corrupt files
        raise ValueError(f"{path}: cannot read the NIfTI file ({exc})") from exc
    data = np.asarray(image.dataobj)
    if data.ndim == 4 and data.shape[3] == 1:
        data = data[..., 0]
    if data.ndim != 3:
        raise ValueError(f"{path}: expected a 3D NIfTI volume, got shape {data.shape}")
    affine = np.asarray(image.affine, float)
    cols = affine[:3, :3]
    spacing = np.linalg.norm(cols, axis=0)
    return Volume(
        np.ascontiguousarray(data.transpose(2, 1, 0)),
        spacing,
        affine[:3, 3],
        cols / spacing,
        str(path),
    )


# --------------------------------------------------------------------------------------------
# DICOM (pydicom)


def read_dicom(path):
    """A DICOM series: every image file of a folder with the same series (needs ``pydicom``).

    Slices are ordered by their position along the slice normal; ``RescaleSlope`` and
    ``RescaleIntercept`` are applied (Hounsfield units for CT). Origin, direction and spacing come
    from ``ImagePositionPatient``, ``ImageOrientationPatient``, ``PixelSpacing`` and the slice
    positions (patient frame, mm).
    """
    try:
        import pydicom
    except ImportError as exc:
        raise ValueError(
            f"{path}: reading DICOM needs the optional package pydicom (pip install pydicom)"
        ) from exc
    path = Path(path)
    files = sorted(p for p in path.iterdir() if p.is_file()) if path.is_dir() else [path]
    slices = []
    for f in files:
        try:
            ds = pydicom.dcmread(str(f))
        except Exception:  # not a DICOM file: skip (folders often hold DICOMDIR, notes, ...)
            continue
        if "PixelData" in ds:
            slices.append(ds)
    if not slices:
        raise ValueError(f"{path}: no DICOM image with pixel data found")
    series = {getattr(ds, "SeriesInstanceUID", None) for ds in slices}
    if len(series) > 1:
        raise ValueError(f"{path}: holds {len(series)} DICOM series; put one series per folder")
    for ds in slices:
        for tag in ("ImagePositionPatient", "ImageOrientationPatient", "PixelSpacing"):
            if tag not in ds:
                raise ValueError(f"{path}: DICOM slice lacks {tag}; cannot build a volume")
    iop = np.array(slices[0].ImageOrientationPatient, float)
    row_dir, col_dir = iop[:3], iop[3:]
    normal = np.cross(row_dir, col_dir)
    positions = np.array([np.array(ds.ImagePositionPatient, float) for ds in slices])
    order = np.argsort(positions @ normal)
    slices = [slices[i] for i in order]
    positions = positions[order]
    dz = np.diff(positions @ normal)
    if len(slices) > 1 and np.any(np.abs(dz) < 1e-6):
        raise ValueError(f"{path}: two DICOM slices share a position; remove duplicates")
    if len(slices) > 1 and np.ptp(dz) > 0.01 * np.abs(dz).mean() + 1e-3:
        raise ValueError(f"{path}: DICOM slices are not evenly spaced; resample the series")
    slice_spacing = (
        float(np.mean(dz)) if len(slices) > 1 else float(getattr(slices[0], "SliceThickness", 1.0))
    )
    shapes = {(int(ds.Rows), int(ds.Columns)) for ds in slices}
    if len(shapes) > 1:
        raise ValueError(f"{path}: DICOM slices differ in size {sorted(shapes)}")
    data = np.stack(
        [
            ds.pixel_array.astype(np.float32) * float(getattr(ds, "RescaleSlope", 1.0))
            + float(getattr(ds, "RescaleIntercept", 0.0))
            for ds in slices
        ]
    )
    row_spacing, col_spacing = (float(v) for v in slices[0].PixelSpacing)
    # PixelSpacing = (between rows, between columns); columns advance along row_dir.
    spacing = np.array([col_spacing, row_spacing, abs(slice_spacing)])
    direction = np.column_stack([row_dir, col_dir, normal])
    return Volume(data, spacing, positions[0], direction, str(path))
