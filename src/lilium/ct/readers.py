"""CT volume readers: DICOM series, NRRD, NIfTI, MetaImage and headerless raw slices.

Every reader returns a :class:`~lilium.ct.volume.Volume` (data ``[slice, row, column]``, spacing
and origin in (x, y, z) order, direction columns = index axes). NRRD, MetaImage and raw files are
parsed here without extra packages; DICOM needs ``pydicom`` and NIfTI ``nibabel`` (optional,
imported only when such a file is read; :mod:`lilium.ct.medical`). Header fields and compressed
data are checked by :mod:`lilium.ct.decode`: every malformed header, truncated or corrupt
payload and oversized (bomb) stream is a one-line ``ValueError`` naming the file and the field.
"""

import dataclasses
import re
from pathlib import Path

import numpy as np

from .decode import check_voxel_count, floats, inflate, integers
from .frame import normalise_space, orientation_code_to_direction
from .medical import read_dicom, read_nifti
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
    allow_outside_data=False,
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
    allow_outside_data : bool
        Let a detached NRRD/MetaImage header name data files outside its own folder
        (``--allow-outside-data``); by default that is an error, as a header could name any
        file on the machine.

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
        volume = read_nrrd(first, allow_outside_data)
    elif name.endswith(NIFTI_SUFFIXES):
        volume = read_nifti(first, spacing_given=spacing is not None)
    elif name.endswith(META_SUFFIXES):
        volume = read_metaimage(first, allow_outside_data)
    else:
        raise ValueError(
            f"{first}: unknown volume format; use a DICOM folder, .nrrd/.nhdr, .nii/.nii.gz, "
            ".mhd/.mha, or raw data with raw_shape, raw_dtype and spacing"
        )
    if spacing is not None or origin is not None:
        volume = dataclasses.replace(
            volume,
            spacing_mm=(
                volume.spacing_mm if spacing is None else check_spacing(spacing, "--spacing")
            ),
            origin_mm=volume.origin_mm if origin is None else origin,
        )
    return volume


def read_bytes(path):
    """The bytes of a file, or a ``ValueError`` naming it (a folder, no permission, ...)."""
    try:
        return Path(path).read_bytes()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the file ({exc.strerror or exc})") from exc


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
        dt = None
        cause = exc
    else:
        cause = None
    if dt is None or dt.kind not in "iuf" or dt.itemsize > 8:
        raise ValueError(
            f"{source}: unknown voxel type {name!r}; give --raw-dtype int16, uint16, int32, "
            "float32, ..."
        ) from cause
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
    check_voxel_count(shape, source)
    if int(header_bytes) < 0:
        raise ValueError(f"{source}: --header-bytes must be 0 or more, got {header_bytes}")
    chunks = []
    for p in paths:
        raw = read_bytes(p)[int(header_bytes) :]
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


def _header_end(blob):
    """Offset of the blank line ending a text header (``\\n\\n`` or ``\\r\\n\\r\\n``), or -1."""
    ends = [(i, n) for i, n in ((blob.find(b"\n\n"), 2), (blob.find(b"\r\n\r\n"), 4)) if i >= 0]
    return min(ends) if ends else (-1, 0)


def detached_file(header, name, field, allow_outside=False):
    """The data file ``name`` a detached header names, checked to exist and, unless
    ``allow_outside``, to lie in the header's folder (or below it)."""
    target = header.parent / name
    if not allow_outside:
        folder = header.parent.resolve()
        resolved = target.resolve()
        if folder not in resolved.parents:
            raise ValueError(
                f"{header}: the data file {name!r} ({field}) lies outside the header's folder; "
                "put the data beside the header, or give --allow-outside-data if you trust "
                "this header"
            )
    if not target.is_file():
        raise ValueError(f"{header}: detached data file {target} not found ({field})")
    return target


