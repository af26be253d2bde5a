"""Rotations and the pinhole camera of SPEC section 8."""

from .camera import (
    backproject_rays,
    check_skull2cam,
    point_ray_distance,
    principal_point_of,
    project,
    project_batch,
    project_population,
    subject_camera_distance,
)
from .rotations import (
    check_rotation,
    geodesic_angle_deg,
    matrix_to_rotvec,
    rotvec_to_matrix,
)

__all__ = [
    "backproject_rays",
    "check_rotation",
    "check_skull2cam",
    "geodesic_angle_deg",
    "matrix_to_rotvec",
    "point_ray_distance",
    "principal_point_of",
    "project",
    "project_batch",
    "project_population",
    "rotvec_to_matrix",
    "subject_camera_distance",
]
