"""``lilium case`` with photos prepared by ``lilium photo`` (docs/method/photo.md): a prepared
folder
as ``--photo``, ``--auto-landmarks`` on a bare image, the automatic priors' provenance, the
template rule, the report's "automatic, unreviewed" line and the one-line errors.

The skull is the stand-in of ``standin_case`` and the photo scikit-image's astronaut: the SFO's
numbers mean nothing here, only the flow is tested.
"""

import json
import shutil
import sys

import numpy as np
import pytest
from PIL import Image
from PIL.TiffImagePlugin import IFDRational

from cli_helpers import _edit_json, _run
from lilium.cli.main import main
from lilium.geometry.rotations import geodesic_angle_deg
from standin_case import make_standin_case

try:
    import ai_edge_litert  # noqa: F401

    HAVE_LITERT = True
except ImportError:
    HAVE_LITERT = False

needs_litert = pytest.mark.skipif(not HAVE_LITERT, reason="needs lilium[photo] (ai-edge-litert)")

#: A DE budget that only shows the flow.
SMALL_DE = ["--generations", "3", "--population", "16"]


def _result(out, photo_id, tag):
    return json.loads((out / photo_id / tag / "result.json").read_text())


@pytest.fixture(scope="module")
def standin(tmp_path_factory):
    subject_dir, _ = make_standin_case(tmp_path_factory.mktemp("standin"), seed=0)
    return subject_dir


@pytest.fixture(scope="module")
def portrait(tmp_path_factory):
    """The astronaut as a JPEG with EXIF (FocalLengthIn35mmFilm 50 mm) in a folder of its own."""
    from skimage import data

    folder = tmp_path_factory.mktemp("user")
    exif = Image.Exif()
    exif.get_ifd(0x8769)[0xA405] = 50
    exif.get_ifd(0x8769)[0x920A] = IFDRational(9.0)
    Image.fromarray(data.astronaut()).save(folder / "astronaut.jpg", quality=95, exif=exif)
    return folder / "astronaut.jpg"


@pytest.fixture(scope="module")
def prepared(tmp_path_factory, portrait):
    folder = tmp_path_factory.mktemp("prepared") / "astro"
    assert main(["photo", str(portrait), "--out", str(folder)]) == 0
    return folder


@needs_litert
def test_a_prepared_folder_is_a_photo_folder(standin, prepared, tmp_path, capsys):
    from lilium.casework.build import read_skull
    from lilium.photo.headpose import head_rotation_skull2cam

    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--photo", prepared, *SMALL_DE, "--out", out]
    code, stdout, err = _run(argv, capsys)
    assert code == 0, err
    assert "astro: facial landmarks automatic, unreviewed" in stdout
    meta = json.loads((prepared / "photo.json").read_text())
    result = _result(out, "astro", "lilium-skof+pll")
    priors = result["priors"]
    # Every prior lilium photo found keeps its provenance (docs/checks.md).
    assert priors["focal_px"]["source"] == "automatic"
    assert priors["focal_px"]["range"] == pytest.approx(meta["priors"]["focal_px"])
    assert priors["scd_mm"]["source"] == "automatic"
    assert priors["scd_mm"]["range"] == pytest.approx(meta["priors"]["scd_mm"])
    # The face frame's orientation, turned into skull2cam through the stand-in's frame.
    head = priors["head_rotation"]
    assert head["source"] == "automatic" and head["tolerance_deg"] == 15
    skull = read_skull(standin)
    expected = head_rotation_skull2cam(meta["priors"]["head_rotation_face2cam"], skull.landmarks_mm)
    assert np.allclose(head["skull2cam"], expected)
    assert geodesic_angle_deg(np.asarray(head["skull2cam"]), np.eye(3)) > 90  # not face2cam
    # Tracked landmarks used, template ones (unconfirmed) not.
    quality = {k: s["quality"] for k, s in meta["landmark_sources"].items()}
    used = set(result["landmark_error"]["per_landmark_px"])
    assert used and all(quality[k] == "tracked" for k in used)
    assert "gonion_r" in quality and "zygion_l" in quality
    text = (out / "report.html").read_text()
    assert text.count("landmarks-origin") == 2  # in the summary and above the landmark table
    assert "Photo <b>astro</b>: facial landmarks automatic, unreviewed" in text
    assert f"check them in {prepared / 'review.html'}" in text
    assert "automatic, tracked" in text and "automatic, template" not in text
    assert "to skull2cam through the skull&#x27;s midline" in text


@needs_litert
def test_a_command_line_focal_gives_the_iris_distance(standin, prepared, tmp_path, capsys):
    from lilium.photo.headpose import iris_distance_mm

    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--photo", prepared, "--method", "posest-sfo"]
    code, _, err = _run(argv + ["--focal-px", "900", "1100", "--out", out], capsys)
    assert code == 0, err
    priors = _result(out, "astro", "posest-sfo")["priors"]
    assert priors["focal_px"] == {"range": [900, 1100], "source": "command line"}
    iris = json.loads((prepared / "photo.json").read_text())["priors"]["iris_diameter_px"]
    lo, hi = iris_distance_mm(900, iris)[1][0], iris_distance_mm(1100, iris)[1][1]
    assert priors["scd_mm"]["source"] == "automatic"
    assert priors["scd_mm"]["range"] == pytest.approx([lo, hi])
    code, _, err = _run(argv + ["--scd-mm", "500", "900", "--out", out], capsys)
    assert code == 0, err
    assert _result(out, "astro", "posest-sfo")["priors"]["scd_mm"]["source"] == "command line"


