"""What is checked before and after an SFO (docs/checks.md), as pure functions.

Anatomical directions of a skull, from its landmarks (:func:`skull_directions`):

- **origin**: the porion midpoint, or the mesh centroid (mean vertex) when a porion is missing;
- **anterior**: from the origin to nasion; without nasion, to the first present of
  :data:`ANTERIOR_TARGETS`, else to the mean midpoint of the orbital and nasal pairs
  (:data:`ANTERIOR_PAIRS`); no direction (no check) without any of them;
- **right** (towards the subject's right): the mean unit ``_r - _l`` of the bilateral pairs;
- **superior**: nasion minus prosthion; without one of them, the mean of the upper midline
  landmarks (nasion, glabella, metopion, bregma) minus the mean of the lower ones (prosthion,
  subspinale, infradentale, pogonion, gnathion).

Rules (each one skipped, never guessed, when the landmarks it needs are absent):

- **skull faces the camera** (:func:`facing_angle_deg`): the angle between the anterior
  direction and the direction from the origin to the camera centre is at most
  :data:`~lilium.constants.FACING_MAX_DEG`; both methods treat a camera beyond it as no
  solution (:func:`facing_check`);
- **left and right of the skull** (:func:`check_skull_labels`): ``dot(right x anterior,
  superior) > 0`` (the right-handed RAS frame); mirrored labels or a mirrored mesh make it
  negative: an error naming the landmark file;
- **left, right, up and down of a photo**
  (:func:`~lilium.methods.photo_checks.check_photo_labels`): facing the camera, the subject's
  left is on the image's right, so each ``_l`` landmark of a frontal photo has the larger
  ``u``; every pair reversed is a mirrored photo (or labels), some pairs reversed are swapped
  labels; the forehead's midline landmarks below the chin's is an upside-down photo (any
  view): an error naming the file;
- **declared view** (:func:`view_warning`): after the SFO, frontal = at most
  :data:`~lilium.constants.VIEW_SPLIT_DEG` from the anterior direction, lateral = at least
  that, on the declared side (``lateral_left``: the face points to the image's left, so the
  camera sees the subject's left side); otherwise warning ``view_mismatch``;
- **priors** (:func:`~lilium.methods.prior_checks.prior_warnings`): ``no_focal_prior``,
  ``no_scd_prior``, ``outside_prior``;
- **chin** (:func:`chin_warning`): an SFO with no landmark pair on the chin or the mandible
  (:data:`CHIN_LANDMARKS`) and no chin-jaw curve term (P_pll on a frontal photo) fits the
  midface alone; warning ``chin_unconstrained`` (issue 25: on a face of another size the skull's
  chin then lies anywhere).

:func:`landmark_error` is the comparable error of every result (pixels and millimetres at each
landmark's depth). :func:`finish_result` attaches the warnings, the priors' provenance and the
landmark error to a result; :func:`lilium.methods.run_sfo` calls it for every method.
"""

from dataclasses import dataclass, replace

import numpy as np

from ..constants import FACING_MAX_DEG, MIN_DEPTH_MM, VIEW_SPLIT_DEG
from ..inputs import CaseWarning
from ..softtissue.landmarks import side, twin
from .photo_checks import (
    check_landmarks_in_mask,
    check_photo_labels,
    coincident_message,
    coincident_pairs,
)
from .prior_checks import prior_warnings, priors_record

#: Anterior landmarks the anterior direction aims at when nasion is missing, in order.
ANTERIOR_TARGETS = ("glabella", "subspinale", "prosthion", "metopion", "pogonion", "gnathion")

#: Bilateral pairs whose mean midpoint is the anterior target without any midline landmark.
ANTERIOR_PAIRS = ("dacryon", "ectoconchion", "alare")

#: Upper and lower midline landmarks of the superior direction's fallback.
UPPER_MIDLINE = ("nasion", "glabella", "metopion", "bregma")
LOWER_MIDLINE = ("prosthion", "subspinale", "infradentale", "pogonion", "gnathion")

