"""The head mask of docs/method/photo.md: the head as seen (face, forehead, hair, ears) down to the
upper neck; not shoulders or background.

No open model parses skin and hair, so the mask is built from two models' outputs:

1. the selfie-segmentation *person* probability (head, hair, ears, neck, shoulders, body);
2. a cut below the chin, perpendicular to the face's vertical axis in the image (nasion ->
   gnathion), :data:`NECK_BELOW_CHIN` face heights below the gnathion: what lies below is
   shoulders and body; below the jaw angles (gonion level) only a band as wide as
   :data:`NECK_WIDTH` times the gonion distance is kept, so shoulders beside the neck go;
3. the union with the face mesh's outline (dilated by :data:`MESH_MARGIN` face heights), so
   every landmark the mesh gives lies inside even where the person mask misses skin.

Hair makes the mask larger than the skull, as docs/method/photo.md intends.
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


def head_mask(
    person_prob, mesh_uv, nasion_index=168, gnathion_index=152, gonion_indices=(172, 397)
):
    """The head mask.

    Parameters
    ----------
    person_prob : ndarray of shape (H, W)
        Person probability in [0, 1].
    mesh_uv : ndarray of shape (468, 2+)
        Face mesh in image pixels.

    Returns
    -------
    mask : ndarray of shape (H, W), bool
    """
    h, w = person_prob.shape
    # Work at most WORK_SIDE_PX on the long side: the person mask comes from 256 x 256 anyway.
    scale = min(1.0, WORK_SIDE_PX / max(h, w))
    hs, ws = max(1, round(h * scale)), max(1, round(w * scale))
    prob = cv2.resize(person_prob.astype(np.float32), (ws, hs), interpolation=cv2.INTER_AREA)
    mesh = np.asarray(mesh_uv, dtype=float)[:, :2] * scale
    top, chin = mesh[nasion_index], mesh[gnathion_index]
    face_height = float(np.linalg.norm(chin - top))
    down = (chin - top) / face_height
    cut = chin + NECK_BELOW_CHIN * face_height * down
    vv = np.arange(hs, dtype=np.float32)[:, None]
    uu = np.arange(ws, dtype=np.float32)[None, :]
    along = (uu - cut[0]) * down[0] + (vv - cut[1]) * down[1]
    gonion_r, gonion_l = mesh[list(gonion_indices)]
    jaw_level = ((gonion_r + gonion_l) / 2 - cut) @ down
    across = np.abs((uu - chin[0]) * down[1] - (vv - chin[1]) * down[0])
    neck = (along <= jaw_level) | (across <= NECK_WIDTH * np.linalg.norm(gonion_l - gonion_r) / 2)
    mask = (prob > PERSON_THRESHOLD) & (along <= 0) & neck
    # The mesh outline grown by the margin: the hull of the mesh points shifted round a disc.
    r = MESH_MARGIN * face_height
    disc = r * np.stack(
        [
            np.cos(np.linspace(0, 2 * np.pi, 16, endpoint=False)),
            np.sin(np.linspace(0, 2 * np.pi, 16, endpoint=False)),
        ],
        axis=1,
    )
    grown = (mesh[:, None, :] + disc[None]).reshape(-1, 2)
    face = np.zeros((hs, ws), np.uint8)
    cv2.fillConvexPoly(face, cv2.convexHull(np.round(grown).astype(np.int32)), 1)
    mask |= face.astype(bool)
    # Keep the connected part holding the face (drops stray person blobs, e.g. a hand).
    n, labels = cv2.connectedComponents(mask.astype(np.uint8))
    if n > 2:
        centre = np.round(mesh.mean(axis=0)).astype(int)
        label = labels[np.clip(centre[1], 0, hs - 1), np.clip(centre[0], 0, ws - 1)]
        mask = labels == label
    if scale < 1.0:
        mask = cv2.resize(mask.astype(np.float32), (w, h), interpolation=cv2.INTER_LINEAR) > 0.5
    return mask


def mask_outline(mask, max_points=200):
    """The outer outline of the mask's largest part, ``(N, 2)`` uv pixels (for the review)."""
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return np.zeros((0, 2))
    contour = max(contours, key=cv2.contourArea)[:, 0, :].astype(float)
    step = max(1, len(contour) // max_points)
    return contour[::step]
