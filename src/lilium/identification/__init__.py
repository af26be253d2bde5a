"""Identification (docs/method/identification.md): from an SFO result to a likelihood ratio and a
conclusion.

- :mod:`~lilium.identification.terms`: the model, maths only (marginal landmark likelihood
  over the soft tissue, soft-tissue typicality, prior excess);
- :mod:`~lilium.identification.score`: the terms of one SFO result, single or joint;
- :mod:`~lilium.identification.calibration`: terms -> log10 LR (logistic regression,
  cross-validated by subject), Cllr, Cllr_min, rates of misleading evidence;
- :mod:`~lilium.identification.conclusion`: log10 LR -> the verbal scale, capped by the
  material;
- :mod:`~lilium.identification.decision`: one decision, :func:`identify` ->
  :class:`Identification` (the models and the cohort passed in).
"""

from .decision import Identification, identify

__all__ = ["Identification", "identify"]
