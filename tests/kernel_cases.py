"""The cases shared by the compiled-kernel tests (``test_kernels_mesh.py``,
``test_kernels_camera.py``): a bumpy two-walled skull shell, a face mask with a notch and a
hole, cameras around the shell (some clipping the image, some with vertices behind them), the
image they project into, and the mark that skips a test where numba is not installed.
"""

import numpy as np
import pytest

from lilium import jit
from lilium.geometry.rotations import rotvec_to_matrix

needs_numba = pytest.mark.skipif(not jit.NUMBA_AVAILABLE, reason="numba is not installed")

HEIGHT, WIDTH = 480, 640
CENTRE = np.array([320.0, 240.0])


def shell_skull(n_lat=40, n_lon=60, rng=0):
    """A bumpy two-walled shell (outer and inner table, mm) with a hole at the bottom.

    Open borders, back faces inside the front ones, about 2 n_lat n_lon faces per wall.
    """
    rng = np.random.default_rng(rng)
    theta = np.linspace(0.05, 0.8 * np.pi, n_lat)
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    bumps = 0.08 * np.sin(3 * T) * np.cos(5 * P) + 0.01 * rng.standard_normal(T.shape)
    direction = np.stack([np.sin(T) * np.cos(P), np.cos(T), np.sin(T) * np.sin(P)], -1)
    radii = np.array([70.0, 85.0, 90.0])
    walls, faces = [], []
    idx = np.arange(n_lat * n_lon).reshape(n_lat, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    quads = [
        np.stack([idx[:-1], nxt[:-1], nxt[1:]], -1).reshape(-1, 3),
        np.stack([idx[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 3),
    ]
    for k, scale in enumerate((1.0, 0.9)):
        walls.append((direction * ((1 + bumps) * scale)[..., None] * radii).reshape(-1, 3))
        wall_faces = np.vstack(quads) + k * n_lat * n_lon
        faces.append(wall_faces if k == 0 else wall_faces[:, ::-1])
    return np.vstack(walls), np.vstack(faces)


def face_mask(holes=True):
    """An elliptical head mask, with a notch and a hole (non-convex, not simply connected)."""
    rows, cols = np.mgrid[:HEIGHT, :WIDTH]
    mask = ((cols - 320) / 190.0) ** 2 + ((rows - 250) / 215.0) ** 2 <= 1.0
    if not holes:
        return mask
    mask[300:330, 120:260] = False
    mask[150:170, 300:330] = False
    return mask


def cameras(n, rng=0):
    """Rotated, scaled and shifted cameras looking at the shell: some clip the image, some put
    vertices behind the camera."""
    rng = np.random.default_rng(rng)
    R = np.array([rotvec_to_matrix(rng.normal(scale=0.6, size=3)) for _ in range(n)])
    depth = rng.uniform(400.0, 2500.0, n)
    depth[: n // 8] = rng.uniform(60.0, 110.0, n // 8)  # the camera inside the shell's reach
    t = np.column_stack([rng.normal(scale=40.0, size=(n, 2)), depth])
    focal = depth * rng.uniform(1.2, 3.2, n)
    return R, t, focal
