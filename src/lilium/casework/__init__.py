"""Case workflows: from the user's files to written results (what the ``lilium`` commands call).

- :mod:`~lilium.casework.folders`: one SFO on docs/contract.md folders (``lilium sfo``);
- :mod:`~lilium.casework.inputs`: a user's skull and photos from folders or plain files, with
  the precedence of priors (command line, ``photo.json``, EXIF);
- :mod:`~lilium.casework.prepared`: photo folders of ``lilium photo`` in a case (landmarks'
  origin, automatic priors paired with the skull) and ``lilium case --auto-landmarks``;
- :mod:`~lilium.casework.case`: every SFO of a case and its HTML report (``lilium case``).

The flow runs down once: cli -> casework -> methods (:func:`lilium.methods.run_sfo`) -> pose /
fitness -> geometry; reading and writing files is :mod:`lilium.io`'s job.
"""
