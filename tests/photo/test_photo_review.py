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

from lilium.cli.main import main  # noqa: E402
from lilium.io.case import read_photo  # noqa: E402


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
