"""The detailed skull render (depth, normals, cavities, creases) and the skull-alone views."""

import re

import numpy as np
import pytest

from lilium import jit
from lilium.casework.build import read_skull
from lilium.fitness.regions import anatomical_frame
from lilium.geometry.camera import Camera
from lilium.geometry.rotations import rotvec_to_matrix
from lilium.imaging.raster import skull_raster
from lilium.imaging.shading import creases, render_surface, shade_surface
from lilium.imaging.skull_views import SKULL_VIEWS, skull_view, view_rotation
from lilium.report.pictures import skull_view_pictures
from lilium.report.svg import LABEL_COLUMN, skull_view_svg

#: A camera looking along +z at the origin plane from 500 mm: 2 px per mm.
SIZE_WH = (240, 240)


def _camera():
    skull2cam = np.eye(4)
    skull2cam[2, 3] = 500.0
    return Camera(skull2cam, 1000.0, np.array([119.5, 119.5]))


def _grid(depth_of, half_mm=50, step_mm=1.0):
    """A height field z = depth_of(x, y) (mm, away from the camera) as a triangle mesh."""
    xs = np.arange(-half_mm, half_mm + step_mm / 2, step_mm)
    x, y = np.meshgrid(xs, xs)
    vertices = np.stack([x, y, depth_of(x, y)], axis=-1).reshape(-1, 3)
    n = len(xs)
    i = np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]
    i = i.ravel()
    faces = np.concatenate([np.stack([i, i + 1, i + n], 1), np.stack([i + 1, i + n + 1, i + n], 1)])
    return vertices, faces


def _pit(x, y):
    return np.where(np.maximum(np.abs(x), np.abs(y)) <= 10, 15.0, 0.0)


def test_surface_buffers_of_a_plane():
    v, f = _grid(lambda x, y: np.zeros_like(x))
    camera = _camera()
    surface = render_surface(v, f, camera, SIZE_WH)
    assert np.array_equal(surface.covered, skull_raster(camera.project(v), f, SIZE_WH[::-1]))
    on = surface.covered
    assert on.sum() > 0.9 * 200 * 200
    assert np.allclose(surface.depth_mm[on], 500.0, atol=1e-3)
    assert np.all(np.isnan(surface.depth_mm[~on]))
    # Normals towards the camera whatever the winding (the grid is wound either way).
    assert np.allclose(surface.normal_cam[on], [0, 0, -1], atol=1e-6)
    flipped = render_surface(v, f[:, ::-1], camera, SIZE_WH)
    assert np.allclose(flipped.normal_cam[on], [0, 0, -1], atol=1e-6)
    assert surface.mm_to_px(10.0) == pytest.approx(20.0)
    shade = shade_surface(surface)
    assert np.ptp(shade[on]) < 1e-3 and not np.any(shade[~on])  # flat: one shade


@pytest.mark.skipif(not jit.NUMBA_AVAILABLE, reason="numba is not installed")
def test_compiled_surface_buffers_are_the_numpy_ones():
    """The per-pixel depth and normals (pit walls, a mesh wound either way, a tilted camera)
    come out of the compiled kernel bit for bit as from the numpy steps."""
    v, f = _grid(_pit)
    f[::3] = f[::3, ::-1]  # some triangles wound the other way
    skull2cam = np.eye(4)
    skull2cam[:3, :3] = rotvec_to_matrix([0.3, -0.2, 0.1])
    skull2cam[2, 3] = 500.0
    camera = Camera(skull2cam, 1000.0, np.array([119.5, 119.5]))
    compiled = render_surface(v, f, camera, SIZE_WH)
    with jit.kernels("numpy"):
        reference = render_surface(v, f, camera, SIZE_WH)
    assert compiled.covered.sum() > 1000
    np.testing.assert_array_equal(compiled.depth_mm, reference.depth_mm)
    np.testing.assert_array_equal(compiled.normal_cam, reference.normal_cam)


def test_a_pit_reads_darker_and_its_rim_is_drawn():
    v, f = _grid(_pit)
    camera = _camera()
    surface = render_surface(v, f, camera, SIZE_WH)
    shade, lines = shade_surface(surface), creases(surface)
    c = 119  # the image centre sees the pit's floor (x = y = 0)
    assert surface.depth_mm[c, c] == pytest.approx(515.0, abs=1e-3)
    floor = shade[c - 8 : c + 9, c - 8 : c + 9]
    flat = shade[c - 8 : c + 9, c + 50 : c + 67]  # 25-33 mm to the side, on the plane
    assert floor.mean() < 0.8 * flat.mean()
    # The pit's walls (x = +-10 mm, 20 px from the centre) carry a crease line; the flat does not.
    assert lines[c, c + 20] > 0.5 and lines[c, c - 20] > 0.5
    assert lines[c, c + 60] == 0 and lines[c, c] == 0


