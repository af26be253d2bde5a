"""The HTML case report: self-contained, complete, and its controls work in a real browser."""

import html
import json
import re

import numpy as np
import pytest

from browser import needs_chromium, run_chromium
from lilium.casework.build import read_photo, read_skull
from lilium.io.provenance import sha256_of
from lilium.methods.posest_sfo import posest_sfo
from lilium.report import ReportEntry, build_report, skull_layer_rgba, write_report
from lilium.report.pictures import (
    MIN_ACROSS_PX,
    picture_scale,
    picture_size,
    sfo_pictures,
    view_box,
)


@pytest.fixture
def report(case, tmp_path):
    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    result = posest_sfo(skull, photo)
    assert result
    inputs = {"skull mesh": subject_dir / "skull.ply", "photo": photo_dir / "image.png"}
    entries = [
        ReportEntry(skull, photo, result, inputs, {"focal prior": "photo.json"}),
        ReportEntry(skull, photo, result, inputs),
    ]
    path = write_report(tmp_path / "out" / "report.html", entries, command="lilium case ...")
    return path, entries


def test_report_is_self_contained_and_complete(report):
    path, entries = report
    text = path.read_text()
    assert not re.search(r"""(src|href)=["']?(https?:)?//""", text), "nothing from the network"
    assert text.count('class="skull-layer"') == 2 and text.count('class="photo"') == 2
    assert "data:image/png;base64," in text and "data:image/jpeg;base64," in text
    assert sha256_of(entries[0].inputs["skull mesh"]) in text
    for needle in ("numpy", "python", "report date", "SCD mm", "skull2cam", "exocanthion_l"):
        assert needle in text
    assert 'id="sfo-1"' in text and 'id="sfo-2"' in text and 'href="#sfo-2"' in text
    assert "MSE<sub>pix</sub>" in text and "off" in text
    with pytest.raises(ValueError, match="at least one SFO"):
        build_report([])


def test_fitness_curve_is_drawn_from_the_history(report):
    _, entries = report
    e = entries[0]
    history = list(np.geomspace(1e4, 3.0, 40))
    result = type(e.result)(**{**e.result.__dict__, "extra": {"history": history}})
    text = build_report([ReportEntry(e.skull, e.photo, result)])
    points = re.search(r'<polyline points="([^"]+)" class="fit"', text).group(1).split()
    assert len(points) == 40
    ys = [float(p.split(",")[1]) for p in points]
    assert ys[0] < ys[-1]  # falling fitness goes down the plot (SVG y grows downwards)


def test_skull_layer_is_transparent_off_the_skull(report):
    _, entries = report
    e = entries[0]
    rgba = skull_layer_rgba(e.result, e.skull, (0, 0, 1200, 900), scale=0.5)
    assert rgba.shape == (450, 600, 4)
    assert rgba[0, 0, 3] == 0 and rgba[225, 300, 3] == 255
    assert 0.1 < (rgba[..., 3] > 0).mean() < 0.9
    # A crop shows the same skull pixels, shifted.
    crop = skull_layer_rgba(e.result, e.skull, (300, 200, 900, 700))
    full = skull_layer_rgba(e.result, e.skull, (0, 0, 1200, 900))
    agree = (crop[..., 3] > 0) == (full[200:700, 300:900, 3] > 0)
    assert agree.mean() > 0.995


def test_skull_views_beside_every_sfo_embedded_once(report):
    path, entries = report
    text = path.read_text()
    # Frontal photo: a frontal and a left lateral view per SFO, each picture embedded once.
    assert text.count('<image id="skv1-frontal"') == 1
    assert text.count('<image id="skv1-lateral_left"') == 1
    assert text.count('href="#skv1-frontal"') == 2 and text.count('href="#skv1-lateral_left"') == 2
    assert text.count('class="skull-view"') == 4
    # The cranial counterparts of the landmark table's rows carry its numbers.
    assert ">1 ectoconchion_l</text>" in text or ">2 ectoconchion_l</text>" in text
    assert "subject&#x27;s left" in text and "subject's left" in text


def test_small_face_is_pictured_at_least_1000_px_across(report):
    _, entries = report
    e = entries[0]
    for box in [(500, 300, 650, 480), (0, 0, 1200, 900), (10, 10, 4010, 3010)]:
        w, h = picture_size(box, picture_scale(box))
        assert min(w, h) >= MIN_ACROSS_PX
        assert max(w, h) <= max(2000, MIN_ACROSS_PX * max(w, h) / min(w, h)) + 1
    # A face of 150 x 180 photo pixels: photo (upscaled) and skull layer share one large size.
    from io import BytesIO

    from PIL import Image

    box = (520, 330, 670, 510)
    pictures = sfo_pictures(e.result, e.skull, e.photo, box, show_outside=False)
    photo = Image.open(BytesIO(pictures.photo_jpeg))
    layer = Image.open(BytesIO(pictures.skull_png))
    assert photo.size == layer.size and photo.size[0] >= 1000
    assert layer.mode == "P" and layer.info.get("transparency") is not None
    rgba = np.asarray(layer.convert("RGBA"))
    assert set(np.unique(rgba[..., 3])) <= {0, 255} and (rgba[..., 3] == 255).mean() > 0.5


