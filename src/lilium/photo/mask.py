"""The head mask of docs/method/photo.md: the head as seen (face, forehead, hair, ears) down to the
upper neck; not shoulders or background.

No open model parses skin and hair, so the mask is built from two models' outputs:

1. the selfie-segmentation *person* probability (head, hair, ears, neck, shoulders, body), run
   on :func:`segmentation_input`: the photo with its lightness equalised locally (CLAHE), so a
   grayscale, sepia or faded print gets the head as a colour portrait does (on a washed-out
   grayscale print the model otherwise finds no person at all, docs/method/photo.md);
2. a cut below the chin, perpendicular to the face's vertical axis in the image (nasion ->
   gnathion), :data:`NECK_BELOW_CHIN` face heights below the gnathion: what lies below is
   shoulders and body; below the jaw angles (gonion level) only a band as wide as
   :data:`NECK_WIDTH` times the gonion distance is kept, so shoulders beside the neck go;
   The person mask of a second pass, on a crop around the head (:func:`head_crop_box`), is
   added above the nasion within the face's width (the crown band): on a whole portrait the
   model sees the head at a few dozen of its 256 pixels and may lose a dark cap or dark hair on
   a dark background (docs/method/photo.md, "Head mask");
3. the union with the face mesh's outline (dilated by :data:`MESH_MARGIN` face heights), so
   every landmark the mesh gives lies inside even where the person mask misses skin.

Hair makes the mask larger than the skull, as docs/method/photo.md intends. Where the
segmentation still finds no head the mask is the face outline alone: :func:`is_head_mask` tells
the two apart, and ``lilium photo`` marks such a folder (``head_mask_face_only``).
"""

import cv2
import numpy as np

#: Person probability above which a pixel is person.
PERSON_THRESHOLD = 0.5
#: Cut below the chin, in face heights (nasion to gnathion distance).
NECK_BELOW_CHIN = 0.25
#: Width of the kept neck band below the jaw angles, over the gonion-to-gonion distance.
NECK_WIDTH = 0.8
#: Long side (pixels) the mask is computed at, then resized to the photo.
WORK_SIDE_PX = 1024
#: Margin added around the mesh outline, in face heights.
MESH_MARGIN = 0.05
#: CLAHE on the lightness before the segmentation: clip limit and tiles per side (OpenCV's
#: ``createCLAHE``). Chosen on washed-out grayscale and sepia prints (docs/method/photo.md,
#: "Head mask"): a plain 1-99 % stretch fails on a print scanned with its white margin, clip 2
#: on the faintest prints, clip 16 swells the mask into the background.
CLAHE_CLIP = 8.0
CLAHE_TILES = 8
#: A mask is a head mask (:func:`is_head_mask`) when its part beyond the face outline (mesh
#: outline plus margin) and above the jaw angles is at least this share of the face outline's
#: area; the face outline alone gives 0, a head with hair 0.26-0.95 on the measured prints.
HEAD_BEYOND_FACE = 0.2
#: The second segmentation pass (:func:`head_crop_box`): a square this many face heights from
#: its centre to each side, centred :data:`HEAD_CROP_RAISE` face heights above the nasion. Its
#: person pixels are kept only in the crown band: above the nasion, across no wider than the
#: face mesh. Measured on the prints of benchmarks/studies/head_mask_prints.py: without the
#: band the crop pass adds background beside the head (28 % outside on the colour astronaut).
HEAD_CROP_HALF = 1.6
#: A head mask reaches at least this many face heights above the nasion (or the photo's edge,
#: where the frame cuts the head): the vertex lies about 0.9 face heights above it, the face
#: outline alone reaches 0.40-0.50; complete masks on the measured prints reach 0.72-1.24 (0.72:
#: Hopper's crop, whose frame cuts her cap), the whole Hopper scanned print without the crown
#: pass 0.76. Lower, the mask misses the head's top (:func:`reaches_head_top`).
HEAD_TOP_ABOVE_NASION = 0.6
HEAD_CROP_RAISE = 0.3


def segmentation_input(image):
    """The photo as the person segmentation gets it: the lightness (CIE L*) equalised by CLAHE
    (:data:`CLAHE_CLIP`, :data:`CLAHE_TILES`), hue and chroma kept.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB

    Returns
    -------
    ndarray of shape (H, W, 3), uint8 RGB
    """
    lab = cv2.cvtColor(np.ascontiguousarray(image, dtype=np.uint8), cv2.COLOR_RGB2LAB)
    clahe = cv2.createCLAHE(clipLimit=CLAHE_CLIP, tileGridSize=(CLAHE_TILES, CLAHE_TILES))
    lab[..., 0] = clahe.apply(lab[..., 0])
    return cv2.cvtColor(lab, cv2.COLOR_LAB2RGB)


def _face_geometry(mesh, nasion_index, gnathion_index):
    """Face height (nasion to gnathion, pixels) and the unit vector down the face."""
    top, chin = mesh[nasion_index], mesh[gnathion_index]
    face_height = float(np.linalg.norm(chin - top))
    return face_height, (chin - top) / face_height


