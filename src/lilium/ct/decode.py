"""Header fields and compressed voxel data, read defensively.

Every failure is a ``ValueError`` naming the file, the field and the fix. Decompression is
bounded: a gzip or zlib stream is inflated in chunks and stops as soon as it passes the size the
header announces plus :data:`DECOMPRESS_MARGIN_BYTES`, so a "gzip bomb" costs at most that much
memory (besides the compressed bytes themselves) instead of whatever it expands to.
"""

import zlib

import numpy as np

#: Bytes a compressed payload may decompress to beyond what the header's sizes need (NRRD's
#: ``byte skip`` or padding); more is an error.
DECOMPRESS_MARGIN_BYTES = 1 << 20

#: Largest volume read, in voxels (2^29, e.g. 1024 x 1024 x 512). The importer's peak memory
#: is about the file's size plus 10 bytes per voxel for int16 data (the voxels, the float32 copy
#: marching cubes works on and its padded copy), so at most about 5.4 GB plus the file; a
#: 512 x 512 x 400 head CT needs about 1.1 GB. Crop or downsample larger scans first.
MAX_VOXELS = 1 << 29

_CHUNK = 1 << 24


def integers(text, field, source, count=None, minimum=None):
    """Whitespace-separated integers of a header field (``"64 64 93"``)."""
    try:
        values = [int(v) for v in str(text).split()]
    except ValueError:
        values = None
    if values is None or (count is not None and len(values) != count) or not values:
        n = f"{count} " if count else ""
        raise ValueError(f"{source}: header field '{field}' must be {n}integers, got {text!r}")
    if minimum is not None and min(values) < minimum:
        raise ValueError(
            f"{source}: header field '{field}' must be integers >= {minimum}, got {text!r}"
        )
    return values


def floats(text, field, source, count=None):
    """Separated finite numbers of a header field (spaces, commas, parentheses allowed)."""
    cleaned = str(text).replace(",", " ").replace("(", " ").replace(")", " ")
    try:
        values = np.array([float(v) for v in cleaned.split()], dtype=float)
    except ValueError:
        values = None
    if (
        values is None
        or not len(values)
        or (count is not None and len(values) != count)
        or not np.all(np.isfinite(values))
    ):
        n = f"{count} " if count else ""
        raise ValueError(
            f"{source}: header field '{field}' must be {n}finite numbers, got {text!r}"
        )
    return values


def check_voxel_count(sizes, source):
    """Refuse a volume above :data:`MAX_VOXELS` before any memory is spent on it."""
    n = int(np.prod([int(s) for s in sizes], dtype=object))
    if n > MAX_VOXELS:
        raise ValueError(
            f"{source}: {n} voxels (sizes {list(sizes)}) is above the limit of {MAX_VOXELS}; "
            "crop or downsample the scan first"
        )
    return n


def inflate(blob, expected_bytes, source, kind):
    """Decompress a gzip or zlib stream, refusing one that is corrupt, truncated or too large.

    Parameters
    ----------
    blob : bytes
        The compressed data (several concatenated gzip members are allowed).
    expected_bytes : int
        What the header's sizes need; output beyond ``expected_bytes +
        DECOMPRESS_MARGIN_BYTES`` is refused.
    kind : {"gzip", "zlib"}
        For messages; either header is accepted (writers of both formats use both).

    Returns
    -------
    bytes
    """
    limit = int(expected_bytes) + DECOMPRESS_MARGIN_BYTES
    wbits = 32 + zlib.MAX_WBITS  # gzip or zlib header, detected
    what = "gzip" if kind == "gzip" else "zlib (CompressedData)"
    out = []
    total = 0
    data = bytes(blob)
    if not data:
        raise ValueError(f"{source}: the {what} data are empty; the file is truncated")
    while data:
        engine = zlib.decompressobj(wbits)
        try:
            while True:
                chunk = engine.decompress(data, min(_CHUNK, limit + 1 - total))
                total += len(chunk)
                out.append(chunk)
                if total > limit:
                    raise ValueError(
                        f"{source}: the {what} data decompress to more than the "
                        f"{int(expected_bytes)} bytes the header's sizes need (stopped at "
                        f"{limit}); the header or the data are wrong (a gzip bomb?)"
                    )
                data = engine.unconsumed_tail
                if engine.eof or (not data and not chunk):
                    break
        except zlib.error as exc:
            raise ValueError(
                f"{source}: the {what} data are corrupt ({exc}); export the volume again"
            ) from exc
        if not engine.eof:
            raise ValueError(
                f"{source}: the {what} data end early (truncated file); copy or export the "
                "volume again"
            )
        data = engine.unused_data
    return b"".join(out)
