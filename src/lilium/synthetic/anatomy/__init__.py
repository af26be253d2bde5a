"""The synthetic anatomy of a subject, by part (skull frame, mm; fields negative inside).

- :mod:`.shape`: the shape parameters (:class:`~.shape.SubjectShape`) and their population.
- :mod:`.parts`: primitive specs and how a part joins a field (boxes, blends, bumps).
- :mod:`.bone`: the design positions and the skull field, built from
  :mod:`.cranium` (vault, temporal fossae, face block, zygomatics, brow, orbits, nose, ear
  canals) and :mod:`.jaws` (alveolar process, teeth, mandible).
- :mod:`.landmarks`: the cranial landmarks on the bone, the mouth corners on the skin.
- :mod:`.soft_tissue`: the true soft-tissue depths and directions.
- :mod:`.skin`: the skin field through every facial target, with :mod:`.features` (pads,
  nose, lips, ears).

:mod:`lilium.synthetic.subjects` assembles them into a
:class:`~lilium.synthetic.subjects.SyntheticSubject`.
"""
