"""A user's skull and photos, from docs/contract.md folders or the files a practitioner has.

Sidecar files, used when the command line does not name the file (each one found is logged,
e.g. ``front: using mask front_mask.png (found beside the photo)``): a mesh's landmark file is
a sibling with the mesh's stem (``skull.fcsv``, ``skull.mrk.json``, ...); beside an image
``<stem>.png``/``.jpg``, its facial landmarks ``<stem>.csv``/``.json``/``.tsv``/``.txt`` or
``<stem>_landmarks.*``, its face mask ``<stem>_mask.png`` and its facial curve
``<stem>_face_curve.json``. A photo folder holds its own ``face_mask.png`` and
``face_curve.json`` (docs/contract.md). Priors: the command line's ``--focal-px``/``--scd-mm``
override ``photo.json``; without either, the focal prior comes from the photo's EXIF when it
has one.
"""

from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

from ..inputs import CaseWarning
from ..io.case import (
    IMAGE_NAMES,
    check_axes_file,
    check_distinct_files,
    first_file,
    parse_skull_files,
    read_mask,
    subject_files,
)
from ..io.curves import read_face_curve
from ..io.formats import find_landmark_file
from ..io.mesh import MESH_SUFFIXES
from ..io.paths import path_id, safe_id
from ..io.prepared import read_prepared
from ..methods.photo_checks import check_distinct_photos, check_landmarks_in_mask
from ..validation import fmt_range
from .build import build_skull, photo_from_files, read_photo
from .prepared import landmark_origin, prepare_bare_photo, with_automatic_priors
from .request import PriorOverrides

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


class PhotoRecord(NamedTuple):
    """One photo of a case as :func:`load_photos` read it; ``camera``: the examiner's camera
    to score (:class:`~lilium.inputs.GivenCamera`, ``--camera``), read by
    :func:`~lilium.casework.read.read_case`."""

    photo: object
    inputs: dict
    notes: dict
    origin: object = None
    camera: object = None


def load_skull(source, log=None, out=None):
    """Read the skull from a subject folder or a mesh file.

    A mesh without a landmark file (none given, none beside it) gets its cranial landmarks
    placed automatically (``lilium skull``, :func:`~lilium.skull.prepare.prepare_skull`) into
    ``out/prepared-skull/`` (reused while the mesh is unchanged), with its ``review.html``;
    they are automatic and unreviewed, which leaves every conclusion undetermined until they are
    reviewed (``unreviewed_skull_landmarks``, docs/method/skull.md).

    Parameters
    ----------
    source : SkullSource
        The skull as given (:class:`~lilium.casework.request.SkullSource`).
    log : callable, optional
        Receives one line for a landmark file found beside a mesh, and one for landmarks placed
        automatically.
    out : Path, optional
        The output folder; without one a mesh needs its landmark file.

    Returns
    -------
    skull : Skull
        Its ``landmarks_file`` named (for the left/right messages).
    inputs : dict of str -> Path
        The files used, labelled, for the provenance.

    Raises
    ------
    ValueError
        Also when ``source.axes`` is given but is not a file (it is never ignored).
    """
    files = skull_files(source, log=log, out=out)
    parsed = parse_skull_files(files.mesh, files.landmarks, files.axes, files.skull_id)
    skull = build_skull(parsed)
    return replace(skull, landmarks_file=str(files.landmarks)), files.inputs


class SkullFiles(NamedTuple):
    """The files a skull is built from (:func:`skull_files`).

    Attributes
    ----------
    mesh, landmarks : Path
        The mesh to read (millimetres) and its cranial landmark file.
    axes : Path or None
        The soft-tissue axes file (absent or None: the skull-surface normals).
    skull_id : str or None
        None: :func:`~lilium.io.case.parse_skull_files`'s default.
    inputs : dict of str -> Path
        The files used, labelled, for the provenance (``"skull mesh"`` is the mesh given).
    """

    mesh: Path
    landmarks: Path
    axes: Path | None
    skull_id: str | None
    inputs: dict


