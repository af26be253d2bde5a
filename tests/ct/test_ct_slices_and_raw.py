"""``lilium import-ct`` on DICOM slices of another grid and on bad raw-data options: each input
ends in one error line that names the file or option."""

import pytest

from ct_phantom import head, write_dicom
from lilium.cli.main import main


def _error(capsys, argv):
    assert main([str(a) for a in argv]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(lines) == 1 and ": error:" in lines[0], lines
    return lines[0]


@pytest.mark.parametrize(
    ("tag", "value"),
    [("ImageOrientationPatient", [0, 1, 0, 1, 0, 0]), ("PixelSpacing", [3.0, 3.0])],
)
def test_a_dicom_slice_of_another_grid_is_refused(tmp_path, capsys, tag, value):
    pytest.importorskip("pydicom")
    import pydicom

    folder = write_dicom(tmp_path / "dcm", head(hu=True)[:12])
    odd = sorted(folder.iterdir())[5]
    ds = pydicom.dcmread(odd)
    setattr(ds, tag, value)
    ds.save_as(odd, enforce_file_format=True)
    line = _error(capsys, ["import-ct", folder, "--out", tmp_path / "s"])
    assert odd.name in line and tag in line and "differs" in line
    assert not (tmp_path / "s" / "skull.ply").exists()


def test_raw_options_are_named(tmp_path, capsys):
    raw = tmp_path / "v.raw"
    raw.write_bytes(bytes(1024))
    base = ["import-ct", raw, "--out", tmp_path / "s", "--raw-shape", "8,8,8", "--spacing", "1,1,1"]
    assert "--raw-dtype" in _error(capsys, [*base, "--raw-dtype", "int17"])
    line = _error(capsys, [*base, "--raw-dtype", "int16", "--header-bytes", "-5"])
    assert "--header-bytes" in line
