"""A request's inputs read once into typed inputs, every file parsed and checked, before
anything runs: the skull (its cranial landmark file named), each photo with its priors, the SFO
options with the request's depth table, and the calibration models.

``lilium case``, ``lilium lineup`` and the single SFO read their request here
(:func:`read_case`), then run on what it returns (:class:`CaseInputs`); nothing reads a file
after that but the resume machinery (:mod:`~lilium.casework.folders`).
"""

from dataclasses import dataclass, field, replace
from pathlib import Path

from ..inputs import CaseWarning
from ..io.calibration import Calibrations
from ..io.case import parse_depth_table
from ..io.results import read_camera
from ..methods.checks import check_inputs
from ..methods.options import SfoOptions
from ..methods.registry import check_runnable
from ..softtissue.depths import check_depth_table, depth_table_warning
from .inputs import load_photos, load_skull


@dataclass(frozen=True)
class CaseInputs:
    """What a request's files hold, read and checked.

    Attributes
    ----------
    skull : Skull
        Its ``landmarks_file`` named (for the left/right messages).
    skull_inputs : dict of str -> Path
        The skull's files, labelled (provenance, fingerprints).
    records : tuple of PhotoRecord
        The request's photos (:func:`~lilium.casework.inputs.load_photos`), each with the
        depth table's warning when it has one and the camera given to score (``--camera``).
    candidates : tuple of (str, tuple of PhotoRecord)
        A lineup's candidates and their photos.
    options : SfoOptions
        The request's, with its depth table.
    calibrations : Calibrations
    terms_off : dict of str -> dict of str -> str
        Read with ``plan``: by photo id of :attr:`records`, what Lilium's SFO of it will switch
        off, and why (:func:`~lilium.methods.registry.check_runnable`); else empty.
    """

    skull: object
    skull_inputs: dict
    records: tuple
    candidates: tuple
    options: SfoOptions
    calibrations: Calibrations
    terms_off: dict = field(default_factory=dict)

    @property
    def photos(self):
        """The photos of :attr:`records`."""
        return [record.photo for record in self.records]


def read_case(request, log=None, out=None, plan=False):
    """Read and check every input of ``request``.

    Parameters
    ----------
    request : CaseRequest
    log : callable, optional
        Receives one line per sidecar file found and per photo prepared automatically
        (:func:`~lilium.casework.inputs.load_photos`).
    out : Path, optional
        The output folder photos are prepared in (``request.auto_landmarks``); hold its lock.
    plan : bool
        Also check that every SFO of the request's photos can run, and find what Lilium's
        will switch off (:func:`~lilium.methods.registry.check_runnable`; ``lilium case``).

    Returns
    -------
    CaseInputs

    Raises
    ------
    ValueError
        An invalid input, naming the file or option, checked in this order: a skull that
        cannot be read, a photo given twice (by path or by the image's bytes) or that cannot
        be read, a depth table or calibration file that cannot be parsed, mirrored left/right
        labels (:func:`~lilium.methods.checks.check_inputs`), with ``plan`` landmarks that do
        not pair, then the depth table's values. The request's own faults (an unknown method
        or variant, ``--joint`` with fewer than two photos or no joint method) are refused
        when it is made (:class:`~lilium.casework.request.CaseRequest`), before any file is
        read.
    """
    # The request's methods were checked when it was made (CaseRequest); its files are read
    # in one pass: the skull, the photos (each given once), then the small files (the depth
    # table, the calibration models), and the whole checked together.
    skull, skull_inputs = load_skull(request.skull, log=log, out=out or request.out)

    def photos_of(sources, **kwargs):
        # A lilium photo folder's automatic head orientation is paired with this skull's frame.
        return load_photos(sources, request.priors, log=log, skull=skull, **kwargs)

    records = photos_of(request.photos, auto_landmarks=request.auto_landmarks, out=out)
    records = [
        r if s.camera is None else r._replace(camera=read_camera(s.camera))
        for r, s in zip(records, request.photos, strict=True)
    ]
    candidates = tuple((c.name, tuple(photos_of(c.photos))) for c in request.candidates)
    table = None if request.depth_table is None else parse_depth_table(request.depth_table)
    calibrations = Calibrations(request.calibration)
    for record in [*records, *(r for _, rs in candidates for r in rs)]:
        check_inputs(skull, record.photo)
    terms_off = {}
    for record in records if plan else ():
        photo_file = record.inputs.get("facial landmarks") or record.inputs.get("photo.json")
        terms_off[record.photo.id] = check_runnable(
            skull, record.photo, request.methods, request.options.variant, photo_file
        )
    options = request.options
    if table is not None:
        # The table checked, and its warning ``implausible_depth`` when some of its mean depths
        # are implausible put into the photos (a photo's warnings are its results'): into the
        # result of every SFO that uses it.
        table = check_depth_table(table, source=str(Path(request.depth_table)))
        options = replace(options, depth_table=table)
        message = depth_table_warning(table, str(request.depth_table))
        if message:
            warning = CaseWarning("implausible_depth", message)
            records = [
                r._replace(photo=replace(r.photo, warnings=(*r.photo.warnings, warning)))
                for r in records
            ]
    return CaseInputs(
        skull, skull_inputs, tuple(records), candidates, options, calibrations, terms_off
    )

