"""The priors' checks of an SFO result (docs/checks.md): each prior's provenance
(:func:`priors_record`, the ``"priors"`` of ``result.json``), the warnings about missing priors
and about a camera outside one (:func:`prior_warnings`), a camera whose perspective
contradicts the distance prior (:func:`perspective_conflict`, which keeps a conclusion from
support) and a camera far outside its priors (:func:`prior_conflicts`). Pure functions;
:func:`lilium.methods.checks.finish_result` attaches them to a result.
"""

import numpy as np

from ..constants import focal_cap_px
from ..fitness.camera_penalty import head_deviation_deg
from ..inputs import CaseWarning
from ..validation import fmt_number, fmt_range

#: Options that give each prior, for the messages.
PRIOR_OPTIONS = {
    "focal_px": "--focal-px LO HI (or priors.focal_px in photo.json, or a photo with EXIF)",
    "scd_mm": "--scd-mm LO HI (or priors.scd_mm in photo.json)",
}


def _source(photo, key, value):
    if value is None:
        return "none"
    return photo.prior_sources.get(key, "photo.json")


def priors_record(photo):
    """The ``"priors"`` of ``result.json``: each prior's value and where it came from.

    Returns
    -------
    dict
        ``{"focal_px": {"range": [lo, hi] | None, "source": ...}, "scd_mm": {...},
        "head_rotation": {"skull2cam": 3x3 | None, "tolerance_deg": float | None,
        "source": ...}}``.
    """
    p = photo.priors
    head = p.head_rotation_skull2cam if p.uses_head else None
    return {
        "focal_px": {
            "range": None if p.focal_px is None else [float(x) for x in p.focal_px],
            "source": _source(photo, "focal_px", p.focal_px),
        },
        "scd_mm": {
            "range": None if p.scd_mm is None else [float(x) for x in p.scd_mm],
            "source": _source(photo, "scd_mm", p.scd_mm),
        },
        "head_rotation": {
            "skull2cam": None if head is None else np.asarray(head, float).tolist(),
            "tolerance_deg": None if head is None else float(p.head_tolerance_deg),
            "source": _source(photo, "head_rotation", head),
        },
    }


def scd_point_mm(facial_landmarks_mm):
    """The point the subject-to-camera distance is measured to (docs/method/lilium.md)."""
    if "nasion" in facial_landmarks_mm:
        return np.asarray(facial_landmarks_mm["nasion"], float)
    return np.mean([np.asarray(v, float) for v in facial_landmarks_mm.values()], axis=0)


#: Depth of a face along the line of sight (mm, nose tip to ear) over which a camera's
#: perspective is judged (:func:`perspective_conflict`).
FACE_DEPTH_MM = 100.0

#: A camera whose perspective over the face's depth differs from the one its distance prior
#: allows by more than this share contradicts what is known of the photo: its conclusion is
#: never support (a consistency failure, ``perspective_mismatch``).
PERSPECTIVE_MISMATCH = 0.1


