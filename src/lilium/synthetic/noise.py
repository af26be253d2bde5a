"""Noise profiles of the paper's experiments (docs/method/evaluation.md).

- ``A`` (ideal): no noise.
- ``B`` (landmark noise): each given 2D landmark moved by an offset drawn uniformly in
  ``[-5, 5]`` px, independently per coordinate (:func:`perturb_landmarks`).
- ``C`` (realistic): the landmarks of B (the same noisy positions) plus soft-tissue directions
  perturbed by up to 30 degrees: :data:`N_AXES_SETS` perturbed copies of the subject's
  ``soft_tissue_axes`` (:func:`perturbed_axes_sets`), each axis rotated away from the truth by an
  angle uniform *on the spherical cap* of half-angle 30 degrees (so directions are uniform on
  the cap, the angle itself has density ~ sin), about a uniformly random azimuth. The methods
  run once per set (5 sets x 5 DE runs = 25 executions per SFO in the paper's protocol).
"""

import numpy as np

from ..constants import EXPERIMENTS as NOISE_PROFILES

#: Largest landmark offset (pixels, per coordinate) of profiles B and C.
LANDMARK_NOISE_PX = 5.0

#: Largest angle (degrees) between a perturbed soft-tissue axis and the true one (profile C).
AXIS_NOISE_DEG = 30.0

#: Number of perturbed soft-tissue axis sets per subject (profile C).
N_AXES_SETS = 5


def check_profile(profile):
    if profile not in NOISE_PROFILES:
        raise ValueError(f"noise profile must be one of {NOISE_PROFILES}, got {profile!r}")
    return profile


def perturb_landmarks(landmarks_uv, rng, max_px=LANDMARK_NOISE_PX):
    """Move every 2D landmark by a uniform random offset in ``[-max_px, max_px]`` per coordinate.

    Parameters
    ----------
    landmarks_uv : dict
        Name -> ``(2,)`` pixel position. Names are processed in sorted order, so the result
        does not depend on the dict's order.
    rng : anything ``np.random.default_rng`` accepts
    max_px : float

    Returns
    -------
    dict
        Name -> ``ndarray (2,)``.
    """
    rng = np.random.default_rng(rng)
    names = sorted(landmarks_uv)
    offsets = rng.uniform(-max_px, max_px, size=(len(names), 2))
    return {n: np.asarray(landmarks_uv[n], dtype=float) + offsets[i] for i, n in enumerate(names)}


def random_directions_in_cap(axes, rng, max_deg=AXIS_NOISE_DEG):
    """Unit vectors drawn uniformly on the spherical caps of half-angle ``max_deg`` around ``axes``.

    Parameters
    ----------
    axes : array_like of shape (N, 3)
        Cap centres (normalised here).
    rng : anything ``np.random.default_rng`` accepts
    max_deg : float

    Returns
    -------
    directions : ndarray of shape (N, 3)
    """
    rng = np.random.default_rng(rng)
    a = np.asarray(axes, dtype=float)
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    n = len(a)
    cos_max = np.cos(np.radians(max_deg))
    cos_angle = rng.uniform(cos_max, 1.0, size=n)
    sin_angle = np.sqrt(np.clip(1.0 - cos_angle**2, 0.0, None))
    azimuth = rng.uniform(0.0, 2 * np.pi, size=n)
    # Orthonormal basis (u, v) perpendicular to each axis.
    helper = np.where(np.abs(a[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(a, u)
    d = cos_angle[:, None] * a + sin_angle[:, None] * (
        np.cos(azimuth)[:, None] * u + np.sin(azimuth)[:, None] * v
    )
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def perturb_axes(axes, rng, max_deg=AXIS_NOISE_DEG):
    """One perturbed copy of a soft-tissue axes dict (name -> unit ``(3,)``), names sorted."""
    names = sorted(axes)
    if not names:
        return {}
    d = random_directions_in_cap([axes[n] for n in names], rng, max_deg)
    return {n: d[i] for i, n in enumerate(names)}


def perturbed_axes_sets(axes, rng, n_sets=N_AXES_SETS, max_deg=AXIS_NOISE_DEG):
    """``n_sets`` independent perturbed copies of ``axes`` (profile C).

    Returns
    -------
    list of dict
    """
    rng = np.random.default_rng(rng)
    return [perturb_axes(axes, rng, max_deg) for _ in range(n_sets)]
