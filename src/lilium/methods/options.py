"""The one options type of an SFO, whatever the method (:class:`SfoOptions`)."""

from dataclasses import dataclass, field, replace

from ..optimisation.de import DEOptions
from ..pose.posest import PosestOptions
from ..pose.refine import RefineOptions


@dataclass(frozen=True)
class SfoOptions:
    """Options of one SFO; each method reads the fields it uses.

    Attributes
    ----------
    variant : {"base", "pll", "skof", "skof+pll"}
        Lilium's fitness variant (which optional penalties are on); ignored by POSEST-SFO.
    de : DEOptions
        Lilium's differential evolution (population, F, CR, generations, wall clock).
    refine : RefineOptions
        Lilium's warm-started inner Levenberg-Marquardt (few iterations: it starts near the
        optimum).
    posest : PosestOptions
        POSEST (RANSAC + LM): POSEST-SFO's estimator, Lilium's initial camera and fallback.
    depth_table : dict or None
        A user's soft-tissue depth table (:func:`lilium.io.case.read_depth_table`); None = the
        built-in table.
    """

    variant: str = "skof+pll"
    de: DEOptions = field(default_factory=DEOptions)
    refine: RefineOptions = field(
        default_factory=lambda: RefineOptions(max_iterations=6, cost_tol=1e-8, gradient_tol=1e-8)
    )
    posest: PosestOptions = field(default_factory=PosestOptions)
    depth_table: dict | None = None

    def with_de(self, **changes):
        """A copy with the given :class:`DEOptions` fields changed (``None`` values ignored)."""
        changes = {k: v for k, v in changes.items() if v is not None}
        return replace(self, de=replace(self.de, **changes))
