"""Ground truth of generated photos: read in one place, scored with evaluation.score."""

import json
import math

import numpy as np
import pytest

from lilium.casework.build import read_photo
from lilium.evaluation import score
from lilium.io.truth import read_facial_landmarks, read_ground_truth


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    from lilium.synthetic.dataset import generate_dataset

    root = tmp_path_factory.mktemp("truth")
    index = generate_dataset(root, 1, 1, seed=0, experiments=("C",), workers=1)
    subject_dir = root / index["subjects"][0]["path"]
    return index, subject_dir, [root / p["paths"]["C"] for p in index["photos"]]


def test_true_camera_of_a_generated_photo_scores_zero(generated):
    index, subject_dir, photo_dirs = generated
    for entry, photo_dir in zip(index["photos"], photo_dirs, strict=True):
        truth = read_ground_truth(photo_dir, subject_dir)
        assert truth.subject == entry["subject"] == subject_dir.name
        assert truth.photo == photo_dir.name and truth.noise == "C"
        photo = read_photo(photo_dir, load_image=False)
        assert truth.image_size_wh == photo.image_size_wh
        assert set(photo.landmarks_uv) <= set(truth.visible) <= set(truth.landmarks_noise_free)
        facial = truth.facial_landmarks_mm
        names = [n for n in truth.landmarks_noise_free if n in facial]
        assert len(names) >= 10
        uv = truth.camera.project(np.array([facial[n] for n in names]))
        np.testing.assert_allclose(uv, [truth.landmarks_noise_free[n] for n in names], atol=1e-6)
        assert score(truth.camera, truth).bpe_mm == pytest.approx(0.0, abs=1e-6)
        moved = truth.camera.from_rt(
            truth.camera.R,
            truth.camera.t + [5.0, 0.0, 0.0],
            truth.camera.focal_px,
            truth.camera.principal_point_px,
        )
        assert score(moved, truth).bpe_mm > 1.0


def test_no_bpe_without_a_camera_or_3d_landmarks(generated):
    _, subject_dir, photo_dirs = generated
    truth = read_ground_truth(photo_dirs[0])
    assert truth.facial_landmarks_mm is None
    assert math.isnan(score(truth.camera, truth).bpe_mm)
    assert math.isnan(score(None, read_ground_truth(photo_dirs[0], subject_dir)).bpe_mm)


def test_principal_point_defaults_to_the_image_centre(case):
    _, photo_dir = case  # the stand-in's ground truth has no principal point or image size
    truth = read_ground_truth(photo_dir)
    assert truth.image_size_wh == (1200, 900)
    np.testing.assert_allclose(truth.camera.principal_point_px, [599.5, 449.5])


def _edit_truth(photo_dir, change):
    path = photo_dir / "photo.json"
    data = json.loads(path.read_text())
    change(data["ground_truth"])
    path.write_text(json.dumps(data))


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda gt: gt.pop("subject"), r"ground_truth.subject must be the subject's id"),
        (lambda gt: gt.update(focal_px="x"), r"ground_truth: focal_px and principal_point_px"),
        (lambda gt: gt.update(skull2cam=[[1, 0], [0, 1]]), r"ground_truth.skull2cam"),
        (lambda gt: gt.update(scd_mm=-1), r"ground_truth.scd_mm must be a positive number"),
        (lambda gt: gt.pop("noise"), r"ground_truth.noise must be the experiment letter"),
        (
            lambda gt: gt.pop("landmarks_noise_free"),
            r"ground_truth.landmarks_noise_free must be an object",
        ),
        (
            lambda gt: gt["landmarks_noise_free"].update(chin=[1, 2]),
            r"ground_truth.landmarks_noise_free: unknown facial landmark 'chin'",
        ),
    ],
)
def test_malformed_ground_truth_names_the_file_and_field(case, change, match):
    _, photo_dir = case
    _edit_truth(photo_dir, change)
    with pytest.raises(ValueError, match=r"photo.json: " + match):
        read_ground_truth(photo_dir)


def test_missing_ground_truth_or_bad_facial_landmarks(case):
    subject_dir, photo_dir = case
    path = photo_dir / "photo.json"
    data = json.loads(path.read_text())
    del data["ground_truth"]
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=r"photo.json: no ground_truth object"):
        read_ground_truth(photo_dir)
    (subject_dir / "facial_landmarks.json").write_text('{"landmarks": {"nasion": [1, 2]}}')
    with pytest.raises(
        ValueError, match=r"facial_landmarks.json: landmarks: 'nasion' must have 3 numeric"
    ):
        read_facial_landmarks(subject_dir)
    (subject_dir / "facial_landmarks.json").unlink()
    assert read_facial_landmarks(subject_dir) is None
