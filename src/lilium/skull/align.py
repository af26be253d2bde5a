"""Pose normalisation of a skull mesh: the rigid motion (and the scale) that brings it onto the
template skull, and its mirror-symmetry plane.

Conventions, written once: a similarity ``p -> s R p + t`` maps mesh points into the skull frame
of the template (x = the subject's left, y = up, z = anterior, mm); ``R`` is a proper rotation
(a mirrored mesh is not un-mirrored: a skull is too symmetric to tell). The landmark searches
work in the *normalised frame*: the mesh moved by the rigid part only, ``p -> R p + t / s``
(``mesh2skull``, a 4x4), so that distances stay the mesh's own millimetres.

Steps (:func:`align_to_template`): the mesh's mirror plane (among the planes normal to its
principal axes, refined by a mirror ICP) fixes the x axis up to its sign; turns about it every
7.5 degrees, counted from the mesh's principal axis in the plane (:func:`in_plane_axis`: the
starts, hence the fit, do not depend on the mesh's pose), start a trimmed rigid ICP (mesh
points -> nearest template points: a partial mesh, cut vault or missing mandible, still has a
counterpart for every point) onto each template (with and without the mandible); the best few
are refined by a similarity ICP and a two-sided score picks the template and the fit; then the
mirror plane (:func:`symmetrise`) replaces the fit's x axis and offset.
"""

from dataclasses import dataclass

import numpy as np

#: ICP: points sampled (coarse search, refinement), iterations, share of the pairs kept (the
#: nearest), and the bounds of the scale (the mesh is in mm: an adult skull is within about 12 %
#: of the template's size; mesh -> template ICP shrinks a partial mesh, so the coarse search
#: keeps the scale at 1 and the refinement bounds it). With 300 and 3,000 points the fit
#: depended on its draws: over 8 seeds the Cranium CT's landmarks lay 2.5-30.4 mm (median)
#: from its hand placement, the worst landmark 50 mm off (the head turned into another
#: minimum); with 600 and 15,000, over 20 seeds, 2.3-4.5 mm, the worst 11.5 mm (twice the time).
COARSE_POINTS = 600
COARSE_TEMPLATE_POINTS = 3000
FINE_POINTS = 15_000
COARSE_ITERATIONS = 12
FINE_ITERATIONS = 30
TRIM = 0.8
SCALE_BOUNDS = (0.88, 1.14)
#: Mirror ICP of the symmetry plane: iterations and share of the pairs kept.
MIRROR_ITERATIONS = 30
MIRROR_TRIM = 0.7
MIRROR_POINTS = 2000
#: Turns about the mirror plane's normal tried (degrees), and the coarse fits refined. At 15
#: degrees the Cranium CT's fit fell into another minimum by where the turns started: 6.2 or
#: 3.1 mm from the hand placement (median) by the pose it was given, and from the mesh's own
#: axis a fit that found 64 % of the face's patches (refused as not a skull); 7.5: 4.6 mm.
TURN_STEP_DEG = 7.5
FINE_CANDIDATES = 3


@dataclass(frozen=True)
class Alignment:
    """A mesh brought onto the template.

    Attributes
    ----------
    mesh2skull : ndarray of shape (4, 4)
        Rigid motion from the mesh's frame to the normalised skull frame (mm).
    scale : float
        Template size / mesh size: template points ``q`` map to the normalised frame as
        ``q / scale``.
    rms_mm : float
        Trimmed RMS distance of the fit (template mm).
    """

    mesh2skull: np.ndarray
    scale: float
    rms_mm: float

    def to_skull(self, points):
        """Mesh-frame points ``(N, 3)`` in the normalised frame."""
        return np.asarray(points, float) @ self.mesh2skull[:3, :3].T + self.mesh2skull[:3, 3]

    def to_mesh(self, points):
        """Normalised-frame points ``(N, 3)`` in the mesh's frame."""
        R, t = self.mesh2skull[:3, :3], self.mesh2skull[:3, 3]
        return (np.asarray(points, float) - t) @ R


def umeyama(src, dst, with_scale=True, scale_bounds=SCALE_BOUNDS):
    """Least-squares similarity ``dst ~ s R src + t`` (Umeyama 1991).

    Parameters
    ----------
    src, dst : ndarray of shape (N, 3)
    with_scale : bool
    scale_bounds : (float, float)

    Returns
    -------
    s : float
    R : ndarray of shape (3, 3)
        Proper rotation.
    t : ndarray of shape (3,)
    """
    mu_s, mu_d = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - mu_s, dst - mu_d
    U, S, Vt = np.linalg.svd(b.T @ a / len(src))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    R = U @ D @ Vt
    s = 1.0
    if with_scale:
        var = np.mean(np.sum(a**2, axis=1))
        s = float(np.clip(np.trace(np.diag(S) @ D) / var, *scale_bounds))
    return s, R, mu_d - s * R @ mu_s


