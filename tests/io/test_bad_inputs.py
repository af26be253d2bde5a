"""Hardening of the inputs (issue 13, docs/checks.md): every bad input a one-line error naming
the file or option (exit 2), nothing silently wrong, nothing written outside ``--out``, memory
bounded for large photos, no traceback."""

import json
import shutil
import struct
import tracemalloc
import zlib

import numpy as np
import pytest
from PIL import Image

from cli_helpers import _edit_json, _one_line_error, _run, _sfo
from lilium.casework.build import read_photo, read_skull
from lilium.cli import argtypes
from lilium.cli.main import main
from lilium.constants import MAX_PHOTO_PIXELS
from lilium.geometry.camera import Camera
from lilium.imaging import overlay as overlay_module
from lilium.imaging.overlay import SKULL_RGB, blend_skull, draw_overlay
from lilium.io.formats import name_error
from lilium.io.images import image_size_wh, read_image, read_mask
from lilium.io.paths import path_id, safe_id
from lilium.report.html import relative_href
from standin_case import scaled_photo


def _png_header(path, width, height):
    """A PNG whose header says ``width x height`` (8-bit RGB) with no pixel data: opening it
    costs nothing, decoding it fails."""

    def chunk(kind, data):
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b""))


# -- runaway resources -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "curve, needles",
    [
        ([[100, 700], [5e6, 5e6]], ["chin_jaw[1] = (5e+06, 5e+06)", "outside the 1200x900"]),
        ([[-4000, 700], [600, 800], [1100, 700]], ["chin_jaw[0]", "1 of 3 points"]),
        ([[600, 800]], ["at least two [u, v] points"]),
        ("[[600, 800], [700, 800]]", ["at least two [u, v] points", "'[[600"]),
        ([[600, 800], [700, None]], ["finite [u, v] pairs"]),
    ],
)
def test_face_curve_must_lie_in_the_photo(case, tmp_path, capsys, curve, needles):
    _, photo_dir = case
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": curve}))
    _one_line_error(capsys, _sfo(case, tmp_path / "out"), "face_curve.json", *needles)
    assert not (tmp_path / "out").exists()


def test_face_curve_of_the_wrong_shape_or_view(case, tmp_path, capsys):
    _, photo_dir = case
    path = photo_dir / "face_curve.json"
    path.write_text(json.dumps("chin"))
    _one_line_error(capsys, _sfo(case, tmp_path), "face_curve.json", "must be a JSON object")
    path.write_text(json.dumps({"forehead": [[1, 2], [3, 4]]}))
    _one_line_error(capsys, _sfo(case, tmp_path), "no 'chin_jaw' curve", "'forehead'")
    path.write_text(json.dumps({"chin_jaw": [[400, 700], [600, 790], [800, 700]]}))
    curve = read_photo(photo_dir).face_curve_uv  # resampled to whole pixels (issue 28)
    assert curve[0].tolist() == [400, 700] and curve[-1].tolist() == [800, 700]
    assert len(curve) == 401 and [600, 790] in curve.tolist()


@pytest.mark.parametrize("size_wh", [(20000, 20000), (12000, 12000)])
def test_photo_over_the_pixel_limit(case, tmp_path, capsys, size_wh):
    _, photo_dir = case
    _png_header(photo_dir / "image.png", *size_wh)
    line = _one_line_error(
        capsys, _sfo(case, tmp_path), "image.png", "too large", "at most 100", "downscale it"
    )
    assert f"{size_wh[0] * size_wh[1] / 1e6:.0f} megapixels" in line
    with pytest.raises(ValueError, match="too large"):
        image_size_wh(photo_dir / "image.png")


def test_legal_size_is_read_from_the_header(tmp_path):
    _png_header(tmp_path / "big.png", 9000, 9000)  # 81 MP: legal; no pixels decoded
    assert 9000 * 9000 <= MAX_PHOTO_PIXELS
    assert image_size_wh(tmp_path / "big.png") == (9000, 9000)
    with pytest.raises(ValueError, match="big.png: cannot read the image"):
        read_image(tmp_path / "big.png")


