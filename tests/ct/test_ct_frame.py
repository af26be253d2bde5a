"""CT import in one right-handed patient frame (LPS): every format's orientation honoured, left-
handed spaces never mirror the skull, landmarks follow the mesh, HU levels, the warnings."""

import json

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ct_phantom import CENTRE_LPS, SHAPE_ZYX, VOXEL, head, write_dicom, write_metaimage, write_nrrd
from lilium.cli.main import main
from lilium.ct import import_ct
from lilium.ct.checks import spine_check

N_K, N_J, N_I = SHAPE_ZYX
LAST = VOXEL * (np.array([N_I, N_J, N_K]) - 1)  # far corner, LPS mm


def _signed_volume(vertices, faces):
    tri = vertices[faces]
    return np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The phantom declared in LPS with identity directions: the mesh every variant must give."""
    folder = tmp_path_factory.mktemp("ref")
    path = write_nrrd(folder / "lps.nrrd", head())
    return import_ct(path, folder / "out", face=False)["skull"]


def _same_mesh(mesh, reference, tol=1e-4):
    (v, f), (v_ref, f_ref) = mesh, reference
    assert len(f) == len(f_ref)
    d_there, _ = cKDTree(v_ref).query(v)
    d_back, _ = cKDTree(v).query(v_ref)
    assert max(d_there.max(), d_back.max()) < tol
    assert _signed_volume(v, f) > 0  # outward winding: not turned inside out


def _nrrd(tmp_path, name, data, **header):
    return write_nrrd(tmp_path / f"{name}.nrrd", data, **header)


def _variants(tmp_path):
    """The same physical head in other frames, index orders and formats."""
    data = head()
    flip_i, flip_j, flip_k = data[:, :, ::-1], data[:, ::-1, :], data[::-1]
    ras_dirs = np.diag([-VOXEL, -VOXEL, VOXEL])
    yield (
        "nrrd RAS, directions negated",
        _nrrd(tmp_path, "ras1", data, space="RAS", directions=ras_dirs),
    )
    yield (
        "nrrd RAS, array flipped",
        _nrrd(
            tmp_path,
            "ras2",
            data[:, ::-1, ::-1],
            space="right-anterior-superior",
            origin=(-LAST[0], -LAST[1], 0),
        ),
    )
    yield (
        "nrrd LAS (left-handed)",
        _nrrd(tmp_path, "las", flip_j, space="left-anterior-superior", origin=(0, -LAST[1], 0)),
    )
    yield (
        "nrrd 3D-left-handed, slices head to feet",
        _nrrd(tmp_path, "lh", flip_k, space="3D-left-handed", origin=(0, 0, -LAST[2])),
    )
    yield (
        "nrrd 3D-right-handed, k direction negative",
        _nrrd(
            tmp_path,
            "rh",
            flip_k,
            space="3D-right-handed",
            directions=np.diag([VOXEL, VOXEL, -VOXEL]),
            origin=(0, 0, LAST[2]),
        ),
    )
    yield (
        "metaimage TransformMatrix",
        write_metaimage(
            tmp_path / "m1.mha",
            flip_j,
            f"TransformMatrix = 1 0 0 0 -1 0 0 0 1\nOffset = 0 {LAST[1]} 0\n",
        ),
    )
    yield (
        "metaimage AnatomicalOrientation RPI",
        write_metaimage(
            tmp_path / "m2.mha", flip_j, f"AnatomicalOrientation = RPI\nOffset = 0 {LAST[1]} 0\n"
        ),
    )
    nibabel = pytest.importorskip("nibabel")
    affine = np.diag([VOXEL, -VOXEL, VOXEL, 1.0])
    affine[:3, 3] = (-LAST[0], 0, 0)  # RAS x = -LPS x; a left-handed index frame (det < 0)
    image = nibabel.Nifti1Image(flip_i.transpose(2, 1, 0).copy(), affine)
    image.set_sform(affine, code=1)
    nibabel.save(image, tmp_path / "h.nii.gz")
    yield "nifti sform, left-handed affine", tmp_path / "h.nii.gz"
    pytest.importorskip("pydicom")
    yield (
        "dicom, rows running right to left",
        write_dicom(
            tmp_path / "dicom",
            flip_i - 1000,
            iop=(-1, 0, 0, 0, 1, 0),
            position=lambda k: (LAST[0], 0.0, VOXEL * k),
        ),
    )


def test_every_format_and_frame_gives_the_same_lps_mesh(tmp_path, reference):
    seen = []
    for name, path in _variants(tmp_path):
        hu = name.startswith("dicom")  # HU = scanner units - 1000 in the phantom
        bone = 1150 - 1000 * hu
        result = import_ct(path, tmp_path / f"out_{len(seen)}", bone_iso=bone, face=False)
        try:
            _same_mesh(result["skull"], reference)
        except AssertionError as exc:
            raise AssertionError(f"{name}: {exc}") from exc
        seen.append(name)
    assert len(seen) == 9


def test_same_voxels_right_and_left_handed_are_mirror_images(tmp_path):
    data = head()
    right = import_ct(
        _nrrd(tmp_path, "r", data, space="3D-right-handed"), tmp_path / "r", face=False
    )
    left = import_ct(_nrrd(tmp_path, "l", data, space="3D-left-handed"), tmp_path / "l", face=False)
    (v_r, f_r), (v_l, f_l) = right["skull"], left["skull"]
    np.testing.assert_allclose(v_l, v_r * [1, 1, -1], atol=1e-9)
    np.testing.assert_array_equal(f_l, f_r[:, ::-1])
    assert _signed_volume(v_r, f_r) > 0 and _signed_volume(v_l, f_l) > 0
    record = json.loads((tmp_path / "l" / "ct_import.json").read_text())
    assert record["frame"] == "LPS" and record["orientation"] == "assumed"
    assert np.allclose(np.array(record["file_to_frame"])[:3, :3], np.diag([1, 1, -1]))
    assert "orientation_assumed" in [w["code"] for w in record["warnings"]]


def test_the_knob_stays_on_the_patients_left(tmp_path, reference):
    v, _ = reference
    tip = v[np.argmax(v[:, 0])]
    assert tip[0] == pytest.approx(CENTRE_LPS[0] + 40, abs=VOXEL)  # LPS +x = left
    chin = v[np.argmin(v[:, 2])]
    assert chin[1] < CENTRE_LPS[1] - 15  # the lowest bone is anterior (LPS -y)


@pytest.mark.parametrize(
    "name, text",
    [
        ("lm.csv", "name,x,y,z\nnasion,{x},{y},{z}\n"),
        ("lm.json", '{{"landmarks": {{"nasion": [{x}, {y}, {z}]}}}}'),
        ("lm.pp", '<PickedPoints><point name="nasion" x="{x}" y="{y}" z="{z}"/></PickedPoints>'),
    ],
)
def test_landmarks_in_the_files_frame_land_on_the_mesh(tmp_path, name, text):
    """A left-handed file: the knob tip in the file's coordinates lands on the imported knob."""
    data = head()[::-1]
    path = _nrrd(tmp_path, "lh", data, space="3D-left-handed", origin=(0, 0, -LAST[2]))
    tip_lps = CENTRE_LPS + [40, 0, 5]
    tip_file = tip_lps * [1, 1, -1]
    lm = tmp_path / name
    lm.write_text(text.format(x=tip_file[0], y=tip_file[1], z=tip_file[2]))
    result = import_ct(path, tmp_path / "out", face=False, landmarks=lm)
    np.testing.assert_allclose(result["landmarks"]["nasion"], tip_lps)
    distance, _ = cKDTree(result["skull"][0]).query(result["landmarks"]["nasion"])
    assert distance < 2 * VOXEL
    assert "landmark_off_mesh" not in [w["code"] for w in result["warnings"]]
    written = json.loads((tmp_path / "out" / "cranial_landmarks.json").read_text())["landmarks"]
    np.testing.assert_allclose(written["nasion"], tip_lps)