def skull_files(source, log=None, out=None):
    """The files of the skull ``source`` names (:func:`load_skull`), found beside it or, for a
    mesh without landmarks, prepared in ``out/prepared-skull/`` (:func:`_automatic_skull`).

    Returns
    -------
    SkullFiles
    """
    landmarks, axes = source.landmarks, source.axes
    skull_path = Path(source.path)
    if axes is not None:
        check_axes_file(axes)
    skull_id = None
    if skull_path.is_dir():
        mesh, found = subject_files(skull_path)
        landmarks = Path(landmarks) if landmarks is not None else found
        axes = Path(axes) if axes else skull_path / "soft_tissue_axes.json"
        skull_id = path_id(skull_path, "skull")
    elif skull_path.is_file():
        mesh = skull_path
        if skull_path.suffix.lower() not in MESH_SUFFIXES:
            raise ValueError(
                f"{skull_path}: --skull must be a subject folder or a PLY/OBJ/STL mesh; convert "
                "the skull to one of those"
            )
        if landmarks is None:
            landmarks = find_landmark_file(
                skull_path.parent, [skull_path.stem, f"{skull_path.stem}_landmarks"]
            )
            if landmarks is None and out is None:
                raise ValueError(
                    f"{skull_path}: no cranial landmark file next to the mesh; give it with "
                    "--landmarks FILE (.mrk.json, .fcsv, .pp, .csv or .json)"
                )
            if landmarks is None:
                return _automatic_skull(skull_path, axes, Path(out) / SKULL_FOLDER, log)
            _found(log, skull_path.stem, "cranial landmarks", landmarks, "the mesh")
    else:
        raise ValueError(
            f"{skull_path}: --skull not found; give a subject folder or a skull mesh file"
        )
    inputs = {"skull mesh": mesh, "cranial landmarks": Path(landmarks)}
    if axes is not None and Path(axes).is_file():
        inputs["soft-tissue axes"] = Path(axes)
    return SkullFiles(mesh, Path(landmarks), axes, skull_id, inputs)


def _automatic_skull(mesh, axes, folder, log):
    """:func:`skull_files` of a mesh without landmarks: its subject folder placed by ``lilium
    skull`` in ``folder`` (or read back from there)."""
    from ..skull.prepare import parts_left_out_sentence, prepare_skull

    done = prepare_skull(mesh, folder, reuse=True)
    if log is not None:
        how = "read back from" if done["reused"] else "placed automatically (lilium skull) in"
        log(
            f"{mesh.name}: no cranial landmark file beside the mesh: landmarks {how} {folder} "
            f"(automatic, unreviewed: check them in {folder / 'review.html'})"
        )
        if done["result"] is not None and done["result"].parts_left_out:
            log(f"{mesh.name}: {parts_left_out_sentence(done['result'].parts_left_out)}")
    axes = Path(axes) if axes is not None else folder / "soft_tissue_axes.json"
    landmarks = folder / "cranial_landmarks.json"
    inputs = {"skull mesh": mesh, "cranial landmarks": landmarks}
    if axes.is_file():
        inputs["soft-tissue axes"] = axes
    return SkullFiles(folder / "skull.ply", landmarks, axes, mesh.stem, inputs)


def _sibling(image_path, stems, suffixes):
    for stem in stems:
        for suffix in suffixes:
            candidate = image_path.with_name(stem + suffix)
            if candidate.is_file() and candidate != image_path:
                return candidate
    return None


def _found(log, owner, what, path, beside):
    if log is not None:
        log(f"{owner}: using {what} {Path(path).name} (found beside {beside})")