#: Landmarks on the chin and the mandible (facial names, the same as the cranial ones): an SFO
#: with a pair among them, or with P_pll's chin-jaw curve, constrains the chin.
CHIN_LANDMARKS = ("pogonion", "gnathion", "gonion_l", "gonion_r")


def _unit(v):
    n = float(np.linalg.norm(v))
    return None if not np.isfinite(n) or n < 1e-9 else np.asarray(v, float) / n


@dataclass(frozen=True)
class SkullDirections:
    """Anatomical directions of a skull, skull frame.

    Attributes
    ----------
    origin_mm : ndarray of shape (3,)
    anterior : ndarray of shape (3,)
        Unit vector from the origin to the anterior target.
    right : ndarray of shape (3,) or None
        Unit vector towards the subject's right (None without a bilateral pair).
    superior : ndarray of shape (3,) or None
        Unit vector (None without an upper and a lower midline landmark).
    origin_source, anterior_source : str
        E.g. ``"porion midpoint"``, ``"nasion"``, for the messages.
    """

    origin_mm: np.ndarray
    anterior: np.ndarray
    right: np.ndarray | None
    superior: np.ndarray | None
    origin_source: str
    anterior_source: str


def _right(lm):
    diffs = [_unit(lm[twin(n)] - lm[n]) for n in lm if side(n) == "l" and twin(n) in lm]
    diffs = [d for d in diffs if d is not None]
    return _unit(np.mean(diffs, axis=0)) if diffs else None


def _superior(lm):
    if "nasion" in lm and "prosthion" in lm:
        return _unit(lm["nasion"] - lm["prosthion"])
    upper = [lm[n] for n in UPPER_MIDLINE if n in lm]
    lower = [lm[n] for n in LOWER_MIDLINE if n in lm]
    if not upper or not lower:
        return None
    return _unit(np.mean(upper, axis=0) - np.mean(lower, axis=0))


def skull_directions(landmarks_mm, vertices_mm):
    """The skull's origin, anterior, right and superior directions (module docstring).

    Parameters
    ----------
    landmarks_mm : dict of str -> array_like of shape (3,)
        Cranial landmarks, skull frame.
    vertices_mm : ndarray of shape (V, 3)
        The skull mesh (its centroid is the origin without porion).

    Returns
    -------
    SkullDirections or None
        None when no anterior target is present (the rules that need it are skipped).
    """
    lm = {k: np.asarray(v, dtype=float) for k, v in landmarks_mm.items()}
    if "porion_l" in lm and "porion_r" in lm:
        origin, origin_source = (lm["porion_l"] + lm["porion_r"]) / 2, "porion midpoint"
    else:
        origin, origin_source = np.mean(np.asarray(vertices_mm, float), axis=0), "mesh centroid"
    targets = [n for n in ("nasion", *ANTERIOR_TARGETS) if n in lm]
    if targets:
        target, target_source = lm[targets[0]], targets[0]
    else:
        mids = [
            (lm[f"{b}_l"] + lm[f"{b}_r"]) / 2
            for b in ANTERIOR_PAIRS
            if f"{b}_l" in lm and f"{b}_r" in lm
        ]
        if not mids:
            return None
        target, target_source = np.mean(mids, axis=0), "orbital and nasal pair midpoints"
    anterior = _unit(target - origin)
    if anterior is None:
        return None
    return SkullDirections(
        origin, anterior, _right(lm), _superior(lm), origin_source, target_source
    )


def camera_centres_mm(R, t):
    """Camera centres ``-R^T t`` (S, 3), skull frame, of ``R (S, 3, 3)`` and ``t (S, 3)``."""
    R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    t = np.asarray(t, dtype=float).reshape(-1, 3)
    return -np.einsum("sji,sj->si", R, t)


def facing_angle_deg(directions, R, t):
    """Angle (degrees) between the anterior direction and the direction skull -> camera.

    Parameters
    ----------
    directions : SkullDirections
    R : array_like of shape (S, 3, 3)
    t : array_like of shape (S, 3)
        World-to-camera (``skull2cam``) rotations and translations (mm).

    Returns
    -------
    angle_deg : ndarray of shape (S,)
        About 0 for a frontal camera, 90 for a lateral one, 180 behind the head; NaN for a
        camera that is not finite.
    """
    return np.degrees(np.arccos(np.clip(_facing_cos(directions, R, t), -1.0, 1.0)))