def test_slicer_markups_keep_their_own_frame_and_off_mesh_points_are_reported(tmp_path):
    path = _nrrd(tmp_path, "ras", head(), space="RAS", directions=np.diag([-VOXEL, -VOXEL, VOXEL]))
    tip_lps = CENTRE_LPS + [40, 0, 5]
    ras = tip_lps * [-1, -1, 1]
    (tmp_path / "lm.fcsv").write_text(
        "# Markups fiducial file version = 4.11\n# CoordinateSystem = RAS\n"
        "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"
        f"1,{ras[0]},{ras[1]},{ras[2]},0,0,0,1,1,1,0,nasion,,\n"
        f"2,{ras[0]},{ras[1]},{ras[2] + 200},0,0,0,1,1,1,0,bregma,,\n"
    )
    result = import_ct(path, tmp_path / "out", face=False, landmarks=tmp_path / "lm.fcsv")
    np.testing.assert_allclose(result["landmarks"]["nasion"], tip_lps)
    (warning,) = [w for w in result["warnings"] if w["code"] == "landmark_off_mesh"]
    assert "bregma" in warning["message"] and "nasion" not in warning["message"]


def test_hounsfield_units_get_their_own_levels(tmp_path):
    pytest.importorskip("pydicom")
    folder = write_dicom(tmp_path / "dicom", head(hu=True))
    rc = main(["import-ct", str(folder), "--out", str(tmp_path / "out")])
    assert rc == 0
    record = json.loads((tmp_path / "out" / "ct_import.json").read_text())
    assert record["units"] == "HU" and (record["bone_iso"], record["skin_iso"]) == (300, -400)
    from lilium.io.mesh import read_mesh

    skin, _ = read_mesh(tmp_path / "out" / "face.ply")
    skull, _ = read_mesh(tmp_path / "out" / "skull.ply")
    # face.ply is the skin (lateral half-width 44 mm), not the bone (36 + the 40 mm knob side).
    assert np.ptp(skin[:, 1]) == pytest.approx(100, abs=2 * VOXEL)
    assert np.ptp(skull[:, 1]) == pytest.approx(84, abs=2 * VOXEL)
    # The same volume in HU as an NRRD: detected from the air at -1000.
    path = _nrrd(tmp_path, "hu", head(hu=True))
    assert import_ct(path, tmp_path / "o2")["record"]["units"] == "HU"


