"""POSEST: P4Pf minimal solver -> MSAC RANSAC -> Levenberg-Marquardt (three separate layers)."""

from .minimal import p4pf
from .posest import PoseResult, PosestOptions, check_camera, posest
from .ransac import RansacOptions, RansacResult, msac
from .refine import BatchRefineResult, RefineOptions, refine_batch
from .residuals import reprojection_sq_errors

__all__ = [
    "BatchRefineResult",
    "PoseResult",
    "PosestOptions",
    "RansacOptions",
    "RansacResult",
    "RefineOptions",
    "check_camera",
    "msac",
    "p4pf",
    "posest",
    "refine_batch",
    "reprojection_sq_errors",
]
