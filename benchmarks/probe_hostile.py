"""Hostile-input probes of every ``lilium`` command (issue 28): each probe runs one command line
through :func:`lilium.cli.main.main` in this process, under a time limit, with the files of its
own folder traced, and gets one verdict:

- ``pass``: an expected error is one line naming the file or option (the probe's needles), an
  expected success exits 0 (with the expected warning, when one is expected);
- ``traceback``: an exception escaped, or the line says "internal error" (a bug);
- ``silently wrong``: an input that must be refused (or warned about) ran to exit 0 without it;
- ``hang``: over the time limit;
- ``write outside --out``: a file changed in the probe's folder outside its ``--out``;
- ``unclear message``: the error is not one line, or does not name what the probe expects;
- ``wrongly refused``: a valid input was refused;
- ``stray output``: a library's warning reached stderr.

This file runs every probe (:func:`main`); the machinery (:class:`Probe`, :class:`Workspace`,
the verdicts, the shared set-ups, the runner of one group alone) is in
``probe_hostile_machinery.py``. The probes are in the
``probe_hostile_*.py`` modules: broken ``photo.json``, subject folders, meshes, images, masks,
face curves, options of ``lilium sfo`` and ``lilium case``, experiment configs and databases,
``lilium photo`` and ``lilium import-ct`` in ``probe_hostile_basic.py``. Probes of ``lilium
photo`` and ``lilium import-ct`` (whose fixes belong to the photo/CT work of issue 28) are
counted apart. Those of ``lilium lineup``, ``lilium calibrate``, ``--calibration`` and the joint
SFO are in ``probe_hostile_casework.py``; more of ``lilium photo``, ``lilium import-ct`` and
``lilium synth`` (EXIF, image modes, DICOM series, NIfTI affines, counts) are in
``probe_hostile_inputs.py``; resumes after a crash's leftovers in ``probe_hostile_resume.py``;
degenerate or damaged geometry (mesh fragments, unreferenced vertices, twins at one place,
planar landmarks, masks of every pixel) in ``probe_hostile_geometry.py``; the same case
transformed in ways that must not change the answer (resampled, padded, another file format,
the skull moved, inputs in another order) in ``probe_hostile_metamorphic.py``; what the HTML
reports and the console show against each ``result.json`` in ``probe_hostile_report.py``;
experiments, reports and calibrations that must repeat whatever the workers, resumes and orders
in ``probe_hostile_determinism.py``. ::

    python benchmarks/probe_hostile.py --work /tmp/probes [--only SUBSTRING] [--limit-s 60]

prints one line per probe that did not pass and the counts per verdict; exits 1 when a probe
of this work's own commands did not pass.
"""

import argparse
import os
import sys
from pathlib import Path

from probe_hostile_machinery import VERDICTS, _fresh_work, _run_probes


def all_probes():
    # The probes live in their own modules (each reads in one sitting).
    from probe_hostile_basic import (
        experiment_probes,
        image_probes,
        option_probes,
        photo_and_ct_probes,
        photo_json_probes,
        skull_probes,
    )
    from probe_hostile_casework import casework_probes
    from probe_hostile_determinism import determinism_probes
    from probe_hostile_geometry import geometry_probes
    from probe_hostile_inputs import input_probes
    from probe_hostile_metamorphic import metamorphic_probes
    from probe_hostile_outputs import output_probes
    from probe_hostile_report import report_probes
    from probe_hostile_resume import resume_probes
    from probe_hostile_runs import run_probes
    from probe_hostile_semantic import semantic_probes

    return (
        photo_json_probes()
        + skull_probes()
        + image_probes()
        + option_probes()
        + experiment_probes()
        + casework_probes()
        + photo_and_ct_probes()
        + input_probes()
        + run_probes()
        + output_probes()
        + resume_probes()
        + semantic_probes()
        + geometry_probes()
        + metamorphic_probes()
        + report_probes()
        + determinism_probes()
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True, help="scratch folder (emptied)")
    parser.add_argument("--only", help="run the probes whose name holds this text")
    parser.add_argument("--limit-s", type=int, default=60, help="time limit per probe")
    parser.add_argument("--list", action="store_true", help="list the probes and stop")
    parser.add_argument("--verbose", action="store_true", help="a line for every probe")
    parser.add_argument("--keep", action="store_true", help="keep each probe's folder")
    parser.add_argument("--range", default=":", help="probes START:STOP only (by index)")
    args = parser.parse_args(argv)
    os.environ.pop("LILIUM_DEBUG", None)  # as users run it: the CLI's own handlers on
    start, stop = (int(x) if x else None for x in args.range.split(":"))
    probes = all_probes()[start:stop]
    probes = [p for p in probes if not args.only or args.only in p.name]
    if args.list:
        for p in probes:
            print(f"{p.owner:5} {p.expect:5} {p.name}")
        print(f"{len(probes)} probes")
        return 0
    counts = _run_probes(probes, args, _fresh_work(args.work), owners=True)
    for owner, label in (("rel", "this work"), ("photo", "lilium photo"), ("ct", "import-ct")):
        total = sum(counts[owner].values())
        parts = ", ".join(f"{v} {counts[owner][v]}" for v in VERDICTS)
        print(f"{label}: {total} probes: {parts}")
    own = counts["rel"]
    return 0 if own["pass"] == sum(own.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
