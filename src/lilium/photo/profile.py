"""Profile landmarks from the head's silhouette, for photos beyond the face mesh's yaw range
(docs/method/photo.md, "Profiles").

In a lateral photo the face mesh finds nothing, but the person segmentation still draws the
head's silhouette, and the silhouette's front edge is the profile line: its extremes and
concavities are soft-tissue landmarks. The rules, in the *face frame* of the silhouette
(``a`` = anterior, towards the nose; ``b`` = inferior, along the face line; pixels):

1. **facing side**: the nose is the silhouette's sharpest protrusion; the side whose front edge
   protrudes most beyond both its neighbours :data:`SPIKE_WINDOW` head lengths above and below
   (the smaller of the two steps) is the face (``lateral_left``: the nose points to the
   image's left, -u, docs/contract.md);
2. **profile line**: the outline from the top of the head down the front to
   :data:`PROFILE_DEPTH` head lengths below the top (head length: the silhouette's largest
   front-to-back extent within its top part), resampled at 1 px;
3. **pronasale**: the most anterior point between :data:`NOSE_ROWS` head lengths below the top;
4. **nasion**: on the line's stretch from pronasale up to :data:`FOREHEAD_ROWS` head lengths
   above it, the point deepest behind the stretch's anterior convex hull (the nasal root);
   **glabella**: the most anterior point within :data:`GLABELLA_ROWS` face heights above nasion;
5. **cervical point** (throat): on the line from pronasale down to its lowest point within
   :data:`THROAT_DEPTH` head lengths below pronasale, the point deepest behind the stretch's
   anterior convex hull, and at least :data:`THROAT_MIN` head lengths below pronasale;
6. **gnathion**: between pronasale and the throat, the point furthest along the bisector of
   anterior and inferior (``a + b``), the lowest-most-anterior chin point;
7. **subnasale, labiale superius, stomion, labiale inferius**: behind the chord pronasale -
   gnathion, the line's depth alternates: subnasale is the first concavity below the nose, then
   the upper lip's convexity (labiale superius), the mouth's concavity (stomion), the lower
   lip's convexity (labiale inferius);
8. **pogonion**: the lowest local maximum of ``a`` within :data:`CHIN_ROWS` face heights above
   gnathion; a receding chin has none, and pogonion is then put :data:`POGONION_ROWS` face
   heights above gnathion, as template.

Rules 3-8 run twice: once with the image's vertical as the face line, then with the face line
through nasion and pogonion (a head nodding by 10 degrees moves "most anterior" along the chin).

Each point is tagged by how well the line's geometry locates it: ``tracked`` when the stretch
of the line within :data:`LOCATE_TOL` face heights of the extreme (or concavity) is at most
:data:`LOCATE_SPAN` face heights long on either side, else ``template``; and only points of
:data:`PROFILE_TRACKABLE` (those measured within 5 % of the face height, docs/method/photo.md)
can be tracked at all. Face height: nasion to gnathion. ``pronasale``, ``stomion`` and
``labiale_inferius`` are not catalogue landmarks (docs/method/skull.md): they are returned as
``anchors`` and not written to ``photo.json``.
"""

from dataclasses import dataclass, field

import cv2
import numpy as np

from .landmarks import TEMPLATE, TRACKED