def _facing_cos(directions, R, t):
    """Cosine ``(S,)`` of :func:`facing_angle_deg` (NaN for a camera that is not finite)."""
    d = camera_centres_mm(R, t) - directions.origin_mm
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        d = d / np.max(np.abs(d), axis=1, keepdims=True)  # run-off cameras: no overflow
        return (d @ directions.anterior) / np.sqrt(np.einsum("si,si->s", d, d))


@dataclass(frozen=True)
class FacingRule:
    """The skull-faces-camera rule of one skull as a batched predicate.

    ``rule(R (S, 3, 3), t (S, 3)) -> (S,) bool``: True where the camera sees the front of the
    skull (a non-finite camera passes: it fails elsewhere). The angle > :data:`FACING_MAX_DEG`
    is compared as cosines (``cos_max``; the DE asks every generation): the same rule but for
    rounding at the boundary itself. The compiled camera checks
    (:func:`lilium.fitness._camera_kernels.camera_checks_kernel`) read its fields.
    """

    directions: SkullDirections
    cos_max: float

    def __call__(self, R, t):
        return ~(_facing_cos(self.directions, R, t) < self.cos_max)


def facing_check(skull):
    """The skull-faces-camera rule of one skull (:class:`FacingRule`), or None when the skull
    has no anterior direction (the rule is then skipped)."""
    directions = skull_directions(skull.landmarks_mm, skull.vertices_mm)
    if directions is None:
        return None
    return FacingRule(directions, float(np.cos(np.radians(FACING_MAX_DEG))))


def check_given_camera(camera, skull, photo, name="camera"):
    """Raise when a camera given to score (an examiner's, ``--camera``) cannot show the skull
    in the photo: a skull landmark at or behind the camera, the skull's front turned away
    (the facing rule of the search, :func:`facing_check`), or a principal point outside the
    image.

    Parameters
    ----------
    camera : Camera
    skull : Skull
    photo : Photo
    name : str
        Where the camera came from (a file), for the message.

    Raises
    ------
    ValueError
        Naming ``name``, what is wrong and the fix.
    """
    points = np.array(list(skull.landmarks_mm.values()) or skull.vertices_mm[:1], dtype=float)
    depth = camera.to_camera_frame(points)[:, 2]
    if np.any(depth <= MIN_DEPTH_MM):
        raise ValueError(
            f"{name}: the skull lies behind this camera (a landmark {depth.min():.0f} mm from "
            "its image plane); give the camera of an overlay (skull2cam maps the skull in front "
            "of the camera, z forward)"
        )
    rule = facing_check(skull)
    if rule is not None and not rule(camera.R[None], camera.t[None])[0]:
        raise ValueError(
            f"{name}: this camera sees the back of skull {skull.id!r} (more than "
            f"{FACING_MAX_DEG:g} deg from its anterior direction); give the camera of an overlay"
        )
    (w, h), (u, v) = photo.image_size_wh, camera.principal_point_px
    if not (-0.5 <= u <= w - 0.5 and -0.5 <= v <= h - 0.5):
        raise ValueError(
            f"{name}: principal point ({u:g}, {v:g}) px lies outside the {w} x {h} photo "
            f"{photo.id!r}; is the camera for another photo?"
        )


def facing_failure(skull, photo):
    """The message of an SFO whose landmarks fit only from behind the skull."""
    skull_file = skull.landmarks_file or f"the cranial landmarks of skull {skull.id!r}"
    photo_file = photo.landmarks_file or f"the facial landmarks of photo {photo.id!r}"
    return (
        f"the landmarks fit only with a camera behind the skull (more than {FACING_MAX_DEG:g} "
        f"deg from its anterior direction): are left and right swapped in {skull_file} (or in "
        f"{photo_file})? Swap the _l and _r names of the mirrored file"
    )