def similarity_icp(points, tree, target, s, R, t, iterations, trim=TRIM, with_scale=True):
    """Trimmed ICP of ``points`` onto the points of ``tree`` (a cKDTree of ``target``).

    Parameters
    ----------
    points : ndarray of shape (N, 3)
    tree : scipy.spatial.cKDTree
    target : ndarray of shape (M, 3)
    s, R, t : float, ndarray of shape (3, 3), ndarray of shape (3,)
        Start: ``p -> s R p + t``.
    iterations : int
    trim : float
        Share of the pairs kept each iteration (the nearest).

    Returns
    -------
    s, R, t, rms : the fit and its trimmed RMS distance (target units).
    """
    keep = max(3, int(trim * len(points)))
    rms = np.inf
    for _ in range(iterations):
        moved = s * points @ R.T + t
        d, j = tree.query(moved)
        best = np.argpartition(d, keep - 1)[:keep]
        s, R, t = umeyama(points[best], target[j[best]], with_scale)
        rms = float(np.sqrt(np.mean(d[best] ** 2)))
    return s, R, t, rms


def mirror_normal(points, rng):
    """The normal of the mirror plane of a point set, among its three principal axes (a
    mirror-symmetric set has the plane's normal as one of them), refined by :func:`symmetry_plane`:
    ``(n, d)`` of the plane ``n . p = d`` with the smallest mirror residual."""
    sample = _sample(points, MIRROR_POINTS, rng)
    centre = sample.mean(axis=0)
    _, _, axes = np.linalg.svd(sample - centre, full_matrices=False)
    best = None
    for axis in axes:
        B = _basis(axis)  # rows: the axis, two in-plane directions
        local = (sample - centre) @ B.T
        n, d, rms = symmetry_plane(local, with_rms=True)
        if best is None or rms < best[2]:
            best = (n @ B, d + (n @ B) @ centre, rms)
    return best[0], best[1]


def _basis(axis, reference=None):
    """A rotation ``(3, 3)`` whose first row is the unit ``axis`` and whose second is the part
    of ``reference`` normal to it (default: a coordinate axis, which depends on the pose)."""
    axis = axis / np.linalg.norm(axis)
    if reference is None:
        reference = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
    e1 = reference - (reference @ axis) * axis
    e1 /= np.linalg.norm(e1)
    return np.array([axis, e1, np.cross(axis, e1)])


def in_plane_axis(points, normal):
    """The principal axis of ``points`` (N, 3) nearest to the plane of ``normal``: a direction
    the mesh itself fixes (for a skull, about front to back), so that the turns of
    :func:`candidate_rotations` start at the same place on the skull whatever its pose."""
    _, _, axes = np.linalg.svd(points - points.mean(axis=0), full_matrices=False)
    return axes[int(np.argmin(np.abs(axes @ normal)))]


def candidate_rotations(normal, reference=None):
    """Rotations taking the mirror plane's ``normal`` to +x or -x, every
    :data:`TURN_STEP_DEG` about x, the first taking ``reference`` (:func:`in_plane_axis`) to
    +y: ``(K, 3, 3)``."""
    out = []
    for sign in (1.0, -1.0):
        B = _basis(sign * normal, reference)
        for a in np.radians(np.arange(0.0, 360.0, TURN_STEP_DEG)):
            c, s = np.cos(a), np.sin(a)
            out.append(np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ B)
    return np.array(out)


def _sample(points, n, rng):
    return points[rng.choice(len(points), size=min(n, len(points)), replace=False)]


