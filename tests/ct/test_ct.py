"""CT import: readers for every format, volume -> mesh, the import-ct command, bad inputs."""

import gzip
import json
from pathlib import Path

import numpy as np
import pytest

from lilium.cli.main import main
from lilium.ct import Volume, import_ct, read_landmark_file, read_volume, volume_to_mesh

SPACING = (1.5, 2.0, 2.5)  # x, y, z (mm)
SHAPE_ZYX = (24, 30, 36)
HEADSQ = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "headsq"


def _phantom():
    """A 'head': skin ellipsoid (600) around a bone shell (1300) around brain (300), int16."""
    k, j, i = np.indices(SHAPE_ZYX, dtype=float)
    x, y, z = i * SPACING[0], j * SPACING[1], k * SPACING[2]
    c = np.array([26.25, 29.0, 28.75])
    r = np.sqrt(((x - c[0]) / 20) ** 2 + ((y - c[1]) / 24) ** 2 + ((z - c[2]) / 22) ** 2)
    data = np.zeros(SHAPE_ZYX, np.int16)
    data[r < 1.0] = 600
    data[r < 0.85] = 1300
    data[r < 0.7] = 300
    return data, c


def _check_extents(vertices, centre, radii, tol):
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    np.testing.assert_allclose(lo, centre - radii, atol=tol)
    np.testing.assert_allclose(hi, centre + radii, atol=tol)


def test_volume_to_mesh_matches_the_ellipsoid():
    data, c = _phantom()
    v, f = volume_to_mesh(data, 450, spacing=SPACING)
    _check_extents(v, c, np.array([20.0, 24.0, 22.0]), tol=max(SPACING) * 1.2)
    # Outward winding: positive enclosed volume close to the ellipsoid's.
    tri = v[f]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert volume == pytest.approx(4 / 3 * np.pi * 20 * 24 * 22, rel=0.08)


def test_largest_component_and_crop():
    data, c = _phantom()
    data[1:3, 1:3, 1:3] = 1300  # a speck of 'bone' away from the skull
    v_all, _ = volume_to_mesh(data, 1000, spacing=SPACING, largest_component=False)
    v, _ = volume_to_mesh(data, 1000, spacing=SPACING)
    assert v_all.min(axis=0)[0] < 5 < v.min(axis=0)[0]
    v_crop, _ = volume_to_mesh(data, 450, spacing=SPACING, crop=((0, 18), (0, 30), (0, 24)))
    assert v_crop.max(axis=0)[0] <= 18 * SPACING[0]  # closed within a voxel of the cut


def test_decimation_reaches_the_target():
    pytest.importorskip("fast_simplification")
    data, _ = _phantom()
    _, f = volume_to_mesh(data, 450, spacing=SPACING, target_faces=500)
    assert 400 <= len(f) <= 500


def _write_nrrd(path, data, gz=False, detached=False):
    payload = data.astype("<i2").tobytes()
    header = (
        "NRRD0004\ntype: short\ndimension: 3\n"
        f"sizes: {data.shape[2]} {data.shape[1]} {data.shape[0]}\n"
        f"space directions: ({SPACING[0]},0,0) (0,{SPACING[1]},0) (0,0,{SPACING[2]})\n"
        "space origin: (10,20,30)\nendian: little\n"
        f"encoding: {'gzip' if gz else 'raw'}\n"
    )
    if gz:
        payload = gzip.compress(payload)
    if detached:
        nslices = data.shape[0]
        for k in range(nslices):
            (path.parent / f"slice.{k + 1}").write_bytes(data[k].astype("<i2").tobytes())
        header += f"data file: slice.%d 1 {nslices} 1\n"
        path.write_text(header + "\n")
    else:
        path.write_bytes(header.encode() + b"\n" + payload)


@pytest.mark.parametrize("variant", ["raw", "gzip", "detached"])
def test_nrrd_round_trip(tmp_path, variant):
    data, c = _phantom()
    path = tmp_path / ("head.nhdr" if variant == "detached" else "head.nrrd")
    _write_nrrd(path, data, gz=variant == "gzip", detached=variant == "detached")
    vol = read_volume(path)
    np.testing.assert_array_equal(vol.data, data)
    np.testing.assert_allclose(vol.spacing_mm, SPACING)
    v, _ = volume_to_mesh(vol, 450)
    _check_extents(v, c + (10, 20, 30), np.array([20.0, 24.0, 22.0]), max(SPACING) * 1.2)


