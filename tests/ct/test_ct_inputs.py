"""``lilium import-ct`` on inputs a real first case brings: raw slices stored upside down with
``--orientation``, the headsq CT (raw slices = its NRRD), NaN voxels, a NIfTI without voxel
size, absurd ``--spacing``, a landmark file in an unknown frame, a detached header pointing
outside its folder."""

import json
from pathlib import Path

import numpy as np
import pytest

from lilium.cli.main import main
from lilium.io.mesh import read_mesh

SPACING = (1.5, 2.0, 2.5)  # x, y, z (mm)
HEADSQ = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "headsq"


def _phantom(shape_zyx=(24, 30, 36), dtype=np.int16):
    """A 'head' (skin 600, bone 1300, brain 300) with a nose (+y, anterior in LPS is -y)."""
    k, j, i = np.indices(shape_zyx, dtype=float)
    x, y, z = i * SPACING[0], j * SPACING[1], k * SPACING[2]
    r = np.sqrt(((x - 26) / 20) ** 2 + ((y - 29) / 24) ** 2 + ((z - 26) / 20) ** 2)
    data = np.zeros(shape_zyx, dtype)
    data[r < 1.0] = 600
    data[r < 0.85] = 1300
    data[(r < 0.7)] = 300
    data[(z > 40) & (r < 0.85)] = 1300  # a thick vault: top and bottom differ
    return data


def _slices(folder, data, dtype="<i2"):
    folder.mkdir()
    for k in range(data.shape[0]):
        (folder / f"s.{k + 1}").write_bytes(data[k].astype(dtype).tobytes())
    return str(folder / "s.*")


def _import(capsys, *argv):
    code = main(["import-ct", *map(str, argv)])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _one_line(capsys, needles, *argv):
    code, _, err = _import(capsys, *argv)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for needle in needles:
        assert needle in lines[0], lines[0]


def _raw(pattern, shape, *extra):
    spacing = ",".join(f"{s:g}" for s in SPACING)
    return [pattern, "--raw-shape", shape, "--raw-dtype", "int16", "--spacing", spacing, *extra]


def test_an_upside_down_raw_volume_is_oriented_by_the_option(tmp_path, capsys):
    data = _phantom()
    upright = _slices(tmp_path / "up", data)
    flipped = _slices(tmp_path / "down", data[::-1])  # first slice = top of the head
    code, _, err = _import(capsys, *_raw(upright, "30,36"), "--no-face", "--out", tmp_path / "a")
    assert code == 0, err
    argv = [*_raw(flipped, "30,36"), "--orientation", "lpi", "--no-face", "--out", tmp_path / "b"]
    code, out, err = _import(capsys, *argv)
    assert code == 0, err
    assert "orientation given (--orientation LPI)" in out and "orientation_assumed" not in out
    (va, fa), (vb, fb) = (
        read_mesh(tmp_path / "a" / "skull.ply"),
        read_mesh(tmp_path / "b" / "skull.ply"),
    )
    shift = np.array([0, 0, (data.shape[0] - 1) * SPACING[2]])
    assert va.shape == vb.shape and fa.shape == fb.shape
    np.testing.assert_allclose(np.sort(va, axis=0), np.sort(vb + shift, axis=0), atol=1e-4)
    record = json.loads((tmp_path / "b" / "ct_import.json").read_text())
    assert record["orientation"] == "given (--orientation LPI)"
    assert np.allclose(np.asarray(record["index_to_frame"])[:3, :3], np.diag([1.5, 2.0, -2.5]))


def test_a_bad_orientation_is_one_line(tmp_path, capsys):
    pattern = _slices(tmp_path / "v", _phantom())
    _one_line(capsys, ["--orientation 'LPX'", "one of each pair"],
              *_raw(pattern, "30,36"), "--orientation", "LPX", "--out", tmp_path / "o")  # fmt: skip
    assert not (tmp_path / "o").exists()


@pytest.mark.skipif(not (HEADSQ / "quarter.nhdr").is_file(), reason="shared/data/headsq absent")
def test_headsq_raw_slices_with_the_orientation_equal_its_nrrd(tmp_path, capsys):
    argv = ["--no-face", "--out"]
    assert _import(capsys, HEADSQ / "quarter.nhdr", *argv, tmp_path / "nrrd")[0] == 0
    raw = [str(HEADSQ / "quarter.[0-9]*"), "--raw-shape", "64,64", "--raw-dtype", "int16"]
    raw += ["--spacing", "3.2,3.2,1.5", "--orientation", "LPI"]
    assert _import(capsys, *raw, *argv, tmp_path / "raw")[0] == 0
    (va, fa), (vb, fb) = (read_mesh(tmp_path / d / "skull.ply") for d in ("nrrd", "raw"))
    assert va.shape == vb.shape and np.array_equal(fa, fb)
    assert np.max(np.abs(va - vb)) < 1e-4  # the same LPS mesh


