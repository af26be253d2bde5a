"""Checks of a photo's files against each other, before any SFO (docs/checks.md).

- **left, right, up and down** (:func:`check_photo_labels`): an upside-down photo (any view),
  and in a frontal photo every left/right pair reversed (mirrored) or some pairs reversed while
  the others are not (their labels swapped).
- **landmarks on the face mask** (:func:`check_landmarks_in_mask`): every facial landmark lies
  on the face, so on (or next to) the face mask. Each landmark's distance to the mask (0 inside)
  is divided by the mask's bounding-box diagonal; on clean photos (the stand-in and generated
  experiments A, B and C, noisy landmarks included) this ratio is at most about 0.02, while an
  inverted mask, the mask of another photo or an image rescaled without its landmarks puts
  several landmarks beyond 0.1. A landmark beyond :data:`MASK_OFF_FRACTION` is *off the mask*;
  more than half of them off is an error, some of them a warning ``landmark_outside_mask``.
- **twins at one place** (:func:`coincident_pairs`): a bilateral pair's ``_l`` and ``_r``
  closer than :data:`PAIR_REVERSED_FRACTION` of the landmarks' extent (one copied from the
  other), on a frontal photo and on a skull.
- **one photo given twice** (:func:`check_distinct_photos`): two photos of one view whose
  landmarks match after a similarity within :data:`COPY_FRACTION` (a resized copy).
"""

import numpy as np

from ..imaging.raster import covered_box
from ..inputs import CaseWarning
from ..softtissue.landmarks import side, twin

#: A landmark farther than this fraction of the mask's bounding-box diagonal outside the mask
#: is off it (clean photos: at most about 0.02; broken pairs: 0.1 to 0.6).
MASK_OFF_FRACTION = 0.05

#: What makes a photo's landmarks and mask disagree, and what to check.
MASK_FIX = (
    "the mask may be inverted, of another photo, or the image rescaled without its landmarks; "
    "check that the face is the mask's non-zero pixels and that the image, mask and landmarks "
    "are of the same photo at the same size"
)


def landmark_mask_distances_px(landmarks_uv, mask):
    """Distance of each landmark to the nearest mask pixel (0 on the mask).

    Parameters
    ----------
    landmarks_uv : ndarray of shape (N, 2)
        ``(u = column, v = row)`` pixels; rounded to the nearest pixel, clipped to the image.
    mask : ndarray of shape (H, W), bool
        The face mask.

    Returns
    -------
    ndarray of shape (N,)
        Pixels (the Euclidean distance between pixel centres, as a distance transform gives);
        ``inf`` for every landmark off an empty mask.
    """
    h, w = mask.shape
    cols = np.clip(np.rint(landmarks_uv[:, 0]), 0, w - 1).astype(int)
    rows = np.clip(np.rint(landmarks_uv[:, 1]), 0, h - 1).astype(int)
    out = np.zeros(len(rows))
    outside = ~mask[rows, cols]
    if not outside.any():
        return out  # the clean case: no look at the whole mask
    if not mask.any():
        return np.full(len(rows), np.inf)
    for k in np.flatnonzero(outside):
        out[k] = _distance_to_mask_px(mask, rows[k], cols[k])
    return out


def _distance_to_mask_px(mask, row, col):
    """Distance from pixel ``(row, col)`` to the nearest pixel of a non-empty ``mask``.

    Searched in square windows around the pixel, doubled until one holds a mask pixel within
    its half-width: any pixel outside a window of half-width ``r`` is farther than ``r``, so
    that one is the nearest of all. A landmark a few pixels off the face (the clean case) costs
    a window of a few hundred pixels, not a distance transform of the whole photo (0.17 s at
    24 MP).
    """
    h, w = mask.shape
    radius = 8
    while True:
        r0, r1 = max(row - radius, 0), min(row + radius + 1, h)
        c0, c1 = max(col - radius, 0), min(col + radius + 1, w)
        rr, cc = np.nonzero(mask[r0:r1, c0:c1])
        if len(rr):
            nearest = np.sqrt(np.min((rr + r0 - row) ** 2 + (cc + c0 - col) ** 2))
            if nearest <= radius or (r1 - r0 == h and c1 - c0 == w):
                return float(nearest)
        radius *= 2


