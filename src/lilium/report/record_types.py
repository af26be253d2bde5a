"""The plain record types of a case report: numbers, strings and encoded pictures, no markup.

:class:`SfoRecord` is one SFO as the page shows it (:func:`lilium.report.records.sfo_record`
makes it); :class:`ReportRecord` is a page. Image coordinates are ``uv`` = (column, row) pixels
of the full photo; vectors are tuples of floats, matrices tuples of row tuples.
"""

from dataclasses import dataclass

from ..io.provenance import InputFile
from .pictures import Pictures, SkullViewPicture


@dataclass(frozen=True)
class LandmarkRow:
    """One facial landmark: marked in the photo, estimated by the SFO.

    Attributes
    ----------
    name : str
    photo_uv : tuple of 2 float
        Marked in the photo (pixels).
    estimate_uv : tuple of 2 float
        The estimated 3D facial landmark projected with the camera; NaN when the SFO failed.
    error_px : float
        Distance between the two (NaN when the SFO failed).
    """

    name: str
    photo_uv: tuple
    estimate_uv: tuple
    error_px: float


@dataclass(frozen=True)
class CameraFacts:
    """The camera of a successful SFO in the units a practitioner reads.

    Attributes
    ----------
    focal_px : float
    principal_point_px : tuple of 2 float
    scd_mm : float
        Subject-to-camera distance to ``scd_point``.
    scd_point : str
        ``"facial nasion"`` or ``"centroid of the facial landmarks"``.
    rotation_angle_deg : float
        Angle of the rotation skull -> camera.
    rotation_axis : tuple of 3 float
        Its unit axis (skull frame); (0, 0, 1) for no rotation.
    euler_xyz_deg : tuple of 3 float
        Extrinsic x, y, z Euler angles.
    translation_mm : tuple of 3 float
    skull2cam : tuple of 4 tuples of 4 float
        The 4x4 rigid transform (rotation, translation in mm).
    head_deviation_deg : float or None
        Angle to the photo's a-priori head orientation; None without that prior.
    focal_prior_px, scd_prior_mm : tuple (low, high) or None
        The photo's priors.
    head_tolerance_deg : float or None
        Tolerance of the head-orientation prior.
    """

    focal_px: float
    principal_point_px: tuple
    scd_mm: float
    scd_point: str
    rotation_angle_deg: float
    rotation_axis: tuple
    euler_xyz_deg: tuple
    translation_mm: tuple
    skull2cam: tuple
    head_deviation_deg: float | None = None
    focal_prior_px: tuple | None = None
    scd_prior_mm: tuple | None = None
    head_tolerance_deg: float | None = None

    @property
    def focal_in_prior(self):
        """Whether the focal length lies in its prior (None without one)."""
        return None if self.focal_prior_px is None else _within(self.focal_px, self.focal_prior_px)

    @property
    def scd_in_prior(self):
        """Whether the distance lies in its prior (None without one)."""
        return None if self.scd_prior_mm is None else _within(self.scd_mm, self.scd_prior_mm)


@dataclass(frozen=True)
class Summary:
    """The summary-table row of one SFO (None where not defined).

    Attributes
    ----------
    status : str
        ``"ok"``, ``"implausible"`` (a camera that puts skull pixels beyond the head mask's edge
        band, whatever the method: the identification's ``skull_outside_head``) or
        ``"failed: ..."``.
    focal_px, scd_mm : float or None
    mean_error_px, mean_error_mm : float or None
        ``landmark_error`` of the result (docs/checks.md): comparable across methods.
    fitness : float
        The method's own score (lower is better), not comparable across methods.
    score_label : str
        What that score is (``"mean landmark error, px"``, ``"fitness"``).
    outside_pct : float or None
    implausible : bool or None
        Whether skull pixels lie beyond the head mask's edge band
        (:func:`lilium.identification.score.skull_beyond_head`; None: failed, or no mask).
        ``outside_pct`` counts every skull pixel outside the mask.
    warnings : tuple of (str, str)
        The result's warnings, ``(code, message)``.
    seconds : float
    """

    status: str
    focal_px: float | None
    scd_mm: float | None
    mean_error_px: float | None
    fitness: float
    outside_pct: float | None
    seconds: float
    mean_error_mm: float | None = None
    score_label: str = "fitness"
    implausible: bool | None = None
    warnings: tuple = ()


