"""``lilium photo``: write a docs/contract.md photo folder from a plain photograph
(docs/method/photo.md).

The folder holds the image (copied unchanged for PNG/JPEG, so its EXIF stays), ``photo.json``
(landmarks, ``landmark_sources``, priors with their sources), ``face_mask.png`` and
``review.html``. ``photo.json``'s priors carry, beside the contract's fields:

- ``"source": "automatic"`` and ``"sources"``: where each prior came from;
- ``"head_rotation_face2cam"`` (3 x 3) and ``"head_angles_deg"`` (yaw, pitch, roll): the face
  frame of :mod:`.headpose` in the camera frame. ``head_rotation_skull2cam`` needs a skull:
  ``lilium case`` (or :func:`lilium.photo.headpose.head_rotation_skull2cam`) converts it
  once one is paired, so this folder never holds a head prior the SFO would apply to an
  arbitrary skull frame;
- ``"scd_mm"`` from the iris (camera-to-eye distance) only when the focal is known (EXIF).
"""

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..constants import MIN_PHOTO_SIDE_PX
from ..io.case import read_image
from ..io.formats import read_landmarks
from ..io.jsonio import write_json
from ..io.results import write_page
from .analysis import analyse_face, find_faces, upright_turns
from .folder import PREPARED_BY, check_image_path, check_photo_not_output, claim_folder
from .headpose import implausible_distance, iris_distance_mm
from .landmarks import mesh_face_curves
from .mask import (
    HEAD_BEYOND_FACE,
    head_share_beyond_face,
    is_head_mask,
    mask_outline,
    polygon_mask,
)
from .profile import profile_of_photo
from .review import read_head_outline, review_page

#: Head-orientation tolerance (degrees) proposed with the automatic orientation.
HEAD_TOLERANCE_DEG = 15.0
#: Beyond this yaw (degrees) the face mesh no longer follows the face: the profile is read.
MESH_MAX_YAW_DEG = 60.0


def _profile_fallback(image, analysis, view):
    """The profile (:mod:`.profile`) and its head mask when the face mesh found no face or one
    turned beyond :data:`MESH_MAX_YAW_DEG`, and no frontal view was given; else ``(None, None)``.
    """
    if view == "frontal" or (analysis and abs(analysis.angles_deg["yaw"]) < MESH_MAX_YAW_DEG):
        return None, None
    profile, mask = profile_of_photo(image, view=view)
    return (profile, mask) if profile else (None, None)


@dataclass(frozen=True)
class PreparedPhoto:
    """What :func:`prepare_photo` wrote.

    Attributes
    ----------
    folder : Path
    face_found : bool
    message : str
        One line for the user (why no face was found, or a summary).
    view : str
    n_tracked, n_template : int
    warnings : tuple of dict
        ``{"code", "message"}`` (docs/checks.md codes), also in ``photo.json``.
    """

    folder: Path
    face_found: bool
    message: str
    view: str
    n_tracked: int = 0
    n_template: int = 0
    warnings: tuple = ()


def _copied_image_name(image_path, turned=False):
    """The folder's image name when it is the photo copied unchanged (PNG or JPEG, not turned),
    else None (the folder then holds a converted ``image.png``)."""
    suffix = image_path.suffix.lower()
    if suffix in (".png", ".jpg", ".jpeg") and not turned:
        return f"image{suffix}"
    return None


def _copy_image(image_path, image, out, turned=False):
    name = _copied_image_name(image_path, turned)
    if name is not None:
        target = out / name
        if not (target.exists() and target.samefile(image_path)):  # the folder's own image
            shutil.copyfile(image_path, target)
        return target
    from PIL import Image

    target = out / "image.png"
    Image.fromarray(image).save(target)
    return target


def _priors(image_path, analysis, sensor_width_mm):
    """``photo.json``'s priors and the warnings (``{"code", "message"}``) found on the way."""
    from ..io.exif import exif_focal

    priors, sources, warnings = {"source": "automatic"}, {}, []
    focal, unusable = exif_focal(image_path, sensor_width_mm=sensor_width_mm)
    if unusable:
        warnings.append({"code": "exif_focal_unusable", "message": unusable})
    if focal is not None and analysis:
        why = implausible_distance(focal.focal_px, analysis.iris_diameter_px)
        if why:
            warnings.append(
                {
                    "code": "implausible_prior",
                    "message": f"{image_path}: EXIF focal not used: {why} ({focal.source}); if "
                    "the distance is real, give the focal with lilium case --focal-px LO HI",
                }
            )
            focal = None
    if focal is not None:
        priors["focal_px"] = [float(x) for x in focal.focal_px]
        sources["focal_px"] = f"EXIF: {focal.source}"
    if analysis:
        priors["head_rotation_face2cam"] = analysis.face2cam.tolist()
        priors["head_angles_deg"] = {k: round(v, 2) for k, v in analysis.angles_deg.items()}
        priors["head_tolerance_face_deg"] = HEAD_TOLERANCE_DEG
        sources["head_rotation_face2cam"] = (
            "automatic: face mesh frame (lilium.photo.headpose); convert with a paired skull"
        )
        priors["iris_diameter_px"] = round(analysis.iris_diameter_px, 2)
        if focal is not None:
            f = float(np.mean(focal.focal_px))
            distance, interval = iris_distance_mm(f, analysis.iris_diameter_px)
            priors["scd_mm"] = [round(x, 1) for x in interval]
            sources["scd_mm"] = (
                f"automatic: iris {analysis.iris_diameter_px:.1f} px = 11.7 mm at focal "
                f"{f:.0f} px -> {distance:.0f} mm (camera to eyes)"
            )
    priors["sources"] = sources
    return priors, warnings