def mask_diagonal_px(mask):
    """Diagonal of the mask's bounding box, pixels (``mask`` (H, W) bool, not empty)."""
    rows, cols = covered_box(mask)
    return float(np.hypot(rows.stop - rows.start, cols.stop - cols.start))


def landmark_mask_ratios(photo):
    """Each landmark's distance to the face mask over the mask's bounding-box diagonal.

    Parameters
    ----------
    photo : Photo

    Returns
    -------
    dict of str -> float
        By landmark name, 0 on the mask; empty without a mask (or an empty one).
    """
    mask = photo.face_mask
    if mask is None or not photo.landmarks_uv:
        return {}
    mask = np.asarray(mask, bool)
    names = list(photo.landmarks_uv)
    uv = np.array([np.asarray(photo.landmarks_uv[n], float) for n in names])
    ratios = landmark_mask_distances_px(uv, mask)
    if np.isinf(ratios).any():
        return {}  # an empty mask (refused where masks are read)
    if ratios.any():  # the clean case skips the scan of the whole mask for its diagonal
        ratios = ratios / mask_diagonal_px(mask)
    return dict(zip(names, ratios.tolist(), strict=True))


def check_landmarks_in_mask(photo):
    """The facial landmarks against the face mask: an error, a warning or nothing.

    Parameters
    ----------
    photo : Photo
        Its ``landmarks_uv`` (pixels) and ``face_mask`` ((H, W) bool or None: nothing checked).

    Returns
    -------
    list of CaseWarning
        One ``landmark_outside_mask`` naming the landmarks off the mask when some, but at most
        half, are farther than :data:`MASK_OFF_FRACTION` of the mask's bounding-box diagonal
        outside it; else empty.

    Raises
    ------
    ValueError
        More than half of the landmarks off the mask, naming the landmark file (or the photo),
        their number and the fix (:data:`MASK_FIX`).
    """
    where, mask = _where(photo)  # the files the messages name
    ratios = landmark_mask_ratios(photo)
    off = sorted((n for n, r in ratios.items() if r > MASK_OFF_FRACTION), key=ratios.get)[::-1]
    if not off:
        return []
    worst = f"up to {ratios[off[0]]:.2f} of the mask's bounding-box diagonal"
    counted = f"{len(off)} of {len(ratios)} facial landmarks lie outside {mask}"
    if 2 * len(off) > len(ratios):
        raise ValueError(f"{where}: {counted} ({worst}; {_names(off)}){_small(photo)}: {MASK_FIX}")
    return [
        CaseWarning(
            "landmark_outside_mask",
            f"{where}: {counted} ({worst}): {_names(off)}; check these landmarks and the mask: "
            f"{MASK_FIX}",
        )
    ]


def _small(photo):
    """A clause for a mask far smaller than the landmarks' box (a pixel, a line), else ""."""
    uv = np.array([np.asarray(p, float) for p in photo.landmarks_uv.values()])
    box = float(np.prod(np.ptp(uv, axis=0) + 1))
    area = int(np.count_nonzero(photo.face_mask))
    if area >= 0.1 * box:
        return ""
    return f"; the mask covers {area} px against {box:.0f} px for the landmarks' box"


def _where(photo):
    """The landmark file (else the photo) and the mask, as the message names them."""
    mask = f"the face mask {photo.mask_file}" if photo.mask_file else None
    if photo.landmarks_file:
        return str(photo.landmarks_file), mask or f"the face mask of photo {photo.id!r}"
    return f"photo {photo.id!r}", mask or "its face mask"


def _names(names, limit=8):
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown} and {len(names) - limit} more"


