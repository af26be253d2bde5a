"""workbench.html: the skull drawn through the SFO's camera in headless Chromium (WebGL on
SwiftShader), turned, read back, saved.

The page's ``?test`` hook draws, measures the drawn skull's box on pixels read back from the
GPU, picks the surface at the projected nasion and presses Save; ``--dump-dom`` returns the
page with those in ``<pre>`` elements. The input is the stand-in case (tests/standin_case.py)
with an SFO camera a little off the truth, so the landmark errors are not zero.
"""

import base64
import html
import json
import re
import sys
import time
import urllib.parse
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from browser import WEBGL_FLAGS, needs_chromium, run_chromium
from lilium.casework.build import read_photo, read_skull
from lilium.geometry.camera import Camera, principal_point_of
from lilium.geometry.rotations import geodesic_angle_deg, matrix_to_rotvec, rotvec_to_matrix
from lilium.io.jsonio import read_json
from lilium.io.results import read_camera
from lilium.methods.checks import landmark_error
from lilium.methods.result import SfoResult
from lilium.report.workbench import (
    PAGE_SIDE_PX,
    _photo_data_url,
    adjusted_camera,
    skull_centre,
    workbench_axes,
    workbench_page,
    write_workbench,
)
from standin_case import make_standin_case

#: Faces the test page draws: fewer than the stand-in's 5,120, so the page is decimated.
MAX_FACES = 2000

#: The drawn box against the projected mesh (pixels): rasterisation keeps pixel centres only.
BOX_TOLERANCE_PX = 3.0


def _sfo(subject_dir, photo_dir):
    """Skull, photo and a result whose camera is 1.5 degrees and 4 mm off the true one."""
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    truth = read_json(photo_dir / "photo.json")["ground_truth"]
    T = np.asarray(truth["skull2cam"], float)
    T[:3, :3] = rotvec_to_matrix(np.radians([0.5, 1.0, 1.0])) @ T[:3, :3]
    T[:3, 3] += [4.0, -2.0, 10.0]
    camera = Camera(T, truth["focal_px"], principal_point_of(photo.image_size_wh))
    facial = read_json(subject_dir / "facial_landmarks.json")["landmarks"]
    facial = {k: np.asarray(v, float) for k, v in facial.items()}
    result = SfoResult(
        "posest-sfo", None, None, skull.id, photo.id, camera, 0.0, {}, facial, 0.0,
        landmark_error=landmark_error(camera, facial, photo),
    )  # fmt: skip
    return skull, photo, result


@pytest.fixture(scope="module")
def sfo(tmp_path_factory):
    return _sfo(*make_standin_case(tmp_path_factory.mktemp("case"), seed=0))


@pytest.fixture(scope="module")
def page(sfo, tmp_path_factory):
    return write_workbench(tmp_path_factory.mktemp("page") / "workbench.html", *sfo,
                           max_faces=MAX_FACES)  # fmt: skip


def _open(path, query):
    """The page's DOM after its scripts ran, opened with ``?query``."""
    args = (*WEBGL_FLAGS, "--dump-dom", path.as_uri() + "?" + query)
    return run_chromium(*args, tmp_path=path.parent).stdout


@pytest.fixture(scope="module")
def opened(page):
    """``opened(query)``: the DOM of the test page with ``?query`` (each opened once)."""
    doms = {}

    def dom(query):
        if query not in doms:
            doms[query] = _open(page, query)
        return doms[query]

    return dom


def _pre(dom, element_id):
    return html.unescape(re.search(rf'<pre id="{element_id}">(.*?)</pre>', dom, re.S)[1])


def _page_camera(dom):
    return Camera.from_dict(json.loads(_pre(dom, "camera")))


def _embedded(text):
    """The page's data and mesh (vertices in the skull frame, float32 as drawn)."""

    def block(name):
        return re.search(rf'<script type="[^"]+" id="{name}">(.*?)</script>', text, re.S)[1]

    data = json.loads(block("workbench-data"))
    positions = np.frombuffer(base64.b64decode(block("mesh-positions")), "<f4").reshape(-1, 3)
    faces = np.frombuffer(base64.b64decode(block("mesh-indices")), "<u4").reshape(-1, 3)
    return data, positions.astype(float) + data["mesh_origin_mm"], faces.astype(np.int64)


def _projected_box(camera, vertices, faces):
    uv = camera.project(vertices[np.unique(faces)])
    return np.concatenate([np.nanmin(uv, axis=0), np.nanmax(uv, axis=0)])