#: Person probability above which a pixel is the person.
PERSON_THRESHOLD = 0.5
#: Crop around the person for the second segmentation pass, over the person's box side.
CROP_MARGIN = 0.15
#: Window (head lengths) of the protrusion that finds the nose (rule 1).
SPIKE_WINDOW = 0.06
#: The profile line ends this many head lengths below the top of the head (rule 2).
PROFILE_DEPTH = 1.8
#: Pronasale is searched between these depths below the top, in head lengths (rule 3).
NOSE_ROWS = (0.35, 1.1)
#: The throat is searched this far below pronasale, in head lengths (rule 4).
THROAT_DEPTH = 0.9
#: ... and at least this far below it (the lips' concavities lie above).
THROAT_MIN = 0.3
#: Nasion is searched this far above pronasale, in head lengths (rule 7).
FOREHEAD_ROWS = 0.45
#: Pogonion is the lowest extreme within CHIN_ROWS face heights above gnathion; without one (a
#: receding chin) it is put POGONION_ROWS face heights above gnathion, as template (rule 5).
CHIN_ROWS = 0.22
POGONION_ROWS = 0.08
#: Glabella is searched this far above nasion, in face heights (rule 7).
GLABELLA_ROWS = 0.3
#: Smoothing of the line (Gaussian sigma, head lengths) before extremes are read.
SMOOTH = 0.004
#: Smallest prominence of an extreme or a concavity, in head lengths.
MIN_PROMINENCE = 0.008
#: Quality: an extreme (or concavity) is ``tracked`` when the line stays within LOCATE_TOL face
#: heights of it over at most LOCATE_SPAN face heights on either side.
LOCATE_TOL = 0.01
LOCATE_SPAN = 0.05
#: The profile landmarks that may be tracked at all: those within 5 % of the face height of the
#: true point on every measured lateral render (``benchmarks/studies/photo_profile.py``,
#: docs/method/photo.md, "Profiles"). None is yet: nasion comes closest (at most 4.6 % on the
#: renders' own masks, 5.3 % through the segmentation), the segmentation loses the nose or the
#: chin of some renders. The geometric tag (``span_face_heights``) is still written.
PROFILE_TRACKABLE = ()
#: The head mask: the person mask cut this many face heights below gnathion, perpendicular to
#: the face line (as :mod:`.mask` does for frontal photos).
NECK_BELOW_CHIN = 0.25
#: Catalogue facial landmarks the profile gives (docs/method/skull.md), top-down.
PROFILE_LANDMARKS = (
    "glabella",
    "nasion",
    "subnasale",
    "labiale_superius",
    "pogonion",
    "gnathion",
)


@dataclass(frozen=True)
class Profile:
    """Profile landmarks of one silhouette; falsy (with a ``message``) when none were found.

    Attributes
    ----------
    message : str
        Empty on success; otherwise why the profile gave no landmarks.
    view : str
        ``lateral_left`` (the nose points to -u) or ``lateral_right``.
    line_uv : ndarray of shape (N, 2)
        The profile line, top-down, image pixels (u, v).
    landmarks : dict of str -> ndarray of shape (2,)
        Catalogue facial landmarks (:data:`PROFILE_LANDMARKS`), image pixels.
    sources : dict of str -> dict
        ``{"source": "automatic", "quality": ..., "from": "profile"}`` per landmark.
    anchors : dict of str -> ndarray of shape (2,)
        Points that are not catalogue landmarks (pronasale, stomion, labiale_inferius, cervical).
    face_height_px : float
        Nasion to gnathion.
    """

    message: str = ""
    view: str = ""
    line_uv: np.ndarray | None = None
    landmarks: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    anchors: dict = field(default_factory=dict)
    face_height_px: float = 0.0

    def __bool__(self):
        return not self.message


