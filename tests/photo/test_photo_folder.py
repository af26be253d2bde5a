"""``lilium photo``'s folder: the facial curves from the face mesh (never the head mask), the
folder it owns (one image, its own files replaced, others' refused) and its one-line errors."""

import json

import numpy as np
import pytest
from PIL import Image

pytest.importorskip("ai_edge_litert")

from lilium.casework.build import read_photo  # noqa: E402
from lilium.cli.main import main  # noqa: E402


def _grey(path, w=320, h=240):
    Image.fromarray(np.full((h, w, 3), 128, np.uint8)).save(path)
    return path


@pytest.fixture(scope="module")
def astro(tmp_path_factory):
    from skimage import data

    root = tmp_path_factory.mktemp("astro")
    Image.fromarray(data.astronaut()).save(root / "astronaut.png")
    assert main(["photo", str(root / "astronaut.png"), "--out", str(root / "astro")]) == 0
    return root / "astro"


def test_the_chin_jaw_curve_follows_the_chin_not_the_collar(astro):
    curves = json.loads((astro / "face_curve.json").read_text())
    meta = json.loads((astro / "photo.json").read_text())
    assert meta["face_mask_is_head"] is True
    assert curves["curve_sources"]["chin_jaw"]["source"] == "automatic"
    chin = np.array(curves["chin_jaw"])
    lm = {k: np.array(v) for k, v in meta["landmarks"].items()}
    # Between the verticals of the mouth corners, through the chin (gnathion).
    assert (
        chin[:, 0].min() >= lm["cheilion_r"][0] - 1 and chin[:, 0].max() <= lm["cheilion_l"][0] + 1
    )
    assert np.min(np.linalg.norm(chin - lm["gnathion"], axis=1)) < 2
    assert np.max(np.linalg.norm(np.diff(chin, axis=0), axis=1)) <= 1.01
    # The head mask goes on down the neck: its lower edge is far below the chin.
    mask = np.asarray(Image.open(astro / "face_mask.png")) > 0
    u = int(round(lm["gnathion"][0]))
    assert np.nonzero(mask[:, u])[0].max() > lm["gnathion"][1] + 15
    forehead = np.array(curves["forehead"])
    assert forehead[:, 1].max() == pytest.approx(lm["glabella"][1], abs=1)
    # Read back as whole pixels along the written curve (lilium.io.curves resamples it).
    read = read_photo(astro).face_curve_uv
    gap = np.linalg.norm(read[:, None, :] - chin[None, :, :], axis=2).min(axis=1)
    assert len(read) >= 0.8 * len(chin) and gap.max() <= 1.0


def test_a_prepared_head_mask_never_gives_a_curve(astro, tmp_path):
    import shutil

    legacy = tmp_path / "legacy"  # a folder of the older lilium photo: no face_curve.json
    shutil.copytree(astro, legacy)
    (legacy / "face_curve.json").unlink()
    meta = json.loads((legacy / "photo.json").read_text())
    del meta["prepared_by"], meta["face_mask_is_head"]
    (legacy / "photo.json").write_text(json.dumps(meta))
    photo = read_photo(legacy)
    # An empty curve, not the mask's lower edge: P_pll is switched off ("curve is empty").
    assert photo.face_mask is not None and photo.face_curve_uv.shape == (0, 2)
    # A hand-made folder's mask (no landmark_sources) still gives the curve (docs/method/lilium.md).
    del meta["landmark_sources"]
    (legacy / "photo.json").write_text(json.dumps(meta))
    assert read_photo(legacy).face_curve_uv is None


def test_a_second_photo_replaces_the_first_one_s_files(tmp_path, capsys):
    folder = tmp_path / "D"
    assert main(["photo", str(_grey(tmp_path / "A.png")), "--out", str(folder)]) == 3
    Image.open(tmp_path / "A.png").save(tmp_path / "B.jpg")
    assert main(["photo", str(tmp_path / "B.jpg"), "--out", str(folder)]) == 3
    assert not (folder / "image.png").exists() and (folder / "image.jpg").is_file()
    # Rerun on the folder's own image: it stays in place.
    assert main(["photo", str(folder / "image.jpg"), "--out", str(folder)]) == 3
    assert (folder / "image.jpg").is_file() and (folder / "photo.json").is_file()
    # A user's folder holding only the photo, named as docs/contract.md names it.
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "image.jpg").write_bytes((folder / "image.jpg").read_bytes())
    assert main(["photo", str(mine / "image.jpg"), "--out", str(mine)]) == 3
    assert (mine / "photo.json").is_file() and "SameFile" not in capsys.readouterr().err