def align_to_template(vertices, templates, score, rng=0):
    """The similarity that brings a mesh onto the best of a few templates.

    The mesh's mirror plane (:func:`mirror_normal`) fixes its x axis up to sign; the turns about
    it (:func:`candidate_rotations`) start a coarse rigid ICP onto each template; the
    :data:`FINE_CANDIDATES` best are refined (similarity ICP) and ``score`` picks the winner.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        The mesh (or a sample of its surface), mm.
    templates : dict of key -> ndarray of shape (M, 3)
        Template point sets (skull frame, mm), e.g. with and without the mandible.
    score : callable
        ``score(fit, key) -> float``, lower is better.
    rng : anything :func:`numpy.random.default_rng` accepts
        Draws the point samples.

    Returns
    -------
    key : the winning template's key
    fit : Alignment
    scores : dict of key -> float (each template's best score)
    fits : dict of key -> Alignment (each template's best fit)
    """
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(rng)
    n, d = mirror_normal(vertices, rng)
    coarse = _sample(vertices, COARSE_POINTS, rng)
    fine = _sample(vertices, FINE_POINTS, rng)
    on_plane = vertices.mean(axis=0) - (n @ vertices.mean(axis=0) - d) * n
    starts = candidate_rotations(n, in_plane_axis(coarse, n))
    best, scores, fits_by_key = None, {}, {}
    for key, points in templates.items():
        target = _sample(points, COARSE_TEMPLATE_POINTS, rng)
        tree = cKDTree(target)
        fits = []
        for R in starts:
            t = points.mean(axis=0) - R @ on_plane
            fits.append(similarity_icp(coarse, tree, target, 1.0, R, t, COARSE_ITERATIONS,
                                       with_scale=False))  # fmt: skip
        fits.sort(key=lambda f: f[3])
        tree = cKDTree(points)
        for s0, R0, t0, _ in fits[:FINE_CANDIDATES]:
            s, R, t, rms = similarity_icp(fine, tree, points, s0, R0, t0, FINE_ITERATIONS)
            mesh2skull = np.eye(4)
            mesh2skull[:3, :3], mesh2skull[:3, 3] = R, t / s
            fit = Alignment(mesh2skull, float(s), rms)
            value = score(fit, key)
            if value < scores.get(key, np.inf):
                scores[key], fits_by_key[key] = value, fit
            if best is None or value < best[0]:
                best = (value, key, fit)
    return best[1], best[2], scores, fits_by_key


def symmetrise(fit, points):
    """``fit`` turned and shifted so that the mirror plane of ``points`` (mesh frame, e.g. a
    sample of the cranium's) is ``x = 0`` of the normalised frame.

    Returns
    -------
    Alignment
    """
    R, t = fit.mesh2skull[:3, :3], fit.mesh2skull[:3, 3]
    n, d = symmetry_plane(fit.to_skull(points))
    # The smallest rotation taking n to +x, about the axis n x e_x.
    ex = np.array([1.0, 0.0, 0.0])
    axis = np.cross(n, ex)
    sin, cos = np.linalg.norm(axis), float(n @ ex)
    Q = np.eye(3)
    if sin > 1e-12:
        k = axis / sin
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        Q = Q + sin * K + (1 - cos) * K @ K
    mesh2skull = np.eye(4)
    # A point of the plane (d n) goes to x = 0.
    mesh2skull[:3, :3], mesh2skull[:3, 3] = Q @ R, Q @ t - np.array([d, 0.0, 0.0])
    return Alignment(mesh2skull, fit.scale, fit.rms_mm)


def symmetry_plane(points, iterations=MIRROR_ITERATIONS, trim=MIRROR_TRIM, with_rms=False):
    """The mirror-symmetry plane of a point set near the plane ``x = 0``.

    The points mirrored in ``x = 0`` are fitted back onto themselves (trimmed rigid ICP);
    the fitted improper isometry ``p -> R S p + t`` (``S = diag(-1, 1, 1)``) is the reflection in
    the plane ``n . p = d`` with ``n`` the eigenvector of ``R S`` for -1 and ``d = n . t / 2``.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
        Roughly symmetric about ``x = 0``.

    Returns
    -------
    n : ndarray of shape (3,)
        Unit normal, ``n[0] > 0``.
    d : float
    rms : float
        The mirror fit's trimmed RMS (only ``with_rms``).
    """
    from scipy.spatial import cKDTree

    mirrored = points * (-1.0, 1.0, 1.0)
    tree = cKDTree(points)
    _, R, t, rms = similarity_icp(mirrored, tree, points, 1.0, np.eye(3), np.zeros(3),
                                  iterations, trim, with_scale=False)  # fmt: skip
    w, v = np.linalg.eig(R @ np.diag([-1.0, 1.0, 1.0]))
    n = np.real(v[:, np.argmin(np.real(w))])
    n = n / np.linalg.norm(n) * (1.0 if n[0] >= 0 else -1.0)
    return (n, float(n @ t / 2.0), rms) if with_rms else (n, float(n @ t / 2.0))
