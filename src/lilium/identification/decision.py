"""One identification decision: the terms of one or more SFO results, their calibrated log10 LR
and the conclusion, capped by the material and by any inconsistency.

Which calibration model a decision uses: ``<method>/<variant>/frontal`` or ``/lateral`` for
one photo, ``lilium-joint/<variant>/joint`` for a joint SFO. Separate SFOs of one frontal and
one lateral photo add the two photos' log10 LRs (each from its own view's model) and calibrate
the sum with ``<method>/<variant>/pair_sum`` (a slope and an offset fitted on same- and
different-person pairs instead of assuming the photos independent, which they are not: they
share the soft tissue; Lilium's slope came out above 1, each photo's own model being
conservative; without that model, the plain sum, and the note says so). Measured on 52
generated subjects (docs/decisions/0014-identification-several-photos.md): Cllr 0.242
against 0.265 for the plain sum and 0.417 for one model of both photos with their soft tissue
shared. Any other two or more photos use ``<method>/<variant>/pair`` (that shared-soft-tissue
model, fitted on a frontal and a lateral photo; the decision's note says so). Without a model
for the decision the LR is not given and the conclusion is "undetermined", naming the model
missing and how to fit it.

Maths and rules only: the calibration models and the cohort are passed in (the workflow reads
them, :mod:`lilium.casework.identify`).
"""

from dataclasses import dataclass, field

from ..methods.pairs import correspondences
from ..methods.prior_checks import perspective_conflict, prior_conflicts
from ..softtissue.landmarks import MANDIBLE_LANDMARKS
from .calibration import VIEWS_LOG10_LR
from .conclusion import EXAMINER_CAMERA, UNREVIEWED_SKULL, conclude, material_caps
from .score import nll_score, terms_and_overlaps, worst_landmark_of


@dataclass(frozen=True)
class Identification:
    """The identification of one decision, as ``result.json``'s ``"identification"`` holds it.

    Attributes
    ----------
    calibration : dict
        ``model`` (the key, ``" -> <pair_sum key>"`` appended when the views' sum is
        calibrated), ``file``, ``provenance``, and ``views_model`` for a frontal and a lateral
        photo taken together.
    score : float or None
        The terms' negative log-likelihood (None when an SFO failed).
    terms : dict of str -> float or None, or None
    log10_lr : float or None
    conclusion, conclusion_uncapped : str
        The verbal scale's label after and before the caps.
    caps : dict of str -> str
        The caps that apply (code -> sentence); ``outside_calibration`` first when present.
    inconsistent : dict of str -> str
        Consistency failures (``view_mismatch``, ``skull_outside_head``, ...).
    note : str
    worst_landmark : dict or None
        ``{"name", "misfit"}``: the photo landmark that fits worst and its misfit per
        coordinate (one misplaced landmark lowers the LR: the examiner is told which to
        check); absent from :meth:`to_dict` for a failed SFO.
    views_log10_lr : list of float or None, optional
        A frontal and a lateral photo's own log10 LRs, when the decision adds them.
    """

    calibration: dict
    score: float | None
    terms: dict | None
    log10_lr: float | None
    conclusion: str
    conclusion_uncapped: str
    caps: dict
    inconsistent: dict
    note: str
    worst_landmark: dict | None = None
    views_log10_lr: list | None = field(default=None)

    @property
    def failed(self):
        """Whether an SFO behind the decision failed (no camera: nothing to conclude)."""
        return self.terms is None

    def to_dict(self):
        """The JSON record (``result.json``'s ``"identification"``)."""
        out = {"calibration": self.calibration}
        if self.views_log10_lr is not None:
            out["views_log10_lr"] = self.views_log10_lr
        out |= {
            "score": self.score,
            "terms": self.terms,
            "log10_lr": self.log10_lr,
            "conclusion": self.conclusion,
            "conclusion_uncapped": self.conclusion_uncapped,
            "caps": self.caps,
            "inconsistent": self.inconsistent,
        }
        if not self.failed:
            out["worst_landmark"] = self.worst_landmark
        return out | {"note": self.note}

    @classmethod
    def from_dict(cls, record):
        """The decision of a record written by :meth:`to_dict` (a stored ``result.json``)."""
        names = cls.__dataclass_fields__
        return cls(**{k: v for k, v in record.items() if k in names})


def _group(photo):
    return "frontal" if photo.view == "frontal" else "lateral"


def adds_views(photos, joint=False):
    """Whether the decision adds a frontal and a lateral photo's LRs (module docstring)."""
    return not joint and sorted(_group(p) for p in photos) == ["frontal", "lateral"]