def _face_only_warning(image_path, partial=False):
    found = (
        "the head mask stops below the head's top (a dark cap or hair on a dark background?): "
        "face_mask.png holds only part of the head"
        if partial
        else "no head was found around the face (a faded, tinted or low-contrast print?): "
        "face_mask.png is the face outline alone, without hair and ears"
    )
    return {
        "code": "head_mask_face_only",
        "message": f"{image_path}: {found}; a case does not count the skull above the eye "
        "corners as outside it. Draw the head's outline in review.html and pass the saved file "
        "with --landmarks",
    }


def prepare_photo(
    image_path, out_dir, view=None, landmarks_path=None, sensor_width_mm=None, face=None
):
    """Write a photo folder from a photograph.

    Parameters
    ----------
    image_path : str or Path
        PNG or JPEG (any format Pillow reads; others are stored as ``image.png``).
    out_dir : str or Path
        The photo folder (created). ``lilium photo`` owns it (:mod:`.folder`): its own files
        of an earlier run are replaced, a folder holding another's is refused.
    view : {"frontal", "lateral_left", "lateral_right"}, optional
        Default: from the fitted yaw (frontal under 30 degrees).
    landmarks_path : str or Path, optional
        Reviewed landmarks (the review page's ``landmarks.json``, or any catalogue facial landmark
        file): they replace the automatic ones and count as confirmed. Its ``head_outline_px``
        (the review page's edited mask outline), when present, becomes the mask.
    sensor_width_mm : float, optional
        For the EXIF focal (see :mod:`lilium.io.exif`).
    face : int, optional
        Which face of a photo with several (1 = the leftmost); default the most confident.

    A face that is upright only in a copy of the photo turned by 90, 180 or 270 degrees
    (:func:`~lilium.photo.analysis.upright_turns`) is prepared on that copy, which the folder
    holds as ``image.png``: landmarks, mask and curves are then in its pixels, the left-right
    checks of a case hold, and the message says so.

    Returns
    -------
    PreparedPhoto
        ``face_found`` is False when the models found no face: the folder then has the image,
        a ``photo.json`` without automatic landmarks and the review page, to mark by hand.
    """
    image_path = check_image_path(image_path)
    out = Path(out_dir)
    check_photo_not_output(out, image_path, _copied_image_name(image_path))
    previous = claim_folder(out, image_path)
    image = read_image(image_path)
    h, w = image.shape[:2]
    if min(h, w) < MIN_PHOTO_SIDE_PX:
        raise ValueError(
            f"{image_path}: the photo is {w}x{h} px, too small to prepare or superimpose (at "
            f"least {MIN_PHOTO_SIDE_PX} px a side); use the original photograph"
        )
    faces = find_faces(image)
    turns = upright_turns(image, faces)
    if turns:
        faces = None
        if image_path.resolve().parent == out.resolve():
            raise ValueError(
                f"{image_path}: the face is upright only with the photo turned by "
                f"{90 * turns} degrees, and the photo lies in --out, where the turned copy would "
                "sit beside it; give another --out folder"
            )
        image = np.ascontiguousarray(np.rot90(image, turns))
        h, w = image.shape[:2]
        check_photo_not_output(out, image_path)  # a link to the folder's image: turned over it
    reviewed = read_landmarks(landmarks_path, "facial") if landmarks_path else None
    outline_px = read_head_outline(landmarks_path, (w, h)) if landmarks_path else None
    analysis = analyse_face(image, face, faces)
    profile, profile_mask = _profile_fallback(image, analysis, view)
    if profile:  # a lateral photo: the silhouette's profile line (docs/method/photo.md)
        why = (
            analysis.message.split(";")[0]
            if not analysis
            else (f"the face mesh is turned {analysis.angles_deg['yaw']:.0f} deg, beyond its range")
        )
        analysis = type(analysis)(message=why, faces=analysis.faces)  # nothing of the mesh
        view = view or profile.view
    view = view or (analysis.view if analysis else "frontal")
    landmarks, sources = dict(analysis.landmarks), dict(analysis.sources)
    if profile:
        landmarks, sources = dict(profile.landmarks), dict(profile.sources)
    if reviewed is not None:
        for name, uv in reviewed.items():
            u, v = uv
            if not (-0.5 <= u <= w - 0.5 and -0.5 <= v <= h - 0.5):
                raise ValueError(
                    f"{landmarks_path}: {name} = ({u:g}, {v:g}) lies outside the {w}x{h} "
                    f"image {image_path.name}; u is the column and v the row, in pixels"
                )
        quality = {k: s["quality"] for k, s in sources.items()}
        landmarks = dict(reviewed)
        sources = {
            k: {"source": "reviewed", "quality": quality.get(k, "manual"), "confirmed": True}
            for k in reviewed
        }
    priors, warnings = _priors(image_path, analysis, sensor_width_mm)
    if analysis.several_faces:
        warnings.append(
            {"code": "several_faces", "message": f"{image_path}: {analysis.several_faces}"}
        )
    if analysis.low_resolution:
        warnings.append(
            {"code": "low_resolution", "message": f"{image_path}: {analysis.low_resolution}"}
        )
    if turns:
        meta_turn = 90 * turns
        warnings.append(
            {
                "code": "photo_turned",
                "message": f"{image_path}: the face is upright only with the photo turned by "
                f"{meta_turn} degrees (counter-clockwise): the folder holds the turned photo "
                "(image.png), and its landmarks, mask and curves are in its pixels",
            }
        )
    head = analysis.mask if analysis else (profile_mask if profile else None)
    if outline_px is not None:  # the reviewed outline: the user's head
        head = polygon_mask(outline_px, (w, h))
    head_is_head = (
        outline_px is not None
        or bool(profile)
        or (bool(analysis) and is_head_mask(head, analysis.mesh_xyz))
    )
    if head is not None and not head_is_head:
        partial = head_share_beyond_face(head, analysis.mesh_xyz) >= HEAD_BEYOND_FACE
        warnings.append(_face_only_warning(image_path, partial))
    curves = mesh_face_curves(analysis.mesh_xyz, (w, h)) if analysis else {}
    meta = {
        "prepared_by": PREPARED_BY,
        "view": view,
        "landmarks": {k: [round(float(x), 2) for x in v] for k, v in landmarks.items()},
        "landmark_sources": sources,
        "priors": priors,
        "faces": [f.to_json() for f in analysis.faces],
    }
    if analysis:
        meta["resolution"] = analysis.resolution
    if head is not None:
        # Never a source of facial curves; False: the face outline alone (docs/method/photo.md).
        meta["face_mask_is_head"] = head_is_head
    if warnings:
        meta["warnings"] = warnings
    out.mkdir(parents=True, exist_ok=True)
    for path in previous:  # this command's files of an earlier run (folder.py)
        path.unlink()
    write_json(out / "photo.json", meta)
    _copy_image(image_path, image, out, turned=bool(turns))
    outline = np.zeros((0, 2))
    if head is not None:
        from PIL import Image

        Image.fromarray(head.astype(np.uint8) * 255).save(out / "face_mask.png")
        outline = mask_outline(head)
    if curves:
        source = {"source": "automatic", "quality": "template", "from": "face mesh outline"}
        curve_file = {k: np.round(c, 2).tolist() for k, c in curves.items()}
        curve_file["curve_sources"] = {k: source for k in curves}
        write_json(out / "face_curve.json", curve_file)
    n_tracked = sum(s["quality"] == "tracked" for s in sources.values())
    n_template = sum(s["quality"] == "template" for s in sources.values())
    if analysis:
        yaw, pitch, roll = (analysis.angles_deg[k] for k in ("yaw", "pitch", "roll"))
        message = (
            f"{n_tracked} tracked and {n_template} template landmarks, view {view}, head yaw "
            f"{yaw:.0f} pitch {pitch:.0f} roll {roll:.0f} deg, "
            f"{analysis.interpupillary_px:.0f} px between the pupils, "
            f"{analysis.head_width_px:.0f} px across the head; review them in "
            f"{out / 'review.html'}"
        )
    elif profile:
        message = (
            f"{analysis.message}: read the profile of the head's silhouette instead (profile "
            f"path), view {view}, {n_tracked} tracked and {n_template} "
            f"template landmarks; review them in {out / 'review.html'}"
        )
    else:
        message = f"{image_path}: {analysis.message}"
    page = review_page(
        image,
        meta["landmarks"],
        sources,
        outline,
        priors,
        image_path.name,
        message,
        faces=meta["faces"],
    )
    write_page(out / "review.html", page)
    found = bool(analysis) or bool(profile)
    return PreparedPhoto(out, found, message, view, n_tracked, n_template, tuple(warnings))
