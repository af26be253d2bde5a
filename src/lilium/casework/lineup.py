"""A lineup (docs/method/identification.md): one skull against several candidate persons, each with
one or
more photos, ranked by the identification's likelihood ratio in one report.

The usual case of a found skull and a missing-persons list. Every photo of every candidate
gets one SFO per method (as in ``lilium case``); a candidate's decision is its photo's
identification, or with several photos their separate SFOs taken together (one shared soft
tissue, :mod:`lilium.casework.identify`). Candidates are ranked by log10 LR (no LR last).

Outputs: ``OUT/<candidate>/<photo>/<method tag>/result.json`` and ``overlay.png`` per SFO,
``OUT/lineup.json`` (the ranking) and ``OUT/report.html`` (the ranking first, then every
SFO with its overlay). **Resumable**: an SFO whose ``result.json`` is already there, whole
with its ``overlay.png``, for the same input files' bytes, method, options, seed and priors
(its ``"inputs_sha256"``, :func:`~lilium.casework.folders.sfo_fingerprint`) is read back, not
run again, so a lineup killed half-way continues where it stopped; any other stored SFO runs
again (the log says why). Its identification is computed again, with this run's calibration
(another ``--calibration`` changes the LRs, not the SFOs); a progress bar counts the SFOs. A
second run on the same ``--out`` is refused while one runs
(:func:`~lilium.casework.folders.output_lock`).
"""

from dataclasses import replace
from pathlib import Path

from ..io.case import repeated_photo
from ..io.jsonio import write_json
from ..io.paths import printable, safe_id
from ..methods.registry import method_tag, run_sfo
from .folders import (
    output_lock,
    resumed_sfo,
    sfo_fingerprint,
    sfo_outputs,
)
from .identify import conclusion_line, decide
from .read import read_case

#: The lineup's own files in its output folder: no candidate's folder may take their names.
OWN_FILES = ("lineup.json", "report.html")


def check_candidates(candidates):
    """Refuse an empty lineup, a candidate without a name or photos, a name given twice or
    taken by the lineup's own files (:data:`OWN_FILES`), and a photo given twice, by path or
    as a copy of its image, for one candidate (it would count as a second view) or for two (a
    photo shows one person).

    Parameters
    ----------
    candidates : list of (str, list of path)
    """
    if not candidates:
        raise ValueError("--candidate: give at least one candidate: --candidate NAME PHOTO ...")
    seen = set()
    for name, photos in candidates:
        key = safe_id(name)
        if not name.strip():
            raise ValueError("--candidate: a candidate's name is empty; give each one a name")
        if not photos:
            raise ValueError(f"--candidate {name}: give one or more photos after the name")
        if key in seen:
            raise ValueError(f"--candidate {name}: the name is given twice; names must differ")
        if key in OWN_FILES:
            raise ValueError(
                f"--candidate {name}: the name of the lineup's own {key}; rename the candidate"
            )
        seen.add(key)
    owners = [(name, path) for name, photos in candidates for path in photos]
    repeat = repeated_photo([path for _, path in owners])
    if repeat is not None:
        (name, path), (other, first) = owners[repeat[0]], owners[repeat[1]]
        raise ValueError(
            f"--candidate {name}: {path} is {repeat[2]} {first} (--candidate {other}); give "
            "each photo once, with the one person it shows"
        )


def rank_key(entry, first_method):
    """Sort key of a lineup entry: the first method's entries first, then by log10 LR
    (highest first; none last). Ties at the calibration's bound are broken by what the bound
    clipped: the views' log10 LRs added (a frontal and a lateral photo), then the unbounded
    score (the NLL, lowest first)."""
    record = entry["identification"]
    lr = record.get("log10_lr")
    views = record.get("views_log10_lr") or []
    score = record.get("score")
    return (
        entry["method"] != first_method,
        -(lr if lr is not None else float("-inf")),
        -(sum(views) if views and None not in views else float("-inf")),
        score if score is not None else float("inf"),
    )


