"""SFO methods: one entry point (:func:`run_sfo`) over a registry (:data:`METHODS`).

- :mod:`~lilium.methods.registry`: :data:`METHODS`, :func:`run_sfo`, :func:`method_tag`;
- :mod:`~lilium.methods.options`: :class:`SfoOptions`, the one options type;
- :mod:`~lilium.methods.pairs`: :func:`~lilium.methods.pairs.correspondences`, the skull's and
  the photo's landmarks paired (the first step of every method and of the checks before one);
- :mod:`~lilium.methods.result`: :class:`SfoResult` and its ``result.json`` dictionary;
- :mod:`~lilium.methods.posest_sfo`: the POSEST-SFO baseline;
- :mod:`~lilium.methods.lilium` and :mod:`~lilium.methods.lilium_terms`: Lilium (DE over
  soft-tissue cones) and its image penalties for a population of cameras;
- :mod:`~lilium.methods.joint`: the joint Lilium SFO of several photos of one person
  (:func:`run_joint_sfo`);
- :mod:`~lilium.methods.overlay`: the overlay picture of a result.
"""

from .options import SfoOptions
from .registry import METHODS, Method, check_method, method_tag, run_joint_sfo, run_sfo
from .result import SfoResult

__all__ = [
    "METHODS",
    "Method",
    "SfoOptions",
    "SfoResult",
    "check_method",
    "method_tag",
    "run_joint_sfo",
    "run_sfo",
]
