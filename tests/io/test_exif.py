"""The focal prior from EXIF: FocalLength with the sensor size, or FocalLengthIn35mmFilm."""

from dataclasses import replace

import numpy as np
import pytest
from PIL import Image
from PIL.TiffImagePlugin import IFDRational

from lilium.io.exif import focal_prior_from_exif, read_exif


def _jpeg(path, size_wh=(600, 400), model=None, **exif_ifd):
    exif = Image.Exif()
    if model:
        exif[0x0110] = model
    tags = {
        "focal_mm": 0x920A,
        "plane_x": 0xA20E,
        "plane_unit": 0xA210,
        "pixel_x": 0xA002,
        "pixel_y": 0xA003,
        "f35": 0xA405,
    }
    ifd = exif.get_ifd(0x8769)
    for key, value in exif_ifd.items():
        ifd[tags[key]] = IFDRational(value) if isinstance(value, float) else value
    Image.new("RGB", size_wh, (90, 90, 90)).save(path, exif=exif)
    return path


def test_focal_plane_resolution(tmp_path):
    # 50 mm lens, 600 px across a 3.6 mm sensor (mm units): the camera's own full frame.
    path = _jpeg(
        tmp_path / "a.jpg",
        focal_mm=5.0,
        plane_x=600 / 3.6,
        plane_unit=4,
        pixel_x=600,
        pixel_y=400,
    )
    prior = focal_prior_from_exif(path)
    expected = 5 * 600 / 3.6
    assert prior.estimate_px == pytest.approx(expected, rel=1e-3)
    assert prior.focal_px == pytest.approx((0.95 * expected, 1.05 * expected), rel=1e-3)
    assert "FocalPlaneXResolution" in prior.source


def test_a_resized_photo_gives_no_focal(tmp_path):
    # The same camera's 6000 x 4000 frame saved at 600 x 400: the tags name the original size.
    from lilium.io.exif import exif_focal

    path = _jpeg(
        tmp_path / "a.jpg", focal_mm=50.0, plane_x=6000 / 36, plane_unit=4, pixel_x=6000,
        pixel_y=4000,
    )  # fmt: skip
    prior, unusable = exif_focal(path)
    assert prior is None
    assert "PixelXDimension/PixelYDimension 6000x4000 differ from the file's 600x400" in unusable
    assert "--focal-px LO HI" in unusable


def test_inch_units(tmp_path):
    path = _jpeg(tmp_path / "a.jpg", focal_mm=3.5, plane_x=600 / (2.35 / 25.4), plane_unit=2)
    # No PixelXDimension: the stored image is taken as the original (600 px / 2.35 mm).
    assert focal_prior_from_exif(path).estimate_px == pytest.approx(3.5 * 600 / 2.35, rel=1e-3)


def test_sensor_width_given_and_from_the_table(tmp_path):
    path = _jpeg(tmp_path / "a.jpg", model="Canon EOS 5D Mark IV", focal_mm=85.0)
    assert focal_prior_from_exif(path).estimate_px == pytest.approx(85 * 600 / 36)
    assert "built-in table" in focal_prior_from_exif(path).source
    given = focal_prior_from_exif(path, sensor_width_mm=24.0)
    assert given.estimate_px == pytest.approx(85 * 600 / 24)
    with pytest.raises(ValueError, match="--sensor-width-mm: the sensor width must be a positive"):
        focal_prior_from_exif(path, sensor_width_mm=-1)


def test_35mm_equivalent_covers_both_conventions(tmp_path):
    path = _jpeg(tmp_path / "a.jpg", size_wh=(400, 300), model="Phone X", focal_mm=4.2, f35=26)
    prior = focal_prior_from_exif(path)
    diagonal = 26 * 500 / np.hypot(36, 24)
    width = 26 * 400 / 36
    assert prior.focal_px[0] == pytest.approx(0.95 * min(diagonal, width))
    assert prior.focal_px[1] == pytest.approx(1.05 * max(diagonal, width))
    assert "FocalLengthIn35mmFilm 26" in prior.source


def test_no_exif_gives_none(tmp_path):
    path = tmp_path / "plain.png"
    Image.new("RGB", (50, 40)).save(path)
    assert focal_prior_from_exif(path) is None
    assert read_exif(path) == {"image_size_wh": (50, 40)}
    # A focal length alone (no sensor size, unknown camera) is not enough.
    assert focal_prior_from_exif(_jpeg(tmp_path / "b.jpg", model="Unknown", focal_mm=50.0)) is None