def run_lineup(request, log=print):
    """Run every candidate's SFOs (or read them back), rank the candidates, write the report.

    Parameters
    ----------
    request : CaseRequest
        The skull, the ``candidates`` (each a name and photo folders or images), the methods
        (the first one ranks the candidates; the others are shown beside it), their options and
        seed, the calibration file, the title, ``progress`` (a progress bar over the SFOs) and
        the output folder.
    log : callable

    Returns
    -------
    list of dict
        The ranking: ``candidate``, ``photos``, ``method``, ``identification``, best first.

    Raises
    ------
    ValueError
        An invalid input (naming the file or option), or another run holding ``out``
        (:func:`~lilium.casework.folders.output_lock`).
    """
    from ..report.html import write_report

    candidates = [(c.name, [source.path for source in c.photos]) for c in request.candidates]
    check_candidates(candidates)
    methods, seed = list(request.methods), request.seed
    out = Path(request.out)
    inputs = read_case(request, log=log)  # every input checked before the first SFO
    with output_lock(out):
        run = _LineupRun(inputs, out, methods, seed, log)
        entries, ranking = run.all(inputs.candidates, request.progress)
        first = method_tag(methods[0], inputs.options.variant)
        ranking.sort(key=lambda entry: rank_key(entry, first))
        for k, entry in enumerate(ranking, start=1):
            entry["rank"] = k
            log(f"{k}. {printable(entry['candidate'])} ({entry['method']}): "
                f"{conclusion_line(entry['identification'])}")
        write_json(out / "lineup.json", {"skull": inputs.skull.id, "ranking": ranking})
        decisions = [
            (f"{e['rank']}. candidate {e['candidate']} ({len(e['photos'])} photo(s)), "
             f"{e['method']}", e["identification"])
            for e in ranking
        ]
        title = request.title or (
            f"Lineup: skull {inputs.skull.id} against {len(candidates)} candidates"
        )
        report = write_report(
            out / "report.html", entries, title=title, command=request.command,
            decisions=decisions, request=request.to_dict(),
        )
    log(f"report: {report}")
    return ranking


class _LineupRun:
    """Every candidate's SFOs of one lineup, each run or reused
    (:func:`~lilium.casework.folders.resumed_sfo`), with one file-digest cache."""

    def __init__(self, inputs, out, methods, seed, log):
        self.skull, self.skull_inputs, self.out = inputs.skull, inputs.skull_inputs, out
        self.methods, self.options, self.seed = methods, inputs.options, seed
        self.calibrations, self.log = inputs.calibrations, log
        self.digests = {}

    def all(self, loaded, progress):
        """The report entries and the (unsorted) ranking of ``loaded``: (name, records) per
        candidate."""
        from tqdm import tqdm

        total = sum(len(records) for _, records in loaded) * len(self.methods)
        bar = tqdm(total=total, desc="lineup SFOs", unit="SFO", disable=not progress)
        entries, ranking = [], []
        for name, records in loaded:
            done = {m: [] for m in self.methods}
            for record in records:
                for method, entry in self.photo(name, record):
                    bar.update(1)
                    done[method].append((entry.photo, entry.result))
                    entries.append(entry)
            ranking += [self.decision(name, method, done[method]) for method in self.methods]
        bar.close()
        return entries, ranking

    def photo(self, name, record):
        """Yield (method, ReportEntry) of each method's SFO of candidate ``name``'s photo."""
        from ..report.html import ReportEntry

        photo, inputs, notes = record.photo, record.inputs, record.notes
        folder_id = safe_id(photo.id)
        # The report and the results name the candidate with the photo.
        photo = replace(photo, id=f"{name}: {photo.id}")
        for method in self.methods:
            folder = self.out / safe_id(name) / folder_id / method_tag(method, self.options.variant)
            fingerprint = sfo_fingerprint(
                method, self.options, self.seed, self.skull, self.skull_inputs, [photo],
                [inputs], self.digests,
            )
            sfo = (method, self.skull, photo, self.options, self.seed)
            result, reused = resumed_sfo(
                folder, *sfo, fingerprint, self.calibrations, self.log, run_sfo
            )
            if reused:
                self.log(f"{printable(photo.id)}: {method}: reusing the stored result in {folder}")
            outputs = sfo_outputs(folder, self.out)
            labelled = {**self.skull_inputs, **inputs}
            yield method, ReportEntry(self.skull, photo, result, labelled, notes, outputs)

    def decision(self, name, method, done):
        """The ranking entry of candidate ``name`` for ``method``: its photos' ``done``
        (photo, result) pairs, taken together when several."""
        photos = [p for p, _ in done]
        results = [r for _, r in done]
        if len(results) == 1:
            record = results[0].extra["identification"]
        else:
            record = decide(self.skull, photos, results, self.calibrations).to_dict()
        return dict(
            candidate=name,
            photos=[p.id for p in photos],
            method=method_tag(method, self.options.variant),
            identification=record,
        )