def test_negative_skin_level_is_a_level_and_no_face_skips_it(tmp_path):
    path = _nrrd(tmp_path, "hu", head(hu=True))
    assert main(["import-ct", str(path), "--out", str(tmp_path / "a"), "--skin-iso", "-600"]) == 0
    record = json.loads((tmp_path / "a" / "ct_import.json").read_text())
    assert record["skin_iso"] == -600 and (tmp_path / "a" / "face.ply").is_file()
    assert main(["import-ct", str(path), "--out", str(tmp_path / "a"), "--no-face"]) == 0
    assert not (tmp_path / "a" / "face.ply").exists()  # the earlier one is not left behind


def test_hu_default_levels_sit_on_the_true_surfaces():
    """The phantom measurement behind DEFAULT_LEVELS (see lilium.ct.checks), at small size."""
    from scipy import ndimage

    from lilium.ct import Volume, volume_to_mesh

    n, ss = 64, 3
    g = (np.arange(n * ss) + 0.5) / ss
    kk, jj, ii = np.meshgrid(g, g, g, indexing="ij")
    r = np.sqrt((ii - 32) ** 2 + (jj - 32) ** 2 + (kk - 32) ** 2)
    v = np.full(r.shape, -1000.0, np.float32)
    v[r < 28] = 40
    v[(r >= 23.2) & (r < 24)] = 1200  # a 0.8 mm plate
    v = ndimage.gaussian_filter(v.reshape(n, ss, n, ss, n, ss).mean(axis=(1, 3, 5)), 0.7)
    vol = Volume(v, (1.0, 1.0, 1.0))
    for level, radius in ((300, 24.0), (-400, 28.0)):
        verts, _ = volume_to_mesh(vol, level)
        rr = np.linalg.norm(verts - 31.5, axis=1)
        assert np.median(rr) == pytest.approx(radius, abs=0.6)


def test_clean_head_has_no_warnings_and_a_cut_one_does(tmp_path):
    clean = import_ct(_nrrd(tmp_path, "c", head()), tmp_path / "c", face=False)
    assert clean["warnings"] == []
    top = import_ct(
        _nrrd(tmp_path, "t", head()[:66]), tmp_path / "t", face=False
    )  # the vault cut 5 mm below its top
    codes = [w["code"] for w in top["warnings"]]
    assert codes == ["skull_cut"] and "superior border" in top["warnings"][0]["message"]


def test_coarse_and_anisotropic_voxels_are_reported(tmp_path):
    data = head()[::2]  # 3 mm slices
    path = _nrrd(tmp_path, "a", data, directions=np.diag([VOXEL, VOXEL, 2 * VOXEL]))
    codes = [w["code"] for w in import_ct(path, tmp_path / "o", face=False)["warnings"]]
    assert "coarse_voxels" in codes and "anisotropic_voxels" not in codes
    path = _nrrd(tmp_path, "b", head()[::4], directions=np.diag([VOXEL, VOXEL, 4 * VOXEL]))
    codes = [w["code"] for w in import_ct(path, tmp_path / "p", face=False)["warnings"]]
    assert "anisotropic_voxels" in codes


def test_an_attached_spine_is_reported(tmp_path):
    result = import_ct(_nrrd(tmp_path, "s", head(spine=True)), tmp_path / "o", face=False)
    codes = [w["code"] for w in result["warnings"]]
    assert "spine_attached" in codes and "skull_cut" in codes  # the column leaves the floor
    assert result["record"]["spine_check"]["attached"] is True


def test_spine_criterion_on_generated_skulls():
    """Generated skulls (mandible, no spine) pass; the same with a column under them trips it."""
    from lilium.synthetic.subjects import make_subject

    subject = make_subject("s0", np.random.default_rng(0))
    v = subject.skull_vertices_mm
    lps = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])  # x left, y up, z front -> LPS
    attached, measures = spine_check(lps)
    assert not attached and measures["posterior_low_mm"] > measures["anterior_low_mm"] + 30
    y_mid = 0.5 * (lps[:, 1].min() + lps[:, 1].max())
    column = np.array([[0.0, y_mid + 10, z] for z in np.linspace(-40, lps[:, 2].min() - 20, 30)])
    assert spine_check(np.vstack([lps, column]))[0]
