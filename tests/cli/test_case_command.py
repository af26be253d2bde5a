"""``lilium case``: folders or plain files in, per-photo results and one HTML report out; every
bad input a one-line error naming the file, the field and the fix."""

import json
import shutil

import numpy as np
import pytest
from PIL import Image
from PIL.TiffImagePlugin import IFDRational

from cli_helpers import _one_line_error, _run
from lilium.cli.main import main
from lilium.io.mesh import write_mesh
from standin_case import scaled_photo

#: Literature-style names for the plain-file case (canonical -> as a user might write it).
FACIAL_ALIASES = {"nasion": "n", "exocanthion_l": "exL", "exocanthion_r": "ex_r", "subnasale": "sn"}
CRANIAL_ALIASES = {"nasion": "N", "ectoconchion_l": "ec_l", "subspinale": "A point"}


@pytest.fixture
def files(case, tmp_path):
    """The stand-in case as the files a practitioner has: mesh, Slicer .fcsv, image, CSV, mask."""
    subject_dir, photo_dir = case
    folder = tmp_path / "files"
    folder.mkdir()
    shutil.copy(subject_dir / "skull.ply", folder / "skull.ply")
    cranial = json.loads((subject_dir / "cranial_landmarks.json").read_text())["landmarks"]
    lines = ["# Markups fiducial file version = 4.11", "# CoordinateSystem = LPS"]
    for k, (name, (x, y, z)) in enumerate(cranial.items()):
        label = CRANIAL_ALIASES.get(name, name)
        lines.append(f"vtkMRMLMarkupsFiducialNode_{k},{x},{y},{z},0,0,0,1,1,1,0,{label},,")
    (folder / "skull.fcsv").write_text("\n".join(lines) + "\n")
    meta = json.loads((photo_dir / "photo.json").read_text())
    rows = [f"{FACIAL_ALIASES.get(n, n)},{u},{v}" for n, (u, v) in meta["landmarks"].items()]
    (folder / "front.csv").write_text("name,u,v\n" + "\n".join(rows) + "\n")
    shutil.copy(photo_dir / "image.png", folder / "front.png")
    shutil.copy(photo_dir / "face_mask.png", folder / "front_mask.png")
    return folder



