"""Evaluation of SFO results against synthetic ground truth (docs/method/evaluation.md)."""

from .metrics import (
    ImplausibleSFO,
    back_projection_error,
    back_projection_error_from_dicts,
    back_projection_errors,
    implausible_sfo,
    outside_face,
    rank_of_true,
)
from .scoring import Score, score

__all__ = [
    "ImplausibleSFO",
    "Score",
    "back_projection_error",
    "back_projection_error_from_dicts",
    "back_projection_errors",
    "implausible_sfo",
    "outside_face",
    "rank_of_true",
    "score",
]