def label_handedness(landmarks_mm, vertices_mm):
    """``dot(right x anterior, superior)`` of a skull's labels; positive when they are right.

    Returns
    -------
    float or None
        In [-1, 1]; None when a direction cannot be formed (no bilateral pair, no anterior or
        superior landmarks).
    """
    d = skull_directions(landmarks_mm, vertices_mm)
    if d is None or d.right is None or d.superior is None:
        return None
    return float(np.cross(d.right, d.anterior) @ d.superior)


def check_skull_labels(skull):
    """Raise when the skull's left and right labels (or its mesh) are mirrored, or a bilateral
    pair's twins lie at one place (one copied from the other).

    Raises
    ------
    ValueError
        Naming ``skull.landmarks_file`` and what to swap.
    """
    where = skull.landmarks_file or f"skull {skull.id!r}: cranial landmarks"
    check_cranial_labels(skull.landmarks_mm, skull.vertices_mm, where)


def check_cranial_labels(landmarks_mm, vertices_mm, where):
    """:func:`check_skull_labels` of landmarks on a mesh (``where`` names them in the
    message)."""
    together = coincident_pairs(landmarks_mm)
    if together:
        raise ValueError(coincident_message(where, together, "mm"))
    handedness = label_handedness(landmarks_mm, vertices_mm)
    if handedness is None or handedness >= 0:
        return
    raise ValueError(
        f"{where}: left and right are mirrored (the _r minus _l direction, anterior and superior "
        f"form a left-handed frame, {handedness:+.2f}); swap every _l and _r name in this file "
        "(zygion_l <-> zygion_r, ...), or, if the labels follow the anatomy, the mesh itself is "
        "mirrored: re-import the CT with lilium import-ct --orientation (the anatomical "
        "direction of each index axis, e.g. RPI) when its files name none, or mirror the mesh "
        "back in the program that exported it"
    )


def check_inputs(skull, photo):
    """The checks before any SFO: left and right of the skull and of the photo, and the
    photo's landmarks against its mask (the warnings of that check are the photo's own,
    :func:`~lilium.casework.inputs.load_photos`).

    Raises
    ------
    ValueError
        The first rule broken, naming the file and the fix.
    """
    check_skull_labels(skull)
    check_photo_labels(photo)
    check_landmarks_in_mask(photo)


def view_warning(skull, photo, camera):
    """Warning ``view_mismatch`` when the camera disagrees with the photo's declared view.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    camera : Camera

    Returns
    -------
    CaseWarning or None
    """
    directions = skull_directions(skull.landmarks_mm, skull.vertices_mm)
    if directions is None:
        return None
    angle = float(facing_angle_deg(directions, camera.R, camera.t)[0])
    seen = "frontal"
    if angle >= VIEW_SPLIT_DEG:
        seen = "lateral"
        if directions.right is not None:
            centre = camera_centres_mm(camera.R, camera.t)[0] - directions.origin_mm
            seen = "lateral_right" if centre @ directions.right > 0 else "lateral_left"
    declared = photo.view
    if seen == declared or (seen == "lateral" and declared != "frontal"):
        return None
    where = photo.landmarks_file or f"photo {photo.id!r}"
    side_text = {
        "frontal": "in front of the face",
        "lateral": "beside the head",
        "lateral_left": "on the subject's left (lateral_left)",
        "lateral_right": "on the subject's right (lateral_right)",
    }[seen]
    return CaseWarning(
        "view_mismatch",
        f"{where} declares the view {declared!r} but the camera found is {angle:.0f} deg from "
        f"the skull's anterior direction, {side_text}; check the view (photo.json's \"view\" "
        "or --view) and the landmarks",
    )