def decision_key(method, variant, photos, joint=False):
    """The calibration key of a decision (module docstring); for a frontal and a lateral
    photo taken separately, the two keys joined by ``+``."""
    if joint:
        return f"lilium-joint/{variant or ''}/joint"
    if adds_views(photos):
        return " + ".join(f"{method}/{variant or ''}/{_group(p)}" for p in photos)
    if len(photos) > 1:
        return f"{method}/{variant or ''}/pair"
    return f"{method}/{variant or ''}/{_group(photos[0])}"


def outside_calibration(model, terms, key):
    """``{"outside_calibration": sentence}`` when a feature of ``terms`` lies outside the range
    the model ``key`` was fitted on (:meth:`Calibration.outside`), else ``{}``: the sentence
    names the first such feature, its value and the range, and how many more there are."""
    outside = model.outside(terms)
    if not outside:
        return {}
    name, value, (lo, hi) = outside[0]
    more = f" (and {len(outside) - 1} more feature(s))" if len(outside) > 1 else ""
    return {"outside_calibration": (
        f"feature {name} = {value:.3g} lies outside the range [{lo:.3g}, {hi:.3g}] the model "
        f"{key} was fitted on{more}: its LR would be an extrapolation, so it gives no support"
    )}


def skull_outside_head(photos, overlaps):
    """The sentence of ``skull_outside_head``, or None: the photos where skull pixels lie
    beyond the head mask's edge band (``overlaps``: per photo its
    :class:`~lilium.identification.score.HeadOverlap` or None,
    :meth:`~lilium.identification.score.HeadOverlap.beyond`), how many and how far."""
    found = []
    for photo, overlap in zip(photos, overlaps, strict=True):
        counts = None if overlap is None else overlap.beyond()
        if counts is None or counts[0] == 0:
            continue
        beyond, skull_px, band = counts
        found.append(
            f"{photo.id}: {beyond} of the skull's {skull_px} pixels ({100 * beyond / skull_px:.2g}"
            f" %) lie more than {band:.1f} px outside the head mask"
        )
    return "; ".join(found) or None


def _inconsistent(photos, results, overlaps, facial_landmarks_mm):
    out = {}
    outside = skull_outside_head(photos, overlaps)
    if outside:
        out["skull_outside_head"] = outside
    conflicts, far = [], {}
    for photo, result in zip(photos, results, strict=True):
        for w in result.warnings:
            if w.code == "view_mismatch":
                out["view_mismatch"] = w.message
        facial = result.facial_landmarks_mm or facial_landmarks_mm
        conflicts.append(perspective_conflict(photo, result.camera, facial))
        for code, sentence in prior_conflicts(photo, result.camera, facial).items():
            far.setdefault(code, []).append(f"{photo.id}: {sentence}")
    if any(conflicts):
        out["perspective_mismatch"] = "; ".join(c for c in conflicts if c)
    out.update({code: "; ".join(sentences) for code, sentences in far.items()})
    return out


def _stored(photo, result, calibrations):
    """The photo's own decision already in its result (``extra["identification"]``, written
    with the same calibration file and the photo's single-photo model), or None: what
    ``identify(skull, [photo], [result], calibrations, cohort)`` would give, not computed a
    second time."""
    record = (getattr(result, "extra", None) or {}).get("identification")
    if not record:
        return None
    calibration = record.get("calibration") or {}
    same_file = calibration.get("file") == str(calibrations.path)
    same_model = calibration.get("model") == decision_key(
        result.method, result.variant, [photo], False
    )
    return Identification.from_dict(record) if same_file and same_model else None


def _caps(skull, photos):
    """The material's caps of a decision (:func:`~.conclusion.material_caps`)."""
    pairs = []
    for photo in photos:
        try:
            pairs.append(len(correspondences(skull, photo).cranial_names))
        except ValueError:
            pairs.append(0)
    used = [
        f for photo in photos for f in photo.landmarks_uv
        if photo.landmark_sources.get(f, "manual") != "manual"
    ]
    caps = material_caps(
        has_mandible=any(n in skull.landmarks_mm for n in MANDIBLE_LANDMARKS),
        photos=len(photos),
        unreviewed_automatic=bool(used),
        pairs=min(pairs),
    )
    if any(source != "manual" for source in skull.landmark_sources.values()):
        caps = {"unreviewed_skull_landmarks": UNREVIEWED_SKULL} | caps
    return caps


