"""The result of one SFO and its docs/contract.md dictionary."""

from dataclasses import dataclass, field

import numpy as np

from ..geometry.camera import Camera


@dataclass(frozen=True)
class SfoResult:
    """Outcome of one skull-face overlay; falsy when no camera was found.

    Attributes
    ----------
    method : str
    variant : str or None
    seed : int or None
    skull_id, photo_id : str
    camera : Camera or None
        The estimated camera; None when the SFO failed.
    fitness : float
        The method's own score (lower is better): mean pixel error for POSEST-SFO, the fitness
        for Lilium; not comparable across methods (``landmark_error`` is).
    terms : dict of str -> float
        ``mse_pix``, ``p_cam``, ``p_skof``, ``p_pll`` (``None`` when switched off).
    facial_landmarks_mm : dict of str -> ndarray of shape (3,)
        Estimated 3D facial landmarks, keyed by facial name, skull frame.
    seconds : float
    error : str
        Why it failed ("" on success).
    extra : dict
        Method-specific additions (e.g. the fitness history).
    warnings : tuple of lilium.inputs.CaseWarning
        docs/checks.md warnings (``view_mismatch``, ``no_focal_prior``, ...).
    priors : dict or None
        The priors used and where each came from
        (:func:`lilium.methods.prior_checks.priors_record`).
    landmark_error : dict or None
        ``mean_px``, ``mean_mm``, ``per_landmark_px``
        (:func:`lilium.methods.checks.landmark_error`); None when the SFO failed.
    terms_off : dict of str -> str
        Terms switched off for this SFO because their inputs are missing, and why
        (docs/method/lilium.md, "When a term cannot apply"): ``p_skof``, ``p_pll`` (asked for by the
        variant), ``p_cam_focal``, ``p_cam_scd``, ``p_cam_head`` (a P_cam part without its
        prior). Empty when every term ran; ``result.json`` then has no ``terms_off`` key.
    camera_source : {"search", "examiner"}
        Where the camera came from: the method's search, or given to score (``--camera``,
        :func:`lilium.methods.run_sfo`'s ``camera``).

    :func:`lilium.methods.run_sfo` fills ``warnings``, ``priors`` and ``landmark_error`` for
    every method (:func:`lilium.methods.checks.finish_result`).
    """

    method: str
    variant: str | None
    seed: int | None
    skull_id: str
    photo_id: str
    camera: Camera | None
    fitness: float
    terms: dict
    facial_landmarks_mm: dict
    seconds: float
    error: str = ""
    extra: dict = field(default_factory=dict)
    warnings: tuple = ()
    priors: dict | None = None
    landmark_error: dict | None = None
    terms_off: dict = field(default_factory=dict)
    camera_source: str = "search"

    def __bool__(self):
        return self.camera is not None

    def to_dict(self):
        """The ``result.json`` dictionary of docs/contract.md."""
        camera = self.camera.to_dict() if self else None
        out = {
            "method": self.method,
            "variant": self.variant,
            "seed": self.seed,
            "subject": self.skull_id,
            "photo": self.photo_id,
            "camera": camera,
            "camera_source": self.camera_source,
            "fitness": finite_or_none(self.fitness),
            "terms": {k: finite_or_none(v) for k, v in self.terms.items()},
            **(
                {"terms_off": {str(k): str(v) for k, v in self.terms_off.items()}}
                if self.terms_off
                else {}
            ),
            "facial_landmarks_3d": {
                k: [float(x) for x in v] for k, v in self.facial_landmarks_mm.items()
            },
            "seconds": float(self.seconds),
            "landmark_error": self.landmark_error,
            "warnings": [w.to_dict() for w in self.warnings],
        }
        if self.priors is not None:
            out["priors"] = self.priors
        if self.error:
            out["error"] = self.error
        out.update(self.extra)
        return out


def finite_or_none(value):
    """``float(value)``, or None for None, NaN and infinities (JSON has no inf)."""
    if value is None:
        return None
    value = float(value)
    return value if np.isfinite(value) else None