def chin_warning(skull, photo, result):
    """Warning ``chin_unconstrained`` when nothing in the SFO holds the chin, else None.

    Nothing holds it when no landmark of :data:`CHIN_LANDMARKS` is both on the skull and in the
    photo, and the SFO ran no chin-jaw curve term (P_pll on a frontal photo; a lateral photo's
    curve is the forehead).

    Parameters
    ----------
    skull : Skull
    photo : Photo
    result : SfoResult

    Returns
    -------
    CaseWarning or None
    """
    if any(n in skull.landmarks_mm and n in photo.landmarks_uv for n in CHIN_LANDMARKS):
        return None
    if photo.view == "frontal" and result.terms.get("p_pll") is not None:
        return None
    on_skull = [n for n in CHIN_LANDMARKS if n in skull.landmarks_mm]
    if not on_skull:
        why = f"skull {skull.id!r} has none of them in its cranial landmarks (no mandible?)"
    else:
        why = f"photo {photo.id!r} has none of {', '.join(on_skull)}"
        if set(photo.landmark_sources.values()) & {"tracked", "template"}:
            why += " (automatic template points count only once confirmed in review.html)"
    curve = (
        "no chin-jaw curve (P_pll off)"
        if photo.view == "frontal"
        else "a lateral photo's curve (P_pll) follows the forehead"
    )
    return CaseWarning(
        "chin_unconstrained",
        f"the chin is unconstrained: no landmark pair on the chin or mandible "
        f"({', '.join(CHIN_LANDMARKS)}) and {curve}; {why}. Only the landmarks down to the "
        "upper lip place the skull, so on a face of another size its chin and jaw can lie "
        "anywhere in the overlay; mark pogonion or gnathion on the photo and the skull, or run "
        "Lilium with --variant pll (or skof+pll) and a chin-jaw curve",
    )


def landmark_error(camera, facial_landmarks_mm, photo):
    """Reprojection error of the estimated facial landmarks, in pixels and millimetres.

    ``mean_mm`` converts each landmark's pixel error to millimetres at its own depth
    (``px * Z / focal_px``, Z = the landmark's camera-frame depth), so methods and photos of
    different resolutions compare.

    Parameters
    ----------
    camera : Camera
    facial_landmarks_mm : dict of str -> array_like of shape (3,)
        Estimated 3D facial landmarks (skull frame), keyed by facial name.
    photo : Photo

    Returns
    -------
    dict or None
        ``{"mean_px", "mean_mm", "per_landmark_px": {name: px}}``; None without a landmark in
        the photo.
    """
    names = [n for n in facial_landmarks_mm if n in photo.landmarks_uv]
    if camera is None or not names:
        return None
    X = np.array([facial_landmarks_mm[n] for n in names], dtype=float)
    uv = np.array([photo.landmarks_uv[n] for n in names], dtype=float)
    err_px = np.linalg.norm(camera.project(X) - uv, axis=1)
    depth_mm = camera.to_camera_frame(X)[:, 2]
    err_mm = err_px * depth_mm / camera.focal_px
    finite = np.isfinite(err_px)
    return {
        "mean_px": float(np.mean(err_px)) if finite.all() else None,
        "mean_mm": float(np.mean(err_mm)) if finite.all() else None,
        "per_landmark_px": {
            n: (float(e) if np.isfinite(e) else None) for n, e in zip(names, err_px, strict=True)
        },
    }


def finish_result(result, skull, photo):
    """A result with its warnings, priors' provenance and landmark error attached.

    Warnings, in order: the skull's own (read with it: ``mesh_part_left_out``), the photo's own
    (read with it, e.g. ``exif_focal_unusable``), the
    method's (e.g. ``focal_cap``), the missing or violated priors, ``chin_unconstrained``,
    ``view_mismatch``.

    Parameters
    ----------
    result : SfoResult
    skull : Skull
    photo : Photo

    Returns
    -------
    SfoResult
    """
    warnings = [*skull.warnings, *photo.warnings, *result.warnings]
    warnings += prior_warnings(photo, result.camera, result.facial_landmarks_mm)
    error = None
    if result:
        chin = chin_warning(skull, photo, result)
        if chin is not None:
            warnings.append(chin)
        view = view_warning(skull, photo, result.camera)
        if view is not None:
            warnings.append(view)
        error = landmark_error(result.camera, result.facial_landmarks_mm, photo)
    return replace(
        result, warnings=tuple(warnings), priors=priors_record(photo), landmark_error=error
    )