def _face_outline(mesh, face_height, shape_hw):
    """The mesh outline grown by :data:`MESH_MARGIN` (the hull of the mesh points shifted round a
    disc), as a bool image."""
    r = MESH_MARGIN * face_height
    angles = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    disc = r * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    grown = (mesh[:, None, :] + disc[None]).reshape(-1, 2)
    face = np.zeros(shape_hw, np.uint8)
    cv2.fillConvexPoly(face, cv2.convexHull(np.round(grown).astype(np.int32)), 1)
    return face.astype(bool)


def _working_scale(shape_hw):
    h, w = shape_hw
    scale = min(1.0, WORK_SIDE_PX / max(h, w))
    return scale, (max(1, round(h * scale)), max(1, round(w * scale)))


def head_crop_box(mesh_uv, shape_hw, nasion_index=168, gnathion_index=152):
    """The crop the second segmentation pass sees (:data:`HEAD_CROP_HALF`,
    :data:`HEAD_CROP_RAISE`), clipped to the photo.

    Parameters
    ----------
    mesh_uv : ndarray of shape (468, 2+)
        Face mesh in image pixels.
    shape_hw : (int, int)
        The photo's height and width.

    Returns
    -------
    (u0, v0, u1, v1) : ints, the crop is ``image[v0:v1, u0:u1]``
    """
    mesh = np.asarray(mesh_uv, dtype=float)[:, :2]
    face_height, down = _face_geometry(mesh, nasion_index, gnathion_index)
    centre = mesh[nasion_index] - HEAD_CROP_RAISE * face_height * down
    half = HEAD_CROP_HALF * face_height
    h, w = shape_hw
    u0, v0 = (int(max(0, np.floor(c - half))) for c in centre)
    u1, v1 = int(min(w, np.ceil(centre[0] + half))), int(min(h, np.ceil(centre[1] + half)))
    return u0, v0, u1, v1


def head_mask(
    person_prob,
    mesh_uv,
    nasion_index=168,
    gnathion_index=152,
    gonion_indices=(172, 397),
    crown_prob=None,
):
    """The head mask.

    Parameters
    ----------
    person_prob : ndarray of shape (H, W)
        Person probability in [0, 1].
    mesh_uv : ndarray of shape (468, 2+)
        Face mesh in image pixels.
    crown_prob : ndarray of shape (H, W), optional
        Person probability of the second pass on :func:`head_crop_box` (0 outside the crop);
        its person pixels in the crown band (above the nasion, within the face mesh's width)
        are added.

    Returns
    -------
    mask : ndarray of shape (H, W), bool
    """
    h, w = person_prob.shape
    # Work at most WORK_SIDE_PX on the long side: the person mask comes from 256 x 256 anyway.
    scale, (hs, ws) = _working_scale((h, w))
    prob = cv2.resize(person_prob.astype(np.float32), (ws, hs), interpolation=cv2.INTER_AREA)
    mesh = np.asarray(mesh_uv, dtype=float)[:, :2] * scale
    chin = mesh[gnathion_index]
    face_height, down = _face_geometry(mesh, nasion_index, gnathion_index)
    cut = chin + NECK_BELOW_CHIN * face_height * down
    vv = np.arange(hs, dtype=np.float32)[:, None]
    uu = np.arange(ws, dtype=np.float32)[None, :]
    along = (uu - cut[0]) * down[0] + (vv - cut[1]) * down[1]
    gonion_r, gonion_l = mesh[list(gonion_indices)]
    jaw_level = ((gonion_r + gonion_l) / 2 - cut) @ down
    across = np.abs((uu - chin[0]) * down[1] - (vv - chin[1]) * down[0])
    neck = (along <= jaw_level) | (across <= NECK_WIDTH * np.linalg.norm(gonion_l - gonion_r) / 2)
    person = prob > PERSON_THRESHOLD
    if crown_prob is not None:
        crown = cv2.resize(crown_prob.astype(np.float32), (ws, hs), interpolation=cv2.INTER_AREA)
        nasion = mesh[nasion_index]
        above = (uu - nasion[0]) * down[0] + (vv - nasion[1]) * down[1] < 0
        side = (uu - nasion[0]) * down[1] - (vv - nasion[1]) * down[0]
        mesh_side = (mesh[:, 0] - nasion[0]) * down[1] - (mesh[:, 1] - nasion[1]) * down[0]
        within = (side >= mesh_side.min()) & (side <= mesh_side.max())
        person |= (crown > PERSON_THRESHOLD) & above & within
    mask = person & (along <= 0) & neck
    mask |= _face_outline(mesh, face_height, (hs, ws))
    # Keep the connected part holding the face (drops stray person blobs, e.g. a hand).
    n, labels = cv2.connectedComponents(mask.astype(np.uint8))
    if n > 2:
        centre = np.round(mesh.mean(axis=0)).astype(int)
        label = labels[np.clip(centre[1], 0, hs - 1), np.clip(centre[0], 0, ws - 1)]
        mask = labels == label
    if scale < 1.0:
        mask = cv2.resize(mask.astype(np.float32), (w, h), interpolation=cv2.INTER_LINEAR) > 0.5
    return mask


