"""Files that pass their own checks but do not belong together (the semantic probes of
tests/acceptance/hostile_semantic.py): landmarks off the face mask, implausible soft-tissue
depths, the curve of the other view."""

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.build import read_photo
from lilium.inputs import Photo
from lilium.io.case import read_depth_table
from lilium.io.curves import read_face_curve
from lilium.io.jsonio import write_json

# -- landmarks on the face mask ---------------------------------------------------------------


def _mask_photo(cx=200, cy=150, rx=80, ry=110, size_wh=(400, 300)):
    """An elliptic face mask and a 5 x 4 grid of landmarks inside it."""
    w, h = size_wh
    v, u = np.mgrid[0:h, 0:w]
    mask = ((u - cx) / rx) ** 2 + ((v - cy) / ry) ** 2 <= 1
    landmarks = {
        f"p{i}{j}": np.array([cx + du, cy + dv], float)
        for i, du in enumerate((-40, -20, 0, 20, 40))
        for j, dv in enumerate((-60, -20, 20, 60))
    }
    return Photo("face", size_wh, "frontal", landmarks, mask)


def test_landmarks_on_the_mask_pass():
    from lilium.methods.photo_checks import check_landmarks_in_mask

    photo = _mask_photo()
    assert check_landmarks_in_mask(photo) == []
    assert check_landmarks_in_mask(replace(photo, face_mask=None)) == []


def test_the_standin_photo_passes(case):
    from lilium.methods.photo_checks import check_landmarks_in_mask, landmark_mask_ratios

    photo = read_photo(case[1], load_image=False)
    assert max(landmark_mask_ratios(photo).values()) < 0.03
    assert check_landmarks_in_mask(photo) == []


@pytest.mark.parametrize(
    "broken",
    [
        lambda m: ~m,  # inverted: the grid's centre lies on the face's hole
        lambda m: np.roll(m, 150, axis=1),  # the mask of another photo, the head aside
    ],
)
def test_a_mask_off_most_landmarks_is_an_error(broken):
    from lilium.methods.photo_checks import check_landmarks_in_mask

    photo = _mask_photo()
    photo = replace(photo, face_mask=broken(photo.face_mask), landmarks_file="lm.json")
    with pytest.raises(ValueError) as err:
        check_landmarks_in_mask(photo)
    text = str(err.value)
    assert "lm.json" in text and "'face'" in text
    assert "of 20 facial landmarks lie outside" in text
    assert "inverted, of another photo, or the image rescaled without its landmarks" in text


def test_some_landmarks_off_the_mask_are_a_warning():
    from lilium.methods.photo_checks import check_landmarks_in_mask

    photo = _mask_photo()
    far = dict(photo.landmarks_uv, p00=np.array([20.0, 20.0]), p01=np.array([380.0, 280.0]))
    warnings = check_landmarks_in_mask(replace(photo, landmarks_uv=far))
    assert [w.code for w in warnings] == ["landmark_outside_mask"]
    assert "photo 'face'" in warnings[0].message
    assert "p00" in warnings[0].message and "p01" in warnings[0].message
    assert "2 of 20" in warnings[0].message


def test_a_landmark_just_off_the_mask_edge_passes():
    """Clean photos put landmarks up to 0.021 of the mask's diagonal outside it."""
    from lilium.methods.photo_checks import check_landmarks_in_mask

    photo = _mask_photo()
    near = dict(photo.landmarks_uv, p00=np.array([200.0 + 80 + 5, 150.0]))  # 5 px off the edge
    assert check_landmarks_in_mask(replace(photo, landmarks_uv=near)) == []