def test_folders_two_photos_one_report(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    # The same person in another photo, in a folder of the same name (its id gets "_2").
    other = scaled_photo(photo_dir, tmp_path / "b" / photo_dir.name, 0.75)
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--photo", other]
    code, stdout, err = _run(argv + ["--method", "posest-sfo", "--out", out], capsys)
    assert code == 0, err
    for photo_id in ("standin_frontal", "standin_frontal_2"):
        # One layout whatever the number of methods: OUT/<photo>/<method>[-<variant>]/.
        assert not (out / photo_id / "result.json").exists()
        result = json.loads((out / photo_id / "posest-sfo" / "result.json").read_text())
        assert result["method"] == "posest-sfo" and result["camera"]["focal_px"] > 0
        assert (out / photo_id / "posest-sfo" / "overlay.png").is_file()
    text = (out / "report.html").read_text()
    assert 'id="sfo-1"' in text and 'id="sfo-2"' in text and "standin_frontal_2" in text
    assert "2470-2730 px (photo.json)" in text
    assert "report:" in stdout



def test_a_photo_given_twice_is_refused(case, tmp_path, capsys):
    # Counted twice it would be a second view: the single-photo cap lifted, a stronger support.
    subject_dir, photo_dir = case
    copy = tmp_path / "copy"
    shutil.copytree(photo_dir, copy)
    for second in (photo_dir, copy):
        argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--photo", second]
        argv += ["--method", "posest-sfo", "--out", tmp_path / "out"]
        _one_line_error(capsys, argv, f"--photo {second}", "give each photo of the person once")
    assert not (tmp_path / "out").exists()

def test_plain_files_with_aliases_and_both_methods(files, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["case", "--skull", files / "skull.ply", "--photo", files / "front.png"]
    argv += ["--method", "posest-sfo", "--method", "lilium", "--variant", "base"]
    argv += ["--generations", "3", "--population", "12", "--scd-mm", "800", "1000"]
    code, stdout, err = _run(argv + ["--focal-px", "2400", "2800", "--out", out], capsys)
    assert code == 0, err
    # Every sidecar file picked up is said, with its name.
    assert "skull: using cranial landmarks skull.fcsv (found beside the mesh)" in stdout
    assert "front: using facial landmarks front.csv (found beside the photo)" in stdout
    assert "front: using mask front_mask.png (found beside the photo)" in stdout
    posest = json.loads((out / "front" / "posest-sfo" / "result.json").read_text())
    lilium = json.loads((out / "front" / "lilium-base" / "result.json").read_text())
    assert (
        "nasion" in posest["facial_landmarks_3d"] and "subnasale" in posest["facial_landmarks_3d"]
    )
    assert len(lilium["history"]) >= 1
    text = (out / "report.html").read_text()
    assert "skull.fcsv" in text and "front_mask.png" in text  # found next to mesh and image
    assert "command line --focal-px" in text and "--scd-mm 800 1000" in text
    assert 'class="fit"' in text  # Lilium's fitness curve


def test_focal_prior_from_exif(files, tmp_path, capsys):
    exif = Image.Exif()
    exif.get_ifd(0x8769)[0xA405] = 90  # FocalLengthIn35mmFilm
    exif.get_ifd(0x8769)[0x920A] = IFDRational(9.0)
    Image.open(files / "front.png").save(files / "front.jpg", quality=95, exif=exif)
    out = tmp_path / "out"
    argv = ["case", "--skull", files / "skull.ply", "--landmarks", files / "skull.fcsv"]
    argv += ["--photo", files / "front.jpg", "--photo-landmarks", files / "front.csv"]
    code, _, err = _run(argv + ["--method", "posest-sfo", "--out", out], capsys)
    assert code == 0, err
    text = (out / "report.html").read_text()
    assert "EXIF FocalLengthIn35mmFilm 90 mm" in text
    code, _, _ = _run(argv + ["--method", "posest-sfo", "--no-exif", "--out", out], capsys)
    assert "none (penalty off)" in (out / "report.html").read_text()



def _argv(files, tmp_path, **change):
    paths = {
        "skull": files / "skull.ply",
        "landmarks": files / "skull.fcsv",
        "photo": files / "front.png",
        "photo-landmarks": files / "front.csv",
    }
    paths.update(change)
    argv = ["case", "--method", "posest-sfo", "--out", tmp_path / "out"]
    for key, value in paths.items():
        argv += [f"--{key}", value]
    return argv


def test_missing_files(files, tmp_path, capsys):
    _one_line_error(
        capsys, _argv(files, tmp_path, skull=files / "nope.ply"), "nope.ply", "--skull not found"
    )
    _one_line_error(
        capsys,
        _argv(files, tmp_path, **{"photo-landmarks": files / "gone.csv"}),
        "gone.csv",
        "file not found",
    )
    (files / "front.csv").rename(files / "elsewhere.csv")
    argv = ["case", "--skull", files / "skull.ply", "--photo", files / "front.png"]
    _one_line_error(
        capsys, argv + ["--out", tmp_path], "front.png", "give it with --photo-landmarks"
    )


def test_unreadable_files(files, tmp_path, capsys):
    (files / "front.csv").write_bytes(b"\xff\xfe\x00\x81binary")
    _one_line_error(capsys, _argv(files, tmp_path), "front.csv", "cannot read", "UTF-8")
    (files / "skull.ply").write_bytes(b"ply\nformat garbage\n")
    _one_line_error(capsys, _argv(files, tmp_path), "skull.ply", "not a readable PLY triangle mesh")


def test_unknown_landmark_suggests_the_closest(files, tmp_path, capsys):
    text = (files / "front.csv").read_text().replace("\nn,", "\nnasoin,")
    (files / "front.csv").write_text(text)
    _one_line_error(
        capsys, _argv(files, tmp_path), "front.csv", "line", "'nasoin'", "did you mean 'nasion'"
    )


def test_nan_coordinates(files, tmp_path, capsys):
    lines = (files / "skull.fcsv").read_text().splitlines()
    fields = lines[2].split(",")
    fields[2] = "nan"
    lines[2] = ",".join(fields)
    (files / "skull.fcsv").write_text("\n".join(lines))
    _one_line_error(capsys, _argv(files, tmp_path), "skull.fcsv", "line 3", "NaN", "remove it")


def test_too_few_usable_landmarks(files, tmp_path, capsys):
    lines = (files / "front.csv").read_text().splitlines()
    (files / "front.csv").write_text("\n".join(lines[:4]) + "\n")  # header + 3 landmarks
    _one_line_error(
        capsys, _argv(files, tmp_path), "front.csv", "only 3 usable landmark pairs", "at least 4"
    )


def test_degenerate_mesh(files, tmp_path, capsys):
    v = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [100, 100, 0]], dtype=float)
    write_mesh(files / "flat.ply", v, np.array([[0, 1, 2], [1, 3, 2]]))
    _one_line_error(
        capsys, _argv(files, tmp_path, skull=files / "flat.ply"), "flat.ply", "degenerate mesh"
    )


