"""review.html of a skull in headless Chromium (WebGL on SwiftShader): a landmark dragged along
the bone, saved, read back as the subject's cranial landmarks.

The page's ``?test`` hook ticks the landmarks named by ``&tick=``, drags the first switched-on
landmark in sight by (+15, +8) CSS pixels with pointer events, lists the landmarks in sight and
presses Save; ``--dump-dom`` returns the page with those in ``<pre>`` elements. The skull is a
generated subject (:func:`lilium.synthetic.subjects.make_subject`, known landmarks), its
mandible's and ears' landmarks marked ``template``.
"""

import base64
import html
import json
import re
import urllib.parse

import numpy as np
import pytest

from browser import WEBGL_FLAGS, needs_chromium, run_chromium
from lilium.casework.build import read_skull
from lilium.geometry.mesh import decimate
from lilium.report.skull_review import skull_review_page, write_skull_review
from lilium.skull.locate import orientation_dependent
from lilium.skull.prepare import FLAG
from lilium.synthetic.subjects import distance_to_mesh, make_subject, write_subject

#: Faces the test page draws (the subject has 50,000): a decimated page, quick to pick on.
MAX_FACES = 20_000

#: The test hook's drag, CSS pixels (headless Chromium: one device pixel each).
DRAG_PX = (15.0, 8.0)

#: A desktop window: the skull about 850 px high, 15 px about 6 mm.
WINDOW = "--window-size=1400,1000"

#: Landmarks marked ``template`` (their prefixes): they start switched off.
TEMPLATE = ("gonion", "mental_foramen", "porion")

#: A point on the surface: distance to the drawn mesh (mm; float32 vertices, a pick's rounding).
ON_SURFACE_MM = 0.5


@pytest.fixture(scope="module")
def subject():
    return make_subject("s0", 0)


def _sources(names):
    quality = {n: "template" if n.startswith(TEMPLATE) else "located" for n in names}
    out = {n: {"source": "automatic", "quality": q} for n, q in quality.items()}
    for n in names:  # as lilium skull flags them (lilium.skull.prepare.landmark_sources)
        if orientation_dependent(n):
            out[n]["flag"] = FLAG
    return out


def _mark_class(dom, name):
    return re.search(rf'<g class="([^"]*)" id="lm-{name}"', dom)[1].split()


@pytest.fixture(scope="module")
def page(subject, tmp_path_factory):
    lm = subject.cranial_landmarks
    return write_skull_review(
        tmp_path_factory.mktemp("page") / "review.html",
        subject.skull_vertices_mm, subject.skull_faces, lm, _sources(lm), title="s0",
        parts={"cranium": True, "mandible": True}, message="porion: template", max_faces=MAX_FACES,
    )  # fmt: skip


@pytest.fixture(scope="module")
def opened(page):
    """``opened(query)``: the DOM of the test page with ``?query`` (each opened once)."""
    doms = {}

    def dom(query):
        if query not in doms:
            args = (*WEBGL_FLAGS, WINDOW, "--dump-dom", page.as_uri() + "?" + query)
            doms[query] = run_chromium(*args, tmp_path=page.parent).stdout
        return doms[query]

    return dom


def _pre(dom, element_id):
    return html.unescape(re.search(rf'<pre id="{element_id}">(.*?)</pre>', dom, re.S)[1])


def _drawn_mesh(text):
    """The page's mesh as drawn (skull frame, float32 vertices)."""

    def block(name):
        return re.search(rf'<script type="[^"]+" id="{name}">(.*?)</script>', text, re.S)[1]

    origin = json.loads(block("review-data"))["mesh_origin_mm"]
    positions = np.frombuffer(base64.b64decode(block("mesh-positions")), "<f4").reshape(-1, 3)
    faces = np.frombuffer(base64.b64decode(block("mesh-indices")), "<u4").reshape(-1, 3)
    return positions.astype(float) + origin, faces.astype(np.int64)


def _check_drag(dom, page, landmarks):
    """The dragged landmark: moved with the pointer, on the drawn surface; its name."""
    dragged = json.loads(_pre(dom, "dragged"))
    saved = json.loads(_pre(dom, "saved"))
    name = dragged["name"]
    assert np.subtract(dragged["to_uv"], dragged["from_uv"]) == pytest.approx(DRAG_PX, abs=0.5)
    point = np.asarray(saved["landmarks"][name])
    assert point == pytest.approx(dragged["point"], abs=1e-4)
    assert np.linalg.norm(point - landmarks[name]) > 2.0  # 15 px is about 6 mm here
    vertices, faces = _drawn_mesh(page.read_text())
    assert distance_to_mesh(vertices, faces, point[None])[0] < ON_SURFACE_MM
    return name, saved