def test_two_images_in_a_photo_folder_are_an_error(astro, tmp_path):
    import shutil

    folder = tmp_path / "two"
    shutil.copytree(astro, folder)
    Image.open(folder / "image.png").convert("RGB").save(folder / "image.jpg")
    with pytest.raises(ValueError, match=r"two: holds image.png and image.jpg; keep only"):
        read_photo(folder)


def test_a_hand_made_folder_is_refused(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    _grey(folder / "image.png")
    (folder / "photo.json").write_text(json.dumps({"view": "frontal", "landmarks": {}}))
    before = (folder / "photo.json").read_text()
    assert main(["photo", str(_grey(tmp_path / "B.png")), "--out", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds image.png, photo.json, not written by lilium photo" in err[0]
    assert "give a new or empty folder with --out" in err[0]
    assert (folder / "photo.json").read_text() == before


@pytest.mark.parametrize(
    "make, needle",
    [
        (lambda d: _grey(d / "dot.png", 1, 1), "the photo is 1x1 px, too small"),
        (lambda d: d, "is a folder, not an image"),
    ],
)
def test_bad_images_are_one_line(tmp_path, capsys, make, needle):
    image = make(tmp_path)
    assert main(["photo", str(image), "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err
    assert not (tmp_path / "p").exists()


def _landmarks(folder):
    meta = json.loads((folder / "photo.json").read_text())
    return meta, {k: np.array(v) for k, v in meta["landmarks"].items()}


def test_an_upside_down_face_is_prepared_upright(astro, tmp_path, capsys):
    from skimage import data

    Image.fromarray(data.astronaut()[::-1, ::-1]).save(tmp_path / "turned.png")
    out = tmp_path / "turned"
    assert main(["photo", str(tmp_path / "turned.png"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning photo_turned:" in err and "turned by 180 degrees" in err
    meta, turned = _landmarks(out)
    _, upright = _landmarks(astro)
    assert np.array_equal(np.asarray(Image.open(out / "image.png")), data.astronaut())
    for name in ("exocanthion_l", "exocanthion_r", "subnasale", "cheilion_l"):
        assert np.linalg.norm(turned[name] - upright[name]) < 3, name
    assert abs(meta["priors"]["head_angles_deg"]["roll"]) < 10


def test_the_exif_orientation_is_honoured(astro, tmp_path, capsys):
    from skimage import data

    exif = Image.Exif()
    exif[0x0112] = 6  # "rotate 90 degrees clockwise to display": stored turned anticlockwise
    Image.fromarray(np.rot90(data.astronaut(), 1)).save(
        tmp_path / "side.jpg", exif=exif, quality=95
    )
    out = tmp_path / "side"
    assert main(["photo", str(tmp_path / "side.jpg"), "--out", str(out)]) == 0
    assert "photo_turned" not in capsys.readouterr().err
    _, found = _landmarks(out)
    _, upright = _landmarks(astro)
    assert read_photo(out).image_size_wh == (512, 512)
    for name in ("exocanthion_l", "exocanthion_r", "subnasale"):
        assert np.linalg.norm(found[name] - upright[name]) < 4, name


def test_two_faces_say_which_was_taken_and_how_to_take_the_other(tmp_path, capsys):
    from skimage import data

    head = data.astronaut()[0:240, 110:340]
    pair = np.full((240, 520, 3), 200, np.uint8)
    pair[:, 10:240], pair[:, 280:510] = head, head
    Image.fromarray(pair).save(tmp_path / "pair.png")
    out = tmp_path / "pair"
    assert main(["photo", str(tmp_path / "pair.png"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert (
        "warning several_faces:" in err and "2 faces in the photo (numbered from the left)" in err
    )
    took = 1 if "took face 1" in err else 2
    other = 3 - took
    assert f"give --face {other} for box u" in err
    _, first = _landmarks(out)
    assert main(["photo", str(tmp_path / "pair.png"), "--out", str(out), "--face", str(other)]) == 0
    _, second = _landmarks(out)
    shift = (second["subnasale"] - first["subnasale"])[0]
    assert abs(abs(shift) - 270) < 5  # the other head, 270 px along
    capsys.readouterr()