def photo_pair_order(landmarks_uv):
    """Bilateral pairs of a photo's landmarks and how many are reversed for a frontal view.

    Returns
    -------
    pairs : list of str
        Base names of the pairs present (``"exocanthion"``, ...).
    reversed_pairs : list of str
        Those whose ``_l`` landmark lies at a smaller ``u`` than its ``_r`` twin.
    """
    pairs, reversed_pairs = [], []
    for name, uv in landmarks_uv.items():
        if side(name) == "l" and twin(name) in landmarks_uv:
            base = name[:-2]
            pairs.append(base)
            if float(uv[0]) < float(landmarks_uv[twin(name)][0]):
                reversed_pairs.append(base)
    return pairs, reversed_pairs


#: A photo's facial landmarks above the eyes and below the nose (its midline): every upper one
#: lies above every lower one in an upright photo, whatever the view.
PHOTO_UPPER_MIDLINE = ("nasion", "glabella", "metopion", "bregma")
PHOTO_LOWER_MIDLINE = ("subnasale", "labiale_superius", "pogonion", "gnathion")

#: A frontal photo's pair is reversed when its ``_l`` twin lies left of its ``_r`` twin by more
#: than this share of the landmarks' extent (on 322 generated frontal photos, Exp. A-C, every
#: pair lay the right way round by at least 0.13 of the extent); and its twins are at one place
#: (one copied from the other) when they lie closer than this share apart. The same share of
#: the cranial landmarks' extent tells a skull's twins at one place.
PAIR_REVERSED_FRACTION = 0.02


#: Two photos of one case are copies of one photo (one perhaps resized, recompressed or its
#: landmarks placed again) when their common landmarks match after scaling, turning and moving
#: to within this share of their extent (root mean square). Two photos taken apart differ by
#: the pose, the expression and the hand that placed the landmarks: several per cent.
COPY_FRACTION = 0.005


def copy_residual(uv_a, uv_b):
    """Root-mean-square residual of ``uv_b`` (N, 2) fitted to ``uv_a`` (N, 2) by a similarity
    (scale, rotation, translation; no reflection), as a share of ``uv_a``'s extent; ``inf``
    when either set is a single point."""
    a = np.asarray(uv_a, float) - np.mean(uv_a, axis=0)
    b = np.asarray(uv_b, float) - np.mean(uv_b, axis=0)
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return np.inf
    u, sv, vt = np.linalg.svd((b / nb).T @ (a / na))
    fit = sv[0] + np.sign(np.linalg.det(u @ vt)) * sv[1]  # the best proper rotation's
    disparity = max(0.0, 1.0 - fit**2)  # of the unit-norm sets
    rms_px = np.sqrt(disparity / len(a)) * na
    return float(rms_px / max(np.ptp(a, axis=0).max(), 1e-12))


def check_distinct_photos(photos):
    """Raise when two photos of one person are copies of one photo (:data:`COPY_FRACTION`):
    counted twice, one photo's evidence would lift the single-photo cap and double its weight.

    Parameters
    ----------
    photos : list of Photo
        The photos of one case (or of one lineup candidate).

    Raises
    ------
    ValueError
        Naming both landmark files (or photos) and the fix.
    """
    for i, p in enumerate(photos):
        for q in photos[i + 1 :]:
            common = [n for n in p.landmarks_uv if n in q.landmarks_uv]
            if len(common) < 4 or p.view != q.view:
                continue
            residual = copy_residual(
                [p.landmarks_uv[n] for n in common], [q.landmarks_uv[n] for n in common]
            )
            if residual <= COPY_FRACTION:
                a = p.landmarks_file or f"photo {p.id!r}"
                b = q.landmarks_file or f"photo {q.id!r}"
                raise ValueError(
                    f"{b}: its {len(common)} landmarks lie where {a} has them (to "
                    f"{residual:.2%} of their extent after scaling): the two are one photo "
                    "(a copy, perhaps resized); give each photo once, or it counts as two "
                    "views of the person"
                )


