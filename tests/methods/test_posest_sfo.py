import json

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.cli.main import main
from lilium.geometry import Camera, geodesic_angle_deg
from lilium.inputs import Photo
from lilium.io.truth import read_ground_truth
from lilium.methods.pairs import correspondences
from lilium.methods.posest_sfo import mean_depth_landmarks, posest_sfo


def test_recovers_the_camera_when_soft_tissue_is_the_mean(case):
    """Photo landmarks made from mean-depth facial landmarks: an exact PnP+f problem."""
    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    truth = read_ground_truth(photo_dir).camera
    skull2cam, focal = truth.skull2cam, truth.focal_px
    corr = correspondences(skull, photo)
    facial = mean_depth_landmarks(corr)
    uv = Camera(skull2cam, focal, [599.5, 449.5]).project(facial)
    exact = Photo(
        "exact", photo.image_size_wh, "frontal", dict(zip(corr.facial_names, uv, strict=True))
    )
    result = posest_sfo(skull, exact)
    assert result
    assert abs(result.camera.focal_px - focal) / focal < 1e-6
    assert result.fitness < 1e-6
    assert geodesic_angle_deg(result.camera.R, skull2cam[:3, :3]) < 1e-6


def test_is_deterministic_and_close_on_the_standin(case):
    skull, photo = read_skull(case[0]), read_photo(case[1])
    a, b = posest_sfo(skull, photo), posest_sfo(skull, photo)
    np.testing.assert_array_equal(a.camera.skull2cam, b.camera.skull2cam)
    # The stand-in's true depths are the means +- 0.5 mm: the camera is close, not exact.
    assert a.fitness < 3.0
    assert abs(a.camera.focal_px - 2600) / 2600 < 0.15


def test_failure_is_a_value(case):
    skull, photo = read_skull(case[0]), read_photo(case[1])
    names = list(photo.landmarks_uv)[:6]
    scrambled = {n: np.array([10.0 + 5 * i, 10.0]) for i, n in enumerate(names)}  # collinear
    bad = Photo("bad", photo.image_size_wh, "frontal", scrambled)
    result = posest_sfo(skull, bad)
    assert not result and result.error.startswith("POSEST failed")
    assert result.to_dict()["camera"] is None and "error" in result.to_dict()


def test_cli_writes_result_json_and_overlay(case, tmp_path):
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    argv = [
        "sfo",
        "--method",
        "posest-sfo",
        "--skull",
        str(subject_dir),
        "--photo",
        str(photo_dir),
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    result = json.loads((out / "result.json").read_text())
    assert set(result) >= {
        "method",
        "variant",
        "seed",
        "subject",
        "photo",
        "camera",
        "fitness",
        "terms",
        "facial_landmarks_3d",
        "seconds",
    }
    assert set(result["terms"]) == {"mse_pix", "p_cam", "p_skof", "p_pll"}
    assert set(result["camera"]) == {"focal_px", "principal_point_px", "skull2cam"}
    assert np.array(result["camera"]["skull2cam"]).shape == (4, 4)
    assert result["camera"]["principal_point_px"] == [599.5, 449.5]
    assert result["subject"] == "standin" and result["method"] == "posest-sfo"
    from PIL import Image

    overlay = np.asarray(Image.open(out / "overlay.png"))
    photo = np.asarray(Image.open(photo_dir / "image.png"))
    assert overlay.shape == photo.shape and np.abs(overlay.astype(int) - photo).sum() > 0


def test_cli_bad_input_is_one_line_error(case, tmp_path, capsys):
    subject_dir, _ = case
    code = main(
        [
            "sfo",
            "--skull",
            str(subject_dir),
            "--photo",
            str(tmp_path / "missing"),
            "--out",
            str(tmp_path / "o"),
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "missing: --photo not found" in err
