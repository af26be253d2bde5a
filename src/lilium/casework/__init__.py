"""Case workflows: from the user's files to written results (what the ``lilium`` commands call).

- :mod:`~lilium.casework.request`: what a user asks to run, one frozen
  :class:`~lilium.casework.request.CaseRequest` (built by ``lilium.cli.options`` or a script);
- :mod:`~lilium.casework.read`: the request's inputs read and checked once
  (:func:`~lilium.casework.read.read_case`), through :mod:`~lilium.casework.inputs` (a user's
  skull and photos from folders or plain files, with the precedence of priors: command line,
  ``photo.json``, EXIF) and :mod:`~lilium.casework.prepared` (photo folders of ``lilium photo``
  in a case, ``--auto-landmarks``);
- :mod:`~lilium.casework.build`: the typed ``Skull`` and ``Photo`` built and checked from what
  :mod:`lilium.io` parses;
- :mod:`~lilium.casework.single`: one SFO without a report (``lilium sfo``);
- :mod:`~lilium.casework.case`: every SFO of a case and its HTML report (``lilium case``);
- :mod:`~lilium.casework.lineup`: one skull against several candidates (``lilium lineup``);
- :mod:`~lilium.casework.folders`: the output folders' machinery (resume, lock, joint files);
- :mod:`~lilium.casework.identify`: each result's identification, with the calibration file
  read once (:class:`~lilium.io.calibration.Calibrations`).

The flow runs down once: cli -> casework -> methods (:func:`lilium.methods.run_sfo`) -> pose /
fitness -> geometry; reading and writing files is :mod:`lilium.io`'s job.

Example (a script's case, as ``lilium case`` runs it)::

    from pathlib import Path
    from lilium.casework.case import run_case
    from lilium.casework.request import CaseRequest, PhotoSource, SkullSource

    request = CaseRequest(
        SkullSource(Path("subject")), Path("case"),
        photos=(PhotoSource(Path("front.jpg"), landmarks=Path("front.csv")),),
    )
    entries = run_case(request)
"""
