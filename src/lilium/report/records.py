"""Plain records of a case report: everything the page shows, computed before any markup.

:func:`sfo_record` turns one SFO (skull, photo, result and the labelled inputs, notes and
outputs of a :class:`ReportEntry`) into an :class:`SfoRecord` of numbers, strings and encoded
pictures; :func:`report_record` collects the records of a page with its provenance. The HTML
module (:mod:`lilium.report.html`) only formats these records.

Image coordinates are ``uv`` = (column, row) pixels of the full photo; the skull frame and the
camera follow :class:`lilium.geometry.camera.Camera` (``x_cam = R x_skull + t``).
"""

import datetime as _dt
import json
from dataclasses import dataclass, field

import numpy as np

from ..evaluation.metrics import ImplausibleSFO
from ..geometry.rotations import geodesic_angle_deg, matrix_to_euler_xyz_deg, matrix_to_rotvec
from ..identification.score import head_overlap
from ..io.provenance import input_files, software_versions
from ..softtissue.landmarks import FACIAL_TO_CRANIAL
from ..validation import fmt_range
from .pictures import sfo_pictures, skull_view_pictures, skull_views_for, view_box
from .record_types import (
    CameraFacts,
    JointLandmarkRow,
    JointRecord,
    LandmarkRow,
    ReportRecord,
    SfoRecord,
    Summary,
)

#: Extra run facts of ``SfoResult.extra`` the report lists, in this order.
RUN_EXTRAS = ("generations", "evaluations", "stop", "fallbacks")

#: What each method's own score is (its ``fitness``; other methods: "fitness").
SCORE_LABELS = {"posest-sfo": "mean landmark error, px"}


@dataclass(frozen=True)
class ReportEntry:
    """One SFO to report.

    Attributes
    ----------
    skull : lilium.inputs.Skull
    photo : lilium.inputs.Photo
        Read with its image.
    result : lilium.methods.result.SfoResult
    inputs : dict of str -> Path
        Input files, labelled (``{"skull mesh": path, ...}``); hashed into the provenance.
    notes : dict of str -> str
        Extra facts shown with the camera (e.g. where each prior came from).
    outputs : dict of str -> str
        Output files, labelled, as links relative to the report.
    landmarks_note : str
        Where the facial landmarks came from, one sentence ("" for landmarks placed by hand),
        e.g. "facial landmarks automatic, unreviewed: ..." for a ``lilium photo`` folder.
    landmarks_unreviewed : bool
        Some landmarks are automatic and nobody confirmed them: the summary says so too.
    landmark_tags : dict of str -> str
        Per facial landmark, its source (``"automatic, tracked"``, ...), shown in the table.
    review_href : str
        The review page as a link relative to the report ("" when it lies elsewhere).
    joint : lilium.methods.joint.JointSfoResult or None
        The joint SFO (docs/method/joint.md) that ``result`` is this photo's part of; None for a
        single-photo SFO. The page then lists the shared soft tissue's 3D facial landmarks.
    """

    skull: object
    photo: object
    result: object
    inputs: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)
    landmarks_note: str = ""
    landmarks_unreviewed: bool = False
    landmark_tags: dict = field(default_factory=dict)
    review_href: str = ""
    joint: object = None


def _floats(values):
    return tuple(float(x) for x in np.ravel(values))


def method_label(result):
    """Method and variant of an SFO, e.g. ``"lilium skof+pll"``; ``"lilium skof+pll joint"``
    for a photo's part of a joint SFO."""
    joint = " joint" if result.extra.get("joint_photos") else ""
    examiner = ""
    if result.camera_source == "examiner":
        examiner = ", examiner's camera (scored, no search)"
    return result.method + (f" {result.variant}" if result.variant else "") + joint + examiner


