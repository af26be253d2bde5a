"""``lilium photo`` on group photos (small faces on a large canvas, numbered from the left,
``--face N``, ``photo.json``'s ``faces``) and the resolution MEPROCS asks for (``resolution``,
warning ``low_resolution``)."""

import json

import cv2
import numpy as np
import pytest
from PIL import Image

pytest.importorskip("ai_edge_litert")

from lilium.cli.main import main  # noqa: E402

#: The astronaut's head (rows, columns) and the detector's face box in it (u0, v0, width), px.
HEAD = (slice(0, 240), slice(110, 340))
FACE_IN_HEAD = (68.0, 81.0, 94.0)


def group_photo(path, faces_px, size_wh=(2000, 1400)):
    """A gray canvas with the astronaut's head pasted side by side, each face ``faces_px[k]``
    wide (the detector's box); returns the face boxes ``(K, 4)`` [u0, v0, u1, v1]."""
    from skimage import data

    w, h = size_wh
    canvas = np.full((h, w, 3), 150, np.uint8)
    boxes = []
    for k, face_px in enumerate(faces_px):
        s = face_px / FACE_IN_HEAD[2]
        head = cv2.resize(data.astronaut()[HEAD], None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
        u0, v0 = int(w * (k + 1) / (len(faces_px) + 1) - head.shape[1] / 2), h // 3
        canvas[v0 : v0 + head.shape[0], u0 : u0 + head.shape[1]] = head
        fu, fv, fw = (x * s for x in FACE_IN_HEAD)
        boxes.append([u0 + fu, v0 + fv, u0 + fu + fw, v0 + fv + fw])
    Image.fromarray(canvas).save(path)
    return np.array(boxes)


def _nose(folder):
    return np.array(json.loads((folder / "photo.json").read_text())["landmarks"]["subnasale"])


def test_two_small_faces_on_a_large_photo_are_found_numbered_and_taken(tmp_path, capsys):
    # 60 and 120 px faces, 3 and 6 % of the photo's width: the whole photo squashed into the
    # detector's 128 px shows them 4 and 8 px wide, and no face was found.
    truth = group_photo(tmp_path / "group.png", [60, 120])
    out = tmp_path / "group"
    assert main(["photo", str(tmp_path / "group.png"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert (
        "warning several_faces:" in err and "2 faces in the photo (numbered from the left)" in err
    )
    meta = json.loads((out / "photo.json").read_text())
    faces = meta["faces"]
    assert [f["number"] for f in faces] == [1, 2]
    for face, box in zip(faces, truth, strict=True):
        assert set(face) == {"number", "box_px", "width_px", "score"}
        centre = (np.array(face["box_px"][:2]) + face["box_px"][2:]) / 2
        assert np.linalg.norm(centre - (box[:2] + box[2:]) / 2) < 0.15 * (box[2] - box[0])
        assert face["width_px"] == pytest.approx(box[2] - box[0], rel=0.2)
        assert face["score"] >= 0.5
        assert f"for box u {round(face['box_px'][0])}-" in err or (
            f"at box u {round(face['box_px'][0])}-" in err
        )
    for number in (1, 2):
        assert (
            main(["photo", str(tmp_path / "group.png"), "--out", str(out), "--face", str(number)])
            == 0
        )
        u0, v0, u1, v1 = truth[number - 1]
        u, v = _nose(out)
        assert u0 < u < u1 and v0 < v < v1, number
        assert "several_faces" in capsys.readouterr().err
    assert main(["photo", str(tmp_path / "group.png"), "--out", str(out), "--face", "3"]) == 2
    assert "the photo has 2 face(s); give a number from 1 to 2" in capsys.readouterr().err


def test_one_face_writes_one_face_and_no_several_faces(tmp_path, capsys):
    group_photo(tmp_path / "one.png", [90], size_wh=(1600, 1200))
    assert main(["photo", str(tmp_path / "one.png"), "--out", str(tmp_path / "one")]) == 0
    assert "several_faces" not in capsys.readouterr().err
    (face,) = json.loads((tmp_path / "one" / "photo.json").read_text())["faces"]
    assert face["number"] == 1


def test_a_small_portrait_is_below_the_meprocs_resolution(tmp_path, capsys):
    from skimage import data

    small = cv2.resize(data.astronaut(), (320, 320), interpolation=cv2.INTER_AREA)
    Image.fromarray(small).save(tmp_path / "small.png")
    out = tmp_path / "small"
    assert main(["photo", str(tmp_path / "small.png"), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    meta = json.loads((out / "photo.json").read_text())
    resolution = meta["resolution"]
    # The astronaut's pupils are 43 px apart at 512 px: 27 px here; her face 92 px wide: 58 px.
    assert resolution["interpupillary_px"] == pytest.approx(43.2 * 320 / 512, rel=0.1)
    assert resolution["head_width_px"] == pytest.approx(92.3 * 320 / 512, rel=0.1)
    (warning,) = [w for w in meta["warnings"] if w["code"] == "low_resolution"]
    assert "px between the pupils (minimum 90)" in warning["message"]
    assert "px across the head (minimum 180)" in warning["message"]
    assert "warning low_resolution:" in captured.err
    assert "px between the pupils" in captured.out and "px across the head" in captured.out


def test_a_large_portrait_reaches_the_meprocs_resolution(tmp_path, capsys):
    from skimage import data

    large = cv2.resize(data.astronaut(), (1280, 1280), interpolation=cv2.INTER_CUBIC)
    Image.fromarray(large).save(tmp_path / "large.png")
    out = tmp_path / "large"
    assert main(["photo", str(tmp_path / "large.png"), "--out", str(out)]) == 0
    assert "low_resolution" not in capsys.readouterr().err
    meta = json.loads((out / "photo.json").read_text())
    assert meta["resolution"]["interpupillary_px"] >= 90
    assert meta["resolution"]["head_width_px"] >= 180
    assert all(w["code"] != "low_resolution" for w in meta.get("warnings", []))


@pytest.mark.parametrize("shape", [(32, 10400), (10400, 32), (32, 32), (385, 400)])
def test_the_pyramid_holds_thin_and_tiny_photos(shape):
    from lilium.photo import runtime

    image = np.random.default_rng(0).integers(0, 255, (*shape, 3), np.uint8)
    levels = list(runtime.image_pyramid(image))
    assert all(level.shape[0] >= 1 and level.shape[1] >= 1 for level, _ in levels)
    assert max(levels[-1][0].shape[:2]) == runtime.DETECTOR_INPUT_PX  # the whole photo, last
    assert runtime.detect_faces(image) == []
