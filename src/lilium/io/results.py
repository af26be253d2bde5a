"""SFO outputs: ``result.json`` (docs/contract.md) and PNG pictures."""

import os
from pathlib import Path

import cv2
import numpy as np

from .formats import points_from_object
from .jsonio import read_json, write_json
from .paths import naming_errors


def write_png(path, image, bilevel=False):
    """Write an RGB ``(H, W, 3)`` or grey ``(H, W)`` uint8 image as a lossless PNG, atomically:
    to a temporary file in the same folder, then renamed over ``path``, so ``path`` is never a
    cut PNG.

    OpenCV's encoder with run-length compression: a 24 MP photo's overlay (a noisy photograph)
    in 0.7 s and 47 MB, where Pillow's default took 3.7 s for the same pixels and size.
    ``bilevel=True`` writes a 1-bit PNG (non-zero -> 255 when read back), about ten times faster
    than 8-bit for masks.

    Raises
    ------
    OSError
        Naming ``path`` (a full disk, a file-size limit, no write permission, ...).
    ValueError
        An array OpenCV cannot encode as PNG.
    """
    image = np.ascontiguousarray(image, dtype=np.uint8)
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_RGB2BGR)
    params = [cv2.IMWRITE_PNG_STRATEGY, cv2.IMWRITE_PNG_STRATEGY_RLE]
    if bilevel:
        params += [cv2.IMWRITE_PNG_BILEVEL, 1]
    encoded, data = cv2.imencode(".png", image, params)
    if not encoded:
        raise ValueError(f"{path}: an image of shape {image.shape} cannot be written as PNG")
    _write_atomic(path, data)


def write_page(path, text):
    """Write an HTML page (UTF-8) atomically: to a temporary file in the same folder, then
    renamed over ``path``.

    Text that is not UTF-8 (a file name's bytes held by Python as lone surrogates) is written
    with U+FFFD in place of its bad bytes; the page is written all the same.

    Raises
    ------
    OSError
        Naming ``path`` (a full disk, a file-size limit, no write permission, ...).
    """
    data = text.encode("utf-8", "surrogateescape").decode("utf-8", "replace").encode()
    return _write_atomic(path, data)