def read_nrrd(path, allow_outside_data=False):
    """An NRRD volume (``.nrrd`` with attached data or ``.nhdr`` with detached data files).

    Supports encodings raw, gzip and ascii, ``spacings`` or ``space directions``, ``space
    origin``, ``space`` (kept as :attr:`Volume.space`, see :mod:`lilium.ct.frame`), and detached
    ``data file`` given as one name, a ``%d`` pattern with ``min max step``, or ``LIST``.
    """
    path = Path(path)
    src = str(path)
    blob = read_bytes(path)
    if not re.match(rb"NRRD000\d\r?\n", blob[:10]):
        raise ValueError(f"{path}: not an NRRD file (no 'NRRD000x' magic line)")
    end, sep = _header_end(blob)
    header_text = blob[: end if end >= 0 else len(blob)].decode("latin-1")
    lines = header_text.splitlines()[1:]
    fields = {}
    list_files = []
    for i, line in enumerate(lines):
        if line.startswith("#") or not line.strip():
            continue
        if ":=" in line:
            continue  # key/value pairs
        if ": " not in line and not line.rstrip().endswith(":"):
            raise ValueError(
                f"{path}: malformed header line {line[:60]!r}; NRRD fields are 'name: value'"
            )
        key, value = line.split(":", 1)
        key, value = key.strip().lower(), value.strip()
        if key in fields:
            raise ValueError(f"{path}: header field '{key}' is given twice; keep one")
        fields[key] = value
        if key in ("data file", "datafile") and value.upper().startswith("LIST"):
            list_files = [ln.strip() for ln in lines[i + 1 :] if ln.strip()]
            break

    def need(key):
        if key not in fields:
            raise ValueError(f"{path}: NRRD header lacks the '{key}' field")
        return fields[key]

    (dim,) = integers(need("dimension"), "dimension", src, count=1)
    if dim != 3:
        raise ValueError(
            f"{path}: header field 'dimension' is {dim}; only 3D volumes are supported (3)"
        )
    sizes = integers(need("sizes"), "sizes", src, count=3, minimum=1)
    n_voxels = check_voxel_count(sizes, src)
    type_name = " ".join(need("type").lower().split())
    if type_name not in _NRRD_TYPES:
        raise ValueError(
            f"{path}: header field 'type' {type_name!r} is not supported; use short, ushort, "
            "int, float, ..."
        )
    encoding = need("encoding").lower()
    if encoding not in ("raw", "gzip", "gz", "ascii", "text", "txt"):
        raise ValueError(
            f"{path}: header field 'encoding' {encoding!r} is not supported; save the volume "
            "as raw or gzip"
        )
    endian = fields.get("endian", "little").lower()
    if endian not in ("little", "big"):
        raise ValueError(f"{path}: header field 'endian' must be little or big, got {endian!r}")
    dt = _dtype(_NRRD_TYPES[type_name], endian, src)
    space = normalise_space(fields.get("space"), f"{path}: header field 'space'")
    if "space dimension" in fields:
        (space_dim,) = integers(fields["space dimension"], "space dimension", src, count=1)
        if space_dim != 3:
            raise ValueError(f"{path}: header field 'space dimension' must be 3, got {space_dim}")

    direction = np.eye(3)
    if "space directions" in fields:
        text = fields["space directions"]
        vecs = re.findall(r"\(([^)]*)\)", text)
        if len(vecs) != 3 or "none" in text.lower():
            raise ValueError(
                f"{path}: header field 'space directions' must give 3 vectors '(x,y,z)' for a "
                f"3D volume, got {text!r}"
            )
        cols = np.array([floats(v, "space directions", src, count=3) for v in vecs]).T
        spacing = np.linalg.norm(cols, axis=0)
        if np.any(spacing <= 0):
            raise ValueError(f"{path}: header field 'space directions' has a zero vector")
        direction = cols / spacing
    elif "spacings" in fields:
        spacing = floats(fields["spacings"], "spacings", src, count=3)
    else:
        spacing = np.ones(3)
    origin = np.zeros(3)
    if "space origin" in fields:
        origin = floats(fields["space origin"], "space origin", src, count=3)
    if "line skip" in fields and integers(fields["line skip"], "line skip", src, 1) != [0]:
        raise ValueError(f"{path}: header field 'line skip' is not supported; remove it")
    (skip,) = integers(fields.get("byte skip", "0"), "byte skip", src, count=1, minimum=-1)

    data_file = fields.get("data file", fields.get("datafile"))
    if data_file is None:
        if end < 0:
            raise ValueError(f"{path}: no blank line ends the header, so no data follow it")
        payload = [blob[end + sep :]]
    else:
        names = _nrrd_data_files(data_file, list_files, path)
        payload = []
        for name in names:
            target = detached_file(path, name, "data file", allow_outside_data)
            payload.append(read_bytes(target))
    if encoding in ("ascii", "text", "txt"):
        values = np.concatenate([floats(b.decode("latin-1"), "data (ascii)", src) for b in payload])
        if len(values) != n_voxels:
            raise ValueError(
                f"{path}: ascii data hold {len(values)} numbers, sizes {sizes} need {n_voxels}"
            )
        data = values.astype(dt.newbyteorder("=")).reshape(sizes[::-1])
        return Volume(data, spacing, origin, direction, src, space=space, space_known=_known(space))
    per_file = n_voxels * dt.itemsize // len(payload)
    chunks = []
    for b in payload:
        if encoding in ("gzip", "gz"):
            b = inflate(b, per_file + max(skip, 0), src, "gzip")
        b = b[len(b) - per_file :] if skip == -1 else b[skip:]
        chunks.append(b)
    raw = b"".join(chunks)
    if len(raw) < n_voxels * dt.itemsize:
        raise ValueError(
            f"{path}: data hold {len(raw)} bytes, sizes {sizes} of {dt.name} need "
            f"{n_voxels * dt.itemsize}; the file is truncated or the header's sizes, type or "
            "data file are wrong"
        )
    data = np.frombuffer(raw[: n_voxels * dt.itemsize], dtype=dt).reshape(sizes[::-1])
    return Volume(
        data.astype(dt.newbyteorder("=")),
        spacing,
        origin,
        direction,
        src,
        space=space,
        space_known=_known(space),
    )


