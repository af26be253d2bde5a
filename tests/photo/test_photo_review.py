"""review.html in headless Chromium: drag a point, press Save, read the file back.

The page runs its own scripted drag when opened with ``?test`` (pointer events on the first
landmark, +10/+5 px, then Save); ``--dump-dom`` returns the page after its scripts ran, with
the saved file in ``<pre id="saved">`` and in the download link's ``data:`` URL.
"""

import html
import json
import re
import urllib.parse

import numpy as np
import pytest
from PIL import Image

from browser import needs_chromium, run_chromium

pytest.importorskip("ai_edge_litert")

from lilium.casework.build import read_photo  # noqa: E402
from lilium.cli.main import main  # noqa: E402
from lilium.photo.mask import mask_outline, polygon_mask  # noqa: E402
from lilium.photo.review import review_page  # noqa: E402


@needs_chromium
def test_drag_save_and_read_back(tmp_path):
    from skimage import data

    Image.fromarray(data.astronaut()).save(tmp_path / "a.png")
    out = tmp_path / "photo"
    assert main(["photo", str(tmp_path / "a.png"), "--out", str(out)]) == 0
    before = json.loads((out / "photo.json").read_text())
    page = (out / "review.html").as_uri() + "?test"
    dom = run_chromium("--dump-dom", page, tmp_path=tmp_path).stdout
    saved = json.loads(html.unescape(re.search(r'<pre id="saved">(.*?)</pre>', dom, re.S)[1]))
    href = html.unescape(re.search(r'id="download"[^>]*href="([^"]+)"', dom)[1])
    assert href.startswith("data:application/json")
    assert json.loads(urllib.parse.unquote(href.split(",", 1)[1])) == saved
    first = next(iter(before["landmarks"]))
    moved = np.subtract(saved["landmarks"][first], before["landmarks"][first])
    assert moved == pytest.approx([10, 5], abs=0.05)
    # Template points start switched off: saving without looking confirms none of them.
    qualities = {k: s["quality"] for k, s in before["landmark_sources"].items()}
    assert set(saved["landmarks"]) == {k for k, q in qualities.items() if q == "tracked"}
    file = tmp_path / "landmarks.json"
    file.write_text(json.dumps(saved))
    again = tmp_path / "reviewed"
    assert (
        main(["photo", str(tmp_path / "a.png"), "--out", str(again), "--landmarks", str(file)]) == 0
    )
    photo = read_photo(again)
    assert photo.landmarks_uv[first] == pytest.approx(saved["landmarks"][first])
    # The first outline point was dragged too: the saved outline becomes the mask.
    outline = mask_outline(np.asarray(Image.open(out / "face_mask.png")) > 0)
    assert np.subtract(saved["head_outline_px"][0], outline[0]) == pytest.approx([10, 5], abs=0.15)
    assert np.subtract(saved["head_outline_px"][1:], outline[1:]) == pytest.approx(0, abs=0.15)
    assert json.loads((again / "photo.json").read_text())["face_mask_is_head"] is True
    rebuilt = np.asarray(Image.open(again / "face_mask.png")) > 0
    assert (rebuilt == polygon_mask(saved["head_outline_px"], rebuilt.shape[::-1])).all()
    assert (rebuilt == photo.face_mask).all()


@needs_chromium
def test_every_face_is_drawn_with_its_box_and_number(tmp_path):
    faces = [
        {"number": 1, "box_px": [10, 12, 40, 44], "width_px": 30, "score": 0.9},
        {"number": 2, "box_px": [60, 10, 90, 42], "width_px": 30, "score": 0.8},
    ]
    page = review_page(
        np.zeros((64, 100, 3), np.uint8), {}, {}, np.zeros((0, 2)), {}, "t", faces=faces
    )
    (tmp_path / "review.html").write_text(page, encoding="utf-8")
    dom = run_chromium("--dump-dom", (tmp_path / "review.html").as_uri(), tmp_path=tmp_path).stdout
    for face in faces:
        u0, v0, u1, v1 = face["box_px"]
        box = re.search(rf'<rect[^>]*id="face-{face["number"]}"[^>]*>', dom)[0]
        assert f'x="{u0}"' in box and f'width="{u1 - u0}"' in box and f'height="{v1 - v0}"' in box
        assert f"face {face['number']}</text>" in dom
