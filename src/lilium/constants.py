"""Named tolerances and magic numbers, in one place."""

#: Penalty for a camera that POSEST could not produce (no solution, focal out of range).
C_INF = 1e12

#: Largest focal length (pixels) a real lens/sensor combination is taken to reach (SPEC 4, 5).
FOCAL_MAX_PX = 10_000.0

#: Smallest focal length (pixels) taken as a camera: below one pixel the "camera" is a collapsed
#: fit, not a lens (treated like SPEC's f <= 0 failure).
FOCAL_MIN_PX = 1.0

#: Smallest camera-frame depth (mm) for a point to count as in front of the camera.
MIN_DEPTH_MM = 1e-6

#: Photo views (SPEC section 8): lateral_left = the face points towards the image's left edge.
VIEWS = ("frontal", "lateral_left", "lateral_right")

#: Fewest 2D-3D correspondences POSEST accepts (a P4Pf sample).
MIN_CORRESPONDENCES = 4

#: Largest soft-tissue polar angle from the cone axis (degrees), SPEC section 3.
CONE_MAX_POLAR_DEG = 40.0

#: Weight of the bilateral hybrid: right genes = W * left + (1 - W) * right (SPEC section 3).
BILATERAL_LEFT_WEIGHT = 0.9

#: Radius (mm) of the skull-surface neighbourhood averaged for a default cone axis.
NORMAL_NEIGHBOURHOOD_MM = 4.0

#: MSAC inlier threshold (pixels) of POSEST's RANSAC stage.
RANSAC_THRESHOLD_PX = 12.0
