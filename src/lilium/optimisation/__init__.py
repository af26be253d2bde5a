"""Differential Evolution on the unit cube (docs/method/lilium.md)."""

from .de import DEOptions, DEResult, DifferentialEvolution, differential_evolution

__all__ = ["DEOptions", "DEResult", "DifferentialEvolution", "differential_evolution"]