def test_metaimage_round_trip(tmp_path):
    data, c = _phantom()
    (tmp_path / "head.raw").write_bytes(data.astype(">i2").tobytes())
    (tmp_path / "head.mhd").write_text(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
        f"Offset = 1 2 3\nElementSpacing = {SPACING[0]} {SPACING[1]} {SPACING[2]}\n"
        f"DimSize = {data.shape[2]} {data.shape[1]} {data.shape[0]}\n"
        "ElementType = MET_SHORT\nElementDataFile = head.raw\n"
    )
    vol = read_volume(tmp_path / "head.mhd")
    np.testing.assert_array_equal(vol.data, data)
    np.testing.assert_allclose(vol.origin_mm, (1, 2, 3))
    v, _ = volume_to_mesh(vol, 450)
    _check_extents(v, c + (1, 2, 3), np.array([20.0, 24.0, 22.0]), max(SPACING) * 1.2)


def test_raw_volume_and_slices(tmp_path):
    data, c = _phantom()
    (tmp_path / "vol.bin").write_bytes(b"HDR!" + data.astype("<i2").tobytes())
    vol = read_volume(
        tmp_path / "vol.bin",
        raw_shape=data.shape,
        raw_dtype="int16",
        spacing=SPACING,
        header_bytes=4,
    )
    np.testing.assert_array_equal(vol.data, data)
    for k in range(data.shape[0]):
        (tmp_path / f"cut.{k + 1}").write_bytes(data[k].astype("<i2").tobytes())
    vol = read_volume(
        tmp_path / "cut.*", raw_shape=data.shape[1:], raw_dtype="int16", spacing=SPACING
    )
    np.testing.assert_array_equal(vol.data, data)  # natural order: cut.2 before cut.10


def test_nifti_round_trip(tmp_path):
    nibabel = pytest.importorskip("nibabel")
    data, c = _phantom()
    affine = np.diag([*SPACING, 1.0])
    affine[:3, 3] = (-5, -6, -7)
    nibabel.save(nibabel.Nifti1Image(data.transpose(2, 1, 0).copy(), affine), tmp_path / "h.nii.gz")
    vol = read_volume(tmp_path / "h.nii.gz")
    np.testing.assert_array_equal(vol.data, data)
    v, _ = volume_to_mesh(vol, 450)
    _check_extents(v, c + (-5, -6, -7), np.array([20.0, 24.0, 22.0]), max(SPACING) * 1.2)


def _write_dicom_series(folder, data):
    pydicom = pytest.importorskip("pydicom")
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, generate_uid

    folder.mkdir()
    series = generate_uid()
    order = np.random.default_rng(0).permutation(data.shape[0])  # files out of slice order
    for n, k in enumerate(order):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID = CTImageStorage
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.SeriesInstanceUID = series
        ds.Modality = "CT"
        ds.Rows, ds.Columns = data.shape[1], data.shape[2]
        ds.PixelSpacing = [SPACING[1], SPACING[0]]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.ImagePositionPatient = [0.0, 0.0, float(k * SPACING[2])]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
        ds.PixelData = (data[k].astype(np.int32) + 1024).astype("<u2").tobytes()
        pydicom.dcmwrite(folder / f"img{n:03d}.dcm", ds, enforce_file_format=True)
    (folder / "notes.txt").write_text("not a DICOM file")


def test_dicom_series_round_trip(tmp_path):
    data, c = _phantom()
    _write_dicom_series(tmp_path / "dicom", data)
    vol = read_volume(tmp_path / "dicom")
    np.testing.assert_allclose(vol.data, data)
    np.testing.assert_allclose(vol.spacing_mm, SPACING)
    v, _ = volume_to_mesh(vol, 450)
    _check_extents(v, c, np.array([20.0, 24.0, 22.0]), max(SPACING) * 1.2)


