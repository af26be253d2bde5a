"""``lilium photo`` and the EXIF of edited photos (docs/method/photo.md): the focal is taken only
from
the camera's own full frame (``exif_focal_unusable`` names the tag that disagrees), a focal
whose iris distance is outside 0.3-10 m gets ``implausible_prior``, and the runtime's own
logging stays off stderr."""

import json

import numpy as np
import pytest
from PIL import Image
from PIL.TiffImagePlugin import IFDRational

from lilium.cli.main import main
from lilium.io.exif import exif_focal

_TAGS = {
    "model": (None, 0x0110),
    "software": (None, 0x0131),
    "focal_mm": (0x8769, 0x920A),
    "f35": (0x8769, 0xA405),
    "plane_x": (0x8769, 0xA20E),
    "plane_unit": (0x8769, 0xA210),
    "pixel_x": (0x8769, 0xA002),
    "pixel_y": (0x8769, 0xA003),
}


def _with_exif(path, pixels, **tags):
    """Write ``pixels`` as a JPEG with EXIF tags as an editor that resized the shot leaves them."""
    exif = Image.Exif()
    for key, value in tags.items():
        ifd, tag = _TAGS[key]
        target = exif if ifd is None else exif.get_ifd(ifd)
        target[tag] = IFDRational(value) if isinstance(value, float) else value
    Image.fromarray(pixels).save(path, quality=92, exif=exif)
    return path


def _grey(w, h):
    return np.full((h, w, 3), 128, np.uint8)


#: The resized official portrait of issue 25: 910 x 1137 px from a full-frame 85 mm shot.
RESIZED = {"model": "Canon EOS 5D Mark III", "focal_mm": 85.0, "plane_x": 160.0, "plane_unit": 4}


def test_a_resized_portrait_gives_no_focal_prior(tmp_path, capsys):
    image = _with_exif(tmp_path / "portrait.jpg", _grey(910, 1137), **RESIZED)
    out = tmp_path / "photo"
    assert main(["photo", str(image), "--out", str(out)]) == 3  # no face in a grey picture
    err = capsys.readouterr().err
    meta = json.loads((out / "photo.json").read_text())
    assert "focal_px" not in meta["priors"] and "scd_mm" not in meta["priors"]
    (warning,) = meta["warnings"]
    assert warning["code"] == "exif_focal_unusable"
    assert "FocalPlaneXResolution 160/unit implies a 7.1 mm sensor" in warning["message"]
    assert "Canon EOS 5D Mark III's sensor is 36 mm" in warning["message"]
    assert "--focal-px LO HI" in warning["message"]
    assert f"warning exif_focal_unusable: {image}" in err


@pytest.mark.parametrize(
    "tags, named",
    [
        ({"pixel_x": 5760, "pixel_y": 3840, "focal_mm": 85.0, "f35": 85}, "PixelXDimension"),
        ({"software": "Adobe Photoshop 25.0 (Windows)", "f35": 85, "focal_mm": 85.0}, "Software"),
        ({"focal_mm": 85.0, "f35": 50}, "FocalLengthIn35mmFilm 50 mm over FocalLength 85 mm"),
        ({"f35": 10_000}, "FocalLengthIn35mmFilm 10000 mm is outside the physical 1-3000 mm"),
        ({"focal_mm": 85.0, "plane_x": 0.5, "plane_unit": 4}, "outside the 2-60 mm"),
    ],
)
def test_the_tag_that_disagrees_is_named(tmp_path, tags, named):
    image = _with_exif(tmp_path / "a.jpg", _grey(910, 1137), model="Canon EOS 5D Mark III", **tags)
    prior, unusable = exif_focal(image)
    assert prior is None and named in unusable


def test_the_camera_s_own_frame_is_used(tmp_path):
    # A full-frame camera's own 6000 x 4000 frame, scaled down here to 600 x 400 with its
    # FocalPlaneXResolution (so the test stays small): every tag agrees.
    image = _with_exif(
        tmp_path / "a.jpg", _grey(600, 400), focal_mm=8.5, f35=85, plane_x=600 / 3.6,
        plane_unit=4, pixel_x=600, pixel_y=400,
    )  # fmt: skip
    prior, unusable = exif_focal(image)
    assert unusable is None and prior.estimate_px == pytest.approx(8.5 * 600 / 3.6)


def test_an_absurd_35mm_focal_is_not_a_prior(tmp_path, capsys):
    image = _with_exif(tmp_path / "tele.jpg", _grey(400, 300), f35=10_000)
    out = tmp_path / "photo"
    assert main(["photo", str(image), "--out", str(out)]) == 3
    meta = json.loads((out / "photo.json").read_text())
    assert "focal_px" not in meta["priors"]
    assert "FocalLengthIn35mmFilm 10000 mm" in meta["warnings"][0]["message"]


def test_a_negative_sensor_width_names_the_option_before_the_models_load(
    tmp_path, capsys, monkeypatch
):
    from lilium.photo import runtime

    def no_models(*args):
        raise AssertionError("the models were loaded")

    monkeypatch.setattr(runtime, "_run", no_models)
    image = _with_exif(tmp_path / "a.jpg", _grey(400, 300), focal_mm=50.0)
    argv = ["photo", str(image), "--out", str(tmp_path / "p"), "--sensor-width-mm", "-3"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "argument --sensor-width-mm: must be a finite positive number" in err
    assert not (tmp_path / "p").exists()


def test_a_focal_that_puts_the_camera_far_away_is_implausible(tmp_path, capfd):
    from skimage import data

    from lilium.photo import runtime

    runtime._model.cache_clear()  # load the models inside this test: their logging is checked
    runtime._detector.cache_clear()
    # A consistent 1000 mm equivalent (crop factor 5): the iris puts the camera ~15 m away.
    image = _with_exif(tmp_path / "astronaut.jpg", data.astronaut(), focal_mm=200.0, f35=1000)
    out = tmp_path / "photo"
    assert main(["photo", str(image), "--out", str(out)]) == 0
    err = capfd.readouterr().err
    assert "XNNPACK" not in err and "INFO:" not in err
    meta = json.loads((out / "photo.json").read_text())
    assert "focal_px" not in meta["priors"] and "scd_mm" not in meta["priors"]
    # The astronaut's pupils are 43 px apart: low_resolution too.
    assert [w["code"] for w in meta["warnings"]] == ["implausible_prior", "low_resolution"]
    warning = meta["warnings"][0]
    assert "outside the 0.3-10 m of a portrait" in warning["message"]
    assert "warning implausible_prior:" in err


def test_a_large_photo_s_exif_is_read_without_pillow_s_warning(tmp_path):
    import struct
    import warnings
    import zlib

    from lilium.io.exif import read_exif

    # A PNG whose header says 10000 x 9460 px (94.6 MP, over Pillow's warning threshold, under
    # Lilium's 100 MP limit); only the header is read.
    path = tmp_path / "big.png"
    _grey_png = tmp_path / "small.png"
    Image.new("RGB", (8, 8)).save(_grey_png)
    blob = bytearray(_grey_png.read_bytes())
    ihdr = struct.pack(">II", 10_000, 9_460) + bytes(blob[24:29])
    blob[16:29] = ihdr
    blob[29:33] = struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
    path.write_bytes(bytes(blob))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_exif(path) == {"image_size_wh": (10_000, 9_460)}