@needs_litert
def test_a_focal_that_puts_the_camera_too_far_is_implausible(standin, prepared, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--photo", prepared, "--method", "posest-sfo"]
    code, _, err = _run(argv + ["--focal-px", "40000", "42000", "--out", out], capsys)
    assert code == 0, err
    result = _result(out, "astro", "posest-sfo")
    (warning,) = [w for w in result["warnings"] if w["code"] == "implausible_prior"]
    assert "outside the 0.3-10 m of a portrait" in warning["message"]
    assert result["priors"]["focal_px"]["source"] == "command line"  # stated: kept


@needs_litert
def test_confirmed_template_points_are_used(standin, prepared, tmp_path, capsys):
    folder = tmp_path / "reviewed"
    shutil.copytree(prepared, folder)
    meta = json.loads((folder / "photo.json").read_text())
    meta["landmark_sources"]["gonion_r"]["confirmed"] = True
    (folder / "photo.json").write_text(json.dumps(meta))
    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--photo", folder, "--method", "posest-sfo", "--out", out]
    code, _, err = _run(argv, capsys)
    assert code == 0, err
    used = _result(out, "reviewed", "posest-sfo")["landmark_error"]["per_landmark_px"]
    assert "gonion_r" in used and "gonion_l" not in used
    assert "automatic, template" in (out / "report.html").read_text()


@needs_litert
def test_a_skull_without_its_frame_switches_the_head_prior_off(standin, prepared, tmp_path, capsys):
    subject = tmp_path / "subject"
    shutil.copytree(standin, subject)
    lm_file = subject / "cranial_landmarks.json"
    cranial = json.loads(lm_file.read_text())
    for name in ("nasion", "glabella"):  # no upper midline, no porion: no face frame
        del cranial["landmarks"][name]
    lm_file.write_text(json.dumps(cranial))
    out = tmp_path / "out"
    argv = ["case", "--skull", subject, "--photo", prepared, "--method", "posest-sfo"]
    code, stdout, err = _run(argv + ["--out", out], capsys)
    assert code == 0, err
    assert "automatic head-orientation prior switched off" in stdout
    head = _result(out, "astro", "posest-sfo")["priors"]["head_rotation"]
    assert head == {"skull2cam": None, "tolerance_deg": None, "source": "none"}
    assert "switched off (automatic: face mesh" in (out / "report.html").read_text()


@needs_litert
def test_auto_landmarks_prepares_a_bare_photo_in_the_output_folder(
    standin, portrait, tmp_path, capsys
):
    before = sorted(p.name for p in portrait.parent.iterdir())
    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--auto-landmarks", "--photo", portrait]
    code, stdout, err = _run(argv + ["--method", "posest-sfo", "--out", out], capsys)
    assert code == 0, err
    assert sorted(p.name for p in portrait.parent.iterdir()) == before  # nothing beside it
    prepared = out / "astronaut" / "prepared"
    assert (prepared / "photo.json").is_file() and (prepared / "review.html").is_file()
    assert "astronaut: lilium photo: 10 tracked and 11 template landmarks" in stdout
    result = _result(out, "astronaut", "posest-sfo")
    assert {v["source"] for v in result["priors"].values()} == {"automatic"}
    sources = json.loads((prepared / "photo.json").read_text())["landmark_sources"]
    used = result["landmark_error"]["per_landmark_px"]
    assert all(sources[k]["quality"] == "tracked" for k in used)
    text = (out / "report.html").read_text()
    line = "facial landmarks automatic, unreviewed: all 10 placed by lilium photo"
    assert f"Photo <b>astronaut</b>: {line}" in text
    assert "check them in astronaut/prepared/review.html" in text  # relative: the folder moves
    assert '<a href="astronaut/prepared/review.html">review page</a>' in text
    assert "--auto-landmarks" in text  # the command line in the provenance


@needs_litert
def test_auto_landmarks_without_a_face_is_one_line(standin, tmp_path, capsys):
    image = tmp_path / "wall.png"
    Image.fromarray(np.full((240, 320, 3), 128, np.uint8)).save(image)
    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--auto-landmarks", "--photo", image, "--out", out]
    code, _, err = _run(argv, capsys)
    assert code == 2
    (line,) = err.strip().splitlines()
    assert str(image) in line and "found no face" in line
    assert "mark its landmarks by hand" in line and "lilium photo" in line
    assert not (out / "report.html").exists()


def test_auto_landmarks_without_the_extra_fails_at_once(standin, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "ai_edge_litert", None)
    monkeypatch.setitem(sys.modules, "ai_edge_litert.interpreter", None)
    image = tmp_path / "photo.png"
    Image.fromarray(np.zeros((240, 320, 3), np.uint8)).save(image)
    out = tmp_path / "out"
    argv = ["case", "--skull", standin, "--auto-landmarks", "--photo", image, "--out", out]
    code, _, err = _run(argv, capsys)
    assert code == 2
    (line,) = err.strip().splitlines()
    assert "pip install 'lilium[photo]'" in line
    assert not out.exists()


def test_a_bare_photo_without_auto_landmarks_names_the_option(standin, tmp_path, capsys):
    image = tmp_path / "photo.png"
    Image.fromarray(np.zeros((240, 320, 3), np.uint8)).save(image)
    argv = ["case", "--skull", standin, "--photo", image, "--out", tmp_path / "out"]
    code, _, err = _run(argv, capsys)
    assert code == 2 and "--photo-landmarks FILE" in err and "--auto-landmarks" in err


def test_the_landmark_line_says_what_was_reviewed(tmp_path):
    from lilium.casework.prepared import landmark_origin
    from lilium.inputs import Photo
    from lilium.io.prepared import PreparedFacts

    photo = Photo("p", (640, 480), "frontal", {"nasion": np.zeros(2), "subnasale": np.ones(2)})
    reviewed = {"source": "reviewed", "quality": "template", "confirmed": True}
    facts = PreparedFacts(
        {"nasion": reviewed, "subnasale": {"source": "automatic", "quality": "tracked"}}, {}
    )
    line = landmark_origin(photo, facts).line()
    assert line.startswith("facial landmarks automatic, unreviewed: 1 of 2 placed")
    assert "(lilium photo, review.html)" in line  # no review page in this folder
    facts = PreparedFacts({"nasion": reviewed, "subnasale": reviewed}, {})
    assert landmark_origin(photo, facts).line() == "facial landmarks reviewed (2 confirmed)"
    assert landmark_origin(photo, None) is None


@needs_litert
def test_an_sfo_without_a_chin_pair_or_curve_says_the_chin_is_unconstrained(
    standin, prepared, tmp_path, capsys
):
    """Issue 25 item 6: with only the midface points (the chin points left unconfirmed: template
    since issue 55) the overlay's chin can lie anywhere: result.json, the console and the
    report say so; P_pll's chin-jaw curve or a confirmed chin pair lifts it."""
    midface = tmp_path / "midface"
    shutil.copytree(prepared, midface)

    def chin_as_template(data):
        for name in ("pogonion", "gnathion"):
            data["landmark_sources"][name]["quality"] = "template"

    _edit_json(midface / "photo.json", chin_as_template)
    skull = tmp_path / "skull"  # the stand-in with the landmarks that cut P_pll's region
    shutil.copytree(standin, skull)

    def mandible(data):
        from standin_case import SKULL_RADII_MM, _direction, _surface_point

        for name, az in (("infradentale", 0), ("mental_foramen_l", 25), ("mental_foramen_r", -25)):
            data["landmarks"][name] = _surface_point(_direction(az, -40), SKULL_RADII_MM)[
                0
            ].tolist()

    _edit_json(skull / "cranial_landmarks.json", mandible)
    out = tmp_path / "out"
    argv = ["case", "--skull", skull, "--photo", midface, "--method", "posest-sfo"]
    argv += ["--method", "lilium", "--variant", "pll", *SMALL_DE, "--out", out]
    code, stdout, err = _run(argv, capsys)
    assert code == 0, err
    posest = _result(out, "midface", "posest-sfo")
    assert not {"pogonion", "gnathion"} & set(posest["landmark_error"]["per_landmark_px"])
    (chin,) = [w for w in posest["warnings"] if w["code"] == "chin_unconstrained"]
    assert "no chin-jaw curve (P_pll off)" in chin["message"]
    assert "confirmed in review.html" in chin["message"] and "--variant pll" in chin["message"]
    assert "warning chin_unconstrained: the chin is unconstrained" in stdout
    report = (out / "report.html").read_text()
    assert "<code>chin_unconstrained</code>: the chin is unconstrained" in report
    # Lilium with the chin-jaw curve of face_curve.json: P_pll holds the chin.
    pll = _result(out, "midface", "lilium-pll")
    assert pll["terms"]["p_pll"] is not None
    assert "chin_unconstrained" not in [w["code"] for w in pll["warnings"]]
    # Pogonion and gnathion confirmed in the review: they pair.
    confirmed = tmp_path / "confirmed"
    shutil.copytree(prepared, confirmed)

    def chin_confirmed(data):
        for name in ("pogonion", "gnathion"):
            data["landmark_sources"][name].update(source="reviewed", confirmed=True)

    _edit_json(confirmed / "photo.json", chin_confirmed)
    out = tmp_path / "out2"
    argv = ["case", "--skull", skull, "--photo", confirmed, "--method", "posest-sfo"]
    code, stdout, err = _run(argv + ["--out", out], capsys)
    assert code == 0, err
    result = _result(out, "confirmed", "posest-sfo")
    assert {"pogonion", "gnathion"} <= set(result["landmark_error"]["per_landmark_px"])
    assert "chin_unconstrained" not in [w["code"] for w in result["warnings"]]
    assert "chin_unconstrained" not in stdout
