"""From a log10 likelihood ratio to a conclusion an examiner can sign
(docs/method/identification.md).

**The verbal scale** (after MEPROCS' seven levels; the bands are Lilium's own):

=========================  ===============================
log10 LR                   conclusion
=========================  ===============================
>= 2                       strong support
[1, 2)                     moderate support
[0.5, 1)                   limited support
(-0.5, 0.5)                undetermined
(-1, -0.5]                 limited support for exclusion
(-2, -1]                   moderate support for exclusion
<= -2                      strong support for exclusion
=========================  ===============================

An LR of 3 (log10 0.5) is the least called support: below it the calibration's own spread
between subject folds is of the same size (docs/method/identification.md, "Identification").

**Caps.** Support is capped by the material: each of these lowers the highest support
level the case can reach by one step (strong -> moderate -> limited -> undetermined), and each
is named in the result: the skull has no mandible; a single photo; automatic landmarks that
nobody reviewed; fewer than 8 landmark pairs. Exclusion is not capped: a poor match is
evidence against the same person whatever the material.

**Outside the calibration.** A decision one of whose features lies beyond the range its
calibration model was fitted on (``outside_calibration``,
:meth:`lilium.identification.calibration.Calibration.outside`) gets no support: its LR is an
extrapolation. It is a cap of its own, named first with the feature, its value and the range,
and it takes the highest level straight to "undetermined"; exclusion stays possible (the LR
is still given).

**Consistency.** A consistency failure (skull pixels outside the head mask: an implausible
SFO; the camera disagreeing with the declared view; a camera whose perspective contradicts the
photo's distance prior, ``perspective_mismatch``; a focal length or distance beyond 1.5 x its
prior's interval, ``camera_outside_priors``) is never support: the conclusion is at most
"undetermined" and says why. A camera that disagrees with the declared view, or whose head
orientation lies more than three tolerances from its prior (``head_outside_prior``), is no
exclusion either (an upside-down or mislabelled photo gave a camera 120 degrees off and
"moderate support for exclusion"): the conclusion is "undetermined". A failed SFO (no camera)
is "undetermined".
"""

from dataclasses import dataclass

import numpy as np

#: The verbal scale, from strongest exclusion to strongest support: (label, lowest log10 LR).
SCALE = (
    ("strong support for exclusion", -np.inf),
    ("moderate support for exclusion", -2.0),
    ("limited support for exclusion", -1.0),
    ("undetermined", -0.5),
    ("limited support", 0.5),
    ("moderate support", 1.0),
    ("strong support", 2.0),
)

#: Index of "undetermined" in :data:`SCALE`.
UNDETERMINED = 3

#: Consistency failures that leave no camera to read any LR from: the conclusion is
#: undetermined in both directions (the others only stop support: a skull that leaves the
#: head is itself evidence against the person).
CAMERA_FAILURES = ("view_mismatch", "head_outside_prior")

#: Caps that allow no support at all (not one step each): the LR is an extrapolation.
NO_SUPPORT_CAPS = ("outside_calibration",)

#: Caps that leave every conclusion undetermined: a camera chosen by hand and scored
#: (``--camera``). The calibration was fitted on the cameras the search finds; a chosen camera
#: moves its features where no searched one lies (measured: POSEST-SFO's log10 LR rose by 0.3
#: to 0.5 when the skull was turned 5 degrees off its SFO, docs/method/workbench.md), so its
#: LR is shown for comparison and concludes nothing.
UNDETERMINED_CAPS = ("examiner_camera", "unreviewed_skull_landmarks")

#: The sentence of the ``unreviewed_skull_landmarks`` cap: cranial landmarks placed by ``lilium
#: skull`` and not reviewed. Measured on the real CT heads (benchmarks/bench_skull_sfo.py):
#: they lie about 4 mm from the written hand placement (median), and with them the true
#: person's frontal + lateral decision moves (moderate support to undetermined on one head,
#: undetermined to limited support on the other): no conclusion either way until a reviewer
#: confirms them.
UNREVIEWED_SKULL = (
    "cranial landmarks placed automatically and not reviewed (lilium skull): review them in "
    "the skull's review.html and give the saved file with --landmarks; until then no conclusion"
)