def perspective_conflict(photo, camera, facial_landmarks_mm):
    """The camera's distance when its perspective contradicts the photo's distance prior.

    The perspective of a camera at distance ``d`` magnifies the front of a face
    ``FACE_DEPTH_MM`` deep by ``D / d`` more than its back; the camera contradicts the prior
    ``[lo, hi]`` when ``D |1/d - 1/d'|`` exceeds :data:`PERSPECTIVE_MISMATCH` for ``d'`` the
    nearest distance the prior allows. Focal length and distance trade against each other
    (POSEST-SFO's mean soft tissue often lands at twice the true distance and focal length on
    a photo from 2.5 m: the same picture, 0.02 apart in perspective), so only a camera whose
    perspective differs is a contradiction: 204 mm from a face photographed from 810-990 mm
    (0.37 apart) read "limited support" before.

    Parameters
    ----------
    photo : Photo
    camera : Camera
    facial_landmarks_mm : dict or None
        The estimated facial landmarks (the distance is measured to their nasion or centroid);
        None: nothing to measure.

    Returns
    -------
    str or None
        A sentence naming the distance, the prior and the difference; None when consistent.
    """
    bounds = photo.priors.scd_mm
    if bounds is None or not facial_landmarks_mm:
        return None
    found = float(np.ravel(camera.distance_mm(scd_point_mm(facial_landmarks_mm)))[0])
    if found <= 0:
        return None
    nearest = min(max(found, bounds[0]), bounds[1])
    apart = FACE_DEPTH_MM * abs(1.0 / found - 1.0 / nearest)
    if apart <= PERSPECTIVE_MISMATCH:
        return None
    return (
        f"the camera found is {fmt_number(found)} mm from the face of photo {photo.id!r}, its "
        f"distance prior {fmt_range(*bounds, 'mm')}: the perspective over the face's depth "
        f"differs by {apart:.0%} (more than {PERSPECTIVE_MISMATCH:.0%})"
    )


#: A camera whose head orientation deviates from its prior by more than this many tolerances,
#: or whose focal length or distance lies beyond this factor of its prior's interval
#: (:data:`FAR_INTERVAL`), is far outside its priors (:func:`prior_conflicts`).
FAR_TOLERANCES = 3.0

#: See :data:`FAR_TOLERANCES`: above ``FAR_INTERVAL * hi`` or below ``lo / FAR_INTERVAL``.
FAR_INTERVAL = 1.5


def _measured(photo, camera, facial_landmarks_mm):
    """``(label, value, prior, unit, key)`` of the camera's focal length and, given the facial
    landmarks, its subject-to-camera distance, for each of the two the photo has a prior of."""
    p = photo.priors
    out = []
    if p.focal_px is not None:
        out.append(("focal length", camera.focal_px, p.focal_px, "px", "focal_px"))
    if facial_landmarks_mm and p.scd_mm is not None:
        scd = float(np.ravel(camera.distance_mm(scd_point_mm(facial_landmarks_mm)))[0])
        out.append(("subject-to-camera distance", scd, p.scd_mm, "mm", "scd_mm"))
    return out


def _head_deviation_deg(photo, camera):
    """The camera's head orientation's deviation (deg) from the photo's prior; None without
    one."""
    return head_deviation_of(photo, camera.R)


def head_deviation_of(photo, R):
    """The deviation (deg) of the head orientation ``R`` (skull2cam rotation, (3, 3)) from the
    photo's prior; None without one."""
    p = photo.priors
    if not p.uses_head:
        return None
    return float(head_deviation_deg(np.asarray(R)[None], p.head_rotation_skull2cam)[0])


def far_from_head_prior(photo, deviation_deg):
    """Whether a head orientation ``deviation_deg`` off the photo's prior (None: no prior) lies
    beyond :data:`FAR_TOLERANCES` tolerances: the rule ``head_outside_prior``, and Lilium's
    restart (:func:`lilium.methods.lilium_outcome.missed_head_prior`)."""
    if deviation_deg is None:
        return False
    return deviation_deg > FAR_TOLERANCES * photo.priors.head_tolerance_deg


