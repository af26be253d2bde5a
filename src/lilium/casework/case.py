"""Every SFO of a user's case, written as it goes, and one HTML report for them all."""

import functools
from dataclasses import replace
from pathlib import Path

from ..inputs import GivenCamera
from ..io.paths import safe_id
from ..methods.registry import method_tag, run_sfo
from .console import log_warnings, status_text
from .folders import output_lock, resumed_sfo, sfo_fingerprint, sfo_outputs
from .identify import conclusion_line, decide
from .joint_case import joint_entry, run_joint_methods
from .prepared import check_photo_extra
from .read import read_case


def searched_line(result):
    """One line for the search's camera scored as a bare examiner's camera is (for Lilium the
    soft tissue fitted under it): fitness and mean landmark error."""
    error = (result.landmark_error or {}).get("mean_px")
    px = "" if error is None else f", mean landmark error {error:.2f} px"
    return f"fitness {result.fitness:.4g}{px}"


def term_label(term):
    """``p_pll`` -> ``P_pll``; ``p_cam_focal`` -> ``P_cam (focal)``."""
    if term.startswith("p_cam_"):
        return f"P_cam ({term[len('p_cam_') :]})"
    return "P_" + term[2:] if term.startswith("p_") else term


def _landmark_info(origin, out):
    """The report's facts about the landmarks' origin (:class:`ReportEntry` fields)."""
    if origin is None:
        return {}
    review = ""
    if origin.review_page is not None:
        try:  # a link when the page lies in the output folder (--auto-landmarks)
            review = Path(origin.review_page).resolve().relative_to(out.resolve()).as_posix()
        except ValueError:
            review = ""
        else:  # the report names it as it links it, relative: the folder can move
            origin = replace(origin, review_page=Path(review))
    return {
        "landmarks_note": origin.line(),
        "landmarks_unreviewed": bool(origin.unreviewed),
        "landmark_tags": dict(origin.tags),
        "review_href": review,
    }


def run_case(request, log=print):
    """Read and check every input, run every SFO, write each result and the report.

    Parameters
    ----------
    request : CaseRequest
        The skull, the photos (:class:`~lilium.casework.request.PhotoSource`: folders or
        images), the methods, their options and seed, the priors given, the depth table and
        calibration files, ``auto_landmarks``, ``joint``, the title and the output folder
        ``request.out``: ``report.html`` and, per photo and method, one folder
        ``<photo>/<method tag>/`` (:func:`~lilium.methods.method_tag`: ``posest-sfo``,
        ``lilium-skof+pll``, ...) with ``result.json`` and ``overlay.png``, however many
        methods run: one layout for scripts to read.

        With ``auto_landmarks``, each image without a landmark file is prepared with ``lilium
        photo`` into ``out/<photo>/prepared/`` (:func:`~lilium.casework.inputs.load_photos`);
        the case fails at once, before reading anything, when ``lilium[photo]`` is not
        installed. With ``joint``, each method that has a joint form (Lilium) runs as one joint
        SFO of all the photos (one soft tissue shared by the photos, one camera each), written
        to ``<out>/joint/<method tag>/`` (``result.json`` with ``"joint": true`` and
        ``overlay_<photo id>.png`` per photo); the other methods run per photo as usual. The
        report shows every photo's overlay and terms from the shared soft tissue, and its 3D
        facial landmarks. Needs two or more distinct photos.

        Every result gets its ``"identification"`` (docs/method/identification.md); with several
        photos, each method's separate SFOs are also taken together as one decision (shared
        soft tissue), shown first in the report and logged.
    log : callable
        Receives one line per sidecar file found beside a mesh or an image, one per photo
        prepared automatically, one per photo with automatic, unreviewed landmarks, one per
        SFO and one per warning of that SFO.

    Returns
    -------
    list of ReportEntry

    Raises
    ------
    ValueError
        An invalid input (naming the file), or another run holding ``out``
        (:func:`~lilium.casework.folders.output_lock`).

    Notes
    -----
    **Resumable**: an SFO whose ``result.json`` is already there, whole with its overlays, for
    the same input files' bytes, method, options, seed and priors (its ``"inputs_sha256"``,
    :func:`~lilium.casework.folders.sfo_fingerprint`) is read back, not run again (its log line
    says ``(stored)``), so a case killed half-way continues where it stopped, with the same
    report as a run that was not stopped; any other stored SFO runs again (the log says why).

    Before the first SFO, ``log`` gets one line per term Lilium will switch off for a photo
    (:func:`~lilium.methods.registry.check_runnable`): ``<photo>: lilium <variant>: P_pll
    switched off: <why>``; each SFO's line ends with the terms it ran without.
    """
    from ..report.html import write_report

    methods, seed = list(request.methods), request.seed
    if request.auto_landmarks:
        check_photo_extra()
    out = Path(request.out)
    with output_lock(out):
        inputs = read_case(request, log=log, out=out, plan=True)
        _log_plan(inputs, log)
        joints = {}  # method -> (JointSfoResult, folder), for the joint methods
        if request.joint:
            joints = run_joint_methods(inputs, methods, seed, out, log)
        run = _CaseRun(inputs, out, seed, log)
        entries = run.entries(inputs.records, methods, joints)
        decisions = run.decisions(methods)
        report = write_report(
            out / "report.html", entries, title=request.title, command=request.command,
            decisions=decisions, request=request.to_dict(),
        )
    log(f"report: {report}")
    return entries


