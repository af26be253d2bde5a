"""Incomplete subjects and photos for the generator: skulls without the mandible, unmarked
landmarks (what real cases look like and the paper's data never does).

- **Skulls without the mandible.** ``no_mandible_share`` of the subjects of a dataset (the
  nearest whole number of them, at least one when the share is above 0) get a skull without
  its mandible (:func:`lilium.synthetic.subjects.make_subject` with ``mandible=False``): the
  same person, face and photos as in the complete dataset of the same seed, only the skull
  mesh and its landmarks differ. Which subjects: the first ones of a permutation of the
  subject ids drawn from :data:`SELECTION_STREAM` of the dataset seed, independent of every
  subject's own random stream.
- **Unmarked landmarks.** Each visible landmark of a photo is left unmarked (removed from
  ``photo.json``'s ``landmarks``, kept in its ground truth and listed there as
  ``"unmarked_landmarks"``) with probability ``drop_landmark_rate``, drawn from the photo's own
  stream: a hidden mouth corner, an unmarked gonion. At least :data:`MIN_MARKED_PAIRS` landmarks
  that pair with the subject's skull stay marked (the candidates least likely to be dropped are
  kept first), so every photo stays usable. When a landmark that bounds the photo's facial curve
  (:func:`lilium.fitness.curves.face_curve_bounds`: a cheilion in a frontal photo, glabella or
  metopion in a lateral one) is unmarked, the photo folder has no ``face_curve.json`` either: a
  user who did not mark the landmark did not cut the curve at it.

The defaults (share 0, rate 0) draw nothing and change nothing: datasets stay bit-identical to
those made before these options existed; the paper's presets keep them (the paper's subjects and
photos are complete).
"""

import numpy as np

from ..fitness.curves import face_curve_bounds

#: Marked landmarks with a cranial counterpart on the subject's skull that every photo keeps.
MIN_MARKED_PAIRS = 6

#: Extra word of the dataset seed's stream that picks the subjects without the mandible.
SELECTION_STREAM = 0x6D616E64  # "mand"


def check_fraction(value, name, closed=True):
    """``value`` as a float in [0, 1] (``[0, 1)`` unless ``closed``), or a ``ValueError``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in [0, 1], got {value!r}") from None
    if not (0.0 <= x <= 1.0) or (not closed and x >= 1.0):
        span = "[0, 1]" if closed else "[0, 1)"
        raise ValueError(f"{name} must be a number in {span}, got {value!r}")
    return x


def mandible_less(subject_ids, share, seed):
    """The ids of the subjects whose skull has no mandible.

    Parameters
    ----------
    subject_ids : sequence of str
    share : float
        In [0, 1]; ``round(share * n)`` subjects, at least one when ``share > 0``.
    seed : int
        The dataset seed.

    Returns
    -------
    frozenset of str
    """
    share = check_fraction(share, "no_mandible_share")
    n = len(subject_ids)
    k = min(n, max(1, int(np.floor(share * n + 0.5)))) if share > 0 else 0
    if k == 0:
        return frozenset()
    order = np.random.default_rng([int(seed), SELECTION_STREAM]).permutation(n)
    return frozenset(subject_ids[i] for i in order[:k])


def unmarked_landmarks(visible, pairable, rate, rng, min_pairs=MIN_MARKED_PAIRS):
    """Which visible landmarks of a photo are left unmarked.

    Parameters
    ----------
    visible : sequence of str
        The photo's visible facial landmarks, in order.
    pairable : collection of str
        Facial names whose cranial counterpart the subject's skull has.
    rate : float
        Probability that each one is left unmarked, in [0, 1).
    rng : anything :func:`numpy.random.default_rng` accepts
    min_pairs : int
        Pairable landmarks that stay marked at least (the photo's own pairable count if lower).

    Returns
    -------
    tuple of str
        In the order of ``visible``; empty when ``rate`` is 0 (nothing is drawn).
    """
    rate = check_fraction(rate, "drop_landmark_rate", closed=False)
    visible = list(visible)
    if rate == 0 or not visible:
        return ()
    u = np.random.default_rng(rng).uniform(size=len(visible))
    n_pairs = sum(1 for n in visible if n in pairable)
    keep_pairs = min(min_pairs, n_pairs)
    dropped = set()
    for i in np.argsort(u, kind="stable"):
        if u[i] >= rate:
            break
        name = visible[i]
        if name in pairable:
            if n_pairs - 1 < keep_pairs:
                continue
            n_pairs -= 1
        dropped.add(name)
    return tuple(n for n in visible if n in dropped)


def curve_kept(view, unmarked):
    """Whether a photo keeps its ``face_curve.json`` with these landmarks unmarked."""
    return not set(face_curve_bounds(view)) & set(unmarked)