def test_empty_and_wrong_size_masks(files, tmp_path, capsys):
    Image.new("L", (1200, 900), 0).save(files / "front_mask.png")
    _one_line_error(capsys, _argv(files, tmp_path), "front_mask.png", "empty", "paint the face")
    Image.new("L", (600, 450), 255).save(files / "front_mask.png")
    _one_line_error(
        capsys, _argv(files, tmp_path), "front_mask.png", "600x450", "make the mask the photo's"
    )


def test_landmark_off_the_image(files, tmp_path, capsys):
    lines = (files / "front.csv").read_text().splitlines()
    lines = ["n,5000,10" if ln.startswith("n,") else ln for ln in lines]
    (files / "front.csv").write_text("\n".join(lines) + "\n")
    _one_line_error(
        capsys, _argv(files, tmp_path), "front.csv", "landmarks.nasion", "outside the 1200x900"
    )


def test_corrupt_image(files, tmp_path, capsys):
    (files / "front.png").write_bytes(b"\x89PNG\r\n\x1a\n truncated")
    _one_line_error(capsys, _argv(files, tmp_path), "front.png", "cannot read the image", "PNG")


def test_command_line_mistakes(files, case, tmp_path, capsys):
    _one_line_error(
        capsys,
        _argv(files, tmp_path) + ["--focal-px", "3000", "2000"],
        "command line: --focal-px must be a finite interval [lo, hi] with 0 < lo <= hi",
    )
    _one_line_error(
        capsys,
        _argv(files, tmp_path) + ["--scd-mm", "0", "900"],
        "--scd-mm must be a finite interval [lo, hi] with 0 < lo <= hi, got [0, 900]",
    )
    other = scaled_photo(case[1], tmp_path / "other", 0.75)  # front.png is the stand-in's image
    argv = _argv(files, tmp_path) + ["--photo", other, "--photo-landmarks", files / "x.csv"]
    _one_line_error(capsys, argv, "--photo-landmarks given 2 times for 1 photo", "once per")


def _add_mandible_landmarks(files):
    """Give the stand-in skull the landmarks of the chin-jaw region (pll, frontal)."""
    from standin_case import SKULL_RADII_MM, _direction, _surface_point

    lines = (files / "skull.fcsv").read_text().splitlines()
    for k, (name, az) in enumerate(
        (("infradentale", 0), ("mental_foramen_l", 25), ("mental_foramen_r", -25))
    ):
        p, _ = _surface_point(_direction(az, -40), SKULL_RADII_MM)
        lines.append(f"vtkMRMLMarkupsFiducialNode_m{k},{p[0]},{p[1]},{p[2]},0,0,0,1,1,1,0,{name},,")
    (files / "skull.fcsv").write_text("\n".join(lines) + "\n")


def _chin_curve(files):
    """A chin-jaw curve for the stand-in photo: the mask's lowest row, left to right."""
    mask = np.asarray(Image.open(files / "front_mask.png").convert("L")) > 0
    rows, cols = np.nonzero(mask)
    bottom = rows.max()
    us = np.arange(cols[rows == bottom].min(), cols[rows == bottom].max() + 1, 4.0)
    return [[float(u), float(bottom)] for u in us] + [[float(us[-1]) + 2, float(bottom) - 2]]


