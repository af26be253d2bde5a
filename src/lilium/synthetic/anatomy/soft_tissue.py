"""True soft tissue of a synthetic subject: a depth and a direction per cranial landmark.

For each cranial landmark of a correspondence, :func:`draw_soft_tissue` draws a depth from the
population table (:data:`~lilium.softtissue.depths.BUILTIN_DEPTHS`, ``N(mean, sd)`` clipped
:data:`DEPTH_MARGIN_MM` inside ``[min, max]``) and a direction within
:data:`MAX_DIRECTION_DEG` of its centre (:func:`direction_centre`); a right twin nearly mirrors
its left one. The facial target is ``F = C + depth * direction`` (skull frame, mm).

The centre is the outward bone normal, but not at the eye corners and the alae: on a real face
the exocanthion lies medial of the lateral orbital margin, the endocanthion lateral of the
medial wall and the ala lateral of the aperture, not over them, while the bone normal there
points sideways (drawn along it, the generated outer eye corners were 119-125 mm apart, the
alae 46-52; real heads and adult norms about 77-95 and 26-38). Their centre is
:func:`lilium.softtissue.normals.beside_axis` in the skull frame, the axes ``lilium skull``
writes for a real skull.
"""

import numpy as np

from ...softtissue.cones import perpendicular_basis
from ...softtissue.depths import BUILTIN_DEPTHS
from ...softtissue.landmarks import CORRESPONDENCES, base_name, twin
from ...softtissue.normals import beside_axis

#: Largest angle (degrees) between a true soft-tissue direction and its centre.
MAX_DIRECTION_DEG = 18.0
#: Scale (degrees) of the half-normal distribution of that angle.
DIRECTION_SD_DEG = 8.0
#: Drawn depths stay this far (mm) inside the population [min, max].
DEPTH_MARGIN_MM = 0.25
#: A right twin: its depth is the left one plus ``N(0, TWIN_DEPTH_SD_FRACTION * sd)``; its
#: direction is the mirrored left one tilted by a half-normal angle of scale
#: :data:`TWIN_TILT_SD_DEG`, at most :data:`TWIN_TILT_MAX_DEG`.
TWIN_DEPTH_SD_FRACTION = 0.25
TWIN_TILT_SD_DEG = 2.0
TWIN_TILT_MAX_DEG = 5.0
#: A draw is accepted when its angle to its centre is within :data:`MAX_DIRECTION_DEG` plus
#: this slack (degrees) and its facial point lies :data:`MIN_BONE_CLEARANCE_MM` outside the
#: bone; at most :data:`MAX_DRAWS` draws per landmark (the last one is kept).
ANGLE_SLACK_DEG = 2.0
MIN_BONE_CLEARANCE_MM = 1.0
MAX_DRAWS = 20
#: Mirror of the skull frame's midsagittal plane (x -> -x).
MIRROR_X = np.diag([-1.0, 1.0, 1.0])
#: The skull frame's left and anterior directions.
LEFT, ANTERIOR = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)


def direction_centre(name, normal):
    """The axis a landmark's true soft-tissue direction is drawn about (module notes).

    Parameters
    ----------
    name : str
        A cranial landmark.
    normal : ndarray of shape (3,)
        Its unit outward bone normal, skull frame.

    Returns
    -------
    ndarray of shape (3,)
        A unit vector, skull frame.
    """
    axis = beside_axis(name, LEFT, ANTERIOR)
    return normal if axis is None else axis


def tilted(axis, angle_rad, azimuth_rad):
    """Unit vector at ``angle_rad`` from ``axis``, towards ``azimuth_rad``.

    The azimuth is measured in the fixed basis
    :func:`~lilium.softtissue.cones.perpendicular_basis` of the plane perpendicular to the axis.

    Parameters
    ----------
    axis : ndarray of shape (3,)
        Normalised here.
    angle_rad, azimuth_rad : float

    Returns
    -------
    ndarray of shape (3,)
    """
    a = axis / np.linalg.norm(axis)
    u, v = perpendicular_basis(a)
    return np.cos(angle_rad) * a + np.sin(angle_rad) * (
        np.cos(azimuth_rad) * u + np.sin(azimuth_rad) * v
    )