def _write_atomic(path, data):
    """Write ``data`` (bytes) to a temporary file beside ``path``, then rename it over
    ``path``; an ``OSError`` names ``path`` and leaves no temporary file. Returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with naming_errors(path):
            _write_bytes(tmp, data)
            os.replace(tmp, path)
    except OSError:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _write_bytes(path, data):
    with open(path, "wb") as file:
        file.write(data)


def remove_overlays(out_dir):
    """Remove the overlays an earlier SFO left in ``out_dir``: ``overlay.png`` (one photo) and
    ``overlay_<photo id>.png`` (a joint SFO), which would show another camera than the
    ``result.json`` written next."""
    out_dir = Path(out_dir)
    if out_dir.is_dir():
        for path in [out_dir / "overlay.png", *out_dir.glob("overlay_*.png")]:
            if path.is_file() or path.is_symlink():
                path.unlink()


def png_readable(path):
    """Whether ``path`` is a whole, readable image file (Pillow's ``verify``): False when it is
    missing, empty or cut."""
    from PIL import Image

    try:
        with Image.open(path) as image:
            image.verify()
    except (OSError, SyntaxError, ValueError):
        return False
    return True


def write_result(out_dir, result, overlay_rgb=None):
    """Write ``out_dir/overlay.png``, when given, then ``out_dir/result.json``.

    Both are written atomically and ``result.json`` last (an earlier one is removed first), so
    a ``result.json`` is only ever there with its whole overlay: a run killed in between
    leaves no result that a resumed run would take as finished. The overlays of an earlier SFO
    in ``out_dir`` (:func:`remove_overlays`, a joint SFO's too) are removed first.

    Returns
    -------
    Path
        The ``result.json`` path.
    """
    out_dir = Path(out_dir)
    path = out_dir / "result.json"
    overlay = out_dir / "overlay.png"
    path.unlink(missing_ok=True)
    remove_overlays(out_dir)
    if overlay_rgb is not None:
        write_png(overlay, overlay_rgb)
    write_json(path, result.to_dict())
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


def read_camera(path):
    """The camera a file gives to score (``--camera``), with the soft tissue it carries.

    The file is a ``camera.json`` (``focal_px``, ``principal_point_px``, ``skull2cam``, and
    ``facial_landmarks_3d`` when ``workbench.html``'s Save wrote it: the soft tissue the page
    showed) or a ``result.json`` (its ``camera`` and ``facial_landmarks_3d``).

    Returns
    -------
    GivenCamera

    Raises
    ------
    ValueError
        A missing or malformed file, camera or soft tissue, or a failed SFO's result, naming
        the file.
    """
    from ..geometry.camera import Camera
    from ..inputs import GivenCamera

    data = read_json(path)
    if not isinstance(data, dict):
        raise ValueError(f"{path}: a camera file holds an object (focal_px, ...); got JSON text")
    camera = data
    if "camera" in data and "focal_px" not in data:
        if data["camera"] is None:
            raise ValueError(
                f"{path}: this result.json is a failed SFO's and has no camera; give a "
                "camera.json (workbench.html's Save) or the result of an SFO that found one"
            )
        camera = data["camera"]
    facial = data.get("facial_landmarks_3d")
    if facial is not None:
        facial = points_from_object(path, "facial_landmarks_3d", facial, "facial", dim=3)
    return GivenCamera(Camera.from_dict(camera, name=str(path)), facial or None, str(path))


#: ``result.json`` keys of one SFO that are :class:`~lilium.methods.result.SfoResult` fields
#: (the others go to its ``extra``).
_SFO_KEYS = {"method", "variant", "seed", "subject", "photo", "camera", "camera_source",
             "fitness", "terms",
             "terms_off", "facial_landmarks_3d", "seconds", "landmark_error", "warnings",
             "priors", "error"}

#: Keys of a joint SFO's ``result.json`` that are not its ``extra``.
_JOINT_KEYS = {"method", "variant", "seed", "subject", "joint", "photos", "fitness",
               "facial_landmarks_3d", "seconds", "error"}

#: Joint run facts each photo's result carries in its ``extra`` (with ``joint_photos``).
_JOINT_RUN_KEYS = ("history", "generations", "evaluations", "stop")


def _camera(value, name):
    from ..geometry.camera import Camera

    return None if value is None else Camera.from_dict(value, name=name)


def _sfo_result(data, camera, extra):
    """An :class:`~lilium.methods.result.SfoResult` from one SFO's ``result.json`` dict."""
    from ..inputs import CaseWarning
    from ..methods.result import SfoResult

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
        extra=extra,
        warnings=tuple(CaseWarning(w["code"], w["message"]) for w in data.get("warnings", [])),
        priors=data.get("priors"),
        landmark_error=data.get("landmark_error"),
        terms_off=dict(data.get("terms_off") or {}),
        camera_source=str(data.get("camera_source", "search")),
    )


def _incomplete(path, exc):
    return ValueError(f"{path}: not a complete result.json ({exc}); delete it to rerun")


def read_result(path):
    """An :class:`~lilium.methods.result.SfoResult` back from the ``result.json`` of one SFO
    (what a resumed run keeps instead of running the SFO again).

    Raises
    ------
    ValueError
        A missing or malformed file, naming it.
    """
    data = read_json(path)
    try:
        camera = read_result_camera(path)
        extra = {k: v for k, v in data.items() if k not in _SFO_KEYS}
        return _sfo_result(data, camera, extra)
    except (KeyError, TypeError, ValueError) as exc:
        raise _incomplete(path, exc) from None


def read_joint_result(path, facial_names=None):
    """A :class:`~lilium.methods.joint.JointSfoResult` back from a joint SFO's ``result.json``
    (docs/method/joint.md; what a resumed ``lilium case --joint`` keeps).

    Parameters
    ----------
    path : path
    facial_names : sequence of sequence of str, optional
        Each photo's facial landmark names, in the file's photo order: its share of the shared
        soft tissue (its result's ``facial_landmarks_mm``, as the joint run gave it). Default:
        every photo gets all the shared landmarks.

    Raises
    ------
    ValueError
        A missing or malformed file, or one of a single SFO, naming it.
    """
    from ..methods.joint import JointSfoResult

    data = read_json(path)
    try:
        if not isinstance(data, dict) or data.get("joint") is not True:
            raise ValueError("not a joint SFO's result")
        shared = {k: np.asarray(v, float) for k, v in data["facial_landmarks_3d"].items()}
        entries = list(data["photos"])
        extra = {k: v for k, v in data.items() if k not in _JOINT_KEYS}
        fitness = float("inf") if data["fitness"] is None else float(data["fitness"])
        history = extra.get("history") or [fitness]
        run = {"joint_photos": [str(e["photo"]) for e in entries], "joint_fitness": history[-1]}
        run |= {k: extra[k] for k in _JOINT_RUN_KEYS if k in extra}
        names = facial_names if facial_names is not None else [list(shared)] * len(entries)
        singles = []
        for entry, own in zip(entries, names, strict=True):
            single = {k: data[k] for k in ("method", "variant", "seed", "subject", "seconds")}
            single |= {**entry, "fitness": entry.get("fitness_unweighted")}
            single["facial_landmarks_3d"] = {n: shared[n] for n in own if n in shared}
            camera = _camera(entry["camera"], f"{path}: photo {entry['photo']}: camera")
            singles.append(_sfo_result(single, camera, dict(run)))
        return JointSfoResult(
            method=str(data["method"]),
            variant=data["variant"],
            seed=data["seed"],
            skull_id=str(data["subject"]),
            photos=tuple(singles),
            fitness=fitness,
            facial_landmarks_mm=shared,
            seconds=float(data["seconds"]),
            weights=tuple(float(e["weight"]) for e in entries),
            extra=extra,
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise _incomplete(path, exc) from None
