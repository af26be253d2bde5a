"""``lilium photo``: head orientation, the face-not-found path, the folder it writes, the
template rule of ``read_photo``, the iris distance, the skull conversion and the time."""

import json
import time

import numpy as np
import pytest
from PIL import Image

pytest.importorskip("ai_edge_litert")

from lilium.casework.build import read_photo  # noqa: E402
from lilium.cli.main import main  # noqa: E402
from lilium.geometry.rotations import rotvec_to_matrix  # noqa: E402
from lilium.photo import runtime  # noqa: E402
from lilium.photo.analysis import analyse_face  # noqa: E402
from lilium.photo.headpose import (  # noqa: E402
    euler_deg,
    head_rotation_skull2cam,
    iris_distance_mm,
    skull_face_frame,
)


@pytest.fixture(scope="module")
def astronaut():
    from skimage import data

    return data.astronaut()


def angles(image):
    found = analyse_face(np.ascontiguousarray(image))
    assert found, found.message
    return found.angles_deg


def test_a_photo_rotated_by_20_degrees_changes_roll_by_20(astronaut):
    before = angles(astronaut)["roll"]
    # PIL turns counter-clockwise on screen: negative roll in our convention (clockwise +).
    after = angles(np.asarray(Image.fromarray(astronaut).rotate(20, Image.BILINEAR)))["roll"]
    assert after - before == pytest.approx(-20, abs=3)


def test_a_mirrored_photo_flips_the_sign_of_yaw_and_roll():
    from skimage import data

    # The cameraman (scikit-image, public domain) looks well to one side: a crop of his head.
    head = np.repeat(data.camera()[40:240, 150:350, None], 3, axis=2)
    head = np.asarray(Image.fromarray(head).resize((400, 400), Image.BILINEAR))
    a, b = angles(head), angles(head[:, ::-1])
    assert abs(a["yaw"]) > 20
    assert np.sign(a["yaw"]) == -np.sign(b["yaw"])
    assert a["yaw"] == pytest.approx(-b["yaw"], abs=5)
    assert a["pitch"] == pytest.approx(b["pitch"], abs=5)