@needs_chromium
def test_frontal_drag_moves_a_point_along_the_bone(subject, page, opened):
    lm = subject.cranial_landmarks
    dom = opened("test")
    assert float(_pre(dom, "first-draw-ms")) > 0
    name, saved = _check_drag(dom, page, lm)
    on = [n for n in lm if not n.startswith(TEMPLATE)]
    assert name == on[0]  # the first switched-on landmark, in sight from the front
    # Template points start switched off: saving without looking confirms none of them.
    assert list(saved["landmarks"]) == on
    # The orientation-dependent extremes are ringed and marked "check" until reviewed.
    assert "flagged" in _mark_class(dom, "zygion_l") and "flagged" in _mark_class(dom, "orbitale_r")
    assert "flagged" not in _mark_class(dom, "nasion")
    rows = re.findall(r"<tr[^>]*>(.*?)</tr>", dom, re.S)
    checked = {re.search(r'id="on-(\w+)"', r)[1] for r in rows if 'class="flag"' in r}
    assert checked == {n for n in lm if orientation_dependent(n)}
    for n in on[1:]:  # the others exactly as given
        assert saved["landmarks"][n] == [float(x) for x in lm[n]], n
    sources = _sources(lm)
    for n in on:
        assert saved["landmark_sources"][n] == {
            "source": "reviewed", "quality": sources[n]["quality"], "confirmed": True,
        }  # fmt: skip
    href = html.unescape(re.search(r'id="download"[^>]*href="([^"]+)"', dom)[1])
    assert href.startswith("data:application/json")
    assert json.loads(urllib.parse.unquote(href.split(",", 1)[1])) == saved


@needs_chromium
def test_left_view_hides_the_right_side_and_ticks_a_template_point(subject, page, opened):
    lm = subject.cranial_landmarks
    dom = opened("test&view=left&tick=gonion_l")
    visible = set(json.loads(_pre(dom, "visible")))
    assert not {n for n in lm if n.endswith("_r")} & visible
    sides = ("zygion_l", "gonion_l", "porion_l", "frontotemporale_l", "mental_foramen_l")
    assert set(sides) | {"nasion", "bregma", "pogonion"} <= visible
    assert not {"ectoconchion_l", "orbitale_l"} & visible  # behind the orbit's rim
    name, saved = _check_drag(dom, page, lm)
    assert name == "dacryon_l"  # ectoconchion_l, the first one switched on, is out of sight
    assert saved["landmark_sources"]["gonion_l"] == {
        "source": "reviewed", "quality": "template", "confirmed": True,
    }  # fmt: skip
    assert saved["landmarks"]["gonion_l"] == [float(x) for x in lm["gonion_l"]]
    assert "flagged" not in _mark_class(dom, "gonion_l")  # ticked: reviewed
    assert "flagged" in _mark_class(dom, "zygion_l")
    assert {n for n in saved["landmarks"] if n.startswith(TEMPLATE)} == {"gonion_l"}


@needs_chromium
def test_saved_file_is_the_subjects_cranial_landmark_file(subject, page, opened, tmp_path):
    name, saved = _check_drag(opened("test"), page, subject.cranial_landmarks)
    folder = tmp_path / "s0"
    write_subject(folder, subject)
    file = tmp_path / "reviewed" / "cranial_landmarks.json"
    file.parent.mkdir()
    file.write_text(json.dumps(saved))
    skull = read_skull(folder, landmarks_path=file)
    assert set(skull.landmarks_mm) == set(saved["landmarks"])
    assert skull.landmarks_mm[name] == pytest.approx(saved["landmarks"][name], abs=1e-9)
    # The moved point is on the subject's own (undecimated) bone too.
    point = [saved["landmarks"][name]]
    assert distance_to_mesh(subject.skull_vertices_mm, subject.skull_faces, point)[0] < 1.0


def test_page_is_self_contained(page):
    text = page.read_text()
    assert not re.search(r"https?:", text)
    assert "__" not in re.sub(r'<script type="application/octet-stream".*?</script>', "", text,
                              flags=re.S).replace("__proto__", "")  # fmt: skip
    assert "found: cranium, mandible" in text and "porion: template" in text


def test_title_and_message_are_escaped(subject):
    v, f = decimate(subject.skull_vertices_mm, subject.skull_faces, 500)
    text = skull_review_page(v, f, {}, {}, title="<b>x</b>", message="a & b",
                             parts={"mandible": False})  # fmt: skip
    assert "&lt;b&gt;x&lt;/b&gt;" in text and "a &amp; b" in text
    assert "not found: <b>mandible</b>" in text


@pytest.mark.parametrize(
    ("vertices", "faces", "landmarks", "match"),
    [
        (np.zeros((3, 2)), [[0, 1, 2]], {}, r"vertices_mm must have shape \(V, 3\)"),
        (np.zeros((3, 3)), [[0, 1, 3]], {}, "faces index vertices 0 to 2"),
        (np.zeros((3, 3)), [[0.0, 1.0, 2.0]], {}, "faces must be integer"),
        (np.zeros((3, 3)), [[0, 1, 2]], {"nasion": [0, np.nan, 0]}, "3 finite numbers"),
    ],
)
def test_invalid_input_is_a_clear_error(vertices, faces, landmarks, match):
    with pytest.raises(ValueError, match=match):
        skull_review_page(vertices, faces, landmarks, {})


@pytest.mark.slow
def test_page_weight_of_a_600k_face_skull(subject):
    import trimesh

    v, f = decimate(subject.skull_vertices_mm, subject.skull_faces, 37_500)
    for _ in range(2):
        v, f = trimesh.remesh.subdivide(v, f)
    assert len(f) == pytest.approx(600_000, rel=0.01)
    text = skull_review_page(v, f, subject.cranial_landmarks, {})
    data = re.search(r'<script type="application/json" id="review-data">(.*?)</script>', text)[1]
    assert json.loads(data)["faces"]["drawn"] == pytest.approx(300_000, rel=0.01)
    assert len(text.encode()) < 30e6  # measured: 7.2 MB