def test_face_curve_option_and_sidecar(files, tmp_path, capsys):
    _add_mandible_landmarks(files)
    curve = {"chin_jaw": _chin_curve(files)}
    (files / "chin.json").write_text(json.dumps(curve))
    base = ["case", "--skull", files / "skull.ply", "--photo", files / "front.png"]
    base += ["--method", "lilium", "--variant", "pll", "--generations", "2", "--population", "8"]
    out = tmp_path / "out"
    code, stdout, err = _run(base + ["--face-curve", files / "chin.json", "--out", out], capsys)
    assert code == 0, err
    assert "using face curve" not in stdout  # named on the command line: nothing to announce
    text = (out / "report.html").read_text()
    assert "chin.json" in text and "--face-curve" in text
    assert (out / "front" / "lilium-pll" / "result.json").is_file()
    # The same file beside the image is picked up, and said.
    (files / "chin.json").rename(files / "front_face_curve.json")
    code, stdout, err = _run(base + ["--out", tmp_path / "out2"], capsys)
    assert code == 0, err
    assert "front: using face curve front_face_curve.json (found beside the photo)" in stdout
    # A curve file without the photo's view's curve is an error naming it, not ignored.
    (files / "front_face_curve.json").write_text(json.dumps({"forehead": [[1, 2], [3, 4]]}))
    _one_line_error(
        capsys,
        base + ["--out", tmp_path / "out3"],
        "front_face_curve.json",
        "no 'chin_jaw' curve for this frontal photo",
        "forehead",
    )
    (files / "front_face_curve.json").write_text(json.dumps({"chin_jaw": [[1, 2], [5000, 4]]}))
    _one_line_error(
        capsys, base + ["--out", tmp_path / "out4"], "front_face_curve.json", "outside the"
    )
    argv = base + ["--face-curve", files / "a.json", "--face-curve", files / "b.json"]
    _one_line_error(capsys, argv + ["--out", tmp_path], "--face-curve given 2 times for 1 photo")


def test_missing_inputs_switch_their_term_off_and_say_so_first(files, tmp_path, capsys):
    """docs/method/lilium.md "when a term cannot apply": no mask, no curve, no mandible landmarks
    are not
    errors; each term they feed is switched off, said before the first SFO and in result.json."""
    _add_mandible_landmarks(files)
    chin = _chin_curve(files)
    (files / "front_mask.png").unlink()
    base = ["case", "--skull", files / "skull.ply", "--photo", files / "front.png"]
    base += ["--method", "lilium", "--generations", "2", "--population", "8"]
    # No mask and no curve: both image terms are off, the SFO runs with the rest.
    code, stdout, err = _run(base + ["--variant", "skof+pll", "--out", tmp_path / "a"], capsys)
    assert code == 0, err
    lines = stdout.splitlines()
    off = [i for i, line in enumerate(lines) if "switched off" in line]
    ran = [i for i, line in enumerate(lines) if "lilium skof+pll: focal" in line]
    assert off and ran and max(off) < ran[0]
    assert sum("P_skof switched off" in lines[i] for i in off) == 1
    assert sum("P_pll switched off" in lines[i] for i in off) == 1
    result = json.loads((tmp_path / "a" / "front" / "lilium-skof+pll" / "result.json").read_text())
    assert set(result["terms_off"]) >= {"p_skof", "p_pll"}
    assert result["terms"]["p_skof"] is None and result["terms"]["p_pll"] is None
    # With a curve, P_pll runs and only P_skof is off.
    (files / "front_face_curve.json").write_text(json.dumps({"chin_jaw": chin}))
    code, stdout, err = _run(base + ["--variant", "skof+pll", "--out", tmp_path / "b"], capsys)
    assert code == 0, err
    result = json.loads((tmp_path / "b" / "front" / "lilium-skof+pll" / "result.json").read_text())
    assert "p_skof" in result["terms_off"] and "p_pll" not in result["terms_off"]
    # Without the mandible landmarks P_pll is off again, and the reason names them.
    lines = (files / "skull.fcsv").read_text().splitlines()
    keep = [ln for ln in lines if ",infradentale," not in ln]
    assert len(keep) == len(lines) - 1
    (files / "skull.fcsv").write_text("\n".join(keep) + "\n")
    code, stdout, err = _run(base + ["--variant", "pll", "--out", tmp_path / "c"], capsys)
    assert code == 0, err
    assert "P_pll switched off" in stdout and "infradentale" in stdout


def test_help_defines_the_face_mask_and_the_sidecars(capsys):
    assert main(["case", "--help"]) == 0
    text = capsys.readouterr().out
    for needle in (
        "face, the\n  forehead, the hair and the ears",
        "upper neck",
        "not the shoulders" if "not the shoulders" in text else "zero\n  on the shoulders",
        "NAME_mask.png",
        "NAME_face_curve.json",
        "--face-curve",
        "DIR/<photo>/<method>[-<variant>]/result.json",
    ):
        assert needle in text, needle