@needs_chromium
def test_drawn_skull_sits_where_the_camera_projects_it(sfo, page, opened):
    skull, _, result = sfo
    dom = opened("test")
    data, vertices, faces = _embedded(page.read_text())
    assert len(faces) <= MAX_FACES < len(skull.faces)
    drawn = _page_camera(dom)
    assert np.allclose(drawn.skull2cam, result.camera.skull2cam, atol=1e-9)
    assert drawn.focal_px == pytest.approx(result.camera.focal_px, rel=1e-12)
    box = np.array(_pre(dom, "skull-box").split(), float)
    expected = _projected_box(result.camera, vertices, faces)
    assert box == pytest.approx(expected, abs=BOX_TOLERANCE_PX)
    # The surface pick at the projected nasion finds the nasion (on the mesh, in front).
    pick = json.loads(_pre(dom, "pick"))
    assert pick["landmark"] == "nasion"
    assert np.linalg.norm(np.subtract(pick["point"], skull.landmarks_mm["nasion"])) < 1.5


@needs_chromium
def test_live_errors_are_the_results_landmark_errors(sfo, opened):
    errors = sfo[2].landmark_error
    dom = opened("test")
    rows = dict(re.findall(r"<tr><td>([a-z_]+)</td><td>([0-9.]+)</td>", dom))
    assert set(rows) == set(errors["per_landmark_px"])
    for name, px in errors["per_landmark_px"].items():
        assert float(rows[name]) == pytest.approx(px, abs=0.051), name
    mean = re.search(r'<td id="mean-error">([0-9.]+)</td>', dom)[1]
    assert float(mean) == pytest.approx(errors["mean_px"], abs=0.0051)
    assert errors["mean_px"] > 1.0  # the SFO camera is off the truth: a real check


@needs_chromium
def test_yaw_turns_the_skull_about_its_vertical_axis(sfo, page, opened):
    skull, _, result = sfo
    data, vertices, faces = _embedded(page.read_text())
    turned = _page_camera(opened("test&yaw=5"))
    assert geodesic_angle_deg(turned.R, result.camera.R) == pytest.approx(5.0, abs=0.05)
    # In the skull frame the turn is about the anatomical up axis (right hand).
    rotvec = matrix_to_rotvec(result.camera.R.T @ turned.R)
    assert np.degrees(rotvec) @ data["axes"]["up"] == pytest.approx(5.0, abs=0.05)
    axes = workbench_axes(skull.landmarks_mm, result.camera)
    assert np.allclose(data["axes"]["up"], axes.up)
    # ... through the skull's centre, which stays where it was.
    pivot = skull_centre(skull.vertices_mm)
    assert turned.to_camera_frame(pivot[None]) == pytest.approx(
        result.camera.to_camera_frame(pivot[None]), abs=1e-6
    )
    expected = adjusted_camera(result.camera, axes, pivot, yaw_deg=5)
    assert np.allclose(turned.skull2cam, expected.skull2cam, atol=1e-6)
    box = np.array(_pre(opened("test&yaw=5"), "skull-box").split(), float)
    assert box == pytest.approx(_projected_box(expected, vertices, faces), abs=BOX_TOLERANCE_PX)


@needs_chromium
def test_pitch_and_roll_follow_the_python_model(sfo, opened):
    skull, _, result = sfo
    turned = _page_camera(opened("test&pitch=4&roll=-3"))
    axes = workbench_axes(skull.landmarks_mm, result.camera)
    pivot = skull_centre(skull.vertices_mm)
    expected = adjusted_camera(result.camera, axes, pivot, pitch_deg=4, roll_deg=-3)
    assert np.allclose(turned.skull2cam, expected.skull2cam, atol=1e-6)


@needs_chromium
def test_saved_camera_reads_back(sfo, opened, tmp_path):
    """camera.json: the page's camera and the soft tissue it showed (the result's facial
    landmarks), as ``--camera`` reads them (:func:`lilium.io.results.read_camera`)."""
    result = sfo[2]
    dom = opened("test&yaw=5")
    href = html.unescape(re.search(r'id="download"[^>]*href="([^"]+)"', dom)[1])
    assert href.startswith("data:application/json")
    saved = json.loads(urllib.parse.unquote(href.split(",", 1)[1]))
    assert set(saved) == {"focal_px", "principal_point_px", "skull2cam", "facial_landmarks_3d"}
    camera = Camera.from_dict(saved)
    assert np.allclose(camera.skull2cam, _page_camera(dom).skull2cam, atol=1e-12)
    path = tmp_path / "camera.json"
    path.write_text(json.dumps(saved))
    given = read_camera(path)
    assert np.allclose(given.camera.skull2cam, camera.skull2cam, atol=0)
    assert set(given.facial_landmarks_mm) == set(result.facial_landmarks_mm)
    for name, point in result.facial_landmarks_mm.items():
        assert np.allclose(given.facial_landmarks_mm[name], point, atol=1e-9)