def identify(skull, photos, results, calibrations, cohort, facial_landmarks_mm=None, joint=False):
    """The identification of one decision.

    Parameters
    ----------
    skull : Skull
    photos : sequence of Photo
    results : sequence of SfoResult
        One per photo (a joint SFO's per-photo results, or separate SFOs).
    calibrations : object
        The calibration models: ``get(key)`` -> :class:`~.calibration.Calibration` or None,
        and ``path`` (named in the record); :class:`lilium.casework.identify.Calibrations`.
    cohort : Cohort
        The cohort of the centred cohort terms (:mod:`~lilium.identification.cohort`), the one
        the calibration was fitted with.
    facial_landmarks_mm : dict, optional
        The soft tissue of the decision's terms (default: the first frontal photo's result's,
        else the first result's). A frontal and a lateral photo's separate SFOs each give their
        LR from their own result's soft tissue.
    joint : bool
        The results are one joint SFO's.

    Returns
    -------
    Identification
    """
    method, variant = results[0].method, results[0].variant
    key = decision_key(method, variant, photos, joint)
    caps = _caps(skull, photos)
    if any(r.camera_source == "examiner" for r in results):
        caps = {"examiner_camera": EXAMINER_CAMERA} | caps
    calibration = {"model": key, "file": str(calibrations.path)}
    if not all(results):
        verdict = conclude(None, caps)
        return Identification(
            calibration, None, None, None, verdict.label, verdict.uncapped, caps, {},
            "no camera: the SFO failed, so nothing can be concluded",
        )
    # Several photos' terms share one soft tissue: the first frontal photo's SFO's, as the
    # calibration's pairs take it (lilium.experiments.calibrate), whatever the photos' order.
    frontal = next(
        (r for p, r in zip(photos, results, strict=True) if _group(p) == "frontal"), results[0]
    )
    facial = facial_landmarks_mm or frontal.facial_landmarks_mm
    # The built-in depth table, whatever the SFO used: the calibration was fitted on terms
    # computed with it, and a user's table would move the terms off that calibration.
    terms, overlaps = terms_and_overlaps(
        skull, photos, [r.camera for r in results], facial, cohort=cohort
    )
    model = calibrations.get(key)
    note, views = "", None
    if adds_views(photos, joint):
        # Each photo's LR from its own SFO's soft tissue, as the views' models were fitted.
        parts = [
            _stored(p, r, calibrations) or identify(skull, [p], [r], calibrations, cohort)
            for p, r in zip(photos, results, strict=True)
        ]
        views = [part.log10_lr for part in parts]
        views_key = f"{method}/{variant or ''}/pair_sum"
        lr, note = _views_lr(views, [p.id for p in photos], calibrations, views_key, calibration)
        # Outside the calibration when a photo's features are (the sum of two LRs is not
        # range-checked: lilium.identification.calibration.fit, keep_ranges).
        outside = [f"{p.id}: {part.caps['outside_calibration']}"
                   for p, part in zip(photos, parts, strict=True)
                   if "outside_calibration" in part.caps]
        if outside:
            caps = {"outside_calibration": "; ".join(outside)} | caps
        note = "; ".join([part.note for part in parts if part.note] + [note] * bool(note))
        calibration.setdefault("provenance", parts[0].calibration.get("provenance"))
    elif model is None:
        lr = None
        note = (
            f"no calibration for {key} in {calibrations.path}: fit one with lilium calibrate "
            "DB on an experiment that ran this method and variant, and give it with "
            "--calibration"
        )
    else:
        lr = float(model.log10_lr([terms])[0])
        caps = outside_calibration(model, terms, key) | caps
        calibration["provenance"] = model.provenance
        if len(photos) > 1 and not joint:
            note = "calibrated on one frontal and one lateral photo; these photos differ"
    worst, misfit = worst_landmark_of(skull, photos, [r.camera for r in results])
    inconsistent = _inconsistent(photos, results, overlaps, facial)
    verdict = conclude(lr, caps, inconsistent)
    return Identification(
        calibration,
        nll_score(terms),
        {k: (None if v is None else float(v)) for k, v in terms.items()},
        lr,
        verdict.label,
        verdict.uncapped,
        caps,
        inconsistent,
        note,
        worst_landmark=None if worst is None else {"name": worst, "misfit": misfit},
        views_log10_lr=views,
    )


def _views_lr(lrs, photo_ids, calibrations, key, calibration):
    """The log10 LR of a frontal and a lateral photo's log10 LRs ``lrs`` (None if either is
    missing; ``photo_ids`` in the same order): their sum calibrated by the model ``key``, or
    the plain sum without one; and the note that says which. Names the model in the record's
    ``calibration``."""
    model = calibrations.get(key)
    calibration["views_model"] = None if model is None else key
    if None in lrs:
        return None, ""
    added = float(sum(lrs))
    if model is None:
        return added, (
            f"the frontal and the lateral photo's log10 LRs added, as if independent (no {key} "
            f"model in {calibrations.path}; lilium calibrate DB fits one)"
        )
    calibration["provenance"] = model.provenance
    calibration["model"] += f" -> {key}"
    lr = float(model.log10_lr([{VIEWS_LOG10_LR: added}])[0])
    parts = ", ".join(f"{i} {v:+.2f}" for i, v in zip(photo_ids, lrs, strict=True))
    return lr, f"the photos' log10 LRs ({parts}) added and calibrated as one decision ({key})"
