"""Cranial landmarks on a bare skull mesh: the pipeline of ``lilium skull``.

Stages (:func:`locate_skull_landmarks`, each timed in :attr:`SkullLandmarks.profile_s`):

1. ``check``: the parts apart from the mesh's largest left out, the rest's size a skull's in
   millimetres (:mod:`lilium.skull.checks`);
2. ``align``: the rigid motion (and scale) onto the template skull (:mod:`lilium.skull.align`),
   with and without the template's mandible; the fit that lays the template's cranium best is
   kept, and bone where it puts the template's mandible body says whether the lower jaw is
   there (:func:`~lilium.skull.transfer.mandible_coverage`); parts far from the fitted template
   left out (:data:`FOREIGN_PART_MM`; judged by the largest part's own fit when the fit is
   poor, :data:`PULLED_FIT_RMS_MM`) and the skull fitted again without them;
3. ``symmetry``: the mirror plane to ``x = 0``;
4. ``transfer``: the template's landmarks fitted patch by patch (:mod:`lilium.skull.transfer`);
   the fit checked (not a skull: an error);
5. ``rules``: each landmark's own definition on the normalised mesh (:mod:`lilium.skull.rules`):
   quality ``"located"``; where a rule finds nothing, or its point lies at an open edge of the
   mesh or far from the fitted template (:data:`NEAR_CUT_MM`, :data:`FAR_FROM_TEMPLATE_MM`), the
   transfer stays, ``"template"``;
6. ``axes``: the cone axes at the landmarks in the fitted frame
   (:func:`lilium.softtissue.normals.fitted_axes`: the outward surface normals, ``lilium
   case``'s default, but the eye corners' and the alae's, which lie beside them).

Landmarks given (``keep``, e.g. reviewed ones) are kept as they are and not placed again.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from ..constants import PART_APART_MM
from ..geometry.mesh import (
    compact,
    face_components,
    largest_component,
    open_edge_points,
    parts_apart,
)
from ..softtissue.landmarks import CRANIAL_NAMES, CRANIAL_TO_FACIAL, MANDIBLE_LANDMARKS
from .align import align_to_template, symmetrise
from .checks import SKULL_EXTENT_MM, check_skull_extent, check_skull_fit
from .template import mean_template
from .transfer import (
    MANDIBLE_COVERED,
    SURFACE_SAMPLES,
    cranium_mismatch_mm,
    mandible_body,
    mandible_coverage,
    mismatch_mm,
    surface_samples,
    transfer_landmarks,
)

#: Mesh surface samples the mirror plane is fitted on.
SYMMETRY_POINTS = 6000

#: Qualities of a placed landmark (docs/method/skull.md).
LOCATED, TEMPLATE, GIVEN = "located", "template", "given"

#: A rule's point within ``NEAR_CUT_MM`` (mm) of an open edge of the mesh that runs at least
#: ``CUT_EDGE_MM`` in one piece (a cut vault, a broken or missing part; not a pinhole) is not
#: located: the bone its definition looks for may lie beyond the edge (a vault cut just above
#: the glabella had its glabella "located" on the cut). It keeps the template's estimate,
#: quality template.
NEAR_CUT_MM, CUT_EDGE_MM = 3.0, 20.0

#: Bregma's rule takes the vault's top at the depth where the template patch put it, and the
#: patch slides along a vault cut behind it: with the vault's back cut off at 0 to 14 mm behind
#: the true bregma (generated skulls), the patch moved it 10-22 mm forward and the rule's point
#: lay 6-8 mm from the cut. A bregma within ``VAULT_CUT_MM`` (mm) of a cut is not located.
VAULT_CUT_MM = 10.0

#: Parts of the mesh that are not the skull are left out before anything is placed: those
#: apart from the largest part (``PART_APART_MM`` between bounding boxes, as ``lilium case``'s
#: skull reader leaves them out), then, after the template fit, a part whose vertices lie
#: farther than this (mm, the median) from the fitted template (a stand under the chin, a
#: label, a mounting pin); the skull is fitted again without them. Measured: the largest part
#: of generated skulls 1.7-3.2 mm, of the real heads 4.5-4.8 mm (their inner surfaces
#: included); a box under a generated chin 15.9 mm, which put pogonion and gnathion 29-32 mm
#: off, "located".
FOREIGN_PART_MM = 10.0
#: A fit worse than this (trimmed RMS, mm) on a mesh of several parts may have been pulled by
#: an object beside the skull: its largest part is fitted alone, and the other parts judged by
#: that fit. The real heads fit to 4.3-4.7 mm, generated skulls 1.3-3.8; a 60 mm block 10 mm
#: beside a generated skull pulled the fit to 7.5 mm and the skull was refused as no skull.
PULLED_FIT_RMS_MM = 5.5

#: A point (a rule's or the template patch's) farther than this (mm) from the fitted template's
#: own landmark found another structure: a rule's is not located (the estimate stays, as
#: template, where it is within this), an estimate is left out. Every located landmark of 12
#: generated skulls and of the real heads lies within 23 mm of it, but headsq's bregma: on
#: vaults cut off "the highest point of the vault" was on the cut or the skull base, 122-152 mm
#: off, and a frontotemporale was found 143 mm off, on the other side.
FAR_FROM_TEMPLATE_MM = 30.0

#: Landmarks flagged for review wherever they were placed automatically: extreme points (the
#: top of the ear canal, the lowest point of the orbit's margin, the angle of the jaw, the most
#: lateral point of the arch) whose place along a flat stretch of bone depends on the head's
#: orientation, where observers disagree most (docs/method/skull.md).
ORIENTATION_DEPENDENT = ("porion", "orbitale", "gonion", "zygion")


def orientation_dependent(name):
    """Whether the landmark ``name`` (``zygion_l``, ...) is one of
    :data:`ORIENTATION_DEPENDENT`."""
    return name.removesuffix("_l").removesuffix("_r") in ORIENTATION_DEPENDENT


@dataclass(frozen=True)
class SkullLandmarks:
    """The landmarks placed on a skull mesh (its own frame and units).

    Attributes
    ----------
    landmarks : dict of str -> ndarray of shape (3,)
        In the order of :data:`~lilium.softtissue.landmarks.CRANIAL_NAMES`, mm.
    quality : dict of str -> str
        ``"located"`` (the landmark's own definition found it), ``"template"`` (only the fitted
        template places it) or ``"given"`` (kept from ``keep``).
    axes : dict of str -> ndarray of shape (3,)
        Unit outward surface normal of each landmark of a correspondence.
    mandible : bool
        Whether the mesh has a mandible.
    mismatch_mm : dict of bool -> float
        The two-sided mismatch of the fits with (True) and without (False) the template's
        mandible (:func:`~lilium.skull.transfer.mismatch_mm`), each template's best.
    mandible_coverage : float
        Share of the fitted template's mandible body with bone of the mesh there
        (:func:`~lilium.skull.transfer.mandible_coverage`); ``mandible`` is whether it reaches
        :data:`~lilium.skull.transfer.MANDIBLE_COVERED`.
    mesh2skull : ndarray of shape (4, 4)
        Rigid motion from the mesh's frame to the normalised skull frame.
    scale : float
        Template size over mesh size.
    fit_rms_mm : float
    profile_s : dict of str -> float
        Seconds per stage.
    doubtful : dict of str -> str
        The landmarks whose rule's point was not kept, and why: at an open edge of the mesh
        (:data:`NEAR_CUT_MM`) or far from the fitted template (:data:`FAR_FROM_TEMPLATE_MM`);
        each is template (its estimate) or absent.
    parts_left_out : tuple of int
        The face counts of the mesh's parts left out as not the skull's (apart from it, or far
        from the fitted template: :data:`FOREIGN_PART_MM`), largest first.
    faces_kept : ndarray of shape (F,), bool
        Which of the mesh's faces are the skull's (all but those parts).
    """

    landmarks: dict
    quality: dict
    axes: dict
    mandible: bool
    mismatch_mm: dict
    mesh2skull: np.ndarray
    scale: float
    fit_rms_mm: float
    profile_s: dict = field(default_factory=dict)
    mandible_coverage: float = float("nan")
    doubtful: dict = field(default_factory=dict)
    parts_left_out: tuple = ()
    faces_kept: np.ndarray | None = None


def locate_skull_landmarks(vertices, faces, keep=None, rng=0, source="mesh"):
    """Every cranial landmark a skull mesh has.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        mm, any frame; a vertex no face uses is left out.
    faces : ndarray of shape (F, 3), int
    keep : dict of str -> ndarray of shape (3,), optional
        Landmarks to keep as they are (mesh frame).
    rng : anything :func:`numpy.random.default_rng` accepts
        Draws the point samples of the fit; the same seed gives the same result.
    source : str
        Names the mesh in the messages.

    Returns
    -------
    SkullLandmarks

    Raises
    ------
    ValueError
        The mesh is not a skull in millimetres (:mod:`lilium.skull.checks`).
    """
    from scipy.spatial import cKDTree

    from ..softtissue.normals import fitted_axes
    from .rules import apply_rules

    # A vertex that no face uses is no bone (a rule or a patch would find it).
    vertices, faces = compact(np.asarray(vertices, float), np.asarray(faces, np.int64))
    rng = np.random.default_rng(rng)
    keep = {n: np.asarray(p, float) for n, p in (keep or {}).items()}
    profile, clock = {}, [time.perf_counter()]

    def lap(stage):
        now = time.perf_counter()
        profile[stage] = now - clock[0]
        clock[0] = now

    kept, left_out = _skull_part(vertices, faces)  # of the mesh's faces
    check_skull_extent(vertices[np.unique(faces[kept])], source)
    template = mean_template()
    lap("check")
    seed = rng.integers(2**63)  # every fit below draws the same samples
    skull_v, skull_f = compact(vertices, faces[kept])
    fit, mismatch, coverage, samples = _align(skull_v, skull_f, template, seed)
    retried = False
    if fit.rms_mm > PULLED_FIT_RMS_MM:  # an object by the skull may have pulled the fit: the
        # largest part's alone, and the other parts judged by it
        largest, others = largest_component(skull_f, len(skull_v))
        retried = bool(others)
        if retried:
            fit = _align(*compact(skull_v, skull_f[largest]), template, seed)[0]
    foreign, counts = foreign_parts(fit.to_skull(skull_v), skull_f, template.vertices / fit.scale)
    if counts or retried:  # fitted again without them (a part far from the skull pulls the
        # fit), with the same seed: the skull alone gets the fit and the landmarks it gets as
        # a mesh alone
        kept[np.flatnonzero(kept)[foreign]] = False
        left_out = tuple(sorted(left_out + counts, reverse=True))
        skull_v, skull_f = compact(vertices, faces[kept])
        fit, mismatch, coverage, samples = _align(skull_v, skull_f, template, seed)
    faces_kept, vertices, faces = kept, skull_v, skull_f
    has_mandible = coverage >= MANDIBLE_COVERED
    lap("align")
    fit = symmetrise(fit, samples[:: max(1, SURFACE_SAMPLES // SYMMETRY_POINTS)])
    tpl = template.vertices / fit.scale
    moved = fit.to_skull(vertices)
    lap("symmetry")
    tree = cKDTree(moved)
    wanted = [n for n in CRANIAL_NAMES if has_mandible or n not in MANDIBLE_LANDMARKS]
    part_of = {n: template.mandible == (n in MANDIBLE_LANDMARKS) for n in wanted}
    expected = {n: template.landmarks[n] / fit.scale for n in wanted}
    found = transfer_landmarks(tree, moved, tpl, expected, part_of)
    check_skull_fit(fit.rms_mm, found, source)
    lap("transfer")
    anchors = {k: v / fit.scale for k, v in template.anchors.items()}
    _, nearest = cKDTree(tpl).query(moved)
    on_mandible = template.mandible[nearest] if has_mandible else np.zeros(len(moved), bool)
    located = apply_rules(moved, faces, on_mandible, found, anchors, fit.scale)
    located, found, doubtful = _plausible(located, found, expected, moved, faces)
    lap("rules")
    placed, quality = {}, {}
    for name in CRANIAL_NAMES:
        if name in keep:
            placed[name], quality[name] = keep[name], GIVEN
        elif name in located:
            placed[name], quality[name] = fit.to_mesh(located[name][None])[0], LOCATED
        elif name in found:
            placed[name], quality[name] = fit.to_mesh(found[name][None])[0], TEMPLATE
    with_axes = {n: p for n, p in placed.items() if n in CRANIAL_TO_FACIAL}
    to_mesh = fit.mesh2skull[:3, :3].T  # the fitted frame: x the head's left, z its front
    axes = fitted_axes(vertices, faces, with_axes, to_mesh[:, 0], to_mesh[:, 2])
    lap("axes")
    return SkullLandmarks(
        placed, quality, axes, bool(has_mandible), mismatch, fit.mesh2skull, fit.scale,
        fit.rms_mm, profile, coverage, doubtful, left_out, faces_kept,
    )  # fmt: skip


def _skull_part(vertices, faces):
    """The faces of the mesh's parts that are not apart from its largest (``(F,)`` bool), and
    the face counts of those apart (:func:`~lilium.geometry.mesh.parts_apart`,
    ``PART_APART_MM``). Where the parts near one another span more than a skull (hundreds of
    specks of a noisy scan chain up), the largest part alone."""
    apart, parts = parts_apart(vertices, faces, None, PART_APART_MM)
    kept = ~apart
    if np.ptp(vertices[np.unique(faces[kept])], axis=0).max() > SKULL_EXTENT_MM[1]:
        return largest_component(faces, len(vertices))
    return kept, tuple(sorted((n for n, _ in parts), reverse=True))


def _align(vertices, faces, template, seed):
    """The mesh fitted onto the template (:func:`~lilium.skull.align.align_to_template`, with
    and without its mandible): the fit that lays the template's cranium best, the two
    hypotheses' mismatches, the share of the template's mandible body with bone there
    (:func:`~lilium.skull.transfer.mandible_coverage`) and the mesh's surface samples."""
    rng = np.random.default_rng(seed)
    samples = surface_samples(vertices, faces, SURFACE_SAMPLES, rng)
    templates = {True: template.vertices, False: template.vertices[~template.mandible]}

    def score(fit, has_mandible):
        return mismatch_mm(fit.to_skull(samples), templates[has_mandible] / fit.scale)

    _, _, mismatch, fits = align_to_template(samples, templates, score, rng)
    cranium = template.vertices[~template.mandible]
    on_cranium = {k: cranium_mismatch_mm(f.to_skull(samples), cranium / f.scale)
                  for k, f in fits.items()}  # fmt: skip
    fit = fits[min(on_cranium, key=on_cranium.get)]
    body = template.vertices[mandible_body(template.vertices, template.mandible)] / fit.scale
    return fit, mismatch, mandible_coverage(fit.to_skull(samples), body), samples