def _ellipsoid_mesh():
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3)
    return np.asarray(sphere.vertices) * [70.0, 85.0, 92.0], np.asarray(sphere.faces)


def test_overlay_blend_is_blockwise_and_exact(monkeypatch):
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (90, 70, 3), dtype=np.uint8)
    shade = rng.random((90, 70)).astype(np.float32)
    covered = rng.random((90, 70)) < 0.4
    covered[:10] = False
    alpha = 0.55 * covered[..., None]
    whole = (1 - alpha) * image.astype(float) + alpha * (shade[..., None] * SKULL_RGB)
    expected = np.clip(whole, 0, 255).astype(np.uint8)
    monkeypatch.setattr(overlay_module, "BLEND_BLOCK_PIXELS", 7 * 70)  # 7 rows a block
    out = blend_skull(image, shade, covered, 0.55)
    np.testing.assert_array_equal(out, expected)
    image16 = image.astype(np.uint16) * 257
    np.testing.assert_array_equal(blend_skull(image16, shade, covered, 0.55), expected)


def test_overlay_memory_is_bounded():
    """A 12 MP overlay used 1.2 GB of float64 temporaries; now the output, the shading and the
    raster (about 10 bytes a pixel: 123 MB at 12 MP) plus fixed-size blocks."""
    vertices, faces = _ellipsoid_mesh()
    width, height = 4000, 3000
    skull2cam = np.diag([1.0, -1.0, -1.0, 1.0])
    skull2cam[2, 3] = 500.0
    camera = Camera(skull2cam, 3000.0, np.array([(width - 1) / 2, (height - 1) / 2]))
    image = np.full((height, width, 3), 90, np.uint8)
    tracemalloc.start()
    try:
        out = draw_overlay(image, vertices, faces, camera)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert out.shape == image.shape and (out != 90).any()
    assert peak < 12 * width * height + 40e6, f"{peak / 1e6:.0f} MB"


# -- silently wrong answers ------------------------------------------------------------------


