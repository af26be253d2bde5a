"""Rotations and the pinhole camera of docs/contract.md (:class:`Camera`, :class:`Cameras`)."""

from .camera import (
    Camera,
    Cameras,
    check_skull2cam,
    point_ray_distance,
    principal_point_of,
    project_points,
    rigid,
    to_camera_frame,
)
from .rotations import (
    check_rotation,
    geodesic_angle_deg,
    matrix_to_rotvec,
    rotvec_to_matrix,
)

__all__ = [
    "Camera",
    "Cameras",
    "check_rotation",
    "check_skull2cam",
    "geodesic_angle_deg",
    "matrix_to_rotvec",
    "point_ray_distance",
    "principal_point_of",
    "project_points",
    "rigid",
    "rotvec_to_matrix",
    "to_camera_frame",
]
