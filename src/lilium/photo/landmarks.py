"""docs/method/skull.md facial landmarks from MediaPipe's 468-point face mesh.

Each landmark is one mesh vertex, chosen by where the vertex lies on the mesh's own topology
and checked on real portraits against points placed by hand (``tests/photo/test_photo_accuracy.py``,
``docs/method/photo.md``). ``"tracked"`` points sit on image evidence the model follows (eye
corners, the alar wings, the nostril base, the lip border, the mouth corners); ``"template"``
points are where the model's face template puts them (nasion, glabella and the forehead, the
cheek and jaw contour, the chin): plausible, not used by an SFO until the user confirms them.
A point beyond the eyes, nose and mouth becomes tracked only when it lies within 5 % of the
eye-corner distance of the true point on at least ten faces; the chin points (pogonion,
gnathion) are within it on the two hand-marked portraits, but were measured 8.7-22 % off by
independent checks and cannot be measured on ten faces offline (docs/method/photo.md, "The
chin"), so they are template.
"""

import numpy as np

TRACKED = "tracked"
TEMPLATE = "template"

#: Catalogue facial landmark -> (mesh vertex index, quality). ``_r`` is the subject's right, the
#: image's left in a frontal photo (MediaPipe's "right eye" 33/133 is the subject's right).
MESH_LANDMARKS = {
    "exocanthion_r": (33, TRACKED),
    "endocanthion_r": (133, TRACKED),
    "exocanthion_l": (263, TRACKED),
    "endocanthion_l": (362, TRACKED),
    "alare_r": (64, TRACKED),
    "alare_l": (294, TRACKED),
    "subnasale": (2, TRACKED),
    "labiale_superius": (0, TRACKED),
    "cheilion_r": (61, TRACKED),
    "cheilion_l": (291, TRACKED),
    "pogonion": (200, TEMPLATE),
    "gnathion": (152, TEMPLATE),
    "nasion": (168, TEMPLATE),
    "glabella": (9, TEMPLATE),
    "metopion": (151, TEMPLATE),
    "zygion_r": (234, TEMPLATE),
    "zygion_l": (454, TEMPLATE),
    "gonion_r": (172, TEMPLATE),
    "gonion_l": (397, TEMPLATE),
    "frontotemporale_r": (54, TEMPLATE),
    "frontotemporale_l": (284, TEMPLATE),
}

#: Mesh vertices of the jaw line from the right ear lobe over the chin to the left one (the
#: lower face contour, used to cut the head mask below the chin).
JAW_LINE = (
    234, 93, 132, 58, 172, 136, 150, 149, 176, 148, 152,
    377, 400, 378, 379, 365, 397, 288, 361, 323, 454,
)  # fmt: skip


def mesh_to_landmarks(mesh_uv):
    """Landmarks (u, v) and their sources from the mesh.

    Parameters
    ----------
    mesh_uv : ndarray of shape (468, 2) or (468, 3)
        Mesh points in image pixels (a third depth column is ignored).

    Returns
    -------
    landmarks : dict of str -> ndarray of shape (2,)
    sources : dict of str -> dict
        ``{"source": "automatic", "quality": "tracked" | "template"}`` per landmark.
    """
    mesh_uv = np.asarray(mesh_uv, dtype=float)
    if mesh_uv.ndim != 2 or mesh_uv.shape[0] != 468:
        raise ValueError(f"the face mesh must be (468, 2+) points, got {mesh_uv.shape}")
    landmarks, sources = {}, {}
    for name, (index, quality) in MESH_LANDMARKS.items():
        landmarks[name] = mesh_uv[index, :2].copy()
        sources[name] = {"source": "automatic", "quality": quality, "mesh_index": index}
    return landmarks, sources


#: Mesh vertices of the midline from the top of the face mesh over metopion (151) to glabella
#: (9): in a lateral view, the forehead's profile.
FOREHEAD_LINE = (10, 151, 9)

#: Mesh vertices of the mouth corners (cheilion_r, cheilion_l): the chin-jaw curve lies between
#: their verticals (the span the face mask's curve takes, docs/method/lilium.md).
MOUTH_CORNERS = (61, 291)

#: Largest step (pixels) between two points of a facial curve.
CURVE_STEP_PX = 1.0


def _densify(points, step=CURVE_STEP_PX):
    """A polyline ``(K, 2)`` resampled so that no two consecutive points are over ``step`` apart."""
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:], strict=True):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        t = np.arange(1, n + 1)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out)


def mesh_face_curves(mesh_uv, image_size_wh):
    """The facial curves of docs/method/photo.md from the face mesh, for ``face_curve.json``.

    Chin-jaw: the mesh's lower face contour (:data:`JAW_LINE`) between the verticals of the mouth
    corners. Forehead: the midline (:data:`FOREHEAD_LINE`) from the top of the mesh to glabella.
    Both follow the face, never the head mask (whose lower edge is the neck, often the collar).

    Parameters
    ----------
    mesh_uv : ndarray of shape (468, 2) or (468, 3)
        Mesh points in image pixels.
    image_size_wh : tuple (width, height)
        Points off the image are left out.

    Returns
    -------
    dict of str -> ndarray of shape (K, 2)
        ``"chin_jaw"`` and ``"forehead"``, ``(u, v)`` pixels at most :data:`CURVE_STEP_PX`
        apart; a curve with fewer than two points on the image is left out.
    """
    mesh_uv = np.asarray(mesh_uv, dtype=float)[:, :2]
    w, h = image_size_wh
    u_lo, u_hi = sorted(mesh_uv[list(MOUTH_CORNERS), 0])
    jaw = _densify(mesh_uv[list(JAW_LINE)])
    curves = {
        "chin_jaw": jaw[(jaw[:, 0] >= u_lo) & (jaw[:, 0] <= u_hi)],
        "forehead": _densify(mesh_uv[list(FOREHEAD_LINE)]),
    }
    out = {}
    for key, curve in curves.items():
        inside = (curve >= -0.5).all(axis=1) & (curve[:, 0] <= w - 0.5) & (curve[:, 1] <= h - 0.5)
        if inside.sum() >= 2:
            out[key] = curve[inside]
    return out