def load_photos(
    sources, priors=PriorOverrides(), log=None, skull=None, auto_landmarks=False, out=None
):
    """Read every photo (folders and image files) with its priors.

    Parameters
    ----------
    sources : sequence of PhotoSource
        Photo folders or PNG/JPEG images, each with the files named for it
        (:class:`~lilium.casework.request.PhotoSource`): an image's landmark file defaults to a
        sibling ``<stem>.csv``/``.json``/``<stem>_landmarks.*``, its mask to
        ``<stem>_mask.png``, its facial curve (``face_curve.json`` format) to
        ``<stem>_face_curve.json``, its view to frontal.
    priors : PriorOverrides
        Priors given for every photo: they win over ``photo.json``; without a focal prior the
        photo's EXIF gives one when ``priors.use_exif``.
    log : callable, optional
        Receives one line per sidecar file found beside an image (not named on the command
        line), e.g. ``"front: using mask front_mask.png (found beside the photo)"``, one per
        photo prepared with ``auto_landmarks`` and one per automatic prior switched off.
    skull : Skull, optional
        The paired skull: the automatic head orientation of a ``lilium photo`` folder becomes
        ``head_rotation_skull2cam`` through its frame
        (:func:`~lilium.casework.prepared.with_automatic_priors`).
    auto_landmarks : bool
        Prepare each image without a landmark file (none given, none beside it) with
        ``lilium photo`` into ``out/<photo>/prepared/`` and use that folder, with the image's
        own ``--mask``, ``--face-curve`` and ``--view`` where given (the mask beside it too).
    out : path, optional
        The case's output folder (needed with ``auto_landmarks``).

    Returns
    -------
    list of PhotoRecord
        ``(photo, inputs, notes, origin)``: ``inputs`` the files used, labelled (provenance);
        ``notes`` where each prior came from, as text for the report; ``origin`` the
        :class:`~lilium.casework.prepared.LandmarkOrigin` of a ``lilium photo`` folder's
        landmarks (None for landmarks placed by hand). Each photo carries its priors' sources
        (``prior_sources``), its ``landmarks_file`` and its input warnings (:func:`with_priors`).

    Raises
    ------
    ValueError
        A photo given twice, by path or as a copy of its image
        (:func:`~lilium.io.case.check_distinct_files`, before any is read) or of its landmarks
        (:func:`~lilium.methods.photo_checks.check_distinct_photos`); a photo that cannot be
        read, naming the file and the fix.
    """
    check_distinct_files([source.path for source in sources])
    focal_cli, scd_cli = priors.focal_px, priors.scd_mm  # checked intervals
    use_exif, sensor_width_mm = priors.use_exif, priors.sensor_width_mm
    records = []
    for source in sources:
        path = Path(source.path)
        inputs, notes, facts, origin = {}, {}, None, None
        if path.is_dir():
            photo = read_photo(path)
            if source.view is not None and source.view != photo.view:
                raise ValueError(
                    f"{path / 'photo.json'}: view is {photo.view!r} but --view says "
                    f"{source.view!r}; --view sets the view of image files, a photo folder's is "
                    "its photo.json's: edit it there (or leave --view out)"
                )
            image = first_file(path, IMAGE_NAMES)
            inputs["photo"] = image
            inputs["photo.json"] = path / "photo.json"
            facts = read_prepared(path)
            lm_file = find_landmark_file(path, ["facial_landmarks", "landmarks"])
            if "landmarks" in _json_keys(path / "photo.json"):
                origin = landmark_origin(photo, facts)
            elif lm_file is not None:
                inputs["facial landmarks"] = lm_file
            for name, label in (("face_mask.png", "face mask"), ("face_curve.json", "face curve")):
                if (path / name).is_file():
                    inputs[label] = path / name
        else:
            if not path.is_file():
                raise ValueError(f"{path}: --photo not found; give a photo folder or an image")
            if path.suffix.lower() not in IMAGE_SUFFIXES:
                raise ValueError(f"{path}: --photo must be a folder or a PNG/JPEG image")
            image = path
            lm_file = source.landmarks or _sibling(
                path,
                [path.stem, f"{path.stem}_landmarks", f"{path.stem}.landmarks"],
                (".csv", ".json", ".tsv", ".txt"),
            )
            if lm_file is None and not auto_landmarks:
                raise ValueError(
                    f"{path}: no facial landmark file for this photo; give it with "
                    "--photo-landmarks FILE (CSV name,u,v or JSON), once per --photo image, or "
                    "let --auto-landmarks find them (pip install 'lilium[photo]')"
                )
            if lm_file is not None and source.landmarks is None:
                _found(log, path.stem, "facial landmarks", lm_file, "the photo")
            mask = source.mask or _sibling(
                path, [f"{path.stem}_mask", f"{path.stem}.mask"], (".png",)
            )
            if mask is not None and source.mask is None:
                _found(log, path.stem, "mask", mask, "the photo")
            curve = source.face_curve or _sibling(path, [f"{path.stem}_face_curve"], (".json",))
            if curve is not None and source.face_curve is None:
                _found(log, path.stem, "face curve", curve, "the photo")
            view = source.view or "frontal"
            if lm_file is None:  # --auto-landmarks: lilium photo into OUT/<photo>/prepared/
                photo, inputs, facts = _prepared_image(
                    path, _taken(records), out, source.view, mask, sensor_width_mm, log
                )
                origin = landmark_origin(photo, facts)
                if curve is not None:
                    photo = replace(
                        photo,
                        face_curve_uv=read_face_curve(curve, photo.view, photo.image_size_wh),
                    )
            else:
                photo = photo_from_files(path, lm_file, view, mask, face_curve_path=curve)
                inputs["photo"] = path
                inputs["facial landmarks"] = lm_file
            if mask is not None:
                inputs["face mask"] = mask
            if curve is not None:
                inputs["face curve"] = curve
        photo_id = unique_id(photo.id, _taken(records))
        photo, notes = with_priors(
            photo, image, focal_cli, scd_cli, use_exif=use_exif, sensor_width_mm=sensor_width_mm
        )
        photo, notes = with_automatic_priors(
            photo, notes, facts, skull, scd_from_cli=scd_cli is not None, log=log
        )
        photo = replace(
            photo, landmarks_file=str(inputs.get("facial landmarks") or inputs["photo.json"])
        )
        off_mask = check_landmarks_in_mask(photo)  # an error, or warnings the result keeps
        photo = replace(photo, id=photo_id, warnings=(*photo.warnings, *off_mask))
        records.append(PhotoRecord(photo, inputs, notes, origin))
    check_distinct_photos([r.photo for r in records])
    return records