def test_view_box_frames_the_skull_and_landmarks():
    covered = np.zeros((900, 1200), dtype=bool)
    covered[300:500, 500:650] = True
    u0, v0, u1, v1 = view_box((1200, 900), covered, None, [(480, 520)])
    assert u0 < 480 and v0 < 300 and u1 > 650 and v1 > 520
    assert (u1 - u0) < 400 and (v1 - v0) < 400
    covered[:] = True
    assert view_box((1200, 900), covered) == (0, 0, 1200, 900)


_PROBE = """
<script>
window.addEventListener('load', function () {
  const out = {};
  for (const sec of document.querySelectorAll('section.sfo')) {
    const skull = sec.querySelector('.skull-layer');
    const stage = sec.querySelector('.stage');
    const opacity = sec.querySelector('input.opacity');
    const wipe = sec.querySelector('input.wipe');
    const marks = sec.querySelector('.marks');
    const style = () => ({opacity: getComputedStyle(skull).opacity,
                          clip: getComputedStyle(skull).clipPath,
                          marks: getComputedStyle(marks).display,
                          loaded: skull.complete && skull.naturalWidth > 0});
    const r = {before: style()};
    opacity.value = '25'; opacity.dispatchEvent(new Event('input'));
    r.opacity25 = style();
    wipe.value = '40'; wipe.dispatchEvent(new Event('input'));
    r.wipe40 = style();
    const box = stage.getBoundingClientRect();
    const at = {clientX: box.left + 0.75 * box.width, clientY: box.top + 10, pointerId: 1,
                bubbles: true};
    stage.dispatchEvent(new PointerEvent('pointerdown', at));
    stage.dispatchEvent(new PointerEvent('pointerup', at));
    r.drag75 = style(); r.drag75.wipe = wipe.value;
    const box2 = skull.getBoundingClientRect();
    r.layerBox = [box2.width, box2.height, box.width, box.height];
    r.views = [...sec.querySelectorAll('svg.skull-view')].map(function (v) {
      return [v.getBoundingClientRect().width, v.querySelector('use').getBBox().width];
    });
    r.dataBox = stage.dataset.box.split(' ').map(Number);
    const toggle = sec.querySelector('input.show-marks');
    toggle.checked = false; toggle.dispatchEvent(new Event('change'));
    r.noMarks = style();
    out[sec.id] = r;
  }
  document.body.setAttribute('data-probe', JSON.stringify(out));
});
</script>
"""


@needs_chromium
def test_controls_change_what_is_shown_in_headless_chromium(report, tmp_path):
    path, _ = report
    probe = path.with_name("probe.html")
    probe.write_text(path.read_text().replace("</body>", _PROBE + "</body>"))
    dom = run_chromium(
        "--window-size=1400,1000",
        "--virtual-time-budget=5000",
        "--dump-dom",
        probe.as_uri(),
        tmp_path=tmp_path,
    ).stdout
    found = re.search(r'data-probe="([^"]*)"', dom)
    assert found, "the probe script did not run"
    result = json.loads(html.unescape(found.group(1)))
    assert set(result) == {"sfo-1", "sfo-2"}
    for r in result.values():
        before = r["before"]
        assert before["loaded"] and float(before["opacity"]) == pytest.approx(0.6)
        assert before["clip"] in ("inset(0px 0% 0px 0px)", "inset(0px 0%)", "inset(0px)")
        assert float(r["opacity25"]["opacity"]) == pytest.approx(0.25)
        assert r["opacity25"]["clip"] == before["clip"]
        assert r["wipe40"]["clip"] in ("inset(0px 60% 0px 0px)", "inset(0px 60% 0px 0%)")
        assert float(r["wipe40"]["opacity"]) == pytest.approx(0.25)
        assert r["drag75"]["wipe"] == "75" and "25%" in r["drag75"]["clip"]
        w, h, sw, sh = r["layerBox"]
        assert w == pytest.approx(sw) and h == pytest.approx(sh) and w >= 1000  # 1,000 px across
        # Both skull-alone views drawn, each showing its picture (embedded once, used twice).
        assert len(r["views"]) == 2
        assert all(width > 300 and used > 0 for width, used in r["views"])
        u0, v0, u1, v1 = r["dataBox"]
        assert h == pytest.approx(w * (v1 - v0) / (u1 - u0), rel=0.01)  # the region's aspect
        assert before["marks"] == "block" and r["noMarks"]["marks"] == "none"


@needs_chromium
def test_screenshot_shows_the_skull_over_the_photo(report, tmp_path):
    from PIL import Image

    path, _ = report
    shot = tmp_path / "shot.png"
    run_chromium(
        "--window-size=1400,1100",
        "--hide-scrollbars",
        f"--screenshot={shot}",
        path.as_uri(),
        tmp_path=tmp_path,
    )
    pixels = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    # The skull outline colour (yellow) appears in the rendered page.
    yellow = (pixels[..., 0] > 200) & (pixels[..., 1] > 170) & (pixels[..., 2] < 80)
    assert yellow.sum() > 200