def align_vectors(a, b):
    """Smallest rotation taking the direction ``a`` to the direction ``b``.

    The closed form ``I + K + K^2 / (1 + a.b)`` (``K`` the cross-product matrix of ``a x b``).
    Kept here rather than :func:`lilium.geometry.rotations.rotvec_to_matrix` of the axis-angle
    (the same rotation): that route goes through ``arccos``/``sin``/``cos`` and rounds
    differently, which would change every seeded subject in the last bits.

    Parameters
    ----------
    a, b : ndarray of shape (3,)
        Normalised here.

    Returns
    -------
    ndarray of shape (3, 3)
        ``-I`` when ``a`` and ``b`` are (nearly) opposite.
    """
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if c < -0.999999:
        return -np.eye(3)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def _draw_left(stats, centre, rng):
    """Depth (mm, unclipped) and direction of a midline or left landmark."""
    depth = rng.normal(stats.mean_mm, stats.sd_mm)
    tilt = np.radians(min(abs(rng.normal(0.0, DIRECTION_SD_DEG)), MAX_DIRECTION_DEG))
    return depth, tilted(centre, tilt, rng.uniform(0, 2 * np.pi))


def _draw_twin(stats, centre, twin_depth, twin_direction, twin_centre, rng):
    """Depth (mm, unclipped) and direction of a right landmark, near its left twin's mirror."""
    depth = twin_depth + rng.normal(0.0, TWIN_DEPTH_SD_FRACTION * stats.sd_mm)
    # The left tilt from its centre, mirrored onto the right centre.
    base_dir = align_vectors(MIRROR_X @ twin_centre, centre) @ (MIRROR_X @ twin_direction)
    tilt = np.radians(min(abs(rng.normal(0.0, TWIN_TILT_SD_DEG)), TWIN_TILT_MAX_DEG))
    return depth, tilted(base_dir, tilt, rng.uniform(0, 2 * np.pi))


def draw_soft_tissue(cranial, normals, bone, rng):
    """True depth and direction of each cranial landmark of a correspondence.

    Depths: ``N(mean, sd)`` of the built-in table clipped inside ``[min, max]``; the right twin
    is the left depth plus a small difference. Directions: the centre (:func:`direction_centre`)
    tilted by a half-normal angle (scale :data:`DIRECTION_SD_DEG`, at most
    :data:`MAX_DIRECTION_DEG`) towards a uniform azimuth; the right twin mirrors the left one,
    plus a few degrees. A draw whose facial point would fall inside the bone is redrawn.

    Parameters
    ----------
    cranial : dict of str -> ndarray of shape (3,)
        Cranial landmarks, mm.
    normals : dict of str -> ndarray of shape (3,)
        Unit outward bone normals at them.
    bone : GridField
        Negative inside, mm.
    rng : numpy.random.Generator

    Returns
    -------
    depths_mm : dict of str -> float
    directions : dict of str -> ndarray of shape (3,)
        Unit vectors, skull frame.
    """
    centres = {name: direction_centre(name, normals[name]) for name, _ in CORRESPONDENCES}
    depths, directions = {}, {}
    for cranial_name, _ in CORRESPONDENCES:
        stats = BUILTIN_DEPTHS[base_name(cranial_name)]
        lo, hi = stats.min_mm + DEPTH_MARGIN_MM, stats.max_mm - DEPTH_MARGIN_MM
        centre, left = centres[cranial_name], twin(cranial_name)
        mirrored = cranial_name.endswith("_r") and left in depths
        for _attempt in range(MAX_DRAWS):
            if mirrored:
                depth, direction = _draw_twin(
                    stats, centre, depths[left], directions[left], centres[left], rng
                )
            else:
                depth, direction = _draw_left(stats, centre, rng)
            depth = float(np.clip(depth, lo, hi))
            angle = np.degrees(np.arccos(np.clip(direction @ centre, -1, 1)))
            target = cranial[cranial_name] + depth * direction
            if (
                angle <= MAX_DIRECTION_DEG + ANGLE_SLACK_DEG
                and bone.sample(target[None])[0] > MIN_BONE_CLEARANCE_MM
            ):
                break
        depths[cranial_name] = depth
        directions[cranial_name] = direction
    return depths, directions