def _known(space):
    from .frame import SPACES

    return space is not None and SPACES[space][1]


def _nrrd_data_files(spec, list_files, path):
    if spec.upper().startswith("LIST"):
        if not list_files:
            raise ValueError(f"{path}: 'data file: LIST' is not followed by any file name")
        return list_files
    parts = spec.split()
    if len(parts) >= 4 and "%" in parts[0]:
        lo, hi, step = integers(" ".join(parts[1:4]), "data file", str(path), count=3)
        if step == 0 or (hi - lo) * step < 0:
            raise ValueError(
                f"{path}: header field 'data file' has min {lo}, max {hi}, step {step}, which "
                "name no file"
            )
        stop = hi + (1 if step > 0 else -1)
        try:
            return [parts[0] % i for i in range(lo, stop, step)]
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"{path}: header field 'data file' pattern {parts[0]!r} is not a printf "
                "pattern with one %d"
            ) from exc
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


def _metaimage_header(path, blob):
    """Fields of a MetaImage header and the offset where the data of a ``.mha`` start."""
    fields = {}
    offset = 0
    while offset < len(blob):
        stop = blob.find(b"\n", offset)
        stop = len(blob) if stop < 0 else stop
        line = blob[offset:stop].decode("latin-1").strip()
        offset = stop + 1
        if not line:
            continue
        if "=" not in line:
            raise ValueError(
                f"{path}: malformed MetaImage header line {line[:60]!r}; fields are 'Name = value'"
            )
        key, value = (t.strip() for t in line.split("=", 1))
        if key in fields:
            raise ValueError(f"{path}: MetaImage header field {key} is given twice; keep one")
        fields[key] = value
        if key == "ElementDataFile":
            return fields, offset
    raise ValueError(f"{path}: MetaImage header lacks ElementDataFile (the last header field)")