def landmark_rows(result, photo):
    """Photo landmark, projected estimate and error of every landmark the SFO used.

    Parameters
    ----------
    result : SfoResult
    photo : Photo

    Returns
    -------
    tuple of LandmarkRow
        In the order of ``result.facial_landmarks_mm``; estimates and errors are NaN when the
        SFO failed.
    """
    names = [n for n in result.facial_landmarks_mm if n in photo.landmarks_uv]
    photo_uv = np.array([photo.landmarks_uv[n] for n in names], dtype=float).reshape(-1, 2)
    if result and names:
        est3d = np.array([result.facial_landmarks_mm[n] for n in names])
        est_uv = result.camera.project(est3d)
    else:
        est_uv = np.full_like(photo_uv, np.nan)
    errors = np.linalg.norm(est_uv - photo_uv, axis=1)
    return tuple(
        LandmarkRow(n, _floats(p), _floats(e), float(d))
        for n, p, e, d in zip(names, photo_uv, est_uv, errors, strict=True)
    )


def camera_facts(result, photo):
    """Camera parameters of a successful SFO, for the report (degrees, mm, pixels).

    Parameters
    ----------
    result : SfoResult
        Successful.
    photo : Photo
        Its priors are recorded with the facts.

    Returns
    -------
    CameraFacts
    """
    camera = result.camera
    T, R = camera.skull2cam, camera.R
    rotvec = matrix_to_rotvec(R)
    angle = float(np.degrees(np.linalg.norm(rotvec)))
    axis = rotvec / np.linalg.norm(rotvec) if angle > 0 else np.array([0.0, 0.0, 1.0])
    lms = result.facial_landmarks_mm
    centre = lms["nasion"] if "nasion" in lms else np.mean(list(lms.values()), axis=0)
    priors = photo.priors
    prior = priors.head_rotation_skull2cam
    return CameraFacts(
        focal_px=float(camera.focal_px),
        principal_point_px=_floats(camera.principal_point_px),
        scd_mm=float(camera.distance_mm(centre)),
        scd_point="facial nasion" if "nasion" in lms else "centroid of the facial landmarks",
        rotation_angle_deg=angle,
        rotation_axis=_floats(axis),
        euler_xyz_deg=_floats(matrix_to_euler_xyz_deg(R)),
        translation_mm=_floats(T[:3, 3]),
        skull2cam=tuple(_floats(row) for row in T),
        head_deviation_deg=None if prior is None else float(geodesic_angle_deg(R, prior)),
        focal_prior_px=None if priors.focal_px is None else _floats(priors.focal_px),
        scd_prior_mm=None if priors.scd_mm is None else _floats(priors.scd_mm),
        head_tolerance_deg=None if prior is None else float(priors.head_tolerance_deg),
    )


def score_label(method):
    """What a method's own score (``SfoResult.fitness``) is, for the report."""
    return SCORE_LABELS.get(method, "fitness")


def prior_rows(result):
    """The priors of a result as ``(name, value, source)`` text rows (``result.priors``)."""
    priors = result.priors or {}
    rows = []
    for key, label, unit in (("focal_px", "focal length", "px"), ("scd_mm", "SCD", "mm")):
        entry = priors.get(key)
        if entry is None:
            continue
        value = "none" if entry["range"] is None else fmt_range(*entry["range"], unit)
        rows.append((label, value, entry["source"]))
    head = priors.get("head_rotation")
    if head is not None:
        value = (
            "none"
            if head["skull2cam"] is None
            else f"given, tolerance {head['tolerance_deg']:g} deg"
        )
        rows.append(("head orientation", value, head["source"]))
    return tuple(rows)


def _skull_uv_in_image(camera, skull, size_wh):
    """The corners ``(2, 2)`` (or ``(0, 2)``) of the box of the projected skull vertices clipped
    to the image: the skull's extent in the photo."""
    uv = camera.project(skull.vertices_mm)
    uv = np.clip(uv[np.all(np.isfinite(uv), axis=1)], 0, np.array(size_wh, dtype=float) - 1)
    return np.array([uv.min(axis=0), uv.max(axis=0)]) if len(uv) else uv