def prior_conflicts(photo, camera, facial_landmarks_mm):
    """The ways a camera lies far outside the photo's priors, as ``{code: sentence}``.

    - ``head_outside_prior``: the head orientation more than :data:`FAR_TOLERANCES`
      tolerances from its prior: the camera looks at another side of the head than the photo
      does (a wrong skull turned 173 deg from a real photo's prior once got the largest LR);
      like a camera that contradicts the declared view, it reads no LR either way;
    - ``camera_outside_priors``: the focal length or the subject-to-camera distance beyond
      :data:`FAR_INTERVAL` times its interval: not the photo's camera, so no support (focal
      length and distance trade against each other, and POSEST-SFO's mean soft tissue often
      doubles both: measured on 40 generated people, 23 of its 40 true pairs, none of
      Lilium's).

    Parameters
    ----------
    photo : Photo
    camera : Camera
    facial_landmarks_mm : dict or None
        The estimated facial landmarks (the distance is measured to their nasion or centroid;
        None: the distance is not checked).

    Returns
    -------
    dict of str -> str
        Empty when the camera is within those bounds (or the photo has no priors).
    """
    p = photo.priors
    out, far = {}, []
    for label, value, bounds, unit, key in _measured(photo, camera, facial_landmarks_mm):
        if not bounds[0] / FAR_INTERVAL <= value <= bounds[1] * FAR_INTERVAL:
            far.append(
                f"the {label} found, {_apart(value, bounds)} {unit}, lies beyond "
                f"{FAR_INTERVAL:g} x its prior {fmt_range(*bounds, unit)} "
                f"({_source(photo, key, bounds)})"
            )
    if far:
        out["camera_outside_priors"] = "; ".join(far)
    dev = _head_deviation_deg(photo, camera)
    if far_from_head_prior(photo, dev):
        out["head_outside_prior"] = (
            f"the head orientation found deviates {dev:.1f} deg from its prior, more than "
            f"{FAR_TOLERANCES:g} x its tolerance of {p.head_tolerance_deg:g} deg "
            f"({_source(photo, 'head_rotation', True)})"
        )
    return out


def _apart(value, bounds):
    """``value`` as :func:`fmt_number` writes it, with decimals added while it reads like one of
    ``bounds`` (3554.6 px just under a prior from 3555 px is not "3555 px")."""
    text = fmt_number(value)
    for decimals in range(1, 4):
        if text not in (fmt_number(bounds[0]), fmt_number(bounds[1])):
            break
        text = f"{value:.{decimals}f}"
    return text


def prior_warnings(photo, camera=None, facial_landmarks_mm=None):
    """Warnings about the priors: missing ones, and a camera outside a given one.

    Parameters
    ----------
    photo : Photo
    camera : Camera, optional
        The SFO's camera (None: failed, only the missing-prior warnings).
    facial_landmarks_mm : dict, optional
        The estimated facial landmarks (the SCD is measured to their nasion or centroid).

    Returns
    -------
    list of CaseWarning
    """
    p = photo.priors
    out = []
    if p.focal_px is None:
        out.append(
            CaseWarning(
                "no_focal_prior",
                "no focal-length prior: the camera is constrained by the landmarks alone "
                "(focal length and distance trade against each other, and the focal length is "
                f"capped at {focal_cap_px(None):.0f} px); give {PRIOR_OPTIONS['focal_px']}",
            )
        )
    if p.scd_mm is None:
        out.append(
            CaseWarning(
                "no_scd_prior",
                "no subject-to-camera distance prior: the distance is constrained by the "
                f"landmarks alone; give {PRIOR_OPTIONS['scd_mm']}",
            )
        )
    if camera is None:
        return out
    for label, value, bounds, unit, key in _measured(photo, camera, facial_landmarks_mm):
        if not bounds[0] <= value <= bounds[1]:
            out.append(
                CaseWarning(
                    "outside_prior",
                    f"the {label} found, {_apart(value, bounds)} {unit}, lies outside its prior "
                    f"{fmt_range(*bounds, unit)} ({_source(photo, key, bounds)}); "
                    "check the prior and the landmarks",
                )
            )
    dev = _head_deviation_deg(photo, camera)
    if dev is not None and dev > p.head_tolerance_deg:
        out.append(
            CaseWarning(
                "outside_prior",
                f"the head orientation found deviates {dev:.1f} deg from its prior "
                f"(tolerance {p.head_tolerance_deg:g} deg, "
                f"{_source(photo, 'head_rotation', True)}); check the prior and the landmarks",
            )
        )
    return out
