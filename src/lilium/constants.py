"""Named tolerances and magic numbers, in one place."""

#: Penalty for a camera that POSEST could not produce (no solution, focal out of range).
C_INF = 1e12

#: Largest focal length (pixels) a real lens/sensor combination is taken to reach
#: (docs/method/pose.md).
FOCAL_MAX_PX = 10_000.0

#: Smallest focal length (pixels) taken as a camera: below one pixel the "camera" is a collapsed
#: fit, not a lens (treated like an f <= 0 failure, docs/method/pose.md).
FOCAL_MIN_PX = 1.0

#: Smallest camera-frame depth (mm) for a point to count as in front of the camera.
MIN_DEPTH_MM = 1e-6

#: Photo views (docs/contract.md): lateral_left = the face points towards the image's left edge.
VIEWS = ("frontal", "lateral_left", "lateral_right")

#: The experiments of docs/method/evaluation.md, each named by its noise profile (ideal, landmark
#: noise,
#: realistic): :mod:`lilium.synthetic.noise` and :mod:`lilium.experiments.config`.
EXPERIMENTS = ("A", "B", "C")

#: Fewest 2D-3D correspondences POSEST accepts (a P4Pf sample).
MIN_CORRESPONDENCES = 4

#: Largest soft-tissue polar angle from the cone axis (degrees), docs/method/lilium.md.
CONE_MAX_POLAR_DEG = 40.0

#: Angular spread (degrees) of a soft-tissue direction about its cone axis: the identification
#: model's (:mod:`lilium.identification.terms`) and the joint SFO's angular prior's.
DIRECTION_SD_DEG = 15.0

#: Weight of the bilateral hybrid: right genes = W * left + (1 - W) * right (docs/method/lilium.md).
BILATERAL_LEFT_WEIGHT = 0.9

#: Radius (mm) of the skull-surface neighbourhood averaged for a default cone axis.
NORMAL_NEIGHBOURHOOD_MM = 4.0

#: MSAC inlier threshold (pixels) of POSEST's RANSAC stage.
RANSAC_THRESHOLD_PX = 12.0

#: Largest angle (degrees) between the skull's anterior direction (porion midpoint -> nasion)
#: and the direction from the skull to the camera for the camera to see the front of the skull
#: (docs/checks.md; a lateral view is about 90). A camera beyond it sees the back of the skull:
#: treated as no solution. docs/checks.md's 110 degrees. (The generator's lateral yaw once
#: reached 105 deg, which with 10 deg of pitch against the anterior axis, tilted about 14 deg
#: above the mesh horizontal, put true cameras at up to 112.7 deg: the generator's lateral yaw
#: range is 75-95 deg since, see lilium.synthetic.photos.CameraRanges.)
FACING_MAX_DEG = 110.0

#: The view check (docs/checks.md): a frontal camera lies at most this far (degrees) from the
#: skull's anterior direction, a lateral one at least this far, on the declared side.
VIEW_SPLIT_DEG = 45.0


def focal_cap_px(focal_prior_px=None):
    """Largest focal length (pixels) accepted as a camera (docs/method/pose.md, focal cap).

    :data:`FOCAL_MAX_PX` unless a focal prior reaches above it; then twice the prior's upper
    bound (a long lens on a large sensor: 200 mm full-frame on a 6,000 px photo is 33,000 px).

    Parameters
    ----------
    focal_prior_px : (float, float) or None
        The photo's focal prior interval (pixels).

    Returns
    -------
    float

    Examples
    --------
    >>> focal_cap_px(None), focal_cap_px((2000.0, 2400.0)), focal_cap_px((31000.0, 35000.0))
    (10000.0, 10000.0, 70000.0)
    """
    if focal_prior_px is None or float(focal_prior_px[1]) <= FOCAL_MAX_PX:
        return FOCAL_MAX_PX
    return 2.0 * float(focal_prior_px[1])


# -- input limits (docs/checks.md) ---------------------------------------------------------------

#: Most pixels a photo (or mask) may have: 100 megapixels, every camera short of medium format.
#: An SFO needs no more (landmarks are marked to a pixel); a larger photo is an error that says
#: how to downscale it, rather than an unbounded decode.
MAX_PHOTO_PIXELS = 100_000_000

#: Shortest photo side (pixels) an SFO is attempted on.
MIN_PHOTO_SIDE_PX = 32

#: Smallest extent of a photo's facial landmarks (the longest distance between two of them), as
#: a fraction of the photo's longer side, and in pixels at least: a smaller face is too small
#: to superimpose (or the landmarks are all at one place).
MIN_LANDMARK_EXTENT_FRACTION = 0.01
MIN_LANDMARK_EXTENT_PX = 16.0

#: Smallest ratio of a landmark configuration's spread across its main direction to its spread
#: along it (the second to the first singular value of the centred points): below it the
#: landmarks lie on a line and do not fix a camera (2D) or a pose (3D).
MIN_LANDMARK_SPREAD_RATIO = 0.02

#: Smallest extent of the cranial landmarks as a fraction of the skull mesh's extent.
MIN_CRANIAL_EXTENT_FRACTION = 0.05

#: A connected part of a skull mesh whose bounding box lies more than this (mm) from the part
#: holding the cranial landmarks is not this skull's bone (a stray fragment, a second copy, scan
#: debris): it is left out, with warning ``mesh_part_left_out``. A separate mandible, teeth or
#: vertebrae touch or nearly touch the cranium's box and stay.
PART_APART_MM = 20.0

#: Physical range of each camera prior (docs/checks.md), with its unit: a focal prior from 10 px
#: (no lens) to 1,000,000 px (an 800 mm lens on a 100 MP sensor is 270,000 px); a
#: subject-to-camera distance from 5 cm to 100 m. A prior outside it is a unit or typing error.
PRIOR_RANGES = {"focal_px": ((10.0, 1_000_000.0), "px"), "scd_mm": ((50.0, 100_000.0), "mm")}

#: Largest soft-tissue depth (mm) a depth table may give (min, mean, max), and largest SD: the
#: thickest facial soft tissue (cheek, gonion of an obese adult) is a few centimetres.
MAX_DEPTH_MM = 100.0
MAX_DEPTH_SD_MM = 50.0

#: Largest DE population a command or config takes: the paper uses 30; a population is
#: evaluated at once, so a typing slip (100000000) would exhaust the memory before the first
#: generation.
MAX_DE_POPULATION = 10_000