def test_landmark_distances_are_the_distance_transform():
    """The windowed search gives a Euclidean distance transform's distances (scipy's, as the
    reference) on masks of several pieces, for landmarks on, next to, far from the mask and at
    the image's edge; and it loads no scipy.ndimage (0.15 s of a `lilium sfo` start)."""
    from scipy.ndimage import distance_transform_edt

    from lilium.methods.photo_checks import landmark_mask_distances_px

    rng = np.random.default_rng(3)
    for _ in range(20):
        mask = np.zeros((rng.integers(40, 300), rng.integers(40, 300)), bool)
        h, w = mask.shape
        for _ in range(rng.integers(1, 4)):
            r, c = rng.integers(0, h), rng.integers(0, w)
            mask[r : r + rng.integers(1, 30), c : c + rng.integers(1, 30)] = True
        uv = np.column_stack([rng.uniform(-5, w + 5, 30), rng.uniform(-5, h + 5, 30)])
        rows = np.clip(np.rint(uv[:, 1]), 0, h - 1).astype(int)
        cols = np.clip(np.rint(uv[:, 0]), 0, w - 1).astype(int)
        expected = distance_transform_edt(~mask)[rows, cols]
        np.testing.assert_allclose(landmark_mask_distances_px(uv, mask), expected, rtol=1e-12)
    assert np.isinf(landmark_mask_distances_px(uv, np.zeros_like(mask))).all()
    code = (
        "import sys, numpy as np\n"
        "from lilium.methods.photo_checks import landmark_mask_distances_px\n"
        "mask = np.zeros((50, 60), bool); mask[10:20, 10:20] = True\n"
        "d = landmark_mask_distances_px(np.array([[40.0, 40.0]]), mask)\n"
        "print(round(float(d[0]), 6), 'scipy.ndimage' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == [str(round(float(np.hypot(21, 21)), 6)), "False"]


# -- implausible soft-tissue depths -----------------------------------------------------------

NAMES = ("nasion", "glabella", "metopion", "pogonion", "gnathion", "zygion", "gonion", "alare")


def _depth_csv(path, rows):
    lines = [f"{n},{m},2,{max(0, m - 5)},{m + 5}" for n, m in rows]
    path.write_text("landmark,mean,sd,min,max\n" + "\n".join(lines) + "\n")
    return path


def test_a_table_of_80_mm_depths_is_refused(tmp_path):
    path = _depth_csv(tmp_path / "d.csv", [(n, 80) for n in NAMES])
    with pytest.raises(ValueError) as err:
        read_depth_table(path)
    text = str(err.value)
    assert str(path) in text and "nasion 80 > 19.5 mm" in text
    assert "not facial soft-tissue depths" in text and "--depth-table" in text


def test_one_implausible_depth_is_a_warning_message(tmp_path):
    from lilium.softtissue.depths import depth_table_warning, implausible_depths

    rows = [("nasion", 80), ("glabella", 6), ("pogonion", 12)]
    table = read_depth_table(_depth_csv(tmp_path / "d.csv", rows))
    assert set(implausible_depths(table)) == {"nasion"}
    message = depth_table_warning(table, "d.csv")
    assert message.startswith("d.csv:") and "nasion 80 > 19.5 mm" in message
    assert "glabella" not in message
    assert depth_table_warning(read_depth_table(_depth_csv(tmp_path / "ok.csv", rows[1:]))) is None


# -- the curve of the other view --------------------------------------------------------------


@pytest.mark.parametrize(
    ("view", "held", "kind"),
    [("frontal", "forehead", "lateral"), ("lateral_left", "chin_jaw", "frontal")],
)
def test_the_other_views_curve_names_the_view(tmp_path, view, held, kind):
    path = tmp_path / "face_curve.json"
    write_json(path, {held: [[10, 10], [20, 12], [30, 15]]})
    with pytest.raises(ValueError) as err:
        read_face_curve(path, view, (100, 100))
    text = str(err.value)
    assert str(path) in text and f"the curve of a {kind} photo" in text
    assert "check the photo's view" in text and "photo.json" in text


def test_a_case_keeps_the_mask_warning_and_refuses_a_mask_of_another_photo(case, tmp_path, capsys):
    import json

    from PIL import Image

    from cli_helpers import _one_line_error, _run, _sfo

    _, photo_dir = case
    mask_path = photo_dir / "face_mask.png"
    mask = np.asarray(Image.open(mask_path)) > 0
    Image.fromarray(np.where(mask, 0, 255).astype(np.uint8)).save(mask_path)  # inverted
    out = tmp_path / "out"
    code, _, err = _run(_sfo(case, out, "--method", "posest-sfo"), capsys)
    assert code == 0, err
    codes = [w["code"] for w in json.loads((out / "result.json").read_text())["warnings"]]
    assert "landmark_outside_mask" in codes
    shifted = np.roll(mask, 400, axis=1)  # the head of another photo, 400 px aside
    Image.fromarray(shifted.astype(np.uint8) * 255).save(mask_path)
    _one_line_error(capsys, _sfo(case, tmp_path / "o2", "--method", "posest-sfo"), "mask")


def test_an_implausible_depth_is_in_the_result(case, tmp_path, capsys):
    import json

    from cli_helpers import _run, _sfo

    rows = [("nasion", 80), ("glabella", 6), ("pogonion", 12)]
    table = _depth_csv(tmp_path / "d.csv", rows)
    out = tmp_path / "out"
    code, _, err = _run(_sfo(case, out, "--method", "posest-sfo", "--depth-table", table), capsys)
    assert code == 0, err
    warnings = json.loads((out / "result.json").read_text())["warnings"]
    (depth,) = [w for w in warnings if w["code"] == "implausible_depth"]
    assert "d.csv" in depth["message"] and "nasion" in depth["message"]


# -- one photo given twice --------------------------------------------------------------------


def test_a_photo_and_its_resized_copy_are_one_photo():
    from lilium.methods.photo_checks import check_distinct_photos, copy_residual

    rng = np.random.default_rng(4)
    photo = replace(_mask_photo(), landmarks_file="a/photo.json")
    uv = np.array(list(photo.landmarks_uv.values()))
    turn = np.array([[np.cos(0.05), -np.sin(0.05)], [np.sin(0.05), np.cos(0.05)]])
    copy = (uv - 100) @ turn.T * 0.5 + 7 + rng.normal(0, 0.05, uv.shape)  # resized, rounded
    assert copy_residual(uv, copy) < 0.002
    # the same person again: landmarks moved by about 1 % of the face (pose, expression, hand)
    other = uv + rng.normal(0, 0.012 * np.ptp(uv, axis=0).max(), uv.shape)
    assert copy_residual(uv, other) > 0.005
    copied = replace(
        photo,
        id="copy",
        landmarks_file="b/photo.json",
        landmarks_uv=dict(zip(photo.landmarks_uv, copy, strict=True)),
    )
    with pytest.raises(ValueError, match="b/photo.json: its 20 landmarks lie where a/photo.json"):
        check_distinct_photos([photo, copied])
    again = replace(copied, landmarks_uv=dict(zip(photo.landmarks_uv, other, strict=True)))
    check_distinct_photos([photo, again])
    check_distinct_photos([photo, replace(copied, view="lateral_left")])  # another view


def test_a_camera_just_outside_a_prior_reads_apart_from_its_bound():
    from lilium.methods.prior_checks import _apart

    assert _apart(3554.6, (3555.2, 3929.0)) == "3554.6"
    assert _apart(3000.0, (3555.2, 3929.0)) == "3000"


def test_a_camera_whose_perspective_contradicts_its_prior_is_never_support(
    case, tmp_path, capsys, calibration_without_ranges
):
    """POSEST-SFO (no priors in its fit) on the stand-in (about 900 mm away) with a distance
    prior of a quarter and of twice that: the first contradicts the camera's perspective (no
    support); the second does not (focal length and distance trade; the same picture), but
    lies beyond 1.5 x the prior, which is no support either, for that reason alone."""
    import json

    from cli_helpers import _run

    subject_dir, photo_dir = case
    meta = json.loads((photo_dir / "photo.json").read_text())
    runs = {}
    for name, scale in (("kept", 1.0), ("near", 0.25), ("far", 2.0)):
        folder = tmp_path / name
        folder.mkdir()
        for p in photo_dir.iterdir():
            (folder / p.name).write_bytes(p.read_bytes())
        edited = dict(meta, priors=dict(meta["priors"]))
        edited["priors"]["scd_mm"] = [x * scale for x in meta["priors"]["scd_mm"]]
        (folder / "photo.json").write_text(json.dumps(edited))
        out = tmp_path / f"out-{name}"
        argv = ["sfo", "--method", "posest-sfo", "--skull", subject_dir, "--photo", folder]
        code, _, err = _run(argv + ["--out", out, "--no-overlay", "--calibration",
                                    calibration_without_ranges], capsys)
        assert code == 0, err
        runs[name] = json.loads((out / "result.json").read_text())["identification"]
    assert runs["kept"]["conclusion"].endswith("support") and not runs["kept"]["inconsistent"]
    near, far = runs["near"], runs["far"]
    # The same camera: only the prior excess (a misfit term, its weight <= 0) reads it apart.
    assert near["log10_lr"] <= runs["kept"]["log10_lr"] + 1e-9
    assert near["conclusion"] == "undetermined"
    assert "the perspective over the face's depth" in near["inconsistent"]["perspective_mismatch"]
    assert far["log10_lr"] <= runs["kept"]["log10_lr"] + 1e-9
    assert far["conclusion"] == "undetermined" and set(far["inconsistent"]) == {
        "camera_outside_priors"}