#: Points of the outline the review page draws (each one a handle to drag; about 2x this at
#: most): enough for hair and ears, few enough to move one by hand.
OUTLINE_POINTS = 80


def mask_outline(mask, max_points=OUTLINE_POINTS):
    """The outer outline of the mask's largest part, ``(N, 2)`` uv pixels (for the review)."""
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return np.zeros((0, 2))
    contour = max(contours, key=cv2.contourArea)[:, 0, :].astype(float)
    step = max(1, len(contour) // max_points)
    return contour[::step]


def head_share_beyond_face(
    mask, mesh_uv, nasion_index=168, gnathion_index=152, gonion_indices=(172, 397)
):
    """The mask's part beyond the face outline and above the jaw angles, over the outline's
    area: 0 for a mask that is the face outline alone (:func:`head_mask`'s fallback).

    Parameters
    ----------
    mask : ndarray of shape (H, W), bool
    mesh_uv : ndarray of shape (468, 2+)
        Face mesh in image pixels.

    Returns
    -------
    float
    """
    mask = np.asarray(mask, dtype=bool)
    scale, (hs, ws) = _working_scale(mask.shape)
    if scale < 1.0:
        mask = cv2.resize(mask.astype(np.uint8), (ws, hs), interpolation=cv2.INTER_NEAREST) > 0
    mesh = np.asarray(mesh_uv, dtype=float)[:, :2] * scale
    face_height, down = _face_geometry(mesh, nasion_index, gnathion_index)
    face = _face_outline(mesh, face_height, (hs, ws))
    jaw = mesh[list(gonion_indices)].mean(axis=0)
    vv = np.arange(hs, dtype=np.float32)[:, None]
    uu = np.arange(ws, dtype=np.float32)[None, :]
    above_jaw = (uu - jaw[0]) * down[0] + (vv - jaw[1]) * down[1] < 0
    return float(np.count_nonzero(mask & ~face & above_jaw) / max(1, np.count_nonzero(face)))


def reaches_head_top(mask, mesh_uv, nasion_index=168, gnathion_index=152):
    """Whether the mask reaches :data:`HEAD_TOP_ABOVE_NASION` face heights above the nasion, up
    the face's axis (or, nearer, the photo's edge on that line).

    Parameters
    ----------
    mask : ndarray of shape (H, W), bool
    mesh_uv : ndarray of shape (468, 2+)
        Face mesh in image pixels.

    Returns
    -------
    bool
    """
    mask = np.asarray(mask, dtype=bool)
    mesh = np.asarray(mesh_uv, dtype=float)[:, :2]
    face_height, down = _face_geometry(mesh, nasion_index, gnathion_index)
    nasion = mesh[nasion_index]
    v, u = np.nonzero(mask)
    if len(u) == 0:
        return False
    reach = -float(np.min((u - nasion[0]) * down[0] + (v - nasion[1]) * down[1]))
    # The photo's edge up the face's axis from the nasion (pixel centres span 0 .. side - 1).
    h, w = mask.shape
    to_edge = np.inf
    for d, x, side in ((-down[0], nasion[0], w), (-down[1], nasion[1], h)):
        if d > 1e-9:
            to_edge = min(to_edge, (side - 1 - x) / d)
        elif d < -1e-9:
            to_edge = min(to_edge, -x / d)
    return reach >= min(HEAD_TOP_ABOVE_NASION * face_height, to_edge - 1.0)


def is_head_mask(mask, mesh_uv):
    """Whether the mask holds the head as seen (hair, ears) rather than the face outline alone
    or a part of the head: :func:`head_share_beyond_face` at least :data:`HEAD_BEYOND_FACE` and
    :func:`reaches_head_top`."""
    return head_share_beyond_face(mask, mesh_uv) >= HEAD_BEYOND_FACE and reaches_head_top(
        mask, mesh_uv
    )


def polygon_mask(outline_uv, size_wh):
    """The mask inside a closed outline (the review page's ``head_outline_px``).

    Parameters
    ----------
    outline_uv : array_like of shape (N, 2)
        Vertices in image pixels, u = column, v = row (pixel centres at integers).
    size_wh : (int, int)
        The photo's width and height.

    Returns
    -------
    ndarray of shape (H, W), bool
    """
    w, h = size_wh
    mask = np.zeros((h, w), np.uint8)
    points = np.round(np.asarray(outline_uv, dtype=float) * 16).astype(np.int32)
    cv2.fillPoly(mask, [points], 1, lineType=cv2.LINE_8, shift=4)
    return mask.astype(bool)
