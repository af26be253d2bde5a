"""Head orientation from the face mesh, its conversion to ``head_rotation_skull2cam``, and the
subject-to-camera distance from the iris.

The face frame
--------------
MediaPipe's legacy mesh model returns 3D points (u, v in image pixels, depth in the same
scale, larger = farther) in a weak-perspective camera frame: x right, y down, z forward, as
docs/contract.md's camera. The *face frame* is defined on landmarks that exist both on the
mesh and on a skull, so that it can be built on both:

- ``x``: the subject's left, the mean direction right -> left of the bilateral pairs (eye
  corners / ectoconchion and dacryon, zygion, gonion);
- ``y``: inferior, from the upper midline (nasion, glabella) to the lower midline (pogonion,
  gnathion), made orthogonal to ``x``;
- ``z = x cross y``: posterior.

A face looking straight into the camera, upright, has ``face2cam = I``. Angles are reported
as ``face2cam = Rz(roll) @ Ry(yaw) @ Rx(pitch)`` about the camera axes (degrees, right-handed
with x right, y down, z forward): positive roll turns the face clockwise on screen, positive
yaw turns the subject's nose towards the image's left (-u), mirroring the photo flips the
sign of yaw and roll.

Conversion once a skull is paired
---------------------------------
``head_rotation_skull2cam = face2cam @ skull2face``, where ``skull2face`` is the same frame
built on the skull's cranial landmarks (:func:`skull_face_frame`). Soft tissue changes the
midline direction by a few degrees only, inside the default head tolerance. When the skull
lacks the midline points, the Frankfurt frame (porion and orbitale: its normal is the ``-y``
axis) is used, pitched by :data:`FRANKFURT_TO_FACE_PITCH_DEG`, the mean angle between the
Frankfurt normal and the nasion/glabella -> pogonion/gnathion line on an adult face.
"""

import numpy as np

#: Mean human iris diameter (mm), the distance prior's ruler.
IRIS_DIAMETER_MM = 11.7
#: Its spread (mm) between adults and the measuring error (px) assumed on the diameter.
IRIS_DIAMETER_SPREAD_MM = 0.5
IRIS_MEASURE_ERROR_PX = 0.5
#: Subject-to-camera distances (mm) of a portrait (docs/method/photo.md): a focal prior that puts
#: the
#: camera nearer or farther through the iris is wrong (warning ``implausible_prior``).
PLAUSIBLE_DISTANCE_MM = (300.0, 10_000.0)
#: Angle (degrees) from the Frankfurt plane's normal (up) to the face frame's ``-y`` axis
#: (gnathion -> nasion), positive with the chin forward. Textbook adult craniofacial
#: proportions put the facial profile line (nasion-pogonion) about 5 degrees off the
#: Frankfurt perpendicular ("facial angle" of about 85-90 degrees); this is the fallback
#: only, used when the skull lacks the midline landmarks.
FRANKFURT_TO_FACE_PITCH_DEG = 5.0

#: Face-mesh vertex pairs (subject's right, left) and midline groups defining the face frame.
MESH_PAIRS = ((33, 263), (133, 362), (234, 454), (172, 397), (61, 291), (64, 294))
MESH_UPPER = (168, 9)
MESH_LOWER = (175, 152)
#: The same on a skull (cranial landmark names, docs/method/skull.md).
SKULL_PAIRS = ("ectoconchion", "dacryon", "zygion", "gonion", "alare", "frontotemporale")
SKULL_UPPER = ("nasion", "glabella")
SKULL_LOWER = ("pogonion", "gnathion")


def _frame(lateral, down, what):
    norm = np.linalg.norm(lateral)
    if norm == 0 or not np.isfinite(norm):
        raise ValueError(f"{what}: the bilateral landmarks coincide; no left-right direction")
    x = lateral / norm
    y = down - (down @ x) * x
    if np.linalg.norm(y) < 1e-9:
        raise ValueError(f"{what}: the midline is parallel to the left-right direction")
    y /= np.linalg.norm(y)
    return np.stack([x, y, np.cross(x, y)], axis=1)


def face_rotation_face2cam(mesh_xyz):
    """The face frame in the camera frame, from the 3D face mesh.

    Parameters
    ----------
    mesh_xyz : ndarray of shape (468, 3)
        Mesh points (u, v, depth) in pixels, camera axes (x right, y down, z forward).

    Returns
    -------
    face2cam : ndarray of shape (3, 3)
        Columns: the face's x (subject's left), y (inferior), z (posterior) in camera axes.
    """
    p = np.asarray(mesh_xyz, dtype=float)
    lateral = sum(p[left] - p[right] for right, left in MESH_PAIRS)
    down = p[list(MESH_LOWER)].mean(axis=0) - p[list(MESH_UPPER)].mean(axis=0)
    return _frame(lateral, down, "face mesh")


def euler_deg(face2cam):
    """``(yaw, pitch, roll)`` degrees with ``face2cam = Rz(roll) Ry(yaw) Rx(pitch)``."""
    R = np.asarray(face2cam, dtype=float)
    yaw = np.degrees(np.arcsin(np.clip(-R[2, 0], -1, 1)))
    pitch = np.degrees(np.arctan2(R[2, 1], R[2, 2]))
    roll = np.degrees(np.arctan2(R[1, 0], R[0, 0]))
    return float(yaw), float(pitch), float(roll)


def _mean_pair(landmarks, base):
    pair = [landmarks.get(f"{base}_r"), landmarks.get(f"{base}_l")]
    return None if any(p is None for p in pair) else np.asarray(pair[1]) - np.asarray(pair[0])