def _largest_part(mask):
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8))
    if n < 2:
        return np.zeros(mask.shape, bool)
    part = labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    # Holes filled: the outer outline is all the profile needs.
    contours, _ = cv2.findContours(part.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    filled = np.zeros(mask.shape, np.uint8)
    cv2.drawContours(filled, contours, -1, 1, thickness=cv2.FILLED)
    return filled.astype(bool)


def person_silhouette(image, person_prob=None):
    """The person's silhouette, segmented twice: on the photo, then on a crop around the person.

    The segmentation model sees 256 x 256 pixels: on a large photo with a small head, one of its
    pixels covers many of the photo's, too coarse for a profile. The second pass runs on a square
    crop round the person found by the first (:data:`CROP_MARGIN`).

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
    person_prob : ndarray of shape (H, W), optional
        The first pass's person probability, if already computed.

    Returns
    -------
    ndarray of shape (H, W), bool
        The largest connected part, holes filled; all False when no person was found.
    """
    from . import runtime

    h, w = image.shape[:2]
    prob = runtime.person_mask(image) if person_prob is None else person_prob
    first = _largest_part(prob > PERSON_THRESHOLD)
    if not first.any():
        return first
    rows, cols = np.nonzero(first)
    v0, v1, u0, u1 = rows.min(), rows.max(), cols.min(), cols.max()
    side = (1 + 2 * CROP_MARGIN) * max(v1 - v0, u1 - u0) + 1
    cu, cv = (u0 + u1) / 2, (v0 + v1) / 2
    a_u, a_v = int(round(cu - side / 2)), int(round(cv - side / 2))
    n = int(round(side))
    pad = max(0, -a_u, -a_v, a_u + n - w, a_v + n - h)
    padded = cv2.copyMakeBorder(image, pad, pad, pad, pad, cv2.BORDER_REPLICATE)
    crop = np.ascontiguousarray(padded[a_v + pad : a_v + pad + n, a_u + pad : a_u + pad + n])
    crop_prob = runtime.person_mask(crop)
    full = np.zeros((h + 2 * pad, w + 2 * pad), np.float32)
    full[a_v + pad : a_v + pad + n, a_u + pad : a_u + pad + n] = crop_prob
    return _largest_part(full[pad : pad + h, pad : pad + w] > PERSON_THRESHOLD)


def _outline(mask):
    """The outer outline, ``(N, 2)`` (u, v) closed, resampled at 1 px."""
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    contour = max(contours, key=len)[:, 0, :].astype(float)
    closed = np.vstack([contour, contour[:1]])
    step = np.linalg.norm(np.diff(closed, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    t = np.arange(0.0, s[-1], 1.0)
    return np.stack([np.interp(t, s, closed[:, 0]), np.interp(t, s, closed[:, 1])], axis=1)


def _head_length(mask):
    """The head's largest front-to-back extent (pixels) in the top part of the silhouette, found
    as the fixed point of "the widest row within 0.75 of it below the top"."""
    rows = np.nonzero(mask.any(axis=1))[0]
    top, bottom = rows[0], rows[-1]
    any_col = mask[top : bottom + 1]
    first = np.argmax(any_col, axis=1)
    last = any_col.shape[1] - 1 - np.argmax(any_col[:, ::-1], axis=1)
    width = np.where(any_col.any(axis=1), last - first + 1, 0)
    k = bottom - top + 1
    for _ in range(8):
        k_new = int(width[: max(1, int(0.75 * k))].max())
        if k_new == k:
            break
        k = k_new
    return float(k), int(top)


def _front_rows(mask, top, length, facing_left):
    """Per row below the top, the silhouette's front edge ``a`` (anterior pixels) and the rows."""
    n = int(min(mask.shape[0] - top, PROFILE_DEPTH * length))
    band = mask[top : top + n]
    present = band.any(axis=1)
    if facing_left:
        edge = -np.argmax(band, axis=1).astype(float)
    else:
        edge = (band.shape[1] - 1 - np.argmax(band[:, ::-1], axis=1)).astype(float)
    return edge[present], np.arange(top, top + n)[present]


def _protrusion(edge, length):
    w = max(2, int(round(SPIKE_WINDOW * length)))
    if len(edge) <= 2 * w:
        return 0.0
    mid = edge[w:-w]
    return float(np.max(np.minimum(mid - edge[: -2 * w], mid - edge[2 * w :])))


def facing_side(mask):
    """``"lateral_left"`` (the nose points to the image's left, -u) or ``"lateral_right"``.

    The nose is the silhouette's sharpest protrusion (rule 1 of the module): the side whose front
    edge (per row, within the head) rises most above the mean of the edge
    :data:`SPIKE_WINDOW` head lengths above and below.

    Parameters
    ----------
    mask : ndarray of shape (H, W), bool

    Returns
    -------
    view : str
    margin : float
        The winning side's protrusion less the other's, in head lengths (near 0: ambiguous).
    """
    length, top = _head_length(mask)
    left = _protrusion(_front_rows(mask, top, length, True)[0], length)
    right = _protrusion(_front_rows(mask, top, length, False)[0], length)
    view = "lateral_left" if left > right else "lateral_right"
    return view, abs(left - right) / length


def profile_line(mask, view):
    """The profile line: the outline from the top of the head down the face, ``(N, 2)`` (u, v),
    top-down, 1 px apart (rule 2 of the module)."""
    length, top = _head_length(mask)
    outline = _outline(mask)
    forward = -1.0 if view == "lateral_left" else 1.0
    # Start at the top of the head (of the top row, its most anterior pixel).
    v_min = outline[:, 1].min()
    at_top = np.nonzero(outline[:, 1] <= v_min + 0.5)[0]
    start = at_top[np.argmax(forward * outline[at_top, 0])]
    stop_v = top + PROFILE_DEPTH * length
    best = None
    for direction in (1, -1):
        order = np.roll(outline, -start, axis=0)
        if direction < 0:
            order = np.vstack([order[:1], order[:0:-1]])
        below = np.nonzero(order[:, 1] > stop_v)[0]
        arc = order[: below[0]] if len(below) else order[: len(order) // 2]
        score = forward * arc[:, 0].mean()
        if best is None or score > best[0]:
            best = (score, arc)
    return best[1]


def _smooth(values, sigma):
    if sigma < 0.5:
        return values
    r = int(np.ceil(3 * sigma))
    kernel = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    kernel /= kernel.sum()
    padded = np.pad(values, r, mode="edge")
    return np.convolve(padded, kernel, mode="valid")


def _local_maxima(values, prominence):
    from scipy.signal import find_peaks

    peaks, _ = find_peaks(values, prominence=prominence)
    return peaks


def _span(values, k, tol):
    """Arc length (samples) on each side of index ``k`` over which ``values`` stays within
    ``tol`` of ``values[k]`` (the larger of the two sides)."""
    inside = np.abs(values - values[k]) <= tol
    lo = k
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    hi = k
    while hi < len(values) - 1 and inside[hi + 1]:
        hi += 1
    return max(k - lo, hi - k)


def _depth_below(points_ab, i, j):
    """Depth of the line's points between ``i`` and ``j`` behind the chord from i to j (pixels,
    positive: behind, i.e. a concavity), over the whole line (outside ``[i, j]``: 0)."""
    p, q = points_ab[i], points_ab[j]
    d = q - p
    normal = np.array([d[1], -d[0]]) / max(np.linalg.norm(d), 1e-9)  # (a, b) -> anterior side
    if normal[0] < 0:
        normal = -normal
    depth = np.zeros(len(points_ab))
    depth[i : j + 1] = -(points_ab[i : j + 1] - p) @ normal
    return depth


def _envelope_depth(a, b):
    """How far each point ``(a, b)`` lies behind the upper concave envelope of ``a`` over ``b``
    (the anterior convex hull of a stretch of the line), ``(N,)`` pixels >= 0."""
    order = np.argsort(b, kind="stable")
    hull = []
    for k in order:
        while len(hull) >= 2:
            (b1, a1), (b2, a2) = (b[hull[-2]], a[hull[-2]]), (b[hull[-1]], a[hull[-1]])
            if (b2 - b1) * (a[k] - a1) - (a2 - a1) * (b[k] - b1) >= 0:
                hull.pop()
            else:
                break
        hull.append(k)
    hull = np.array(hull)
    return np.interp(b, b[hull], a[hull]) - a


def _read_profile(line_uv, view, length, down):
    """Rules 3-8 on the line in the frame whose inferior axis is ``down`` (unit, image uv)."""
    forward = np.array([-1.0, 0.0]) if view == "lateral_left" else np.array([1.0, 0.0])
    # The anterior axis: perpendicular to ``down``, on the nose's side.
    ant = np.array([down[1], -down[0]])
    if ant @ forward < 0:
        ant = -ant
    a = _smooth(line_uv @ ant, SMOOTH * length)
    b = _smooth(line_uv @ down, SMOOTH * length)
    ab = np.stack([a, b], axis=1)
    b_top = b.min()
    prom = MIN_PROMINENCE * length

    rows = (b >= b_top + NOSE_ROWS[0] * length) & (b <= b_top + NOSE_ROWS[1] * length)
    if not rows.any():
        return None, "the silhouette has no face part (too short below the top of the head)"
    pn = int(np.nonzero(rows)[0][np.argmax(a[rows])])
    below = np.nonzero(b <= b[pn] + THROAT_DEPTH * length)[0]
    below = below[below > pn]
    if len(below) < 3:
        return None, "the silhouette ends at the nose (no lips or chin below it)"
    end = below[-1]
    # Nasion: the deepest point behind the envelope of the forehead and the nose, on the line's
    # stretch going up from the nose tip.
    start = pn
    while start > 0 and b[start - 1] >= b[pn] - FOREHEAD_ROWS * length:
        start -= 1
    if pn - start < 3:
        return None, "the silhouette has no forehead above the nose"
    depth = np.zeros(len(a))
    depth[start : pn + 1] = _envelope_depth(a[start : pn + 1], b[start : pn + 1])
    na = int(np.argmax(depth))
    end = pn + int(np.argmax(b[pn : end + 1]))  # the front only, not round a cut neck
    throat = _envelope_depth(a[pn : end + 1], b[pn : end + 1])
    throat[b[pn : end + 1] < b[pn] + THROAT_MIN * length] = -1.0  # not the lips
    cv = pn + int(np.argmax(throat))
    gn = pn + int(np.argmax((a + b)[pn : cv + 1]))
    face_height = float(np.linalg.norm(ab[gn] - ab[na]))
    if gn - pn < 3 or face_height < 1:
        return None, "no chin found on the silhouette below the nose"
    up = np.arange(start, na)[b[start:na] >= b[na] - GLABELLA_ROWS * face_height]
    gl = int(up[np.argmax(a[up])]) if len(up) else start
    # Below the nose: the depth behind the chord pronasale - gnathion.
    lip_depth = _depth_below(ab, pn, gn)
    conc = _local_maxima(lip_depth[pn : gn + 1], prom) + pn
    conv = _local_maxima(-lip_depth[pn : gn + 1], prom) + pn
    if len(conc) == 0:
        return None, "no subnasale concavity between the nose and the chin"
    sn = int(conc[0])
    chin = np.arange(sn, gn + 1)[b[sn : gn + 1] >= b[gn] - CHIN_ROWS * face_height]
    peaks = _local_maxima(a[sn : gn + 1], prom) + sn
    peaks = peaks[np.isin(peaks, chin)]
    chin_extreme = len(peaks) > 0
    if chin_extreme:
        pog = int(peaks[-1])
    else:  # a receding chin: no extreme, the typical height above gnathion (template)
        pog = int(chin[np.argmin(np.abs(b[chin] - (b[gn] - POGONION_ROWS * face_height)))])
    lips = conv[(conv > sn) & (conv < pog)]
    points = {"pronasale": pn, "nasion": na, "glabella": gl, "subnasale": sn}
    points.update({"pogonion": pog, "gnathion": gn, "cervical": cv})
    span_values = {
        "pronasale": a,
        "glabella": a,
        "nasion": depth,
        "subnasale": lip_depth,
        "pogonion": a if chin_extreme else np.zeros(len(a)),
        "gnathion": (a + b) / np.sqrt(2),
    }
    if len(lips):
        ls = int(lips[0])
        points["labiale_superius"] = ls
        span_values["labiale_superius"] = -lip_depth
        mouth = conc[conc > ls]
        if len(mouth):
            points["stomion"] = int(mouth[0])
            lower = lips[lips > mouth[0]]
            if len(lower):
                points["labiale_inferius"] = int(lower[0])
    return (points, span_values, face_height), ""


def read_profile(mask, view=None):
    """Profile landmarks from a silhouette (rules of the module).

    Parameters
    ----------
    mask : ndarray of shape (H, W), bool
        The person's (or head's) silhouette, one connected part.
    view : {"lateral_left", "lateral_right"}, optional
        Default: :func:`facing_side`.

    Returns
    -------
    Profile
        Falsy with a message when the silhouette has no readable profile.
    """
    mask = np.asarray(mask, bool)
    if mask.sum() < 100:
        return Profile(message="no person found in the photo (the segmentation is empty)")
    view = view or facing_side(mask)[0]
    length, _ = _head_length(mask)
    line = profile_line(mask, view)
    down = np.array([0.0, 1.0])
    found, why = _read_profile(line, view, length, down)
    if found is not None:  # again with the face line nasion -> pogonion as the vertical
        points = found[0]
        axis = line[points["pogonion"]] - line[points["nasion"]]
        if np.linalg.norm(axis) > 0:
            refined, _ = _read_profile(line, view, length, axis / np.linalg.norm(axis))
            found = refined or found
    if found is None:
        return Profile(message=f"no profile read ({why})", view=view, line_uv=line)
    points, span_values, face_height = found
    landmarks, sources, anchors = {}, {}, {}
    for name, k in points.items():
        uv = line[k].copy()
        if name not in PROFILE_LANDMARKS:
            anchors[name] = uv
            continue
        span = _span(span_values[name], k, LOCATE_TOL * face_height)
        located = span <= LOCATE_SPAN * face_height
        quality = TRACKED if located and name in PROFILE_TRACKABLE else TEMPLATE
        landmarks[name] = uv
        sources[name] = {
            "source": "automatic",
            "quality": quality,
            "from": "profile",
            "span_face_heights": round(span / face_height, 3),
        }
    return Profile(
        view=view,
        line_uv=line,
        landmarks=landmarks,
        sources=sources,
        anchors=anchors,
        face_height_px=face_height,
    )


def profile_head_mask(silhouette, profile):
    """The head mask of a profile photo: the silhouette cut :data:`NECK_BELOW_CHIN` face heights
    below gnathion, perpendicular to the face line (nasion -> gnathion); the part holding the
    face is kept. ``(H, W)`` bool, like :func:`lilium.photo.mask.head_mask` for frontal photos.
    """
    h, w = silhouette.shape
    nasion, gnathion = profile.landmarks["nasion"], profile.landmarks["gnathion"]
    down = (gnathion - nasion) / max(profile.face_height_px, 1e-9)
    cut = gnathion + NECK_BELOW_CHIN * profile.face_height_px * down
    vv, uu = np.mgrid[0:h, 0:w]
    mask = silhouette & ((uu - cut[0]) * down[0] + (vv - cut[1]) * down[1] <= 0)
    return _largest_part(mask)


def profile_of_photo(image, person_prob=None, view=None):
    """The profile path of ``lilium photo``: segment the person, read the profile.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
    person_prob : ndarray of shape (H, W), optional
        The segmentation of the whole photo, if already run.
    view : {"lateral_left", "lateral_right"}, optional
        Default: from the silhouette.

    Returns
    -------
    profile : Profile
        Falsy with a message when no profile was read.
    mask : ndarray of shape (H, W), bool, or None
        The head mask (:func:`profile_head_mask`).
    """
    silhouette = person_silhouette(image, person_prob)
    profile = read_profile(silhouette, view)
    if not profile:
        return profile, None
    return profile, profile_head_mask(silhouette, profile)