@pytest.mark.parametrize("view", SKULL_VIEWS)
def test_view_rotations_are_proper(view):
    R = view_rotation([0, 0.1, 1], [0, 1, 0.2], view)
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="unknown skull view 'top'"):
        view_rotation([0, 0, 1], [0, 1, 0], "top")


def _swapped(landmarks):
    swap = {"_l": "_r", "_r": "_l"}
    return {(n[:-2] + swap[n[-2:]] if n[-2:] in swap else n): p for n, p in landmarks.items()}


def test_views_follow_the_mesh_so_swapped_labels_show(case):
    subject_dir, _ = case
    skull = read_skull(subject_dir)  # stand-in: x = subject's left, y = up, z = anterior
    lm = skull.landmarks_mm
    frame = anatomical_frame(lm)
    size = (260, 300)
    front = skull_view(
        skull.vertices_mm, skull.faces, lm, frame.anterior, frame.up, "frontal", size
    )
    uv = dict(zip(front.names, front.uv, strict=True))
    for base in ("zygion", "gonion", "ectoconchion", "frontotemporale"):
        assert uv[f"{base}_l"][0] > uv[f"{base}_r"][0] + 20, base  # subject's left: image right
    assert uv["bregma"][1] < uv["nasion"][1] < uv["gnathion"][1]
    assert front.visible.all()
    side = skull_view(
        skull.vertices_mm, skull.faces, lm, frame.anterior, frame.up, "lateral_left", size
    )
    uv = dict(zip(side.names, side.uv, strict=True))
    seen = dict(zip(side.names, side.visible, strict=True))
    assert uv["nasion"][0] < size[0] / 2  # the face towards the image's left
    assert seen["zygion_l"] and seen["gonion_l"] and seen["nasion"]
    assert not seen["zygion_r"] and not seen["gonion_r"]  # the far side
    # Labels swapped left for right: the same picture, the labels on the other side.
    swapped = _swapped(lm)
    frame2 = anatomical_frame(swapped)
    again = skull_view(
        skull.vertices_mm, skull.faces, swapped, frame2.anterior, frame2.up, "frontal", size
    )
    assert np.array_equal(again.image, front.image)
    uv = dict(zip(again.names, again.uv, strict=True))
    assert uv["zygion_l"][0] < uv["zygion_r"][0] - 20


def _label_x(svg, name):
    found = re.search(r'<text x="([-0-9.]+)"[^>]*>(?:\d+ )?' + re.escape(name) + "</text>", svg)
    return None if found is None else float(found.group(1))


def test_skull_view_svg_labels_by_position_and_number(case):
    subject_dir, _ = case
    skull = read_skull(subject_dir)
    front, side = skull_view_pictures(skull, ("frontal", "lateral_left"))
    w = front.size_wh[0]
    svg = skull_view_svg(front, {"ectoconchion_l": 1, "nasion": 14})
    assert f'viewBox="{-LABEL_COLUMN} 0 {w + 2 * LABEL_COLUMN}' in svg
    assert f'<use href="#{front.key}"/>' in svg
    assert _label_x(svg, "zygion_l") > w and _label_x(svg, "zygion_r") < 0
    assert ">1 ectoconchion_l</text>" in svg and ">14 nasion</text>" in svg
    assert svg.count('class="used"') == 2
    svg = skull_view_svg(side)
    assert _label_x(svg, "zygion_r") is None  # hidden behind bone: no label ...
    assert "zygion_r (hidden behind bone in this view)" in svg  # ... but its name on hover
    assert _label_x(svg, "zygion_l") is not None
    # Labels never overlap within a column.
    ys = sorted(float(y) for y in re.findall(r'<text x="-[0-9.]+" y="([0-9.]+)"', svg))
    assert np.all(np.diff(ys) >= 16.9)


def test_no_views_when_the_landmarks_cannot_orient_the_skull(case):
    from dataclasses import replace

    subject_dir, _ = case
    skull = read_skull(subject_dir)
    few = {n: p for n, p in skull.landmarks_mm.items() if n.startswith("zygion")}
    assert skull_view_pictures(replace(skull, landmarks_mm=few), ("frontal",)) == ()