def test_import_ct_writes_a_subject_folder(tmp_path):
    data, c = _phantom()
    _write_nrrd(tmp_path / "head.nrrd", data)
    (tmp_path / "lm.csv").write_text("name,x,y,z\nnasion,30,20,40\nbregma,26,5,30\n")
    rc = main(
        [
            "import-ct",
            str(tmp_path / "head.nrrd"),
            "--out",
            str(tmp_path / "subject"),
            "--bone-iso",
            "1000",
            "--skin-iso",
            "450",
            "--landmarks",
            str(tmp_path / "lm.csv"),
        ]
    )
    assert rc == 0
    out = tmp_path / "subject"
    assert (out / "skull.ply").is_file() and (out / "face.ply").is_file()
    lm = json.loads((out / "cranial_landmarks.json").read_text())["landmarks"]
    assert lm["nasion"] == [30.0, 20.0, 40.0]
    from lilium.io.mesh import read_mesh

    skull, _ = read_mesh(out / "skull.ply")
    skin, _ = read_mesh(out / "face.ply")
    assert np.ptp(skin, axis=0)[0] > np.ptp(skull, axis=0)[0]


def test_bad_inputs_raise_clear_errors(tmp_path):
    data, _ = _phantom()
    with pytest.raises(ValueError, match="file not found"):
        read_volume(tmp_path / "missing.nrrd")
    (tmp_path / "x.xyz").write_text("?")
    with pytest.raises(ValueError, match="unknown volume format"):
        read_volume(tmp_path / "x.xyz")
    (tmp_path / "v.bin").write_bytes(data.astype("<i2").tobytes()[:-2])
    with pytest.raises(ValueError, match="check raw_shape"):
        read_volume(tmp_path / "v.bin", raw_shape=data.shape, raw_dtype="int16", spacing=SPACING)
    with pytest.raises(ValueError, match="spacing"):
        read_volume(tmp_path / "v.bin", raw_shape=data.shape, raw_dtype="int16")
    (tmp_path / "bad.nrrd").write_text("NRRD0004\ntype: short\ndimension: 3\n\n")
    with pytest.raises(ValueError, match="lacks the 'sizes' field"):
        read_volume(tmp_path / "bad.nrrd")
    with pytest.raises(ValueError, match="outside the volume's range"):
        volume_to_mesh(data, 5000, spacing=SPACING)
    with pytest.raises(ValueError, match="spacing must be 3 positive"):
        Volume(data, (1.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="bone level"):
        import_ct(Volume(data, SPACING), tmp_path / "o", bone_iso=400, skin_iso=450)
    (tmp_path / "lm.json").write_text('{"landmarks": {"nose_tip": [0, 0, 0]}}')
    with pytest.raises(ValueError, match="unknown cranial landmark 'nose_tip'"):
        read_landmark_file(tmp_path / "lm.json")
    assert main(["import-ct", str(tmp_path / "x.xyz"), "--out", str(tmp_path / "o")]) == 2


@pytest.mark.skipif(not (HEADSQ / "quarter.nhdr").is_file(), reason="shared/data/headsq absent")
def test_headsq_nrrd_and_raw_agree():
    vol = read_volume(HEADSQ / "quarter.nhdr")
    raw = read_volume(
        HEADSQ / "quarter.[0-9]*", raw_shape=(64, 64), raw_dtype="int16", spacing=(3.2, 3.2, 1.5)
    )
    np.testing.assert_array_equal(vol.data, raw.data)
    v, f = volume_to_mesh(vol, 1150, target_faces=None)
    assert len(f) > 1000
    assert np.all(np.ptp(v, axis=0) > 100)  # a real skull spans > 10 cm each way


@pytest.mark.skipif(not (HEADSQ / "quarter.nhdr").is_file(), reason="shared/data/headsq absent")
def test_headsq_import_names_its_frame_and_warns(tmp_path, capsys):
    """The real CT: left-handed space (z negated to LPS), cut vault, 3.2 mm voxels, spine."""
    assert main(["import-ct", str(HEADSQ / "quarter.nhdr"), "--out", str(tmp_path / "s")]) == 0
    printed = capsys.readouterr().out
    record = json.loads((tmp_path / "s" / "ct_import.json").read_text())
    assert record["frame"] == "LPS" and record["source_space"] == "3d-left-handed"
    assert record["units"] == "scanner" and record["bone_iso"] == 1150
    codes = [w["code"] for w in record["warnings"]]
    for code in ("orientation_assumed", "coarse_voxels", "anisotropic_voxels", "spine_attached"):
        assert code in codes and f"[{code}]" in printed
    assert {c["side"] for c in record["border_cuts"]} == {"superior", "inferior"}
    extent = record["skull_extent_mm"]
    assert extent["max"][2] <= 1.5 and extent["min"][2] < -130  # slice 1 on top, z up
