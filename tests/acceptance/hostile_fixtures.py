"""The inputs and result readers the hostile probes share. For the probes of a generated case
(the semantic, geometry, metamorphic and report groups of the campaign): ``_syn``, a
copy of the campaign's generated dataset (two subjects, ``s01`` and ``s02``, with one frontal
and one lateral photo each: experiment A, made once per campaign in ``WORK/semantic-dataset``,
about 5 s); paths into a probe's ``in/`` folder and the stand-in case; set-ups that edit a JSON
file, a photo's landmarks or its image and mask; and readers of the ``result.json`` a probe's
command wrote (the camera's rotation error, the warnings' codes). For the resume probes and
their scenarios: a run's outputs read for comparison with another's (``_results``,
``_sfo_fields``, ``_png_ok``).
"""

import json
import shutil
from pathlib import Path

import numpy as np

# -- inputs -----------------------------------------------------------------------------------


def _in(ws, *parts):
    return ws.root.joinpath("in", *parts)


def _syn(ws):
    """Set-up: ``in/syn``, a copy of the campaign's generated dataset (made once): subjects
    ``s01``, ``s02``; photos ``photos/A/s0N_f00`` (frontal), ``s0N_l00`` (lateral)."""
    cache = ws.root.parent / "semantic-dataset"
    if not (cache / "dataset.json").is_file():
        from lilium.synthetic.dataset import generate_dataset

        shutil.rmtree(cache, ignore_errors=True)
        generate_dataset(cache, 2, 1, seed=0, experiments=("A",), workers=1)
    if not _in(ws, "syn").exists():
        shutil.copytree(cache, _in(ws, "syn"))


def _subject(name):
    return lambda ws: _in(ws, "syn", "subjects", name)


def _photo(name):
    return lambda ws: _in(ws, "syn", "photos", "A", name)


def _standin_skull(ws):
    return ws.skull


def _standin_photo(ws):
    return ws.photo


def _json(path):
    return json.loads(path.read_text())


def _dump(path, data):
    path.write_text(json.dumps(data))


def _edit_json(where, name, change):
    """Set-up: ``change(data)`` on ``where(ws)/name`` (``where`` a callable of ``ws``)."""

    def setup(ws):
        path = where(ws) / name
        data = _json(path)
        change(data)
        _dump(path, data)

    return setup


def _edit_landmarks(where, change, name="photo.json"):
    """Set-up: ``landmarks = change(landmarks, ws)`` in ``where(ws)/name``."""

    def setup(ws):
        path = where(ws) / name
        data = _json(path)
        data["landmarks"] = change(data["landmarks"], ws)
        _dump(path, data)

    return setup


def _image_op(where, op, names=("image.png", "face_mask.png")):
    """Set-up: ``op(PIL image)`` on the photo's image and mask."""

    def setup(ws):
        from PIL import Image

        for name in names:
            path = where(ws) / name
            if path.is_file():
                with Image.open(path) as im:
                    im.load()
                    out = op(im)
                out.save(path)

    return setup


def _size(where):
    from PIL import Image

    def get(ws):
        with Image.open(where(ws) / "image.png") as im:
            return im.size

    return get


# -- reading results ----------------------------------------------------------------------------


def _rot_err_deg(a, b):
    R = np.asarray(a, float)[:3, :3] @ np.asarray(b, float)[:3, :3].T
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))))


def _result(ws, rel=None):
    if rel is None:
        found = sorted(ws.out.rglob("result.json"))
        if not found:
            return None
        path = found[0]
    else:
        path = ws.out / rel
    return _json(path) if path.is_file() else None


def _codes(result):
    return [w["code"] for w in result.get("warnings", [])]


# -- a run's outputs, compared with another's -------------------------------------------------

#: The fields of a result.json an SFO computes (not its timing).
SFO_FIELDS = ("method", "variant", "seed", "camera", "fitness", "terms", "generations")


def _sfo_fields(path):
    data = json.loads(Path(path).read_text())
    return {k: data.get(k) for k in SFO_FIELDS}


def _results(folder):
    return {p.relative_to(folder).as_posix(): p for p in sorted(Path(folder).rglob("result.json"))}


def _png_ok(path):
    from PIL import Image

    try:
        with Image.open(path) as im:
            im.load()
    except Exception as exc:  # noqa: BLE001
        return f"{Path(path).name} unreadable ({type(exc).__name__})"
    return None