def test_corrupt_image(tmp_path):
    path = tmp_path / "bad.jpg"
    path.write_bytes(b"\xff\xd8 not a jpeg")
    with pytest.raises(ValueError, match=r"bad.jpg: cannot read the image"):
        focal_prior_from_exif(path)


def test_a_focal_length_that_cannot_be_converted_says_so(tmp_path):
    from lilium.io.exif import exif_focal

    path = _jpeg(tmp_path / "b.jpg", model="Unknown", focal_mm=50.0)
    prior, unusable = exif_focal(path)
    assert prior is None
    assert "EXIF FocalLength 50 mm cannot be converted to pixels" in unusable
    assert "camera 'Unknown' is not in the built-in sensor table" in unusable
    assert "--sensor-width-mm" in unusable and "--focal-px" in unusable
    # The option it names fixes it.
    prior, unusable = exif_focal(path, sensor_width_mm=36.0)
    assert unusable is None and prior.estimate_px == pytest.approx(50 * 600 / 36)
    # No FocalLength at all: nothing to say.
    plain = tmp_path / "plain.png"
    Image.new("RGB", (50, 40)).save(plain)
    assert exif_focal(plain) == (None, None)


def test_a_prior_that_contradicts_the_photos_exif_is_named(tmp_path):
    from lilium.casework.inputs import with_priors
    from lilium.inputs import Photo, Priors

    path = _jpeg(tmp_path / "a.jpg", size_wh=(400, 300), model="Phone X", focal_mm=4.2, f35=26)
    exif_px = focal_prior_from_exif(path).focal_px  # about 289-379 px
    photo = Photo("a", (400, 300), "frontal", {}, priors=Priors(focal_px=(600.0, 700.0)))
    checked, _ = with_priors(photo, path)
    (warning,) = [w for w in checked.warnings if w.code == "prior_conflict"]
    assert "a.jpg" in warning.message and "600-700 px (photo.json)" in warning.message
    assert checked.priors.focal_px == (600.0, 700.0)  # photo.json still wins
    overlapping = replace(photo, priors=Priors(focal_px=(exif_px[1] - 10, 700.0)))
    assert not [w for w in with_priors(overlapping, path)[0].warnings if w.code == "prior_conflict"]
    ignored, _ = with_priors(photo, path, use_exif=False)  # --no-exif: EXIF is not read at all
    assert not ignored.warnings


def test_a_pngs_exif_is_read_wherever_its_chunk_lies(tmp_path):
    """PNG keeps EXIF in an ``eXIf`` chunk, before or (as some tools write it) after the pixel
    data; both are read, and no pixel is decoded to find them (Pillow's ``getexif`` decodes a
    whole 24 MP photo for it)."""
    import struct
    import zlib

    from lilium.io.exif import read_exif

    exif = Image.Exif()
    exif[0x0110] = "Test camera"  # Pillow writes no eXIf chunk for an empty IFD0
    exif.get_ifd(0x8769)[0x920A] = IFDRational(5.0)
    before = tmp_path / "before.png"
    Image.new("RGB", (40, 30), (90, 90, 90)).save(before, exif=exif)
    data = before.read_bytes()
    chunks, at = [], 8
    while at < len(data):
        (length,) = struct.unpack(">I", data[at : at + 4])
        chunks.append(data[at : at + 12 + length])
        at += 12 + length
    exif_chunk = next(c for c in chunks if c[4:8] == b"eXIf")
    rest = [c for c in chunks if c[4:8] != b"eXIf"]
    after = tmp_path / "after.png"
    after.write_bytes(data[:8] + b"".join(rest[:-1]) + exif_chunk + rest[-1])
    assert zlib.crc32(exif_chunk[4:-4]) == struct.unpack(">I", exif_chunk[-4:])[0]
    for path in (before, after):
        fields = read_exif(path)
        assert fields["focal_mm"] == pytest.approx(5.0) and fields["model"] == "Test camera"
        assert fields["image_size_wh"] == (40, 30)
    plain = tmp_path / "plain.png"
    Image.new("RGB", (40, 30)).save(plain)
    assert "focal_mm" not in read_exif(plain)