def skull_face_frame(cranial_landmarks):
    """``skull2face`` (3, 3) from a skull's cranial landmarks (mm, skull-mesh frame).

    Uses the face-frame definition of this module: bilateral pairs for ``x``, the midline
    (nasion, glabella -> pogonion, gnathion) for ``y``; without a midline pair, the Frankfurt
    plane (porion_l/_r, orbitale_l/_r) tilted by :data:`FRANKFURT_TO_FACE_PITCH_DEG`.

    Returns
    -------
    skull2face : ndarray of shape (3, 3)
    how : str
        Which landmarks set the frame (for the report).
    """
    lm = {k: np.asarray(v, dtype=float) for k, v in cranial_landmarks.items()}
    diffs = [d for d in (_mean_pair(lm, b) for b in SKULL_PAIRS) if d is not None]
    if not diffs:
        raise ValueError(
            "the skull has no bilateral landmark pair (ectoconchion, dacryon, zygion, gonion, "
            "alare, frontotemporale _l/_r): cannot convert the head orientation"
        )
    lateral = np.sum([d / np.linalg.norm(d) for d in diffs], axis=0)
    upper = [lm[n] for n in SKULL_UPPER if n in lm]
    lower = [lm[n] for n in SKULL_LOWER if n in lm]
    if upper and lower:
        down = np.mean(lower, axis=0) - np.mean(upper, axis=0)
        face2skull = _frame(lateral, down, "skull landmarks")
        return face2skull.T, "midline (nasion/glabella to pogonion/gnathion) and bilateral pairs"
    names = ("porion_l", "porion_r", "orbitale_l", "orbitale_r")
    if not all(n in lm for n in names):
        raise ValueError(
            "the skull needs nasion or glabella with pogonion or gnathion, or porion_l/_r and "
            "orbitale_l/_r (Frankfurt plane), to convert the head orientation"
        )
    porion = (lm["porion_l"] + lm["porion_r"]) / 2
    orbitale = (lm["orbitale_l"] + lm["orbitale_r"]) / 2
    x = lateral / np.linalg.norm(lateral)
    forward = orbitale - porion
    forward -= (forward @ x) * x
    forward /= np.linalg.norm(forward)
    up = np.cross(forward, x)  # x = left, forward = anterior -> up
    a = np.radians(FRANKFURT_TO_FACE_PITCH_DEG)
    # The face's "up" (-y) leans forward by ``a`` from the Frankfurt normal.
    face_up = np.cos(a) * up + np.sin(a) * forward
    face2skull = _frame(lateral, -face_up, "skull landmarks")
    return face2skull.T, f"Frankfurt plane + {FRANKFURT_TO_FACE_PITCH_DEG:g} deg (fallback)"


def head_rotation_skull2cam(face2cam, cranial_landmarks):
    """The head-orientation prior (docs/contract.md) for a paired skull: ``face2cam @
    skull2face``."""
    skull2face, _ = skull_face_frame(cranial_landmarks)
    return np.asarray(face2cam, dtype=float) @ skull2face


def iris_distance_mm(focal_px, iris_diameter_px):
    """Camera-to-eye distance (mm) and its interval from the iris diameter.

    Parameters
    ----------
    focal_px : float
    iris_diameter_px : float
        Mean of the two eyes' iris diameters in the photo.

    Returns
    -------
    distance_mm : float
    interval_mm : (float, float)
        Spread of adult irises (:data:`IRIS_DIAMETER_SPREAD_MM`) and a measuring error of
        :data:`IRIS_MEASURE_ERROR_PX`.
    """
    if not (focal_px > 0 and iris_diameter_px > 2 * IRIS_MEASURE_ERROR_PX):
        raise ValueError(
            f"iris distance needs a positive focal and an iris over "
            f"{2 * IRIS_MEASURE_ERROR_PX:g} px, got {focal_px!r} and {iris_diameter_px!r}"
        )
    d = focal_px * IRIS_DIAMETER_MM / iris_diameter_px
    lo = focal_px * (IRIS_DIAMETER_MM - IRIS_DIAMETER_SPREAD_MM)
    hi = focal_px * (IRIS_DIAMETER_MM + IRIS_DIAMETER_SPREAD_MM)
    lo /= iris_diameter_px + IRIS_MEASURE_ERROR_PX
    hi /= iris_diameter_px - IRIS_MEASURE_ERROR_PX
    return float(d), (float(lo), float(hi))


def implausible_distance(focal_px, iris_diameter_px):
    """Why a focal prior is implausible through the iris, or "" (docs/method/photo.md).

    Parameters
    ----------
    focal_px : (lo, hi)
    iris_diameter_px : float

    Returns
    -------
    str
        A clause naming the focal interval and the distance it implies when the distance at the
        interval's middle lies outside :data:`PLAUSIBLE_DISTANCE_MM`; "" otherwise (also when
        the iris is too small to measure).
    """
    lo, hi = (float(f) for f in focal_px)
    try:
        distance, _ = iris_distance_mm((lo + hi) / 2, iris_diameter_px)
    except ValueError:
        return ""
    d_lo, d_hi = PLAUSIBLE_DISTANCE_MM
    if d_lo <= distance <= d_hi:
        return ""
    return (
        f"the focal prior {lo:.0f}-{hi:.0f} px puts the camera {distance / 1000:.2f} m from the "
        f"eyes (iris {iris_diameter_px:.1f} px = {IRIS_DIAMETER_MM:g} mm), outside the "
        f"{d_lo / 1000:g}-{d_hi / 1000:g} m of a portrait"
    )
