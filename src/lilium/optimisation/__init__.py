"""Differential Evolution on the unit cube (SPEC section 6)."""

from .de import DEOptions, DEResult, DifferentialEvolution, differential_evolution

__all__ = ["DEOptions", "DEResult", "DifferentialEvolution", "differential_evolution"]