@dataclass(frozen=True)
class SfoRecord:
    """Everything the report shows of one SFO.

    Attributes
    ----------
    index : int
        1-based position on the page.
    skull_id, photo_id, view : str
    image_size_wh : tuple (width, height), int
    method : str
    method_label : str
        Method and variant (``"lilium skof+pll"``).
    ok : bool
        Whether the SFO found a camera.
    error : str
        Why it failed ("" on success).
    summary : Summary
    landmarks : tuple of LandmarkRow
    mean_error_px : float or None
        Over ``landmarks``; None when any error is undefined.
    camera : CameraFacts or None
    notes : tuple of (str, str)
    terms : tuple of (str, float or None)
        Fitness terms (None = switched off).
    fitness : float
    outside : ImplausibleSFO or None
        Skull pixels outside the face mask (exact skull raster at photo resolution); None when
        the SFO failed or the photo has no face mask.
    history : tuple of float or None
        Best fitness per generation.
    seed : int or None
    seconds : float
    run_extra : tuple of (str, str)
        Run facts (generations, evaluations, ...).
    warnings : tuple of (str, str)
        docs/checks.md warnings of the result, ``(code, message)``.
    priors : tuple of (str, str, str)
        Each prior: name, value (text) and where it came from.
    inputs : tuple of InputFile
    outputs : tuple of (str, str)
        Label and link (relative to the report).
    pictures : Pictures
    skull_views : tuple of SkullViewPicture
        The skull alone, frontal and lateral, with its cranial landmarks (shared by the SFOs
        of one skull on a page); empty when the landmarks cannot orient the skull.
    cranial_numbers : tuple of (str, int)
        Cranial landmark and the number of its facial counterpart in ``landmarks`` (1-based),
        for the landmarks this SFO used.
    terms_off : tuple of (str, str)
        Terms switched off because their inputs are missing, and why (``SfoResult.terms_off``).
    landmarks_note : str
        Where the facial landmarks came from ("" for landmarks placed by hand).
    landmarks_unreviewed : bool
        Some are automatic and unconfirmed (``lilium photo``): said in the summary too.
    landmark_tags : tuple of (str, str)
        Facial landmark and its source (``"automatic, tracked"``); empty for hand-placed ones.
    review_href : str
        The review page, relative to the report ("" when it lies elsewhere).
    """

    index: int
    skull_id: str
    photo_id: str
    view: str
    image_size_wh: tuple
    method: str
    method_label: str
    ok: bool
    error: str
    summary: Summary
    landmarks: tuple
    mean_error_px: float | None
    camera: CameraFacts | None
    notes: tuple
    terms: tuple
    fitness: float
    outside: object
    history: tuple | None
    seed: int | None
    seconds: float
    run_extra: tuple
    inputs: tuple
    outputs: tuple
    pictures: Pictures
    skull_views: tuple = ()
    cranial_numbers: tuple = ()
    warnings: tuple = ()
    priors: tuple = ()
    terms_off: tuple = ()
    landmarks_note: str = ""
    landmarks_unreviewed: bool = False
    landmark_tags: tuple = ()
    review_href: str = ""


@dataclass(frozen=True)
class JointLandmarkRow:
    """One estimated 3D facial landmark of a joint SFO's shared soft tissue.

    Attributes
    ----------
    name : str
        Facial landmark.
    position_mm : tuple of 3 float
        Skull frame, millimetres.
    photos : tuple of str
        The photos that see it (used it in their fitness).
    """

    name: str
    position_mm: tuple
    photos: tuple


@dataclass(frozen=True)
class JointRecord:
    """A joint SFO: one soft tissue shared by several photos (docs/method/joint.md).

    Attributes
    ----------
    method_label : str
    skull_id : str
    photo_ids : tuple of str
    fitness : float
        The joint fitness (sum over the photos).
    photo_fitness : tuple of float
        Each photo's own fitness, in ``photo_ids`` order.
    ok : bool
        Every photo has a camera.
    landmarks : tuple of JointLandmarkRow
    weights : tuple of float
        Each photo's weight in the joint fitness (:mod:`lilium.methods.joint`).
    """

    method_label: str
    skull_id: str
    photo_ids: tuple
    fitness: float
    photo_fitness: tuple
    ok: bool
    landmarks: tuple
    weights: tuple = ()


@dataclass(frozen=True)
class ReportRecord:
    """A report page: its SFOs and the provenance shared by all of them.

    Attributes
    ----------
    title : str
    date : str
        ISO date-time (UTC).
    command : str or None
        The command line as typed.
    skull_ids : tuple of str
    versions : tuple of (str, str)
        Python, platform and package versions.
    sfos : tuple of SfoRecord
    joints : tuple of JointRecord
        The joint SFOs (docs/method/joint.md) whose photos the page shows; empty without any.
    decisions : tuple of (str, str, dict)
        The identifications (docs/method/identification.md), shown first: a label, the anchor of the
        section
        that shows it ("" for none) and the ``"identification"`` record; every photo's SFO, every
        joint SFO and, with several photos, their separate SFOs taken together.
    request : str or None
        The run's request as JSON (:meth:`lilium.casework.request.CaseRequest.to_dict`).
    """

    title: str
    date: str
    command: str | None
    skull_ids: tuple
    versions: tuple
    sfos: tuple
    joints: tuple = ()
    decisions: tuple = ()
    request: str | None = None

    @property
    def lilium_version(self):
        """The version of Lilium that made the page."""
        return dict(self.versions).get("lilium", "unknown")


def _within(value, bounds):
    lo, hi = bounds
    return bool(lo <= value <= hi)


__all__ = [
    "CameraFacts",
    "InputFile",
    "LandmarkRow",
    "Pictures",
    "ReportRecord",
    "SfoRecord",
    "SkullViewPicture",
    "Summary",
]
