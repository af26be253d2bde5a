"""Bad CT input: each a one-line error naming the file and the field or fix (exit 2), never a
traceback; compressed data bounded (no gzip bomb)."""

import gzip
import zlib

import numpy as np
import pytest

from ct_phantom import write_metaimage
from lilium.cli.main import main
from lilium.ct.decode import DECOMPRESS_MARGIN_BYTES, inflate

SMALL = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)  # [k, j, i]


def _nrrd_header(**override):
    fields = {
        "type": "short",
        "dimension": "3",
        "space": "left-posterior-superior",
        "sizes": "6 5 4",
        "space directions": "(1,0,0) (0,1,0) (0,0,1)",
        "space origin": "(0,0,0)",
        "endian": "little",
        "encoding": "raw",
    }
    fields.update(override)
    lines = [f"{k}: {v}" for k, v in fields.items() if v is not None]
    return "NRRD0004\n" + "\n".join(lines) + "\n"


def _nrrd(payload=None, **override):
    def write(folder):
        data = SMALL.astype("<i2").tobytes() if payload is None else payload
        path = folder / "vol.nrrd"
        path.write_bytes(_nrrd_header(**override).encode() + b"\n" + data)
        return path

    return write


def _mha(extra="", compressed=None, **replace):
    def write(folder):
        path = write_metaimage(folder / "vol.mha", SMALL, extra, compressed=compressed)
        text = path.read_bytes()
        for old, new in replace.items():
            text = text.replace(old.encode(), new.encode())
        path.write_bytes(text)
        return path

    return write


GZ = gzip.compress(SMALL.astype("<i2").tobytes())
ZL = zlib.compress(SMALL.astype("<i2").tobytes())
BOMB = gzip.compress(bytes(20 << 20))  # 20 MiB of zeros for a 240-byte volume


def _corrupt(blob):
    b = bytearray(blob)
    b[12:20] = b"\xff" * 8
    return bytes(b)


def _dicom(truncate):
    def write(folder):
        pytest.importorskip("pydicom")
        from ct_phantom import write_dicom

        series = write_dicom(folder / "dicom", SMALL.repeat(2, axis=0) - 1000)
        victim = sorted(series.glob("*.dcm"))[3]
        blob = victim.read_bytes()
        victim.write_bytes(blob[: len(blob) - 7] if truncate == "pixels" else blob[:200])
        return series

    return write


def _nifti_truncated(folder):
    nibabel = pytest.importorskip("nibabel")
    path = folder / "vol.nii"
    nibabel.save(nibabel.Nifti1Image(SMALL.astype(np.float32), np.eye(4)), path)
    path.write_bytes(path.read_bytes()[:-100])
    return path


def _detached(spec):
    def write(folder):
        path = folder / "vol.nhdr"
        path.write_text(_nrrd_header() + f"data file: {spec}\n")
        return path

    return write


CASES = [
    ("dimension three", _nrrd(dimension="three"), "header field 'dimension' must be"),
    ("dimension 2", _nrrd(dimension="2"), "only 3D volumes"),
    ("sizes not integers", _nrrd(sizes="6 5 x"), "header field 'sizes' must be 3 integers"),
    ("sizes zero", _nrrd(sizes="6 0 4"), "'sizes' must be integers >= 1"),
    ("too many voxels", _nrrd(sizes="100000 100000 100000"), "above the limit"),
    ("unknown type", _nrrd(type="complex"), "header field 'type'"),
    ("unknown encoding", _nrrd(encoding="bzip2"), "header field 'encoding'"),
    ("bad endian", _nrrd(endian="middle"), "header field 'endian'"),
    ("unknown space", _nrrd(space="upside-down"), "unknown space 'upside-down'"),
    ("4D space", _nrrd(space="scanner-xyz-time"), "is 4D"),
    ("2 space directions", _nrrd(**{"space directions": "(1,0,0) (0,1,0)"}), "3 vectors"),
    ("zero direction", _nrrd(**{"space directions": "(1,0,0) (0,0,0) (0,0,1)"}), "zero vector"),
    ("bad origin", _nrrd(**{"space origin": "(0,a,0)"}), "'space origin' must be 3 finite"),
    ("missing sizes", _nrrd(sizes=None), "lacks the 'sizes' field"),
    ("truncated raw", _nrrd(payload=SMALL.tobytes()[:-10]), "the file is truncated"),
    ("truncated gzip", _nrrd(payload=GZ[:-20], encoding="gzip"), "end early"),
    ("corrupt gzip", _nrrd(payload=_corrupt(GZ), encoding="gzip"), "corrupt"),
    ("not gzip at all", _nrrd(payload=b"hello world", encoding="gzip"), "corrupt"),
    ("gzip bomb", _nrrd(payload=BOMB, encoding="gzip"), "decompress to more than"),
    ("missing data file", _detached("slices.raw"), "not found"),
    ("bad data file pattern", _detached("slice.%q 1 3 1"), "pattern"),
    ("metaimage NDims 2", _mha(**{"NDims = 3": "NDims = 2"}), "only 3D volumes"),
    ("metaimage bad DimSize", _mha(**{"DimSize = 6 5 4": "DimSize = 6 5"}), "'DimSize'"),
    ("metaimage bad matrix", _mha("TransformMatrix = 1 0 0 0 1 0\n"), "'TransformMatrix'"),
    ("metaimage bad orientation", _mha("AnatomicalOrientation = RRI\n"), "names an axis twice"),
    ("metaimage bad type", _mha(**{"MET_SHORT": "MET_COMPLEX"}), "'ElementType'"),
    ("metaimage truncated zlib", _mha(compressed=ZL[:-9]), "end early"),
    ("metaimage zlib bomb", _mha(compressed=zlib.compress(bytes(20 << 20))), "more than"),
    ("dicom truncated pixel data", _dicom("pixels"), "cannot decode the pixel data"),
    ("dicom truncated header", _dicom("header"), "without pixel data (the file is truncated)"),
    ("nifti truncated", _nifti_truncated, "cannot read the NIfTI file"),
]


@pytest.mark.parametrize("name, write, fragment", CASES, ids=[c[0] for c in CASES])
def test_bad_volume_is_one_line_naming_the_file(tmp_path, capsys, name, write, fragment):
    path = write(tmp_path)
    rc = main(["import-ct", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(path) in err or str(tmp_path) in err
    assert fragment in err
    assert not (tmp_path / "out" / "skull.ply").exists()


def test_out_that_is_a_file_is_an_error(tmp_path, capsys):
    from ct_phantom import head, write_nrrd

    path = write_nrrd(tmp_path / "h.nrrd", head())
    (tmp_path / "taken").write_text("x")
    assert main(["import-ct", str(path), "--out", str(tmp_path / "taken")]) == 2
    assert "--out" in capsys.readouterr().err


def test_inflate_stops_at_the_header_size_plus_margin():
    """The memory bound: a bomb is refused after at most expected + margin bytes of output."""
    with pytest.raises(ValueError, match="stopped at"):
        inflate(BOMB, 240, "x.nrrd", "gzip")
    ok = bytes(1000)
    assert inflate(gzip.compress(ok) + gzip.compress(ok), 2000, "x", "gzip") == ok + ok
    assert len(inflate(gzip.compress(bytes(DECOMPRESS_MARGIN_BYTES)), 0, "x", "gzip")) == (
        DECOMPRESS_MARGIN_BYTES
    )
