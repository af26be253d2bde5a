"""Photo folders prepared by ``lilium photo`` (docs/method/photo.md): what it wrote beyond
docs/contract.md.

Recognising such a folder, the landmarks it placed from its face template and who placed each
landmark, and the extra facts of its ``photo.json`` (:func:`read_prepared`).
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..validation import is_real
from .jsonio import read_json

__all__ = [
    "EYE_LINE_PAIRS",
    "PREPARED_BY",
    "PreparedFacts",
    "face_only_mask",
    "landmark_qualities",
    "read_prepared",
    "written_by_lilium_photo",
]


#: ``photo.json``'s ``"prepared_by"`` in a folder ``lilium photo`` wrote.
PREPARED_BY = "lilium photo"


def written_by_lilium_photo(meta):
    """Whether a ``photo.json`` object was written by ``lilium photo`` (this or an older one,
    recognised by its automatic ``landmark_sources`` and ``priors.sources``): its
    ``face_mask.png`` is then a head mask, down to the neck (docs/method/photo.md)."""
    if not isinstance(meta, dict):
        return False
    if meta.get("prepared_by") == PREPARED_BY:
        return True
    priors, sources = meta.get("priors"), meta.get("landmark_sources")
    return (
        isinstance(priors, dict)
        and priors.get("source") == "automatic"
        and isinstance(sources, dict)
        and isinstance(priors.get("sources"), dict)
    )


#: The landmark pairs whose line is the eye-corner line of :func:`face_only_mask`, first found.
EYE_LINE_PAIRS = (("exocanthion_r", "exocanthion_l"), ("endocanthion_r", "endocanthion_l"))


def face_only_mask(mask, landmarks, where):
    """The mask a case uses when ``lilium photo`` could find only the face
    (``"face_mask_is_head": false``, warning ``head_mask_face_only``; docs/method/photo.md).

    Such a mask is the face outline without hair, ears or the vault, so the skull above the
    brows would read as outside the head. The rule: every pixel on the vault's side of the
    eye-corner line (through exocanthion_r and exocanthion_l, else the endocanthia) counts as
    inside, so P_skof, the outside fraction, ``skull_outside_head`` and the report's outside
    figure measure only the face below the eyes. The vault's side is the one away from the
    mask's centroid (the face outline runs from the upper forehead to the chin, so its centroid
    lies below the eyes). Without an eye-corner pair there is no line, and the mask is not used
    (those measures are switched off).

    Parameters
    ----------
    mask : ndarray of shape (H, W), bool
        ``face_mask.png``.
    landmarks : dict of str -> ndarray of shape (2,)
        The photo's facial landmarks, uv pixels.
    where : str
        The folder, for the sentence.

    Returns
    -------
    mask : ndarray of shape (H, W), bool, or None
    warning : CaseWarning
        ``head_mask_face_only``, saying what was done.
    """
    from ..inputs import CaseWarning

    pair = next((p for p in EYE_LINE_PAIRS if p[0] in landmarks and p[1] in landmarks), None)
    rows, cols = np.nonzero(mask)
    if pair is None or len(rows) == 0:
        return None, CaseWarning(
            "head_mask_face_only",
            f"{where}: face_mask.png is the face outline alone (photo.json face_mask_is_head "
            "false) and no eye corners mark where the vault starts: the mask is not used (no "
            "P_skof, no skull-outside-the-head measures); draw the head's outline in review.html",
        )
    right, left = (np.asarray(landmarks[name], float) for name in pair)
    across = left - right
    normal = np.array([-across[1], across[0]]) / max(float(np.linalg.norm(across)), 1e-9)
    centre = (right + left) / 2
    if (np.array([cols.mean(), rows.mean()]) - centre) @ normal < 0:
        normal = -normal  # points down the face
    h, w = mask.shape
    vv, uu = np.mgrid[0:h, 0:w]
    vault = (uu - centre[0]) * normal[0] + (vv - centre[1]) * normal[1] < 0
    return np.asarray(mask, bool) | vault, CaseWarning(
        "head_mask_face_only",
        f"{where}: face_mask.png is the face outline alone (photo.json face_mask_is_head false): "
        f"the skull above the eye-corner line ({pair[0]}-{pair[1]}) is not counted as outside "
        "the head; draw the head's outline in review.html for the full check",
    )


def _without_unconfirmed_templates(landmarks, sources):
    """Drop the landmarks ``lilium photo`` placed from its face template (docs/method/photo.md).

    The rule: a landmark whose ``landmark_sources`` entry says ``"quality": "template"`` is
    left out unless the entry also says ``"confirmed": true`` (the review page sets it).
    """
    if not isinstance(sources, dict):
        return landmarks
    return {
        name: uv
        for name, uv in landmarks.items()
        if not (
            isinstance(sources.get(name), dict)
            and sources[name].get("quality") == "template"
            and sources[name].get("confirmed") is not True
        )
    }


def landmark_qualities(sources, landmarks):
    """Who placed each landmark (:attr:`lilium.inputs.Photo.landmark_sources`,
    :attr:`lilium.inputs.Skull.landmark_sources`).

    An entry ``{"source": "automatic", "quality": ...}`` (a photo's ``"tracked"`` or
    ``"template"``, a skull's ``"located"`` or ``"template"``) keeps its quality; a reviewed or
    confirmed point, or one without an entry, is ``manual``.
    """
    out = {}
    for name in landmarks:
        entry = sources.get(name) if isinstance(sources, dict) else None
        quality = entry.get("quality") if isinstance(entry, dict) else None
        automatic = isinstance(entry, dict) and entry.get("source") == "automatic"
        reviewed = isinstance(entry, dict) and entry.get("confirmed") is True
        tagged = automatic and not reviewed and quality in ("tracked", "template", "located")
        out[name] = quality if tagged else "manual"
    return out


@dataclass(frozen=True)
class PreparedFacts:
    """What ``lilium photo`` wrote into a photo folder beyond docs/contract.md
    (docs/method/photo.md).

    Attributes
    ----------
    landmark_sources : dict of str -> dict
        ``photo.json``'s ``landmark_sources`` (every landmark written, used or not): ``{name:
        {"source": "automatic" | "reviewed", "quality": "tracked" | "template" | "manual",
        "confirmed": bool}}``.
    automatic_priors : dict of str -> str
        The priors ``lilium photo`` found (``focal_px``, ``scd_mm``, ``head_rotation_face2cam``)
        and where from (its ``priors.sources`` text), when ``priors.source`` is
        ``"automatic"``; a prior the user added to ``photo.json`` without a ``sources`` entry
        is not in it.
    head_rotation_face2cam : ndarray of shape (3, 3) or None
        The face frame in the camera frame (:mod:`lilium.photo.headpose`).
    head_tolerance_deg : float or None
        ``priors.head_tolerance_face_deg``.
    head_angles_deg : dict of str -> float
        ``yaw``, ``pitch``, ``roll`` (degrees), for the report.
    iris_diameter_px : float or None
        Mean iris diameter (pixels), for the distance prior once a focal is known.
    review_page : Path or None
        The folder's ``review.html``.
    """

    landmark_sources: dict
    automatic_priors: dict
    head_rotation_face2cam: np.ndarray | None = None
    head_tolerance_deg: float | None = None
    head_angles_deg: dict = field(default_factory=dict)
    iris_diameter_px: float | None = None
    review_page: Path | None = None


def read_prepared(folder):
    """The facts of a photo folder written by ``lilium photo`` (:class:`PreparedFacts`).

    Parameters
    ----------
    folder : str or Path
        A photo folder (read it with :func:`lilium.casework.build.read_photo` too: this reads
        only the extras).

    Returns
    -------
    PreparedFacts or None
        None for a folder without ``landmark_sources`` or automatic priors (a hand-made one).

    Raises
    ------
    ValueError
        Naming ``photo.json`` and the field, for an automatic head orientation that is not a
        rotation, a tolerance outside (0, 180] degrees or an iris diameter that is not positive.
    """
    from ..geometry.rotations import check_rotation

    meta_path = Path(folder) / "photo.json"
    meta = read_json(meta_path)
    sources = meta.get("landmark_sources") if isinstance(meta, dict) else None
    priors = meta.get("priors") if isinstance(meta, dict) else None
    sources = sources if isinstance(sources, dict) else {}
    sources = {k: v for k, v in sources.items() if isinstance(v, dict)}
    automatic = {}
    if isinstance(priors, dict) and priors.get("source") == "automatic":
        texts = priors.get("sources") if isinstance(priors.get("sources"), dict) else {}
        automatic = {k: str(texts[k]) for k in texts if k in priors}
    else:
        priors = {}
    if not sources and not automatic:
        return None
    face2cam = tolerance = iris = None
    if "head_rotation_face2cam" in automatic:
        try:
            face2cam = check_rotation(
                priors["head_rotation_face2cam"], name="priors.head_rotation_face2cam"
            )
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{meta_path}: {exc}") from None
        tolerance = priors.get("head_tolerance_face_deg", 15.0)
        if not (is_real(tolerance) and 0 < tolerance <= 180):
            raise ValueError(
                f"{meta_path}: priors.head_tolerance_face_deg must be in (0, 180] degrees"
            )
        tolerance = float(tolerance)
    if priors.get("iris_diameter_px") is not None:
        iris = priors["iris_diameter_px"]
        if not (is_real(iris) and np.isfinite(iris) and iris > 0):
            raise ValueError(f"{meta_path}: priors.iris_diameter_px must be a positive number")
        iris = float(iris)
    angles = priors.get("head_angles_deg") if face2cam is not None else None
    angles = {k: float(v) for k, v in angles.items()} if isinstance(angles, dict) else {}
    review = Path(folder) / "review.html"
    return PreparedFacts(
        sources,
        automatic,
        face2cam,
        tolerance,
        angles,
        iris,
        review if review.is_file() else None,
    )
