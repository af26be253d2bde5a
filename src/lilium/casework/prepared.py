"""Photo folders written by ``lilium photo`` (docs/method/photo.md) in a case: their landmarks'
origin, their automatic priors paired with the skull, and ``lilium case --auto-landmarks``.

Decisions (docs/method/photo.md, "In a case"):

- A prior ``lilium photo`` found (``priors.source`` ``"automatic"`` with a ``priors.sources``
  line) keeps ``"source": "automatic"`` in ``result.json`` (docs/checks.md), the EXIF focal
  included: nobody has checked it; the report gives the line (``"automatic: EXIF: ..."``).
  The command line still wins (``--focal-px``, ``--scd-mm``).
- The head orientation becomes ``head_rotation_skull2cam = face2cam @ skull2face`` through the
  paired skull's frame (:func:`lilium.photo.headpose.skull_face_frame`); a skull whose
  landmarks cannot give that frame runs without the head prior, with a note (never an error).
  A ``head_rotation_skull2cam`` already in ``photo.json`` (put there by the user) wins.
- The iris distance follows the focal actually used: when the focal comes from elsewhere than
  ``lilium photo`` (``--focal-px``, an EXIF focal read with ``--sensor-width-mm``), the
  distance prior is recomputed from the iris with that focal interval's ends, unless
  ``--scd-mm`` is given.
- Landmarks whose source is ``"automatic"`` and that are not ``"confirmed"`` are *automatic,
  unreviewed*: the report says so beside the landmark table and in the summary, with the
  review page to check them in.
"""

from dataclasses import dataclass, replace
from pathlib import Path

from ..validation import fmt_range

#: The words the report and the console use for landmarks nobody has looked at.
UNREVIEWED = "automatic, unreviewed"


@dataclass(frozen=True)
class LandmarkOrigin:
    """Where the facial landmarks of one photo came from, for the report.

    Attributes
    ----------
    tags : dict of str -> str
        Per used landmark, e.g. ``"automatic, tracked"``, ``"reviewed, template"``.
    unreviewed : tuple of str
        Used landmarks that are automatic and unconfirmed.
    left_out : tuple of str
        Template landmarks written but not used (unconfirmed).
    review_page : Path or None
        The folder's ``review.html``.
    """

    tags: dict
    unreviewed: tuple = ()
    left_out: tuple = ()
    review_page: Path | None = None

    def line(self):
        """One sentence for the report and the console ("" for landmarks placed by hand)."""
        if not self.unreviewed:
            reviewed = [k for k, t in self.tags.items() if t.startswith("reviewed")]
            return f"facial landmarks reviewed ({len(reviewed)} confirmed)" if reviewed else ""
        n, total = len(self.unreviewed), len(self.tags)
        count = f"all {n}" if n == total else f"{n} of {total}"
        text = f"facial landmarks {UNREVIEWED}: {count} placed by lilium photo"
        if self.left_out:
            text += f"; {len(self.left_out)} template points left out until confirmed"
        where = f" in {self.review_page}" if self.review_page else " (lilium photo, review.html)"
        return text + f"; check them{where} before relying on this superimposition"


def landmark_origin(photo, facts):
    """The :class:`LandmarkOrigin` of a photo read from a folder, or None (no sources).

    Parameters
    ----------
    photo : Photo
        As read (unconfirmed template points already left out).
    facts : PreparedFacts or None
        :func:`lilium.io.prepared.read_prepared` of its folder.
    """
    if facts is None or not facts.landmark_sources:
        return None
    tags, unreviewed = {}, []
    for name in photo.landmarks_uv:
        entry = facts.landmark_sources.get(name, {})
        source, quality = entry.get("source", "manual"), entry.get("quality", "manual")
        tags[name] = f"{source}, {quality}"
        if source == "automatic" and entry.get("confirmed") is not True:
            unreviewed.append(name)
    left_out = tuple(k for k in facts.landmark_sources if k not in photo.landmarks_uv)
    return LandmarkOrigin(tags, tuple(unreviewed), left_out, facts.review_page)


def _interval_text(values, unit):
    return fmt_range(values[0], values[1], unit)


