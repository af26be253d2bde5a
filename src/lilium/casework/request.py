"""What a user asks Lilium to run: one frozen request, built once (from the command line by
:func:`lilium.cli.options.case_request`, or by a script) and the only thing the case, the
lineup and the single SFO take.

A request names files; it reads none. The workflow reads and checks them once into typed
inputs (:func:`~lilium.casework.inputs.load_skull`, :func:`~lilium.casework.inputs.load_photos`),
then runs. :meth:`CaseRequest.to_dict` is its provenance: the report shows it beside the
command line as typed.

Example
-------
>>> from pathlib import Path
>>> request = CaseRequest(
...     skull=SkullSource(Path("skull.ply"), landmarks=Path("skull.fcsv")),
...     photos=(PhotoSource(Path("front.jpg"), landmarks=Path("front.csv")),),
...     out=Path("case"),
... )
>>> request.to_dict()["photos"][0]["landmarks"]
'front.csv'
"""

import math
from dataclasses import dataclass, field, fields
from pathlib import Path

from ..methods.options import SfoOptions
from ..methods.registry import check_joint_methods, check_method
from ..validation import check_prior


@dataclass(frozen=True)
class SkullSource:
    """The skull as given: a subject folder, or a mesh with its cranial landmark file.

    Attributes
    ----------
    path : Path
        Subject folder or skull mesh (PLY/OBJ/STL, mm).
    landmarks : Path or None
        Cranial landmark file (default: the folder's own, or a sidecar of the mesh).
    axes : Path or None
        Soft-tissue axes file to use instead of the skull's own.
    """

    path: Path
    landmarks: Path | None = None
    axes: Path | None = None


@dataclass(frozen=True)
class PhotoSource:
    """One photo as given: a photo folder, or an image with the files named for it.

    Attributes
    ----------
    path : Path
        Photo folder or PNG/JPEG image.
    landmarks, mask, face_curve : Path or None
        An image's facial landmark file, face mask and facial curve (default: sidecars
        beside the image); None for a folder, which holds its own.
    view : str or None
        An image's view (default frontal, or the head's yaw with automatic landmarks); for
        a folder, the view the user said all photos have (checked against its
        ``photo.json``), else None.
    camera : Path or None
        A camera to score for this photo besides (``lilium case``) or instead of (``lilium
        sfo``) the search: an examiner's ``camera.json`` (``workbench.html``'s Save) or a
        ``result.json`` (``--camera``).
    """

    path: Path
    landmarks: Path | None = None
    mask: Path | None = None
    face_curve: Path | None = None
    view: str | None = None
    camera: Path | None = None


@dataclass(frozen=True)
class PriorOverrides:
    """Camera priors given for every photo of the request, checked when made.

    Attributes
    ----------
    focal_px, scd_mm : (float, float) or None
        Win over each photo's ``photo.json`` and EXIF; checked intervals
        (:func:`~lilium.validation.check_prior`, named as the options ``--focal-px`` and
        ``--scd-mm``).
    use_exif : bool
        Take a focal prior from the image's EXIF when there is no other.
    sensor_width_mm : float or None
        The camera's sensor width, for the EXIF focal prior.
    """

    focal_px: tuple[float, float] | None = None
    scd_mm: tuple[float, float] | None = None
    use_exif: bool = True
    sensor_width_mm: float | None = None

    def __post_init__(self):
        for key, option in (("focal_px", "--focal-px"), ("scd_mm", "--scd-mm")):
            value = getattr(self, key)
            if value is not None:
                checked = check_prior(value, key, f"command line: {option}")
                object.__setattr__(self, key, checked)


@dataclass(frozen=True)
class Candidate:
    """A lineup's candidate: a name and the photos of that person."""

    name: str
    photos: tuple[PhotoSource, ...]


@dataclass(frozen=True)
class CaseRequest:
    """Everything one run needs: the skull, the photos (or a lineup's candidates), the
    methods and their options, the priors given, and where to write.

    Attributes
    ----------
    skull : SkullSource
    out : Path
        Output folder.
    photos : tuple of PhotoSource
        A case's (or a single SFO's) photos, all of one person.
    candidates : tuple of Candidate
        A lineup's candidates (instead of ``photos``).
    methods : tuple of str
        Keys of :data:`lilium.methods.METHODS`; a lineup ranks by the first.
    options : SfoOptions
        Variant and DE settings.
    seed : int
    priors : PriorOverrides
    depth_table : Path or None
        CSV depth table instead of the built-in one.
    calibration : Path or None
        Identification calibration file (default: the shipped one).
    auto_landmarks : bool
        Prepare each image without a landmark file with ``lilium photo``.
    joint : bool
        Run Lilium as one joint SFO of all the photos.
    overlay : bool
        Write the overlay pictures of a single SFO.
    title : str or None
        The report's title.
    progress : bool
        Show a progress bar (lineup).
    command : str or None
        The command line as typed, for the provenance only.

    Raises
    ------
    ValueError
        When made, before any file is read: an unknown method or variant, ``joint`` with
        fewer than two photos or no method with a joint SFO.
    """

    skull: SkullSource
    out: Path
    photos: tuple[PhotoSource, ...] = ()
    candidates: tuple[Candidate, ...] = ()
    methods: tuple[str, ...] = ("lilium",)
    options: SfoOptions = field(default_factory=SfoOptions)
    seed: int = 0
    priors: PriorOverrides = field(default_factory=PriorOverrides)
    depth_table: Path | None = None
    calibration: Path | None = None
    auto_landmarks: bool = False
    joint: bool = False
    overlay: bool = True
    title: str | None = None
    progress: bool = True
    command: str | None = None

    def __post_init__(self):
        for method in self.methods:
            check_method(method, self.options.variant)
        if self.joint:
            check_joint_methods(self.methods, len(self.photos))

    def to_dict(self):
        """The request as plain JSON values (paths as strings; the SFO options as the
        variant and the DE settings, the rest being the defaults). Without ``command``: the
        report shows the command line in a row of its own."""
        skip = ("options", "command")
        out = {f.name: _plain(getattr(self, f.name)) for f in fields(self) if f.name not in skip}
        de = self.options.de
        out["options"] = {
            "variant": self.options.variant,
            "generations": de.max_generations,
            "population": de.population_size,
            "max_seconds": de.max_seconds if math.isfinite(de.max_seconds) else None,
        }
        return out


def _plain(value):
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if hasattr(value, "__dataclass_fields__"):
        return {f.name: _plain(getattr(value, f.name)) for f in fields(value)}
    return value
