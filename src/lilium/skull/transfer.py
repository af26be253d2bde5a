"""The template's landmarks carried onto an aligned mesh, and the mandible detected.

The mandible (:func:`mandible_coverage`): of the two fits (template with and without the
mandible) the one whose cranium lies closer to the mesh (:func:`cranium_mismatch_mm`) is kept;
the mesh has a mandible when bone lies where that fit puts the template's mandible body and
rami (the share of those template points with a mesh surface sample within
:data:`MANDIBLE_ON_MM` reaches :data:`MANDIBLE_COVERED`). Measured (``benchmarks/
bench_skull_landmarks.py``): 0.5-0.9 on skulls with a mandible (headsq 0.54, generated >= 0.8),
at most 0.05 without one (headsq without its mandible, Cranium, generated), in every pose and
after decimation. A global fit score does not tell them apart on a real skull: headsq without
its mandible fits the template with the mandible better (the lowered chin's soft tissue, the
teeth and the hyoid region pull the fit).

Normalised frame (:mod:`lilium.skull.align`): template points ``q`` lie at ``q / scale``. Each
landmark's template neighbourhood (a patch of :data:`PATCH_MM`) is fitted onto the mesh by a
trimmed similarity ICP, and the landmark goes with it, then onto the nearest mesh vertex: the
"template" estimate, and the start of each landmark's own rule (:mod:`lilium.skull.rules`). A
patch that does not find its surface (a cut vault, a missing bone) leaves its landmark out.
"""

import numpy as np

from .align import similarity_icp

#: Radius (mm) of a landmark's template patch; patch ICP iterations; share of the patch points
#: that must lie within :data:`PATCH_ON_MM` of the mesh after the fit for the landmark to be
#: placed; farthest (mm) the fitted landmark may lie from the mesh.
PATCH_MM = 22.0
PATCH_ITERATIONS = 12
PATCH_COVERED = 0.6
PATCH_ON_MM = 3.0
LANDMARK_ON_MM = 5.0
#: Mandible detection: surface samples of the mesh; distances are capped at
#: :data:`MISMATCH_CAP_MM` in the two-sided mismatch of a hypothesis (with / without mandible).
SURFACE_SAMPLES = 20_000
MISMATCH_CAP_MM = 10.0
#: The template's mandible body and rami: its vertices farther than this (mm) from the
#: cranium's (not the teeth in occlusion nor the condyles in their fossae); a point is covered
#: when a mesh sample lies within :data:`MANDIBLE_ON_MM`; the mesh has a mandible when the
#: covered share reaches :data:`MANDIBLE_COVERED`.
MANDIBLE_FAR_MM = 10.0
MANDIBLE_ON_MM = 5.0
MANDIBLE_COVERED = 0.25


def surface_samples(vertices, faces, n, rng):
    """``n`` points spread over a mesh's area (triangles drawn by area, uniform inside):
    ``(n, 3)``."""
    rng = np.random.default_rng(rng)
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    k = rng.choice(len(faces), size=n, p=area / area.sum())
    a, b = rng.random((2, n, 1))
    flip = (a + b) > 1
    a, b = np.where(flip, 1 - a, a), np.where(flip, 1 - b, b)
    t = tri[k]
    return t[:, 0] + a * (t[:, 1] - t[:, 0]) + b * (t[:, 2] - t[:, 0])


def mismatch_mm(samples, template_points):
    """Two-sided mismatch of a mesh and a template (hypothesis) in the normalised frame.

    The mean capped distance from the mesh's surface samples to the template plus the mean
    capped distance from the template's points to the samples: a template with a mandible on a
    mesh without one pays on the second term, a template without one on a mesh with one on
    the first.

    Parameters
    ----------
    samples : ndarray of shape (N, 3)
        Mesh surface samples (:func:`surface_samples`), normalised frame.
    template_points : ndarray of shape (M, 3)
        The hypothesis' template vertices in the normalised frame.

    Returns
    -------
    float
        mm.
    """
    from scipy.spatial import cKDTree

    to_template, _ = cKDTree(template_points).query(samples)
    to_mesh, _ = cKDTree(samples).query(template_points)
    cap = MISMATCH_CAP_MM
    return float(np.minimum(to_template, cap).mean() + np.minimum(to_mesh, cap).mean())


def cranium_mismatch_mm(samples, cranium_points):
    """Mean capped distance (mm) from the template's cranium points to the mesh's surface
    samples (both normalised frame, ``(N, 3)`` and ``(M, 3)``): how well a fit lays the
    template's cranium on the mesh, whatever the mesh has below it."""
    from scipy.spatial import cKDTree

    d, _ = cKDTree(samples).query(cranium_points)
    return float(np.minimum(d, MISMATCH_CAP_MM).mean())


def mandible_body(template_points, mandible):
    """The template's mandible body and rami: ``mandible`` (``(M,)`` bool) less the points
    within :data:`MANDIBLE_FAR_MM` of the cranium's: ``(M,)`` bool."""
    from scipy.spatial import cKDTree

    d, _ = cKDTree(template_points[~mandible]).query(template_points[mandible])
    out = np.zeros(len(template_points), bool)
    out[np.flatnonzero(mandible)[d > MANDIBLE_FAR_MM]] = True
    return out


def mandible_coverage(samples, body_points):
    """Share of the template's mandible body points (normalised frame, ``(M, 3)``) with a mesh
    surface sample (``(N, 3)``) within :data:`MANDIBLE_ON_MM`: is there bone where the fitted
    template has its mandible."""
    from scipy.spatial import cKDTree

    d, _ = cKDTree(samples).query(body_points)
    return float(np.mean(d < MANDIBLE_ON_MM))


def transfer_landmarks(tree, vertices, template_points, landmarks, part_of):
    """Template landmarks fitted locally onto the mesh.

    Parameters
    ----------
    tree : scipy.spatial.cKDTree
        Of ``vertices``.
    vertices : ndarray of shape (V, 3)
        The mesh, normalised frame.
    template_points : ndarray of shape (M, 3)
        Template vertices in the normalised frame.
    landmarks : dict of str -> ndarray of shape (3,)
        Template landmarks in the normalised frame.
    part_of : dict of str -> ndarray of shape (M,), bool
        The template vertices each landmark's patch may use (its bone: cranium or mandible).

    Returns
    -------
    dict of str -> ndarray of shape (3,)
        The landmarks whose patch found its surface, on the nearest mesh vertex.
    """
    out = {}
    for name, q in landmarks.items():
        near = part_of[name] & (np.linalg.norm(template_points - q, axis=1) < PATCH_MM)
        patch = template_points[near]
        if len(patch) < 20:
            continue
        s, R, t, _ = similarity_icp(patch, tree, vertices, 1.0, np.eye(3), np.zeros(3),
                                    PATCH_ITERATIONS)  # fmt: skip
        d, _ = tree.query(s * patch @ R.T + t)
        p = s * R @ q + t
        gap, k = tree.query(p)
        if np.mean(d < PATCH_ON_MM) >= PATCH_COVERED and gap <= LANDMARK_ON_MM:
            out[name] = vertices[k].copy()
    return out