def with_automatic_priors(photo, notes, facts, skull=None, scd_from_cli=False, log=None):
    """A photo whose ``lilium photo`` priors carry ``"automatic"`` and fit the paired skull.

    Parameters
    ----------
    photo : Photo
        After :func:`lilium.casework.inputs.with_priors` (sources ``"photo.json"`` and others).
    notes : dict of str -> str
        Its report notes (``"focal prior"``, ``"SCD prior"``), updated.
    facts : PreparedFacts or None
    skull : Skull, optional
        Without one the head orientation is not converted (a note says so).
    scd_from_cli : bool
        ``--scd-mm`` was given: the iris distance is not recomputed.
    log : callable, optional
        Receives one line when the head prior is switched off.

    Returns
    -------
    photo : Photo
    notes : dict of str -> str
    """
    if facts is None or not facts.automatic_priors:
        return photo, notes
    from ..inputs import CaseWarning
    from ..photo.headpose import implausible_distance, iris_distance_mm, skull_face_frame

    priors, sources, notes = photo.priors, dict(photo.prior_sources), dict(notes)
    warnings = list(photo.warnings)
    auto = facts.automatic_priors
    if facts.iris_diameter_px and priors.focal_px is not None:
        why = implausible_distance(priors.focal_px, facts.iris_diameter_px)
        if why and sources.get("focal_px") == "exif":  # nobody stated it: not used
            priors, notes["focal prior"] = replace(priors, focal_px=None), "none (penalty off)"
            sources.pop("focal_px")
            warnings.append(
                CaseWarning(
                    "implausible_prior",
                    f"{photo.id}: EXIF focal not used: {why}; if the distance is real, give "
                    "the focal with --focal-px LO HI",
                )
            )
        elif why:
            warnings.append(
                CaseWarning(
                    "implausible_prior",
                    f"{photo.id}: {why} (focal prior from {sources.get('focal_px')}); check "
                    "--focal-px or photo.json's focal_px",
                )
            )
    for key, label, unit in (("focal_px", "focal prior", "px"), ("scd_mm", "SCD prior", "mm")):
        if key in auto and sources.get(key) == "photo.json":
            sources[key] = "automatic"
            notes[label] = f"{_interval_text(getattr(priors, key), unit)} ({auto[key]})"
    focal_elsewhere = priors.focal_px is not None and sources.get("focal_px") != "automatic"
    scd_replaceable = not scd_from_cli and sources.get("scd_mm") in (None, "automatic")
    if facts.iris_diameter_px and focal_elsewhere and scd_replaceable:
        try:
            lo = iris_distance_mm(priors.focal_px[0], facts.iris_diameter_px)[1][0]
            hi = iris_distance_mm(priors.focal_px[1], facts.iris_diameter_px)[1][1]
        except ValueError:
            pass  # an iris under 1 px gives no distance; the prior stays as it was
        else:
            priors, sources["scd_mm"] = replace(priors, scd_mm=(lo, hi)), "automatic"
            notes["SCD prior"] = (
                f"{lo:.0f}-{hi:.0f} mm (automatic: iris {facts.iris_diameter_px:.1f} px = "
                f"11.7 mm at the focal prior {_interval_text(priors.focal_px, 'px')}, "
                "camera to eyes)"
            )
    if facts.head_rotation_face2cam is not None and not priors.uses_head:
        angles = ", ".join(f"{k} {v:.0f}" for k, v in facts.head_angles_deg.items())
        found = f"automatic: face mesh{f', {angles} deg' if angles else ''}"
        if skull is None:
            notes["head prior"] = f"not used ({found}): it needs the paired skull's frame"
        else:
            try:
                skull2face, how = skull_face_frame(skull.landmarks_mm)
            except ValueError as exc:
                notes["head prior"] = f"switched off ({found}): {exc}"
                if log is not None:
                    log(f"{photo.id}: automatic head-orientation prior switched off: {exc}")
            else:
                priors = replace(
                    priors,
                    head_rotation_skull2cam=facts.head_rotation_face2cam @ skull2face,
                    head_tolerance_deg=facts.head_tolerance_deg,
                )
                sources["head_rotation"] = "automatic"
                notes["head prior"] = (
                    f"{found}; to skull2cam through the skull's {how}; tolerance "
                    f"{facts.head_tolerance_deg:g} deg"
                )
    photo = replace(photo, priors=priors, prior_sources=sources, warnings=tuple(warnings))
    return photo, notes


def check_photo_extra():
    """Raise the one-line ``ValueError`` naming ``pip install 'lilium[photo]'`` when the LiteRT
    runtime is missing (before any photo is prepared)."""
    from ..photo.runtime import check_runtime

    check_runtime()


def prepare_bare_photo(image_path, folder, view=None, sensor_width_mm=None, log=None):
    """Prepare a bare image with :func:`lilium.photo.prepare.prepare_photo` into ``folder``.

    Parameters
    ----------
    image_path : Path
        The user's image (never written to).
    folder : Path
        ``OUT/<photo>/prepared/``.
    view : str, optional
        ``--view`` for this image; default from the head's yaw.
    sensor_width_mm : float, optional
    log : callable, optional
        Receives one line: what was found and where the review page is.

    Raises
    ------
    ValueError
        When no face was found: naming the photo, saying to mark it by hand.
    """
    from ..photo.prepare import prepare_photo

    prepared = prepare_photo(image_path, folder, view=view, sensor_width_mm=sensor_width_mm)
    if not prepared.face_found:
        raise ValueError(
            f"{image_path}: --auto-landmarks found no face in this photo (a profile, a small "
            "or an occluded face); mark its landmarks by hand and give them with "
            "--photo-landmarks FILE, or run lilium photo on it and mark them in its review.html "
            f"(one is in {folder})"
        )
    if log is not None:
        log(f"{Path(image_path).stem}: lilium photo: {prepared.message}")
    return prepared