def test_missing_axes_file_is_an_error(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    gone = tmp_path / "gone_axes.json"
    _one_line_error(capsys, _sfo(case, tmp_path, "--axes", gone), "--axes", "gone_axes.json")
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--method", "posest-sfo"]
    _one_line_error(capsys, argv + ["--out", tmp_path, "--axes", gone], "--axes", "not found")
    with pytest.raises(ValueError, match="gone_axes.json: soft-tissue axes file not found"):
        read_skull(subject_dir, axes_path=gone)
    from lilium.casework.inputs import load_skull
    from lilium.casework.request import SkullSource

    with pytest.raises(ValueError, match="gone_axes.json"):
        load_skull(SkullSource(subject_dir / "skull.ply", subject_dir / "cranial_landmarks.json",
                               gone))


def test_landmarks_at_one_place_or_on_a_line(case, tmp_path, capsys):
    _, photo_dir = case
    meta = photo_dir / "photo.json"
    original = json.loads(meta.read_text())

    def at_one_pixel(data):
        data["landmarks"] = {name: [600.0, 450.0] for name in data["landmarks"]}

    _edit_json(meta, at_one_pixel)
    _one_line_error(capsys, _sfo(case, tmp_path), "photo.json", "within 0 px", "all at one place")

    def on_a_line(data):
        data["landmarks"] = {
            name: [300.0 + 20 * k, 200.0 + 15 * k] for k, name in enumerate(data["landmarks"])
        }

    _edit_json(meta, on_a_line)
    _one_line_error(capsys, _sfo(case, tmp_path), "photo.json", "on one line")

    def tiny(data):  # a 10 px face in a 1200 px photo: 1 % of 1200 = 12 px needed
        data["landmarks"] = {
            name: [600 + 5 * np.cos(k), 450 + 5 * np.sin(k)]
            for k, name in enumerate(data["landmarks"])
        }

    _edit_json(meta, tiny)
    _one_line_error(capsys, _sfo(case, tmp_path), "at least 16 px is needed")
    meta.write_text(json.dumps(original))
    assert read_photo(photo_dir).landmarks_uv


def test_one_pixel_photo(case, tmp_path, capsys):
    _, photo_dir = case
    Image.new("RGB", (1, 1), (90, 90, 90)).save(photo_dir / "image.png")
    (photo_dir / "face_mask.png").unlink()
    _edit_json(
        photo_dir / "photo.json",
        lambda d: d.update(landmarks={n: [0.0, 0.0] for n in d["landmarks"]}),
    )
    _one_line_error(capsys, _sfo(case, tmp_path), "image.png", "1x1 px", "at least 32 px")


def test_cranial_landmarks_at_one_place(case, tmp_path, capsys):
    subject_dir, _ = case
    path = subject_dir / "cranial_landmarks.json"
    data = json.loads(path.read_text())
    point = data["landmarks"]["nasion"]
    data["landmarks"] = {name: point for name in data["landmarks"]}
    path.write_text(json.dumps(data))
    _one_line_error(capsys, _sfo(case, tmp_path), "cranial_landmarks.json", "all at one place")


def test_16_bit_photo_is_scaled_not_clipped(case, tmp_path, capsys):
    _, photo_dir = case
    grey8 = np.asarray(Image.open(photo_dir / "image.png").convert("L"))
    Image.fromarray(grey8.astype(np.uint16) * 257).save(photo_dir / "image.png")
    assert Image.open(photo_dir / "image.png").mode == "I;16"
    image = read_image(photo_dir / "image.png")
    assert image.dtype == np.uint8 and image.shape == grey8.shape + (3,)
    np.testing.assert_array_equal(image[..., 1], grey8)
    code, _, err = _run(_sfo(case, tmp_path / "out", "--method", "posest-sfo"), capsys)
    assert code == 0, err
    overlay = np.asarray(Image.open(tmp_path / "out" / "overlay.png"))
    assert overlay[0, 0].tolist() == [grey8[0, 0]] * 3 != [255] * 3  # background stays grey


def test_float_and_32_bit_photos_are_scaled(tmp_path):
    ramp = np.linspace(0, 1, 64 * 64, dtype=np.float32).reshape(64, 64)
    Image.fromarray(ramp, mode="F").save(tmp_path / "f.tiff")
    image = read_image(tmp_path / "f.tiff")
    assert image.min() == 0 and image.max() == 255
    Image.fromarray((ramp * 65535).astype(np.int32), mode="I").save(tmp_path / "i.tiff")
    assert read_image(tmp_path / "i.tiff").max() == 255


def test_mask_in_the_alpha_channel(tmp_path):
    face = np.zeros((40, 50), bool)
    face[10:30, 15:35] = True
    for colour in ((255, 255, 255), (0, 0, 0)):  # the face only in the alpha channel
        rgba = np.zeros((40, 50, 4), np.uint8)
        rgba[..., :3] = colour
        rgba[..., 3] = face * 255
        Image.fromarray(rgba, mode="RGBA").save(tmp_path / "mask.png")
        np.testing.assert_array_equal(read_mask(tmp_path / "mask.png", (50, 40)), face)
    rgba = np.zeros((40, 50, 4), np.uint8)  # colour and alpha: a face pixel needs both
    rgba[5:35, 10:40, :3] = 255
    rgba[..., 3] = face * 255
    Image.fromarray(rgba, mode="RGBA").save(tmp_path / "mask.png")
    np.testing.assert_array_equal(read_mask(tmp_path / "mask.png", (50, 40)), face)
    grey = Image.fromarray(face.astype(np.uint8) * 200, mode="L")
    grey.save(tmp_path / "grey.png")
    np.testing.assert_array_equal(read_mask(tmp_path / "grey.png", (50, 40)), face)


def test_mask_covering_the_whole_photo(case, tmp_path, capsys):
    _, photo_dir = case
    Image.new("L", (1200, 900), 255).save(photo_dir / "face_mask.png")
    _one_line_error(
        capsys, _sfo(case, tmp_path), "face_mask.png", "covers the whole photo", "background"
    )
    Image.new("RGBA", (1200, 900), (255, 255, 255, 255)).save(photo_dir / "face_mask.png")
    _one_line_error(capsys, _sfo(case, tmp_path), "face_mask.png", "covers the whole photo")


def test_no_overlay_removes_the_old_overlay(case, tmp_path, capsys):
    out = tmp_path / "out"
    assert _run(_sfo(case, out), capsys)[0] == 0
    assert (out / "overlay.png").is_file()
    assert _run(_sfo(case, out, "--no-overlay"), capsys)[0] == 0
    assert (out / "result.json").is_file() and not (out / "overlay.png").exists()


# -- writes and links outside their place ----------------------------------------------------


def test_safe_ids():
    assert safe_id("standin_frontal") == "standin_frontal"
    assert safe_id("front view (2)") == "front view (2)"
    for bad in ("..", ".", "", " ", "..."):
        assert safe_id(bad) == "photo"
    assert safe_id("../../etc") == "_.._etc"
    assert safe_id("a/b\\c:d") == "a_b_c_d"
    assert safe_id("javascript:alert(1)") == "javascript_alert(1)"
    assert safe_id("CON") == "_CON" and safe_id("nul.txt") == "_nul.txt"
    assert safe_id(".hidden") == "hidden" and len(safe_id("x" * 500)) == 100
    assert path_id("some/dir/..") == "some"


def test_photo_path_with_dot_dot_stays_inside_out(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    (photo_dir / "sub").mkdir()
    work = tmp_path / "work"
    out = work / "out"
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir / "sub" / ".."]
    code, _, err = _run(argv + ["--method", "posest-sfo", "--out", out], capsys)
    assert code == 0, err
    assert sorted(p.name for p in work.iterdir()) == ["out"]
    result = out / "standin_frontal" / "posest-sfo" / "result.json"
    assert result.is_file()
    assert json.loads(result.read_text())["photo"] == "standin_frontal"


def test_report_links_cannot_become_scripts(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    evil = tmp_path / "javascript:alert(1)"
    shutil.copytree(photo_dir, evil)
    out = tmp_path / "out"
    argv = ["case", "--skull", subject_dir, "--photo", evil, "--method", "posest-sfo"]
    code, _, err = _run(argv + ["--out", out], capsys)
    assert code == 0, err
    text = (out / "report.html").read_text()
    assert 'href="javascript:' not in text.lower()
    assert 'href="javascript_alert%281%29/posest-sfo/result.json"' in text
    assert (out / "javascript_alert(1)" / "posest-sfo" / "result.json").is_file()
    assert (
        relative_href("javascript:alert(1)/overlay.png") == "javascript%3Aalert%281%29/overlay.png"
    )
    assert relative_href("//evil.example/x") == "evil.example/x"


# -- tracebacks and messages -----------------------------------------------------------------


def test_out_that_is_a_file_or_under_one(case, tmp_path, capsys):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    _one_line_error(capsys, _sfo(case, blocker), "argument --out", "is a file, not a folder")
    _one_line_error(capsys, _sfo(case, blocker / "sub" / "out"), "--out", "lies under the file")


def test_out_not_writable(case, tmp_path, capsys, monkeypatch):
    # Tests may run as root, for whom every folder is writable: fake the permission check.
    monkeypatch.setattr(argtypes.os, "access", lambda path, mode: False)
    _one_line_error(capsys, _sfo(case, tmp_path / "out"), "argument --out", "is not writable")


@pytest.mark.parametrize(
    "option, value, needle",
    [
        ("--seed", "-5", "argument --seed: must be an integer from 0"),
        ("--seed", str(2**64), "argument --seed"),
        ("--population", "1", "argument --population: must be an integer from 4 to 10000"),
        ("--generations", "0", "argument --generations: must be an integer of at least 1"),
        ("--max-seconds", "-1", "argument --max-seconds: must be a positive number"),
        ("--max-seconds", "nan", "argument --max-seconds"),
        ("--depth-table", "nope.csv", "argument --depth-table: nope.csv: depth table not found"),
    ],
)
def test_options_are_checked_when_parsed(case, tmp_path, capsys, option, value, needle):
    _one_line_error(capsys, _sfo(case, tmp_path, "--method", "lilium", option, value), needle)
    subject_dir, photo_dir = case
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--out", tmp_path]
    _one_line_error(capsys, argv + [option, value], needle.replace("sfo", "case"))


def test_last_resort_handler(case, tmp_path, capsys, monkeypatch):
    import lilium.cli.sfo as sfo_cli

    def broken(*args, **kwargs):
        raise KeyError("camera")

    monkeypatch.setattr(sfo_cli, "single_sfo", broken)
    with pytest.raises(KeyError):  # LILIUM_DEBUG=1 (conftest): a bug fails its test
        main([str(a) for a in _sfo(case, tmp_path)])
    monkeypatch.delenv("LILIUM_DEBUG")
    line = _one_line_error(capsys, _sfo(case, tmp_path), "internal error (KeyError: 'camera')")
    assert "this is a bug: please report it" in line and "LILIUM_DEBUG=1" in line

    def refused(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / "result.json"))

    monkeypatch.setattr(sfo_cli, "single_sfo", refused)
    _one_line_error(capsys, _sfo(case, tmp_path), "result.json: permission denied", "permissions")

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(sfo_cli, "single_sfo", out_of_memory)
    _one_line_error(capsys, _sfo(case, tmp_path), "out of memory", "downscale")


def test_parse_errors_are_one_line(capsys):
    assert main(["sfo", "--skull", "x"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [
        "lilium sfo: error: the following arguments are required: --photo, --out "
        "(see lilium sfo --help)"
    ]
    assert main(["--version"]) == 0


@pytest.mark.parametrize(
    "written, kind, suggestion",
    [
        (" Exocanthoin_L ", "facial", "did you mean 'exocanthion_l'?"),
        ("l_exocantion", "facial", "did you mean 'exocanthion_l'?"),
        ("Zygoin R", "facial", "did you mean 'zygion_r'?"),
        ("Exocanthion_izq", "facial", "'exocanthion_l' or 'exocanthion_r'"),
        ("ectoconchoin_r", "cranial", "did you mean 'ectoconchion_r'?"),
        ("nasoin", "facial", "did you mean 'nasion'?"),
    ],
)
def test_suggestions_keep_the_side(written, kind, suggestion):
    message = str(name_error("f.csv", "line 2", written, kind))
    assert suggestion in message, message


# -- every input checked before the first SFO ------------------------------------------------


def test_bad_third_photo_fails_before_any_sfo(case, tmp_path, capsys, monkeypatch):
    subject_dir, photo_dir = case
    photos = []
    for k in range(3):  # three different photos of the stand-in (a repeated one is refused)
        folder = scaled_photo(photo_dir, tmp_path / f"photo{k}", 1.0 - 0.1 * k)
        photos += ["--photo", folder]
    # Three landmarks left: fewer than four pairs, the one case no term set can run. (A term
    # the variant asks for that cannot apply, P_skof without the mask of photo 0, say, is
    # switched off, not an error: docs/method/lilium.md, tests/methods/test_incomplete.py.)
    _edit_json(
        tmp_path / "photo2" / "photo.json",
        lambda d: d.update(landmarks=dict(list(d["landmarks"].items())[:3])),
    )
    (tmp_path / "photo0" / "face_mask.png").unlink()
    import lilium.casework.case as case_module

    calls = []
    monkeypatch.setattr(case_module, "run_sfo", lambda *a, **k: calls.append(a))
    argv = ["case", "--skull", subject_dir, *photos, "--method", "lilium", "--variant", "skof"]
    _one_line_error(capsys, argv + ["--out", tmp_path / "out"], "photo2", "only 3 usable landmark")
    assert calls == [] and not (tmp_path / "out").exists()
    shutil.rmtree(tmp_path / "photo1")  # a photo that cannot be read at all
    argv[argv.index("skof")] = "base"
    _one_line_error(capsys, argv + ["--out", tmp_path / "out"], "photo1", "not found")
    assert calls == []
