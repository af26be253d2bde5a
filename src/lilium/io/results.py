"""SFO outputs: ``result.json`` (SPEC section 8) and PNG pictures."""

from pathlib import Path

import numpy as np

from .jsonio import read_json, write_json


def write_png(path, rgb):
    """Write an ``(H, W, 3)`` uint8 array as PNG."""
    from PIL import Image

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.asarray(rgb, dtype=np.uint8)).save(path)


def write_result(out_dir, result, overlay_rgb=None):
    """Write ``out_dir/result.json`` and, when given, ``out_dir/overlay.png``.

    Without an overlay, an ``overlay.png`` left in ``out_dir`` by an earlier run is removed: it
    would show another camera than the ``result.json`` beside it.

    Returns
    -------
    Path
        The ``result.json`` path.
    """
    out_dir = Path(out_dir)
    path = out_dir / "result.json"
    overlay = out_dir / "overlay.png"
    if overlay_rgb is None and (overlay.is_file() or overlay.is_symlink()):
        overlay.unlink()
    write_json(path, result.to_dict())
    if overlay_rgb is not None:
        write_png(overlay, overlay_rgb)
    return path


def read_result_camera(path):
    """The estimated camera of a ``result.json``; None for a failed SFO (``"camera": null``).

    Raises
    ------
    ValueError
        A missing or malformed file, or a malformed camera, naming the file.
    """
    from ..geometry.camera import Camera

    data = read_json(path)
    if not isinstance(data, dict) or "camera" not in data:
        raise ValueError(f"{path}: missing field 'camera'")
    if data["camera"] is None:
        return None
    return Camera.from_dict(data["camera"], name=f"{path}: camera")


def read_result(path):
    """An :class:`~lilium.methods.result.SfoResult` back from the ``result.json`` of one SFO
    (what a resumed run keeps instead of running the SFO again).

    Raises
    ------
    ValueError
        A missing or malformed file, naming it.
    """
    import numpy as np

    from ..inputs import CaseWarning
    from ..methods.result import SfoResult

    data = read_json(path)
    known = {"method", "variant", "seed", "subject", "photo", "camera", "fitness", "terms",
             "terms_off", "facial_landmarks_3d", "seconds", "landmark_error", "warnings",
             "priors", "error"}
    try:
        camera = read_result_camera(path)
        return SfoResult(
            method=str(data["method"]),
            variant=data.get("variant"),
            seed=data.get("seed"),
            skull_id=str(data["subject"]),
            photo_id=str(data["photo"]),
            camera=camera,
            fitness=float("inf") if data.get("fitness") is None else float(data["fitness"]),
            terms=dict(data.get("terms") or {}),
            facial_landmarks_mm={
                k: np.asarray(v, float) for k, v in (data.get("facial_landmarks_3d") or {}).items()
            },
            seconds=float(data.get("seconds") or 0.0),
            error=str(data.get("error") or ""),
            extra={k: v for k, v in data.items() if k not in known},
            warnings=tuple(CaseWarning(w["code"], w["message"]) for w in data.get("warnings", [])),
            priors=data.get("priors"),
            landmark_error=data.get("landmark_error"),
            terms_off=dict(data.get("terms_off") or {}),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(
            f"{path}: not a complete result.json ({exc}); delete it to rerun"
        ) from None