def foreign_parts(vertices, faces, template_points):
    """The parts of a mesh that are not bone: apart from its largest part, with their vertices
    farther than :data:`FOREIGN_PART_MM` (median) from the fitted template.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        Normalised frame (the fitted template's), mm.
    faces : ndarray of shape (F, 3), int
    template_points : ndarray of shape (M, 3)
        The fitted template's vertices, same frame.

    Returns
    -------
    foreign : ndarray of shape (F,), bool
        The faces of those parts.
    face_counts : tuple of int
        Each such part's face count, largest first.
    """
    from scipy.spatial import cKDTree

    labels = face_components(faces, len(vertices))
    counts = np.bincount(labels)
    if len(counts) < 2:
        return np.zeros(len(faces), bool), ()
    part_of = np.full(len(vertices), -1)
    part_of[faces.reshape(-1)] = np.repeat(labels, 3)
    other = np.flatnonzero((part_of >= 0) & (part_of != np.argmax(counts)))
    distance = cKDTree(template_points).query(vertices[other])[0]
    part = part_of[other]
    order = np.lexsort((distance, part))  # by part, then by distance: each part's median
    starts = np.flatnonzero(np.r_[True, np.diff(part[order]) != 0])
    ends = np.r_[starts[1:], len(order)]
    middle = distance[order][(starts + ends - 1) // 2] + distance[order][(starts + ends) // 2]
    far = part[order][starts][middle / 2 > FOREIGN_PART_MM]
    foreign = np.isin(labels, far)
    return foreign, tuple(sorted((int(counts[p]) for p in far), reverse=True))


def _plausible(located, found, expected, vertices, faces):
    """The rules' points (``located``) and the template's estimates (``found``) that can be
    trusted (normalised frame, mm): not far from the fitted template's landmark (``expected``,
    :data:`FAR_FROM_TEMPLATE_MM`) and, for a rule's point, not at an open edge of the mesh
    (:data:`NEAR_CUT_MM`; bregma :data:`VAULT_CUT_MM`); and ``{name: why}`` of the rules'
    points not trusted."""
    from scipy.spatial import cKDTree

    def far(name, point):
        return np.linalg.norm(point - expected[name]) > FAR_FROM_TEMPLATE_MM

    doubtful = {n: "far from the fitted template" for n, p in located.items() if far(n, p)}
    cut = open_edge_points(vertices, faces, CUT_EDGE_MM)
    if len(cut):
        near = cKDTree(cut)
        for name, point in located.items():
            if name in doubtful:
                continue
            gap = near.query(point)[0]
            if gap <= NEAR_CUT_MM:
                doubtful[name] = "on an open edge of the mesh (a cut or missing bone)"
            elif name == "bregma" and gap <= VAULT_CUT_MM:
                doubtful[name] = (
                    f"the vault cut within {VAULT_CUT_MM:g} mm of it (its place along the vault "
                    "is the template's, which slides on a cut vault)"
                )
    located = {n: p for n, p in located.items() if n not in doubtful}
    found = {n: p for n, p in found.items() if not far(n, p)}
    return located, found, doubtful
