"""Identification calibrations on disk (docs/method/identification.md): the shipped one and a
user's.

A calibration file is JSON: ``{"format": "lilium-calibration", "version": 1, "models":
{"<method>/<variant>/<decision>": Calibration.to_dict(), ...}, "provenance": {...}}``, with
``<variant>`` empty for POSEST-SFO and ``<decision>`` one of ``frontal``, ``lateral``,
``pair`` (separate SFOs of a frontal and a lateral photo, one shared soft tissue),
``pair_sum`` (the same two SFOs' log10 LRs added, calibrated) and ``joint`` (a joint SFO).
The package ships one (``lilium/data/calibration.json``, fitted by ``lilium calibrate`` on
generated subjects; its provenance says how); ``lilium calibrate DB`` writes another, and
``--calibration FILE`` makes a command use it.

A cohort file (``lilium/data/cohort.json``, format ``lilium-cohort``) holds the cranial
landmarks and soft-tissue axes of other people's skulls, the reference the identification
reads a photo's landmark fit against (:mod:`lilium.identification.cohort`).
"""

from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from ..identification.calibration import Calibration
from ..identification.cohort import Cohort
from .jsonio import read_json, write_json

#: The ``format`` field of a calibration file.
FORMAT = "lilium-calibration"

#: The calibration shipped with the package.
SHIPPED = "calibration.json"

#: The ``format`` field of a cohort file, and the cohort shipped with the package.
COHORT_FORMAT = "lilium-cohort"
SHIPPED_COHORT = "cohort.json"


def shipped_path(name=SHIPPED):
    """Path of one of the package's own files (the calibration by default)."""
    return Path(str(resources.files("lilium") / "data" / name))


def read_cohort(path=None):
    """The :class:`~lilium.identification.cohort.Cohort` of a cohort file (the shipped one by
    default).

    Raises
    ------
    ValueError
        Not a cohort file, or a skull without landmarks or axes, naming the file.
    """
    path = shipped_path(SHIPPED_COHORT) if path is None else Path(path)
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != COHORT_FORMAT:
        raise ValueError(f"{path}: not a Lilium cohort file (no \"format\": \"{COHORT_FORMAT}\")")
    landmarks, axes = [], []
    for k, skull in enumerate(data.get("skulls") or []):
        try:
            landmarks.append({n: np.asarray(v, float) for n, v in skull["landmarks"].items()})
            axes.append({n: np.asarray(v, float) for n, v in skull["axes"].items()})
        except (KeyError, TypeError, AttributeError, ValueError):
            raise ValueError(f"{path}: skull {k} needs \"landmarks\" and \"axes\"") from None
    return Cohort(tuple(landmarks), tuple(axes), dict(data.get("provenance") or {}))


@lru_cache(maxsize=1)
def shipped_cohort():
    """The package's own cohort, read once per process."""
    return read_cohort()


def write_cohort(path, cohort):
    """Write a :class:`~lilium.identification.cohort.Cohort` as a cohort file."""
    skulls = [
        {"landmarks": {n: np.asarray(v).tolist() for n, v in lm.items()},
         "axes": {n: np.asarray(v).tolist() for n, v in ax.items()}}
        for lm, ax in zip(cohort.landmarks_mm, cohort.axes, strict=True)
    ]
    write_json(path, {"format": COHORT_FORMAT, "version": 1, "provenance": cohort.provenance,
                      "skulls": skulls})


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
    entries = data.get("models") or {}
    if not isinstance(entries, dict):
        raise ValueError(
            f'{path}: "models" must be an object of "<method>/<variant>/<decision>": '
            "model; give a file written by lilium calibrate"
        )
    models = {}
    for key, entry in entries.items():
        try:
            models[key] = Calibration.from_dict(entry)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(
                f"{path}: model {key!r} is malformed ({exc}); refit it with lilium calibrate"
            ) from None
    return models, dict(data.get("provenance") or {})


class Calibrations:
    """The calibration models of a file, read once (the shipped file by default), and the
    cohort they were fitted with (the shipped one): what a case identifies its results with.

    Parameters
    ----------
    path : str or Path, optional
        A calibration file (``--calibration``); None: the shipped one.

    Attributes
    ----------
    path : Path
        The file read.
    models : dict of str -> Calibration
        By ``"<method>/<variant>/<decision>"`` (:func:`read_calibration`).
    provenance : dict
        The file's ``provenance``.
    cohort : Cohort
        The shipped cohort (:func:`shipped_cohort`).

    Raises
    ------
    ValueError
        Not a calibration file, or a malformed model, naming the file.
    """

    def __init__(self, path=None):
        self.path = shipped_path() if path is None else path
        self.models, self.provenance = read_calibration(path)
        self.cohort = shipped_cohort()

    def get(self, key):
        """The model of ``key`` (``"<method>/<variant>/<decision>"``), None when absent."""
        return self.models.get(key)


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
