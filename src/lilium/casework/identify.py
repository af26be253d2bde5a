"""The identification in a case's workflow: each result's ``"identification"`` record, and its
console line, with the calibration file read once (:class:`~lilium.io.calibration.Calibrations`).

The decision itself (which model, the terms, the caps) is
:func:`lilium.identification.decision.identify`; here it gets the calibration file the user
gave (``lilium/data/calibration.json`` unless another) and the shipped cohort.
"""

from dataclasses import replace

from ..identification.conclusion import NO_SUPPORT_CAPS
from ..identification.decision import identify

__all__ = ["conclusion_line", "decide", "with_identification"]


def decide(skull, photos, results, calibrations, facial_landmarks_mm=None, joint=False):
    """:func:`~lilium.identification.decision.identify` with the case's calibration file and
    its cohort; returns the :class:`~lilium.identification.decision.Identification`."""
    return identify(
        skull, photos, results, calibrations, calibrations.cohort, facial_landmarks_mm, joint
    )


def conclusion_line(record):
    """One console line: the conclusion, the LR, and what capped it (``record``: the
    ``"identification"`` dict, :meth:`~lilium.identification.decision.Identification.to_dict`)."""
    lr = record.get("log10_lr")
    lr_text = "no LR" if lr is None else f"log10 LR {lr:+.2f} (LR {10**lr:.3g})"
    caps = dict(record.get("caps") or {})
    why = [caps.pop(k) for k in NO_SUPPORT_CAPS if k in caps]  # first: the LR extrapolates
    why += list(record.get("inconsistent", {}).values())
    if record["conclusion"] != record["conclusion_uncapped"]:
        why += list(caps.values())
    extra = f"; capped: {'; '.join(why)}" if why else ""
    note = f"; {record['note']}" if record.get("note") else ""
    return f"identification: {record['conclusion']}, {lr_text}{extra}{note}"


def with_identification(result, skull, photos, calibrations):
    """``result`` (an :class:`SfoResult` or a :class:`JointSfoResult`) with its
    ``"identification"`` record in ``extra`` (so in ``result.json``)."""
    joint = hasattr(result, "photos")
    singles = list(result.photos) if joint else [result]
    decision = decide(skull, photos, singles, calibrations, result.facial_landmarks_mm, joint)
    return replace(result, extra={**result.extra, "identification": decision.to_dict()})