def _log_plan(inputs, log):
    """Log the terms switched off (``inputs.terms_off``) and the photos with unreviewed
    automatic landmarks, before any long run."""
    variant = inputs.options.variant
    for photo_id, off in inputs.terms_off.items():
        for term, why in off.items():
            log(f"{photo_id}: lilium {variant}: {term_label(term)} switched off: {why}")
    for record in inputs.records:
        if record.origin is not None and record.origin.unreviewed:
            log(f"{record.photo.id}: {record.origin.line()}")


class _CaseRun:
    """The per-photo SFOs of one case, each run or reused
    (:func:`~lilium.casework.folders.resumed_sfo`), with one file-digest cache."""

    def __init__(self, inputs, out, seed, log):
        self.skull, self.skull_inputs, self.out = inputs.skull, inputs.skull_inputs, out
        self.options, self.calibrations = inputs.options, inputs.calibrations
        self.seed, self.log = seed, log
        self.digests = {}
        self.separate = {}  # method -> [(photo, result)], for the decision over several photos

    def entries(self, records, methods, joints):
        """The report entries of every photo and method (``joints``: the joint SFOs' runs)."""
        entries = []
        for k, record in enumerate(records):
            photo, inputs, notes = record.photo, record.inputs, record.notes
            landmark_info = _landmark_info(record.origin, self.out)
            labelled = {**self.skull_inputs, **inputs}
            for method in methods:
                if method in joints:
                    run = joints[method]
                    entry = joint_entry(run, k, self.skull, photo, labelled, notes, self.out)
                else:
                    entry = self.single(method, photo, inputs, notes, landmark_info)
                entries.append(entry)
                if record.camera is not None:  # the examiner's, beside the search's
                    entries.append(self.examined(method, record, entry.result, landmark_info))
        return entries

    def single(self, method, photo, inputs, notes, landmark_info, camera=None, folder=None):
        """The report entry of ``method``'s SFO of ``photo``, run or reused, and logged; with
        ``camera`` (:meth:`examined`) that camera scored, in ``folder``."""
        from ..report.html import ReportEntry

        tag = method_tag(method, self.options.variant)
        folder = folder or self.out / safe_id(photo.id) / tag  # ids read from files are safe
        fingerprint = sfo_fingerprint(
            method, self.options, self.seed, self.skull, self.skull_inputs, [photo], [inputs],
            self.digests,
        )
        sfo = (method, self.skull, photo, self.options, self.seed)
        calibrations, log = self.calibrations, self.log
        run = run_sfo if camera is None else functools.partial(run_sfo, camera=camera)
        result, reused = resumed_sfo(folder, *sfo, fingerprint, calibrations, log, run)
        if camera is None:
            self.separate.setdefault(method, []).append((photo, result))
        outputs = sfo_outputs(folder, self.out)
        name = f"{result.method}{f' {result.variant}' if result.variant else ''}"
        name += ", examiner's camera" if camera is not None else ""
        how = " (stored)" if reused else ""
        self.log(
            f"{photo.id}: {name}: {status_text(result)}, {result.seconds:.2f} s{how} -> {folder}"
        )
        log_warnings(result, self.log)
        self.log(f"  {conclusion_line(result.extra['identification'])}")
        labelled = {**self.skull_inputs, **inputs}
        return ReportEntry(self.skull, photo, result, labelled, notes, outputs, **landmark_info)

    def examined(self, method, record, searched, landmark_info):
        """The report entry of the examiner's camera of ``record`` (``--camera``) scored by
        ``method`` without search, in ``<photo>/<method tag>/examiner/``; its notes give the
        search's camera scored the same way (:func:`searched_line`) when the examiner's came
        without its soft tissue (a bare camera: Lilium fits one under it), so that the two
        compare; with the soft tissue of the search the search's own figures compare."""
        photo = record.photo
        folder = self.out / safe_id(photo.id) / method_tag(method, self.options.variant)
        inputs = {**record.inputs, "examiner camera": Path(record.camera.source)}
        notes = dict(record.notes)
        if searched and record.camera.facial_landmarks_mm is None:
            bare = GivenCamera(searched.camera, source="the search")
            rescored = run_sfo(method, self.skull, photo, self.options, self.seed, bare)
            notes["search's camera, scored the same way"] = searched_line(rescored)
        return self.single(
            method, photo, inputs, notes, landmark_info, record.camera, folder / "examiner"
        )

    def decisions(self, methods):
        """Each method's decision over its separate SFOs of two or more photos, logged."""
        decisions = []
        for method in methods:
            done = self.separate.get(method, [])
            if len(done) < 2:
                continue
            photos_m, results_m = zip(*done, strict=True)
            decision = decide(self.skull, list(photos_m), list(results_m), self.calibrations)
            record = decision.to_dict()
            tag = method_tag(method, self.options.variant)
            label = f"photos {', '.join(p.id for p in photos_m)} together, {tag}"
            self.log(f"{label}: {conclusion_line(record)}")
            decisions.append((label, record))
        return decisions
