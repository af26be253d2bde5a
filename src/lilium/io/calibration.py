"""Identification calibrations on disk (SPEC section 12): the shipped one and a user's.

A calibration file is JSON: ``{"format": "lilium-calibration", "version": 1, "models":
{"<method>/<variant>/<decision>": Calibration.to_dict(), ...}, "provenance": {...}}``, with
``<variant>`` empty for POSEST-SFO and ``<decision>`` one of ``frontal``, ``lateral``,
``pair`` (separate SFOs of a frontal and a lateral photo) and ``joint`` (a joint SFO).
The package ships one (``lilium/data/calibration.json``, fitted by ``lilium calibrate`` on
generated subjects; its provenance says how); ``lilium calibrate DB`` writes another, and
``--calibration FILE`` makes a command use it.
"""

from importlib import resources
from pathlib import Path

from ..identification.calibration import Calibration
from .jsonio import read_json, write_json

#: The ``format`` field of a calibration file.
FORMAT = "lilium-calibration"

#: The calibration shipped with the package.
SHIPPED = "calibration.json"


def shipped_path():
    """Path of the package's own calibration file."""
    return Path(str(resources.files("lilium") / "data" / SHIPPED))


def read_calibration(path=None):
    """The models of a calibration file (the shipped one by default).

    Returns
    -------
    models : dict of str -> Calibration
    provenance : dict

    Raises
    ------
    ValueError
        Not a calibration file, or a malformed model, naming the file.
    """
    path = shipped_path() if path is None else Path(path)
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ValueError(
            f"{path}: not a Lilium calibration file (no \"format\": \"{FORMAT}\"); give a file "
            "written by lilium calibrate"
        )
    models = {}
    for key, entry in (data.get("models") or {}).items():
        try:
            models[key] = Calibration.from_dict(entry)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(
                f"{path}: model {key!r} is malformed ({exc}); refit it with lilium calibrate"
            ) from None
    return models, dict(data.get("provenance") or {})


def write_calibration(path, models, provenance):
    """Write ``{key: Calibration}`` as a calibration file."""
    write_json(
        path,
        {
            "format": FORMAT,
            "version": 1,
            "provenance": provenance,
            "models": {k: m.to_dict() for k, m in sorted(models.items())},
        },
    )
