"""The pinhole camera of docs/contract.md: one type, one projection.

Convention, written once: ``skull2cam`` is a 4x4 rigid transform (mm) from the skull-mesh frame to
the camera frame (x right, y down, z forward). A point ``X`` of the skull frame goes to
``X_cam = R X + t`` and projects to ``uv = principal_point_px + focal_px * X_cam[:2] / X_cam[2]``.
Pixel coordinates ``uv`` are (u = column, v = row), the centre of the top-left pixel is (0, 0).
Square pixels, no distortion. Points at or behind the camera project to NaN, so row i stays
point i.

- :class:`Camera`: one camera (``skull2cam``, ``focal_px``, ``principal_point_px``);
- :class:`Cameras`: S cameras sharing a principal point (a DE population), ``cameras[i]`` is a
  :class:`Camera`;
- :func:`project_points`: the projection both use (and every module that projects).
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import MIN_DEPTH_MM
from ._projection_kernels import project_kernel
from .rotations import check_rotation


def principal_point_of(image_size_wh):
    """Image centre (pixels) of an image of ``(width, height)`` pixels.

    With pixel centres at integer coordinates the centre is ``((w - 1) / 2, (h - 1) / 2)``.
    """
    width, height = image_size_wh
    return np.array([(width - 1) / 2.0, (height - 1) / 2.0])


def check_skull2cam(skull2cam, name="skull2cam"):
    """Validate a 4x4 rigid transform and return it as a float array."""
    T = np.asarray(skull2cam, dtype=float)
    if T.shape != (4, 4):
        raise ValueError(f"{name} must be a 4x4 matrix, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise ValueError(f"{name} contains NaN or infinite values")
    check_rotation(T[:3, :3], name=f"{name}[:3, :3]")
    if not np.allclose(T[3], [0, 0, 0, 1]):
        raise ValueError(f"{name} last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    return T


def rigid(R, t):
    """The 4x4 transform ``[[R, t], [0, 0, 0, 1]]``."""
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def to_camera_frame(points_mm, R, t):
    """Points in the frames of S cameras.

    Parameters
    ----------
    points_mm : array_like of shape (N, 3) or (S, N, 3)
        One point set shared by the cameras, or one per camera.
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)

    Returns
    -------
    X_cam_mm : ndarray of shape (S, N, 3)
    """
    P = np.asarray(points_mm, dtype=float)
    R = np.asarray(R, dtype=float)
    S = len(R)
    if P.ndim == 2:
        # One (3S, 3) x (3, N) product instead of S small ones.
        X = (np.reshape(R, (3 * S, 3)) @ P.T).reshape(S, 3, -1)
        X += np.asarray(t, dtype=float)[:, :, None]
        return np.swapaxes(X, 1, 2)
    return np.einsum("sij,snj->sni", R, P) + np.asarray(t, dtype=float)[:, None, :]


def project_points(points_mm, R, t, focal_px, principal_point_px=(0.0, 0.0)):
    """Project points under S cameras: the one pinhole projection of the package.

    Parameters
    ----------
    points_mm : array_like of shape (N, 3) or (S, N, 3)
        Skull-frame points (mm), shared by the cameras or one set per camera.
    R : array_like of shape (S, 3, 3)
    t : array_like of shape (S, 3)
    focal_px : array_like of shape (S,)
    principal_point_px : array_like of shape (2,)
        ``(0, 0)`` gives coordinates centred on the principal point.

    Returns
    -------
    uv : ndarray of shape (S, N, 2)
        Pixel coordinates; NaN for points with camera depth <= ``MIN_DEPTH_MM``.
    """
    if jit.compiled():  # the same projection, compiled (geometry/_projection_kernels.py)
        R = np.ascontiguousarray(np.reshape(np.asarray(R, dtype=float), (-1, 3, 3)))
        S = len(R)
        P = np.asarray(points_mm, dtype=float)
        # One point set per camera, or one shared by all (a view: nothing copied).
        P = np.broadcast_to(P, (S,) + P.shape[-2:])
        if not P.flags.c_contiguous and P.strides[0] != 0:
            P = np.ascontiguousarray(P)
        c = np.asarray(principal_point_px, dtype=float)
        f = np.ascontiguousarray(np.broadcast_to(np.asarray(focal_px, dtype=float), (S,)))
        t = np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=float), (S, 3)))
        return project_kernel(P, R, t, f, float(c[0]), float(c[1]))
    X = to_camera_frame(points_mm, R, t)
    z = X[..., 2]
    behind = z <= MIN_DEPTH_MM
    scale = np.asarray(focal_px, dtype=float)[:, None] / np.where(behind, 1.0, z)
    scale[behind] = np.nan
    c = np.asarray(principal_point_px, dtype=float)
    uv = np.empty(X.shape[:2] + (2,))
    uv[..., 0] = X[..., 0] * scale + c[0]
    uv[..., 1] = X[..., 1] * scale + c[1]
    return uv


@dataclass(frozen=True)
class Camera:
    """One pinhole camera.

    Attributes
    ----------
    skull2cam : ndarray of shape (4, 4)
        Rigid transform (mm) from the skull frame to the camera frame.
    focal_px : float
    principal_point_px : ndarray of shape (2,)

    Examples
    --------
    >>> import numpy as np
    >>> camera = Camera.from_rt(np.eye(3), [0.0, 0.0, 1000.0], 2000.0, [320.0, 240.0])
    >>> camera.project([[10.0, -5.0, 0.0]]).tolist()
    [[340.0, 230.0]]
    """

    skull2cam: np.ndarray
    focal_px: float
    principal_point_px: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "skull2cam", np.asarray(self.skull2cam, dtype=float))
        object.__setattr__(self, "focal_px", float(self.focal_px))
        pp = np.asarray(self.principal_point_px, dtype=float)
        object.__setattr__(self, "principal_point_px", pp)

    @classmethod
    def from_rt(cls, R, t, focal_px, principal_point_px):
        """A camera from a rotation ``(3, 3)`` and translation ``(3,)`` (mm)."""
        return cls(rigid(R, t), focal_px, principal_point_px)

    @property
    def R(self):
        """Rotation ``(3, 3)``, skull frame to camera frame."""
        return self.skull2cam[:3, :3]

    @property
    def t(self):
        """Translation ``(3,)``, mm."""
        return self.skull2cam[:3, 3]

    @property
    def centre_mm(self):
        """The camera centre in the skull frame ``(3,)``."""
        return -self.R.T @ self.t

    def cropped(self, origin_uv, scale=1.0):
        """The camera of a picture of this image cropped at ``origin_uv`` and scaled by ``scale``.

        With pixel centres at integers, a crop pixel ``u'`` sees photo pixel ``u`` with
        ``u' + 0.5 = scale * (u - origin_u + 0.5)``.
        """
        pp = (self.principal_point_px - np.asarray(origin_uv, dtype=float) + 0.5) * scale - 0.5
        return Camera(self.skull2cam, self.focal_px * scale, pp)

    def as_batch(self):
        """This camera as a :class:`Cameras` of one."""
        return Cameras(
            self.R[None], self.t[None], np.array([self.focal_px]), self.principal_point_px
        )

    def to_camera_frame(self, points_mm):
        """Points ``(N, 3)`` in the camera frame (mm)."""
        return to_camera_frame(points_mm, self.R[None], self.t[None])[0]

    def project(self, points_mm):
        """Pixel coordinates ``(N, 2)`` of skull-frame points ``(N, 3)``; NaN behind."""
        return self.as_batch().project(points_mm)[0]

    def rays(self, uv):
        """Rays through pixels ``(N, 2)``, in the skull frame.

        Returns
        -------
        origin_mm : ndarray of shape (3,)
            The camera centre.
        directions : ndarray of shape (N, 3)
            Unit ray directions.
        """
        uv = np.asarray(uv, dtype=float)
        xy = (uv - self.principal_point_px) / self.focal_px
        d = np.column_stack([xy, np.ones(len(xy))]) @ self.R  # R.T @ d_cam for each row
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return self.centre_mm, d

    def distance_mm(self, points_mm):
        """Distance (mm) from the camera centre to skull-frame points ``(..., 3)``."""
        return np.linalg.norm(np.asarray(points_mm, dtype=float) @ self.R.T + self.t, axis=-1)

    def to_dict(self):
        """The ``camera`` object of ``result.json`` (docs/contract.md)."""
        return {
            "focal_px": float(self.focal_px),
            "principal_point_px": [float(x) for x in self.principal_point_px],
            "skull2cam": self.skull2cam.tolist(),
        }

    @classmethod
    def from_dict(cls, data, name="camera"):
        """Inverse of :meth:`to_dict`; a ``ValueError`` names what is wrong."""
        if not isinstance(data, dict):
            raise ValueError(
                f"{name} must be an object with focal_px, principal_point_px, skull2cam"
            )
        try:
            focal = float(data["focal_px"])
            pp = np.asarray(data["principal_point_px"], dtype=float)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{name}: focal_px and principal_point_px must be numbers") from exc
        if not np.isfinite(focal) or focal <= 0 or pp.shape != (2,) or not np.all(np.isfinite(pp)):
            raise ValueError(f"{name}: focal_px must be > 0 and principal_point_px two numbers")
        return cls(check_skull2cam(data.get("skull2cam"), f"{name}.skull2cam"), focal, pp)


@dataclass(frozen=True)
class Cameras:
    """S pinhole cameras with one principal point (a population); ``cameras[i]`` is a Camera.

    Attributes
    ----------
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
        mm.
    focal_px : ndarray of shape (S,)
    principal_point_px : ndarray of shape (2,)
    """

    R: np.ndarray
    t: np.ndarray
    focal_px: np.ndarray
    principal_point_px: np.ndarray

    def __len__(self):
        return len(self.focal_px)

    def __getitem__(self, i):
        return Camera.from_rt(self.R[i], self.t[i], self.focal_px[i], self.principal_point_px)

    def take(self, index):
        """The cameras at ``index`` (int array or bool mask) as a new :class:`Cameras`."""
        return Cameras(self.R[index], self.t[index], self.focal_px[index], self.principal_point_px)

    def project(self, points_mm):
        """Pixel coordinates ``(S, N, 2)`` of points ``(N, 3)`` or ``(S, N, 3)``; NaN behind."""
        return project_points(points_mm, self.R, self.t, self.focal_px, self.principal_point_px)

    def to_camera_frame(self, points_mm):
        """Points ``(N, 3)`` or ``(S, N, 3)`` in each camera's frame, ``(S, N, 3)`` mm."""
        return to_camera_frame(points_mm, self.R, self.t)


def point_ray_distance(points_mm, origin_mm, directions):
    """Distance (mm) from each point to its ray ``origin + s * direction`` (s unrestricted).

    Parameters
    ----------
    points_mm : array_like of shape (N, 3)
    origin_mm : array_like of shape (3,)
    directions : array_like of shape (N, 3)
        Unit vectors.

    Returns
    -------
    distance_mm : ndarray of shape (N,)
    """
    v = np.asarray(points_mm, dtype=float) - np.asarray(origin_mm, dtype=float)
    return np.linalg.norm(np.cross(v, directions), axis=1)