#: The sentence of the ``examiner_camera`` cap.
EXAMINER_CAMERA = (
    "a camera chosen by hand and scored, not searched: the calibration holds for searched "
    "cameras, so this LR is for comparison with the search's and concludes nothing"
)

#: Fewest landmark pairs that do not cap the support.
MIN_PAIRS_UNCAPPED = 8


def level(log10_lr):
    """Index in :data:`SCALE` of a log10 LR (upper band edges belong to the band above, but
    ``-0.5`` / ``-1`` / ``-2`` themselves count as exclusion)."""
    if log10_lr <= -2.0:
        return 0
    if log10_lr <= -1.0:
        return 1
    if log10_lr <= -0.5:
        return 2
    if log10_lr < 0.5:
        return 3
    if log10_lr < 1.0:
        return 4
    if log10_lr < 2.0:
        return 5
    return 6


def material_caps(has_mandible, photos, unreviewed_automatic, pairs):
    """The caps of docs/method/identification.md that apply, as ``{code: sentence}``.

    Parameters
    ----------
    has_mandible : bool
    photos : int
        Photos behind the decision.
    unreviewed_automatic : bool
        Some photo landmark used was placed automatically and not reviewed (a skull's
        unreviewed automatic landmarks leave no conclusion at all: ``unreviewed_skull_landmarks``,
        :data:`UNDETERMINED_CAPS`).
    pairs : int
        Fewest landmark pairs of any photo behind the decision.
    """
    caps = {}
    if not has_mandible:
        caps["no_mandible"] = "the skull has no mandible (chin and jaw cannot be compared)"
    if photos < 2:
        caps["single_photo"] = "a single photo (one view of the face)"
    if unreviewed_automatic:
        caps["unreviewed_landmarks"] = (
            "automatic landmarks nobody reviewed (review them in review.html)"
        )
    if pairs < MIN_PAIRS_UNCAPPED:
        caps["few_pairs"] = f"only {pairs} landmark pairs (fewer than {MIN_PAIRS_UNCAPPED})"
    return caps


@dataclass(frozen=True)
class Conclusion:
    """A conclusion on the verbal scale.

    Attributes
    ----------
    label : str
        One of :data:`SCALE`'s labels.
    uncapped : str
        The label the LR alone would give.
    caps : dict of str -> str
        The material caps that apply (whether or not they lowered this LR's level).
    inconsistent : dict of str -> str
        Consistency failures that keep the conclusion from support (and, for
        :data:`CAMERA_FAILURES`, from exclusion).
    """

    label: str
    uncapped: str
    caps: dict
    inconsistent: dict


def conclude(log10_lr, caps=None, inconsistent=None):
    """The conclusion of a log10 LR under the material caps and consistency failures.

    Parameters
    ----------
    log10_lr : float or None
        None or NaN: no LR (a failed SFO) -> undetermined.
    caps : dict of str -> str, optional
        :func:`material_caps`, and those of :data:`NO_SUPPORT_CAPS` and
        :data:`UNDETERMINED_CAPS`.
    inconsistent : dict of str -> str, optional
        ``{warning code: sentence}`` of consistency failures: none is support; one of
        :data:`CAMERA_FAILURES` is no exclusion either.

    Returns
    -------
    Conclusion
    """
    caps, inconsistent = dict(caps or {}), dict(inconsistent or {})
    if log10_lr is None or not np.isfinite(log10_lr):
        label = SCALE[UNDETERMINED][0]
        return Conclusion(label, label, caps, inconsistent)
    raw = level(log10_lr)
    top = len(SCALE) - 1 - len(caps)
    if inconsistent or any(code in caps for code in NO_SUPPORT_CAPS):
        top = UNDETERMINED
    capped = min(raw, max(top, UNDETERMINED))
    if any(code in inconsistent for code in CAMERA_FAILURES) or any(
        code in caps for code in UNDETERMINED_CAPS
    ):
        capped = UNDETERMINED
    return Conclusion(SCALE[capped][0], SCALE[raw][0], caps, inconsistent)