def skull_views(skull, view, cache=None):
    """The skull-alone pictures shown beside an SFO of a photo in ``view`` (frontal and the
    photo's lateral side, :func:`lilium.report.pictures.skull_views_for`).

    Parameters
    ----------
    skull : Skull
    view : str
        The photo's view.
    cache : dict, optional
        Pictures already rendered on this page, reused (one render per skull and view).

    Returns
    -------
    tuple of SkullViewPicture
    """
    cache = {} if cache is None else cache
    prefixes = cache.setdefault("prefixes", {})
    prefix = prefixes.setdefault(id(skull), f"skv{len(prefixes) + 1}")
    pictures = []
    for v in skull_views_for(view):
        if (prefix, v) not in cache:
            found = skull_view_pictures(skull, (v,), key_prefix=prefix)
            cache[(prefix, v)] = found[0] if found else None
        if cache[(prefix, v)] is not None:
            pictures.append(cache[(prefix, v)])
    return tuple(pictures)


def sfo_record(entry, index=1, hash_cache=None, view_cache=None):
    """The plain record of one SFO.

    Parameters
    ----------
    entry : ReportEntry
    index : int
        1-based position on the page.
    hash_cache : dict, optional
        Digests of input files already hashed (see :func:`lilium.io.provenance.input_files`).
    view_cache : dict, optional
        Skull-alone pictures already rendered on this page (see :func:`skull_views`).

    Returns
    -------
    SfoRecord
    """
    result, photo, skull = entry.result, entry.photo, entry.skull
    if photo.image is None:
        raise ValueError(f"photo {photo.id!r} was read without its image; read it with pixels")
    rows = landmark_rows(result, photo)
    errors = np.array([r.error_px for r in rows])
    mean_err = float(np.mean(errors)) if len(errors) and np.all(np.isfinite(errors)) else None
    camera = camera_facts(result, photo) if result else None
    outside = implausible = None
    if result and photo.face_mask is not None:
        # One raster for both: every skull pixel outside the mask (the figure shown), and the
        # mark by the identification's rule (skull_outside_head: pixels beyond the mask's edge
        # band, not a pixel or two of raster and mask-edge noise).
        overlap = head_overlap(skull, photo, result.camera)
        outside = ImplausibleSFO.of(len(overlap.depths_px), overlap.skull_px)
        implausible = overlap.beyond()[0] > 0
    points = [r.photo_uv for r in rows] + [r.estimate_uv for r in rows]
    if result:
        points += list(_skull_uv_in_image(result.camera, skull, photo.image_size_wh))
    box = view_box(photo.image_size_wh, None, photo.face_mask, points)
    pictures = sfo_pictures(result, skull, photo, box, bool(implausible))
    history = result.extra.get("history")
    warnings = tuple((w.code, w.message) for w in result.warnings)
    error = result.landmark_error or {}
    status = "ok" if result else f"failed: {result.error}"
    if implausible:
        status = "implausible"
    summary = Summary(
        status=status,
        focal_px=camera.focal_px if camera else None,
        scd_mm=camera.scd_mm if camera else None,
        mean_error_px=error.get("mean_px", mean_err),
        fitness=result.fitness,
        outside_pct=None if outside is None else outside.percent_outside,
        seconds=float(result.seconds),
        mean_error_mm=error.get("mean_mm"),
        score_label=score_label(result.method),
        implausible=implausible,
        warnings=warnings,
    )
    return SfoRecord(
        index=index,
        skull_id=str(skull.id),
        photo_id=str(photo.id),
        view=str(photo.view),
        image_size_wh=tuple(int(s) for s in photo.image_size_wh),
        method=result.method,
        method_label=method_label(result),
        ok=bool(result),
        error=result.error,
        summary=summary,
        landmarks=rows,
        mean_error_px=mean_err,
        camera=camera,
        notes=tuple((str(k), str(v)) for k, v in entry.notes.items()),
        terms=tuple(result.terms.items()),
        fitness=result.fitness,
        outside=outside,
        history=None if history is None else _floats(history),
        seed=result.seed,
        seconds=float(result.seconds),
        run_extra=tuple((k, str(result.extra[k])) for k in RUN_EXTRAS if k in result.extra),
        inputs=input_files(entry.inputs, hash_cache),
        outputs=tuple((str(k), str(v)) for k, v in entry.outputs.items()),
        pictures=pictures,
        skull_views=skull_views(skull, photo.view, view_cache),
        cranial_numbers=tuple(
            (FACIAL_TO_CRANIAL[r.name], k)
            for k, r in enumerate(rows, start=1)
            if r.name in FACIAL_TO_CRANIAL and FACIAL_TO_CRANIAL[r.name] in skull.landmarks_mm
        ),
        warnings=warnings,
        priors=prior_rows(result),
        terms_off=tuple((str(k), str(v)) for k, v in result.terms_off.items()),
        landmarks_note=str(entry.landmarks_note),
        landmarks_unreviewed=bool(entry.landmarks_unreviewed),
        landmark_tags=tuple((str(k), str(v)) for k, v in entry.landmark_tags.items()),
        review_href=str(entry.review_href),
    )