def coincident_pairs(landmarks):
    """Base names of the bilateral pairs whose twins lie at one place: closer than
    :data:`PAIR_REVERSED_FRACTION` of the landmarks' extent (2D or 3D points)."""
    points = np.asarray(list(landmarks.values()), float)
    limit = PAIR_REVERSED_FRACTION * float(np.ptp(points, axis=0).max())
    return [
        name[:-2]
        for name, p in landmarks.items()
        if side(name) == "l"
        and twin(name) in landmarks
        and np.linalg.norm(np.asarray(p, float) - landmarks[twin(name)]) <= limit
    ]


def coincident_message(where, bases, unit):
    """The error for twins at one place (``unit``: ``"px"`` or ``"mm"``)."""
    names = ", ".join(f"{b}_l and {b}_r" for b in bases)
    return (
        f"{where}: {names} lie at one place (under 2 % of the landmarks' extent apart, in "
        f"{unit}): one was copied from the other or placed on the wrong side; place each on its "
        "own side, or delete the one that is not seen"
    )


def _upside_down(landmarks_uv):
    """Whether every upper midline landmark lies below (larger ``v``) every lower one."""
    upper = [float(landmarks_uv[n][1]) for n in PHOTO_UPPER_MIDLINE if n in landmarks_uv]
    lower = [float(landmarks_uv[n][1]) for n in PHOTO_LOWER_MIDLINE if n in landmarks_uv]
    return bool(upper and lower) and min(upper) > max(lower)


def check_photo_labels(photo):
    """Raise when a photo's landmarks cannot be the right way up and round: the forehead's
    midline landmarks below the chin's (an upside-down photo, any view); in a frontal photo,
    every left/right pair reversed (a mirrored photo, or all labels swapped), or some pairs
    clearly reversed while the others are not (those pairs' labels swapped).

    A swapped pair is not noise a fit absorbs: it pulls the camera tens of pixels off, and the
    identification would read a labelling slip as a different person.

    Raises
    ------
    ValueError
        Naming ``photo.landmarks_file`` and what to turn, flip or swap.
    """
    where = photo.landmarks_file or f"photo {photo.id!r}: facial landmarks"
    lm = photo.landmarks_uv
    if _upside_down(lm):
        upper = ", ".join(n for n in PHOTO_UPPER_MIDLINE if n in lm)
        lower = ", ".join(n for n in PHOTO_LOWER_MIDLINE if n in lm)
        raise ValueError(
            f"{where}: {upper} lie below {lower}: the photo is upside down or flipped top to "
            "bottom (turn the image and its landmarks upright), or those labels are mixed up"
        )
    if photo.view != "frontal":
        return
    together = coincident_pairs(lm)
    if together:
        raise ValueError(coincident_message(where, together, "px"))
    pairs, reversed_pairs = photo_pair_order(lm)
    if not pairs:
        return
    if len(reversed_pairs) == len(pairs):
        raise ValueError(
            f"{where}: in this frontal photo every _l landmark lies left of its _r twin "
            f"({', '.join(pairs)}), but facing the camera the subject's left is on the image's "
            "right: the photo is mirrored (a selfie or a flipped scan: flip the image and its "
            "landmarks horizontally) or _l and _r are swapped in the labels (swap them)"
        )
    extent = float(np.ptp(np.asarray(list(lm.values()), float), axis=0).max())
    swapped = [
        b
        for b in reversed_pairs
        if lm[f"{b}_r"][0] - lm[f"{b}_l"][0] > PAIR_REVERSED_FRACTION * extent
    ]
    if swapped:
        right = [b for b in pairs if b not in reversed_pairs]
        raise ValueError(
            f"{where}: in this frontal photo {', '.join(b + '_l' for b in swapped)} lie left of "
            f"their _r twins while {', '.join(right)} lie the right way round (the subject's "
            "left on the image's right): swap _l and _r of "
            f"{', '.join(swapped)}, or give the photo's view if it is not frontal"
        )