def test_nan_voxels_are_refused(tmp_path, capsys):
    data = _phantom().astype(np.float32)
    data[10:12, 14, 4:30] = np.nan  # a line of NaN through the bone
    pattern = _slices(tmp_path / "v", data, "<f4")
    argv = [pattern, "--raw-shape", "30,36", "--raw-dtype", "float32", "--spacing", "1.5,2,2.5"]
    _one_line(capsys, ["52 voxels are NaN or infinite", "--crop"], *argv, "--out", tmp_path / "o")


def test_absurd_spacing_names_the_option(tmp_path, capsys):
    pattern = _slices(tmp_path / "v", _phantom())
    argv = [pattern, "--raw-shape", "30,36", "--raw-dtype", "int16", "--spacing", "1e-9,3,3"]
    _one_line(capsys, ["voxel size 1e-09, 3, 3 mm", "0.01-20 mm", "(--spacing X,Y,Z)"], *argv,
              "--out", tmp_path / "o")  # fmt: skip


def test_a_nifti_without_voxel_size_needs_the_spacing(tmp_path, capfd):
    nibabel = pytest.importorskip("nibabel")
    image = nibabel.Nifti1Image(_phantom().transpose(2, 1, 0), None)
    image.header["pixdim"][1:4] = 0
    nibabel.save(image, tmp_path / "head.nii")
    capfd.readouterr()  # nibabel's own line while saving
    assert main(["import-ct", str(tmp_path / "head.nii"), "--out", str(tmp_path / "o")]) == 2
    err = capfd.readouterr().err
    assert "voxel size (pixdim) is 0" in err and "--spacing X,Y,Z" in err
    assert "setting 0 dims to 1" not in err and len(err.strip().splitlines()) == 1
    argv = ["import-ct", str(tmp_path / "head.nii"), "--spacing", "1.5,2,2.5", "--no-face"]
    assert main([*argv, "--out", str(tmp_path / "p")]) == 0
    assert "setting 0 dims" not in capfd.readouterr().err


def test_a_landmark_file_in_an_unknown_frame_is_refused(tmp_path, capsys):
    pattern = _slices(tmp_path / "v", _phantom())
    fcsv = tmp_path / "lm.fcsv"
    fcsv.write_text(
        "# Markups fiducial file version = 4.11\n# CoordinateSystem = XYZ\n"
        "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"
        "1,26,5,26,0,0,0,1,1,1,0,nasion,,\n"
    )
    _one_line(capsys, ["lm.fcsv: coordinate system 'XYZ'", "LPS or RAS"],
              *_raw(pattern, "30,36"), "--landmarks", fcsv, "--out", tmp_path / "o")  # fmt: skip


@pytest.mark.parametrize("suffix", [".nhdr", ".mhd"])
def test_a_detached_header_may_not_name_a_file_elsewhere(tmp_path, capsys, suffix):
    data = _phantom()
    (tmp_path / "secret.raw").write_bytes(data.astype("<i2").tobytes())
    folder = tmp_path / "case"
    folder.mkdir()
    header = folder / f"head{suffix}"
    if suffix == ".nhdr":
        header.write_text(
            "NRRD0004\ndimension: 3\nsizes: 36 30 24\ntype: short\nendian: little\n"
            "encoding: raw\nspacings: 1.5 2 2.5\ndata file: ../secret.raw\n"
        )
    else:
        header.write_text(
            "ObjectType = Image\nNDims = 3\nDimSize = 36 30 24\nElementSpacing = 1.5 2 2.5\n"
            "ElementType = MET_SHORT\nElementDataFile = ../secret.raw\n"
        )
    _one_line(capsys, ["'../secret.raw'", "outside the header's folder", "--allow-outside-data"],
              header, "--out", tmp_path / "o")  # fmt: skip
    code, _, err = _import(
        capsys, header, "--allow-outside-data", "--no-face", "--out", tmp_path / "p"
    )
    assert code == 0, err