def read_metaimage(path, allow_outside_data=False):
    """A MetaImage volume: ``.mhd`` header with a ``.raw`` file, or a single ``.mha``.

    The world frame is LPS (ITK's). ``TransformMatrix`` (or ``Rotation``/``Orientation``) gives
    the direction; without it ``AnatomicalOrientation`` (ITK's letters, ``RAI`` = identity) does;
    with both, the matrix wins and a disagreement is noted.
    """
    path = Path(path)
    src = str(path)
    blob = read_bytes(path)
    fields, offset = _metaimage_header(path, blob)
    for key in ("DimSize", "ElementType"):
        if key not in fields:
            raise ValueError(f"{path}: MetaImage header lacks {key}")
    (ndims,) = integers(fields.get("NDims", "3"), "NDims", src, count=1)
    if ndims != 3:
        raise ValueError(f"{path}: header field 'NDims' is {ndims}; only 3D volumes (NDims = 3)")
    sizes = integers(fields["DimSize"], "DimSize", src, count=3, minimum=1)
    n_voxels = check_voxel_count(sizes, src)
    channels = integers(fields.get("ElementNumberOfChannels", "1"), "ElementNumberOfChannels", src)
    if channels != [1]:
        raise ValueError(f"{path}: ElementNumberOfChannels must be 1 for a CT volume")
    if fields["ElementType"] not in _MET_TYPES:
        raise ValueError(
            f"{path}: header field 'ElementType' {fields['ElementType']!r} is not supported; "
            "use MET_SHORT, MET_USHORT, MET_FLOAT, ..."
        )
    msb = fields.get("BinaryDataByteOrderMSB", fields.get("ElementByteOrderMSB", "False"))
    if msb.lower() not in ("true", "false"):
        raise ValueError(f"{path}: BinaryDataByteOrderMSB must be True or False, got {msb!r}")
    order = "big" if msb.lower() == "true" else "little"
    dt = _dtype(_MET_TYPES[fields["ElementType"]], order, src)
    spacing_key = "ElementSpacing" if "ElementSpacing" in fields else "ElementSize"
    spacing = floats(fields.get(spacing_key, "1 1 1"), spacing_key, src, count=3)
    origin_key = next((k for k in ("Offset", "Origin", "Position") if k in fields), "Offset")
    origin = floats(fields.get(origin_key, "0 0 0"), origin_key, src, count=3)
    matrix_key = next(
        (k for k in ("TransformMatrix", "Rotation", "Orientation") if k in fields), None
    )
    code = fields.get("AnatomicalOrientation")
    notes = []
    if code is not None and code.strip().upper() in ("", "?", "???"):
        code = None
    from_code = None if code is None else orientation_code_to_direction(code, src)
    if matrix_key is not None:
        direction = floats(fields[matrix_key], matrix_key, src, count=9).reshape(3, 3).T
        if from_code is not None and not np.allclose(np.sign(np.round(direction)), from_code):
            notes.append(
                f"{path}: AnatomicalOrientation {code} disagrees with {matrix_key}; the matrix "
                "is used (as ITK does)"
            )
    else:
        direction = np.eye(3) if from_code is None else from_code
    data_file = fields["ElementDataFile"]
    (header_size,) = integers(fields.get("HeaderSize", "0"), "HeaderSize", src, 1, minimum=-1)
    if data_file == "LOCAL":
        raw = blob[offset:]
    elif data_file.upper().startswith("LIST") or "%" in data_file:
        raise ValueError(
            f"{path}: ElementDataFile {data_file.split()[0]} (one file per slice) is not "
            "supported; save the volume as one .mha or .mhd/.raw"
        )
    else:
        target = detached_file(path, data_file, "ElementDataFile", allow_outside_data)
        raw = read_bytes(target)
    n = n_voxels * dt.itemsize
    compressed = fields.get("CompressedData", "False").lower()
    if compressed not in ("true", "false"):
        raise ValueError(f"{path}: CompressedData must be True or False, got {compressed!r}")
    if compressed == "true":
        raw = inflate(raw, n, src, "zlib")
    elif header_size == -1:
        raw = raw[len(raw) - n :] if len(raw) >= n else raw
    else:
        raw = raw[header_size:]
    if len(raw) < n:
        raise ValueError(
            f"{path}: data hold {len(raw)} bytes, DimSize {sizes} of {dt.name} needs {n}; the "
            "file is truncated or the header's DimSize or ElementType is wrong"
        )
    data = np.frombuffer(raw[:n], dtype=dt).reshape(sizes[::-1])
    return Volume(
        data.astype(dt.newbyteorder("=")),
        spacing,
        origin,
        direction,
        src,
        space="lps",
        space_known=matrix_key is not None or from_code is not None,
        notes=tuple(notes),
    )
