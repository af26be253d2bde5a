"""The one options type of an SFO, whatever the method (:class:`SfoOptions`)."""

from dataclasses import dataclass, field, replace

from ..constants import focal_cap_px
from ..optimisation.de import DEOptions
from ..pose.posest import PosestOptions
from ..pose.refine import RefineOptions
from .working_level import WORKING_FACE_PX


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
    working_face_px : float or None
        Lilium's image terms inside the DE run at a working level where the face is about this
        many pixels across (:mod:`lilium.methods.working_level`); the result's terms are
        recomputed at full resolution on the full mesh. None = every evaluation at full level.
    """

    variant: str = "skof+pll"
    de: DEOptions = field(default_factory=DEOptions)
    refine: RefineOptions = field(
        default_factory=lambda: RefineOptions(max_iterations=6, cost_tol=1e-8, gradient_tol=1e-8)
    )
    posest: PosestOptions = field(default_factory=PosestOptions)
    depth_table: dict | None = None
    working_face_px: float | None = WORKING_FACE_PX

    def with_de(self, **changes):
        """A copy with the given :class:`DEOptions` fields changed (``None`` values ignored)."""
        changes = {k: v for k, v in changes.items() if v is not None}
        return replace(self, de=replace(self.de, **changes))


#: How far past the focal cap (factor) the inner Levenberg-Marquardt may run before it stops.
FOCAL_STOP_FACTOR = 100.0


def with_focal_cap(options, focal_prior_px):
    """``options`` with the focal cap of a photo's focal prior (docs/method/pose.md).

    POSEST's ``focal_max_px`` becomes :func:`lilium.constants.focal_cap_px` of the prior
    (10,000 px, or twice the prior's upper bound when the prior reaches above that), and each
    Levenberg-Marquardt stops a run-off fit no earlier than :data:`FOCAL_STOP_FACTOR` times the
    cap. Unchanged (the same object) for a prior below 10,000 px.

    Parameters
    ----------
    options : SfoOptions
    focal_prior_px : (float, float) or None

    Returns
    -------
    SfoOptions
    """
    return with_cap_px(options, focal_cap_px(focal_prior_px))


def with_cap_px(options, cap_px):
    """``options`` with POSEST's focal cap at ``cap_px`` (see :func:`with_focal_cap`)."""
    cap = float(cap_px)
    if cap == options.posest.focal_max_px:
        return options

    def lifted(refine):
        return replace(refine, focal_stop_px=max(refine.focal_stop_px, FOCAL_STOP_FACTOR * cap))

    posest = replace(options.posest, focal_max_px=cap, refine=lifted(options.posest.refine))
    return replace(options, posest=posest, refine=lifted(options.refine))