#: The joint SFOs' folder in a case's output folder (``<out>/joint/<method tag>/``).
JOINT_FOLDER = "joint"

#: Names at the top of a case's output folder that are not photo folders: a photo named so
#: gets another id (``report.html_2``), as a repeated name does.
#: The subject folder ``lilium case`` writes for a mesh without landmarks (:func:`load_skull`).
SKULL_FOLDER = "prepared-skull"

CASE_OWN_NAMES = ("report.html", JOINT_FOLDER, SKULL_FOLDER)


def _taken(records):
    return {*CASE_OWN_NAMES, *(r.photo.id for r in records)}


def unique_id(photo_id, taken):
    """The output id of a photo: ``photo_id``, or the first of ``photo_id_2``, ``photo_id_3``,
    ... that no earlier photo has (``taken``, the ids given so far), so that photos ``front``,
    ``front`` and ``front_2`` write to three folders (``front``, ``front_2``, ``front_2_2``).
    """
    if photo_id not in taken:
        return photo_id
    n = 2
    while f"{photo_id}_{n}" in taken:
        n += 1
    return f"{photo_id}_{n}"


def _prepared_image(path, taken, out, view, mask, sensor_width_mm, log):
    """``--auto-landmarks`` for one bare image: prepare, read back, keep the user's mask.

    ``taken`` holds the output ids of the photos before it (:func:`unique_id`).

    Returns the photo (its id the image's stem, as for an image with a landmark file), its
    labelled inputs and the folder's :class:`~lilium.io.prepared.PreparedFacts`.
    """
    if out is None:
        raise ValueError("--auto-landmarks needs the output folder (--out) to prepare photos in")
    photo_id = safe_id(path.stem, "photo")
    folder = Path(out) / unique_id(photo_id, taken) / "prepared"  # the photo's output folder
    prepare_bare_photo(path, folder, view=view, sensor_width_mm=sensor_width_mm, log=log)
    photo = replace(read_photo(folder), id=photo_id)
    if mask is not None:  # the user's own mask wins over the automatic one
        photo = replace(photo, face_mask=read_mask(mask, photo.image_size_wh), mask_file=str(mask))
    inputs = {"photo": path, "photo.json": folder / "photo.json"}
    if mask is None and (folder / "face_mask.png").is_file():
        inputs["face mask"] = folder / "face_mask.png"
    return photo, inputs, read_prepared(folder)