def report_record(entries, title=None, command=None, date=None, decisions=(), request=None):
    """The plain record of a report page.

    Parameters
    ----------
    entries : list of ReportEntry
        One per SFO; entries of the same photo (e.g. two methods) follow each other.
    title : str, optional
        By default from the skulls' ids.
    command : str, optional
        The command line that produced the results, for the provenance.
    date : str, optional
        ISO date-time; now (UTC) by default.
    decisions : sequence of (str, dict), optional
        Identifications of several photos' SFOs taken together (label, record), shown first
        beside each SFO's own.
    request : dict, optional
        The run's request (:meth:`lilium.casework.request.CaseRequest.to_dict`), for the
        provenance.

    Returns
    -------
    ReportRecord
    """
    if not entries:
        raise ValueError("a report needs at least one SFO result")
    date = date or _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    skull_ids = tuple(sorted({str(e.skull.id) for e in entries}))
    title = title or f"Skull-face overlay: skull {', '.join(skull_ids)}"
    cache, views = {}, {}
    sfos = tuple(sfo_record(e, i, cache, views) for i, e in enumerate(entries, start=1))
    versions = tuple(software_versions().items())
    unique = _unique_joints(entries)
    joints = tuple(joint_record(j) for j in unique)
    found = [(label, "", record) for label, record in decisions]
    found += [
        (f"joint SFO {method_label(j.photos[0])}, photos {', '.join(r.photo_id for r in j.photos)}",
         "", j.extra["identification"])
        for j in unique
        if "identification" in j.extra
    ]
    found += [
        (f"photo {e.photo.id}, {method_label(e.result)}", f"sfo-{i}",
         e.result.extra["identification"])
        for i, e in enumerate(entries, start=1)
        if e.joint is None and "identification" in e.result.extra
    ]
    request = None if request is None else json.dumps(request, sort_keys=True)
    return ReportRecord(
        title, date, command, skull_ids, versions, sfos, joints, tuple(found), request
    )


def _unique_joints(entries):
    found = {}
    for e in entries:
        if e.joint is not None:
            found.setdefault(id(e.joint), e.joint)
    return list(found.values())


def joint_record(joint):
    """The record of a joint SFO's shared soft tissue (the page lists it once).

    Parameters
    ----------
    joint : lilium.methods.joint.JointSfoResult

    Returns
    -------
    JointRecord
    """
    seen = {r.photo_id: set(r.facial_landmarks_mm) for r in joint.photos}
    rows = tuple(
        JointLandmarkRow(
            name=str(name),
            position_mm=_floats(xyz),
            photos=tuple(pid for pid, names in seen.items() if name in names),
        )
        for name, xyz in joint.facial_landmarks_mm.items()
    )
    return JointRecord(
        method_label=method_label(joint.photos[0]),
        skull_id=str(joint.skull_id),
        photo_ids=tuple(str(r.photo_id) for r in joint.photos),
        fitness=float(joint.fitness),
        photo_fitness=tuple(float(r.fitness) for r in joint.photos),
        ok=bool(joint),
        landmarks=rows,
        weights=tuple(float(w) for w in joint.weights),
    )


__all__ = [
    "ReportEntry",
    "camera_facts",
    "joint_record",
    "landmark_rows",
    "method_label",
    "prior_rows",
    "report_record",
    "score_label",
    "sfo_record",
    "skull_views",
]
