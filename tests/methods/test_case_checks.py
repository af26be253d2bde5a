"""End to end, what the user's trial of issue 18 did, on generated data: a skull with mirrored
labels, a photo without priors, a wrong ``--view``, an EXIF focal length that cannot be used;
each gives the error or the warning of docs/checks.md, in ``result.json``, on the console and
in the report."""

import json
import shutil

import pytest
from PIL import Image

from cli_helpers import _run
from lilium.softtissue.landmarks import side, twin
from lilium.synthetic.dataset import generate_dataset


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """One generated subject with a frontal and a lateral Exp. C photo."""
    root = tmp_path_factory.mktemp("generated")
    generate_dataset(root, 1, 1, seed=0, experiments=("C",), workers=1)
    index = json.loads((root / "dataset.json").read_text())
    subject = root / index["subjects"][0]["path"]
    photos = {p["view"].split("_")[0]: root / p["paths"]["C"] for p in index["photos"]}
    return subject, photos["frontal"], photos["lateral"]



def _mirrored_skull(subject, folder):
    shutil.copytree(subject, folder)
    path = folder / "cranial_landmarks.json"
    data = json.loads(path.read_text())
    data["landmarks"] = {(twin(k) if side(k) else k): v for k, v in data["landmarks"].items()}
    path.write_text(json.dumps(data))
    return path


def test_generated_case_trips_no_rule(generated, tmp_path, capsys):
    subject, frontal, lateral = generated
    for photo in (frontal, lateral):
        out = tmp_path / photo.name
        code, stdout, err = _run(
            ["sfo", "--skull", subject, "--photo", photo, "--out", out, "--no-overlay"], capsys
        )
        assert code == 0, err
        result = json.loads((out / "result.json").read_text())
        codes = {w["code"] for w in result["warnings"]}
        assert not codes & {"view_mismatch", "no_focal_prior", "no_scd_prior"}
        assert result["priors"]["focal_px"]["source"] == "photo.json"
        assert result["landmark_error"]["mean_mm"] > 0


def test_mirrored_skull_labels_stop_before_any_sfo(generated, tmp_path, capsys):
    subject, frontal, _ = generated
    landmarks = _mirrored_skull(subject, tmp_path / "mirrored")
    out = tmp_path / "out"
    for command in ("sfo", "case"):
        argv = [command, "--skull", landmarks.parent, "--photo", frontal, "--out", out]
        code, _, err = _run(argv + ["--method", "posest-sfo"], capsys)
        assert code == 2
        assert f"{landmarks}: left and right are mirrored" in err
        assert "swap every _l and _r name in this file" in err
        assert "Traceback" not in err
    assert not (out / "result.json").exists() and not (out / "report.html").exists()


def test_photo_without_priors_and_a_wrong_view(generated, tmp_path, capsys):
    subject, frontal, _ = generated
    folder = tmp_path / "files"
    folder.mkdir()
    meta = json.loads((frontal / "photo.json").read_text())
    rows = [f"{n},{u},{v}" for n, (u, v) in meta["landmarks"].items()]
    (folder / "front.csv").write_text("name,u,v\n" + "\n".join(rows) + "\n")
    shutil.copy(frontal / "image.png", folder / "front.png")
    out = tmp_path / "out"
    argv = ["case", "--skull", subject, "--photo", folder / "front.png", "--view", "lateral_left"]
    argv += ["--method", "posest-sfo", "--method", "lilium", "--variant", "base"]
    argv += ["--generations", "3", "--population", "8", "--out", out]
    code, stdout, err = _run(argv, capsys)
    assert code == 0, err
    for tag in ("posest-sfo", "lilium-base"):
        result = json.loads((out / "front" / tag / "result.json").read_text())
        codes = [w["code"] for w in result["warnings"]]
        assert {"no_focal_prior", "no_scd_prior", "view_mismatch"} <= set(codes)
        assert result["priors"]["focal_px"] == {"range": None, "source": "none"}
        assert set(result["landmark_error"]) == {"mean_px", "mean_mm", "per_landmark_px"}
    assert "warning view_mismatch:" in stdout and "warning no_focal_prior:" in stdout
    assert "declares the view 'lateral_left'" in stdout
    report = (out / "report.html").read_text()
    assert "view_mismatch" in report and "no_focal_prior" in report
    assert "mean error mm" in report


def test_exif_focal_length_that_cannot_be_used(generated, tmp_path, capsys):
    subject, frontal, _ = generated
    photo = tmp_path / "photo"
    shutil.copytree(frontal, photo)
    meta = json.loads((photo / "photo.json").read_text())
    del meta["priors"]["focal_px"]
    (photo / "photo.json").write_text(json.dumps(meta))
    exif = Image.Exif()
    exif.get_ifd(0x8769)[0x920A] = 50.0  # FocalLength only: no 35 mm value, no sensor
    with Image.open(frontal / "image.png") as im:
        im.convert("RGB").save(photo / "image.jpg", exif=exif, quality=95)
    (photo / "image.png").unlink()
    out = tmp_path / "out"
    argv = ["sfo", "--skull", subject, "--photo", photo, "--out", out, "--no-overlay"]
    code, _, err = _run(argv, capsys)
    assert code == 0, err
    result = json.loads((out / "result.json").read_text())
    unusable = [w for w in result["warnings"] if w["code"] == "exif_focal_unusable"]
    assert len(unusable) == 1 and "--sensor-width-mm" in unusable[0]["message"]
    assert "warning exif_focal_unusable:" in err
    assert result["priors"]["focal_px"]["source"] == "none"
    assert result["priors"]["scd_mm"]["source"] == "photo.json"
    # The option the warning names lifts it: the focal prior then comes from EXIF.
    out2 = tmp_path / "out2"
    argv = ["case", "--skull", subject, "--photo", photo, "--method", "posest-sfo"]
    code, stdout, err = _run(argv + ["--sensor-width-mm", "36", "--out", out2], capsys)
    assert code == 0, err
    result = json.loads((out2 / photo.name / "posest-sfo" / "result.json").read_text())
    assert result["priors"]["focal_px"]["source"] == "exif"
    assert "exif_focal_unusable" not in stdout