def with_priors(photo, image, focal_px=None, scd_mm=None, use_exif=True, sensor_width_mm=None):
    """A photo with its priors by precedence (command line > ``photo.json`` > EXIF) and sources.

    Parameters
    ----------
    photo : Photo
        As read (its priors from ``photo.json``).
    image : Path
        The image file (for its EXIF).
    focal_px, scd_mm : (lo, hi), optional
        From the command line (checked intervals).
    use_exif : bool
    sensor_width_mm : float, optional

    Returns
    -------
    photo : Photo
        With ``priors``, ``prior_sources`` (values among :data:`lilium.inputs.PRIOR_SOURCES`)
        and, when the EXIF focal length cannot be converted, warning ``exif_focal_unusable``;
        when a focal prior given on the command line or in ``photo.json`` does not overlap the
        photo's own EXIF focal length, warning ``prior_conflict`` (one of them is wrong).
    notes : dict of str -> str
        The same as text for the report (``"focal prior": "1900-2100 px (photo.json)"``).
    """
    priors, sources, details, warnings = photo.priors, {}, {}, list(photo.warnings)
    if focal_px is not None:
        priors, sources["focal_px"] = replace(priors, focal_px=focal_px), "command line"
        details["focal_px"] = "command line --focal-px"
    elif priors.focal_px is not None:
        sources["focal_px"] = "photo.json"
    elif use_exif and image is not None:
        from ..io.exif import exif_focal

        exif, unusable = exif_focal(image, sensor_width_mm=sensor_width_mm)
        if exif is not None:
            priors, sources["focal_px"] = replace(priors, focal_px=exif.focal_px), "exif"
            details["focal_px"] = exif.source
        elif unusable:
            warnings.append(CaseWarning("exif_focal_unusable", unusable))
    if sources.get("focal_px") in ("command line", "photo.json") and use_exif and image:
        warnings += _exif_conflict(image, priors.focal_px, sources["focal_px"], sensor_width_mm)
    if scd_mm is not None:
        priors, sources["scd_mm"] = replace(priors, scd_mm=scd_mm), "command line"
        details["scd_mm"] = "command line --scd-mm"
    elif priors.scd_mm is not None:
        sources["scd_mm"] = "photo.json"
    if priors.uses_head:
        sources["head_rotation"] = "photo.json"
    notes = {}
    for key, label, unit in (("focal_px", "focal prior", "px"), ("scd_mm", "SCD prior", "mm")):
        value = getattr(priors, key)
        if value is None:
            notes[label] = "none (penalty off)"
        else:
            where = details.get(key, sources[key])
            notes[label] = f"{fmt_range(*value, unit)} ({where})"
    photo = replace(photo, priors=priors, prior_sources=sources, warnings=tuple(warnings))
    return photo, notes


def _exif_conflict(image, focal_px, source, sensor_width_mm):
    """``[CaseWarning("prior_conflict", ...)]`` when the photo's EXIF focal interval does not
    overlap the focal prior it was overruled by, else ``[]`` (no usable EXIF: nothing to say)."""
    from ..io.exif import exif_focal

    exif, _ = exif_focal(image, sensor_width_mm=sensor_width_mm)
    if exif is None or (exif.focal_px[0] <= focal_px[1] and focal_px[0] <= exif.focal_px[1]):
        return []
    return [
        CaseWarning(
            "prior_conflict",
            f"{image}: its EXIF focal length ({fmt_range(*exif.focal_px, 'px')}, {exif.source}) "
            f"lies outside the focal prior {fmt_range(*focal_px, 'px')} ({source}) that "
            "overrules it: one of them is wrong (another photo's prior, a cropped or resized "
            "image); check both",
        )
    ]


def _json_keys(path):
    from ..io.jsonio import read_json

    data = read_json(path)
    return data.keys() if isinstance(data, dict) else ()