def test_no_face_writes_a_folder_to_mark_by_hand(tmp_path, capsys):
    image = tmp_path / "wall.png"
    Image.fromarray(np.full((240, 320, 3), 128, np.uint8)).save(image)
    out = tmp_path / "photo"
    assert main(["photo", str(image), "--out", str(out)]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no face found" in err[0] and "--landmarks" in err[0]
    meta = json.loads((out / "photo.json").read_text())
    assert meta["landmarks"] == {} and meta["view"] == "frontal"
    assert (out / "image.png").is_file() and (out / "review.html").is_file()
    assert not (out / "face_mask.png").exists()


def test_missing_image_is_one_line_exit_2(tmp_path, capsys):
    assert main(["photo", str(tmp_path / "none.jpg"), "--out", str(tmp_path / "p")]) == 2
    assert "file not found" in capsys.readouterr().err
    assert not (tmp_path / "p").exists()


@pytest.fixture(scope="module")
def folder(tmp_path_factory, astronaut):
    root = tmp_path_factory.mktemp("photo")
    Image.fromarray(astronaut).save(root / "astronaut.png")
    assert main(["photo", str(root / "astronaut.png"), "--out", str(root / "out")]) == 0
    return root / "out"


def test_the_folder_holds_sources_mask_and_priors(folder):
    meta = json.loads((folder / "photo.json").read_text())
    qualities = {k: s["quality"] for k, s in meta["landmark_sources"].items()}
    assert set(qualities) == set(meta["landmarks"])
    assert qualities["exocanthion_l"] == "tracked" and qualities["gonion_r"] == "template"
    assert {s["source"] for s in meta["landmark_sources"].values()} == {"automatic"}
    priors = meta["priors"]
    assert priors["source"] == "automatic"
    assert "head_rotation_skull2cam" not in priors  # needs a paired skull
    assert np.allclose(np.linalg.det(priors["head_rotation_face2cam"]), 1)
    assert "scd_mm" not in priors  # a PNG without EXIF: no focal, so no iris distance
    mask = np.asarray(Image.open(folder / "face_mask.png")) > 0
    for u, v in meta["landmarks"].values():
        assert mask[round(v), round(u)]
    assert mask[25, 225]  # the hair on top of the head
    assert not mask[500, 250] and not mask[300, 60]  # the suit and the flag


def test_read_photo_skips_unconfirmed_template_landmarks(folder, tmp_path):
    photo = read_photo(folder)
    assert "exocanthion_l" in photo.landmarks_uv and "gonion_r" not in photo.landmarks_uv
    meta = json.loads((folder / "photo.json").read_text())
    meta["landmark_sources"]["gonion_r"]["confirmed"] = True
    copy = tmp_path / "confirmed"
    copy.mkdir()
    (copy / "image.png").write_bytes((folder / "image.png").read_bytes())
    (copy / "photo.json").write_text(json.dumps(meta))
    assert "gonion_r" in read_photo(copy).landmarks_uv


def test_reviewed_landmarks_replace_the_automatic_ones(folder, tmp_path):
    reviewed = tmp_path / "landmarks.json"
    reviewed.write_text(json.dumps({"landmarks": {"nasion": [225, 97], "subnasale": [224, 132]}}))
    out = tmp_path / "again"
    assert (
        main(["photo", str(folder / "image.png"), "--out", str(out), "--landmarks", str(reviewed)])
        == 0
    )
    meta = json.loads((out / "photo.json").read_text())
    assert meta["landmarks"] == {"nasion": [225, 97], "subnasale": [224, 132]}
    assert meta["landmark_sources"]["nasion"] == {
        "source": "reviewed",
        "quality": "template",
        "confirmed": True,
    }
    assert set(read_photo(out).landmarks_uv) == {"nasion", "subnasale"}


def test_iris_distance():
    d, (lo, hi) = iris_distance_mm(1000.0, 11.7)
    assert d == pytest.approx(1000.0)
    assert lo < d < hi and hi / lo < 1.25
    with pytest.raises(ValueError, match="iris over 1 px"):
        iris_distance_mm(1000.0, 0.5)


def test_skull_conversion_recovers_the_head_rotation():
    rng = np.random.default_rng(3)
    # A skull frame whose face frame is a known rotation away from the mesh frame.
    face2skull = rotvec_to_matrix(np.array([0.2, -0.4, 0.1]))
    local = {
        "ectoconchion_r": [-45, 0, 0], "ectoconchion_l": [45, 0, 0],
        "gonion_r": [-50, 70, 40], "gonion_l": [50, 70, 40],
        "nasion": [0, -5, -5], "gnathion": [0, 110, -5],
    }  # fmt: skip
    skull = {k: face2skull @ np.array(v, float) + [3, 4, 5] for k, v in local.items()}
    face2cam = rotvec_to_matrix(rng.normal(size=3) * 0.3)
    skull2cam = head_rotation_skull2cam(face2cam, skull)
    assert np.allclose(skull2cam, face2cam @ face2skull.T, atol=1e-9)
    frankfurt = {k: v for k, v in skull.items() if k not in ("nasion", "gnathion")}
    with pytest.raises(ValueError, match="Frankfurt"):
        skull_face_frame(frankfurt)


def test_euler_convention():
    yaw, pitch, roll = euler_deg(rotvec_to_matrix(np.radians([0, 0, 10])))
    assert (yaw, pitch) == pytest.approx((0, 0), abs=1e-9) and roll == pytest.approx(10)


def test_under_two_seconds_with_model_loading(astronaut):
    runtime._model.cache_clear()
    runtime._detector.cache_clear()
    start = time.process_time()
    assert analyse_face(astronaut)
    assert time.process_time() - start < 2.0