def test_page_fetches_nothing(page):
    text = page.read_text()
    assert not re.search(r"https?:|ftp:|//[a-z0-9.-]+\.[a-z]{2,}/", text, re.I)
    for link in re.findall(r'(?:src|href)="([^"]*)"', text):
        assert link.startswith("data:") or link == "#", link[:40]


def test_page_without_a_picture(sfo):
    skull, photo, result = sfo
    text = workbench_page(skull, replace(photo, image=None), result, max_faces=MAX_FACES)
    data, _, _ = _embedded(text)
    assert data["has_image"] is False and 'src="data:,"' in text
    assert data["image_size_wh"] == list(photo.image_size_wh)


def test_default_camera_is_the_sfos_and_each_field_does_one_thing(sfo):
    skull, _, result = sfo
    camera, pivot = result.camera, skull_centre(skull.vertices_mm)
    axes = workbench_axes(skull.landmarks_mm, camera)
    assert np.allclose(adjusted_camera(camera, axes, pivot).skull2cam, camera.skull2cam)
    uv = camera.project(pivot[None])[0]
    moved = adjusted_camera(camera, axes, pivot, shift_px=(12.0, -7.0), distance_mm=800.0)
    assert moved.project(pivot[None])[0] == pytest.approx(uv + [12.0, -7.0], abs=1e-9)
    assert moved.distance_mm(pivot) == pytest.approx(800.0)
    zoomed = adjusted_camera(camera, axes, pivot, focal_px=2 * camera.focal_px)
    assert zoomed.project(pivot[None])[0] == pytest.approx(uv, abs=1e-9)
    assert np.allclose(zoomed.R, camera.R)


def test_axes_without_landmarks_are_the_cameras(sfo):
    camera = sfo[2].camera
    axes = workbench_axes({}, camera)
    assert axes.source == "camera"
    assert camera.R @ axes.up == pytest.approx([0, -1, 0])
    assert camera.R @ axes.left == pytest.approx([1, 0, 0])
    assert camera.R @ axes.anterior == pytest.approx([0, 0, -1])


def test_failed_sfo_has_no_workbench(sfo):
    skull, photo, result = sfo
    failed = replace(result, camera=None, error="no solution")
    with pytest.raises(ValueError, match="failed SFO .*no solution"):
        workbench_page(skull, photo, failed)


def test_large_photo_is_embedded_smaller():
    from io import BytesIO

    from PIL import Image

    url = _photo_data_url(np.zeros((300, 4500, 3), np.uint8))
    picture = Image.open(BytesIO(base64.b64decode(url.split(",", 1)[1])))
    assert picture.size == (PAGE_SIDE_PX, round(300 * PAGE_SIDE_PX / 4500))


#: Real size (issue 57): a page for a 500k+ face skull and a 24 MP photo.
REAL_FACES, REAL_MEGAPIXELS = 600_000, 24
MAX_PAGE_MB, MAX_FIRST_DRAW_S = 30, 5


@pytest.mark.slow
@needs_chromium
def test_real_size_page_is_light_and_quick(sfo, tmp_path):
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks" / "datasets"))
    from real_size import photo_at, skull_at

    skull, photo, result = sfo
    big_skull, big_photo = skull_at(skull, REAL_FACES), photo_at(photo, REAL_MEGAPIXELS)
    assert len(big_skull.faces) >= 500_000
    s = big_photo.image_size_wh[0] / photo.image_size_wh[0]
    big = replace(result, camera=result.camera.cropped((0.0, 0.0), s))
    path = write_workbench(tmp_path / "workbench.html", big_skull, big_photo, big)
    assert path.stat().st_size < MAX_PAGE_MB * 1e6
    start = time.perf_counter()
    dom = _open(path, "test")
    wall_s = time.perf_counter() - start
    assert json.loads(_pre(dom, "timing"))["first_draw_ms"] < MAX_FIRST_DRAW_S * 1000, wall_s
    _, vertices, faces = _embedded(path.read_text())
    box = np.array(_pre(dom, "skull-box").split(), float)
    assert box == pytest.approx(_projected_box(big.camera, vertices, faces), abs=BOX_TOLERANCE_PX)
    # and the whole mesh's projection (the decimation keeps the silhouette within the tolerance)
    full = _projected_box(big.camera, big_skull.vertices_mm, big_skull.faces)
    assert box == pytest.approx(full, abs=BOX_TOLERANCE_PX)
