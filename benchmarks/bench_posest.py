"""Benchmark POSEST against independent PnP+f solvers on seeded head-shaped problems.

A script, not a test: it prints a table. Run from the repository root::

    .venv/bin/python benchmarks/bench_posest.py --problems 200 --seed 0

Problems (one per seed draw, the same for every method):

- 15-25 landmark-like points on the visible side of a head-sized ellipsoid (semi-axes 75, 100,
  90 mm: 150 mm wide, 200 mm tall, 180 mm deep), 3 mm of radial jitter; skull frame x = lateral,
  y = down, z = back of the head, so the face looks along -z;
- a view drawn among frontal (|yaw| < 20 deg), oblique (20-70 deg) and lateral (70-95 deg), with
  pitch in [-15, 15] deg and roll in [-10, 10] deg;
- the head centre 500-3000 mm from the camera, focal length 1,000-6,000 px, a 4000 x 3000 image
  with the principal point at its centre; the head lies fully inside the image;
- image noise: i.i.d. Gaussian per coordinate with standard deviation 0, 1 or 2 px.

Methods, each given the same points, the known principal point and no focal length:

- ``posest``: Lilium's POSEST (P4Pf -> MSAC -> Levenberg-Marquardt on the inliers), default
  options;
- ``pycolmap``: ``pycolmap.estimate_and_refine_absolute_pose`` with ``estimate_focal_length`` and
  ``refine_focal_length``, a SIMPLE_PINHOLE start (f = 1.2 max(w, h), principal point fixed),
  the same 12 px RANSAC threshold, a tight gradient tolerance and a 1000 px robust-loss scale
  (so its refinement is least squares, like the others);
- ``opencv``: ``cv2.calibrateCamera`` on the single view with ``CALIB_USE_INTRINSIC_GUESS`` (the
  same f = 1.2 max(w, h) start), fixed principal point and aspect ratio, zero distortion; it fits
  all points by least squares.

Per noise level and method: failures (no camera, f <= 0 or f > 10,000 px), the median and mean
focal relative error and rotation error (deg), the median and mean reprojection RMS over all
points (px), and the median time per call (ms). ``rms/best`` compares POSEST's RMS with the
lower of the two references' on the problems all three solved (median and max ratio, and how many
problems exceed 1 %). A last table times ``refine_batch`` on a population of warm-started
problems (20 points each, 1 px noise, start perturbed by 2 deg, 3 % depth, 5 % focal length).

SFO problems (``--sfo``): the positive pairs of Exp. C made by the project's generator, exactly
as POSEST-SFO hands them to POSEST (:mod:`sfo_problems`: the photo's visible landmarks with
+-5 px noise, 3D points = cranial landmark + population mean depth along the subject's axes set
C1, each true soft-tissue direction turned by up to 30 degrees; frontal and lateral photos; 6-22
points). Scored by BPE (mm, docs/method/evaluation.md) against the truth and the failure rate (no
camera or
f > 10,000 px), for ``pycolmap`` (``estimate_and_refine_absolute_pose``: LO-RANSAC over P4Pf,
12 px threshold, focal refined, its default refinement: Cauchy loss of scale 1 px) and POSEST
with the settings of :data:`SFO_VARIANTS` (prototypes of decisions, through the public
``PosestOptions`` / ``RansacOptions``; ``posest`` is the settings before the defaults changed, the
package's defaults now are the ``rel0.1f6+cand16+lo1`` row, ``...+msac`` the same before issue 27
changed how the refined hypothesis is chosen)::

    .venv/bin/python benchmarks/bench_posest.py --sfo --subjects 12 --photos 4 --seed 0

``--no-mandible``: the same subjects' skulls without the mandible (its landmarks absent, as
``lilium synth --no-mandible-share 1`` writes them; POSEST never sees the mesh), frontal photos
only (issue 27: the near-planar midface)::

    .venv/bin/python benchmarks/bench_posest.py --sfo --no-mandible --subjects 8 --photos 2

``--headsq DIR`` adds the same table for the headsq real-anatomy case (issue 27;
``benchmarks/datasets/headsq_case.py``, its dataset built in DIR when absent): its complete skull
and its mandible-less skull apart, on the same photos.
"""

import argparse
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from lilium.constants import FOCAL_MAX_PX, RANSAC_THRESHOLD_PX
from lilium.geometry import Camera, geodesic_angle_deg, principal_point_of
from lilium.pose import posest, refine_batch
from lilium.pose.posest import PosestOptions
from lilium.pose.ransac import RansacOptions

#: The data tools (benchmarks/datasets) this script imports, ``sfo_problems``, ``headsq_case``.
sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

try:
    import pycolmap
except ImportError:  # the `bench` extra
    pycolmap = None

IMAGE_WH = (4000, 3000)
HEAD_SEMI_AXES_MM = np.array([75.0, 100.0, 90.0])
VIEWS = {"frontal": (0.0, 20.0), "oblique": (20.0, 70.0), "lateral": (70.0, 95.0)}


@dataclass(frozen=True)
class Problem:
    """One PnP+f instance and its ground truth."""

    uv_px: np.ndarray  # (N, 2), noisy
    points_mm: np.ndarray  # (N, 3)
    R: np.ndarray  # (3, 3) true skull2cam rotation
    t: np.ndarray  # (3,)
    focal_px: float
    view: str


def head_points(rng, n_candidates=80):
    """Candidate landmarks (n, 3) and outward normals on the front 3/4 of a head ellipsoid."""
    azimuth = rng.uniform(-110.0, 110.0, n_candidates)  # 0 = the face (-z)
    elevation = rng.uniform(-55.0, 45.0, n_candidates)  # positive = up (-y)
    az, el = np.radians(azimuth), np.radians(elevation)
    d = np.column_stack([np.sin(az) * np.cos(el), -np.sin(el), -np.cos(az) * np.cos(el)])
    points = d * HEAD_SEMI_AXES_MM
    normals = points / HEAD_SEMI_AXES_MM**2
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points = points + normals * rng.uniform(-3.0, 3.0, (n_candidates, 1))
    return points, normals


def make_problem(rng, noise_px):
    """Draw one head-shaped problem whose points are visible and inside the image."""
    c = principal_point_of(IMAGE_WH)
    while True:
        view = list(VIEWS)[rng.integers(len(VIEWS))]
        lo, hi = VIEWS[view]
        yaw = rng.uniform(lo, hi) * rng.choice([-1.0, 1.0])
        pitch, roll = rng.uniform(-15.0, 15.0), rng.uniform(-10.0, 10.0)
        # Head frame faces -z, like the camera's viewing direction reversed: no base flip needed.
        R = Rotation.from_euler("YXZ", [yaw, pitch, roll], degrees=True).as_matrix()
        focal = rng.uniform(1000.0, 6000.0)
        depth = rng.uniform(500.0, 3000.0)
        offset = rng.uniform(-0.3, 0.3, 2) * np.array(IMAGE_WH) * depth / focal
        t = np.array([offset[0], offset[1], depth])
        points, normals = head_points(rng)
        X = points @ R.T + t
        visible = np.einsum("ij,ij->i", normals @ R.T, -X) > 0.1 * np.linalg.norm(X, axis=1)
        n = int(rng.integers(15, 26))
        if visible.sum() < n:
            continue
        points = points[np.flatnonzero(visible)[:n]]
        uv = Camera.from_rt(R, t, focal, c).project(points)
        inside = np.all((uv >= 0) & (uv <= np.array(IMAGE_WH) - 1))
        if not inside:
            continue
        uv = uv + rng.normal(scale=noise_px, size=uv.shape)
        return Problem(uv, points, R, t, focal, view)


def rms_px(problem, R, t, focal_px):
    """Reprojection RMS over all points (pixels)."""
    uv = Camera.from_rt(R, t, focal_px, principal_point_of(IMAGE_WH)).project(problem.points_mm)
    return float(np.sqrt(np.mean(np.sum((uv - problem.uv_px) ** 2, axis=1))))


def run_posest(problem):
    result = posest(problem.uv_px, problem.points_mm, principal_point_of(IMAGE_WH))
    if not result:
        return None
    return result.camera.R, result.camera.t, result.camera.focal_px


def run_pycolmap(problem, seed):
    c = principal_point_of(IMAGE_WH)
    camera = pycolmap.Camera(
        model="SIMPLE_PINHOLE",
        width=IMAGE_WH[0],
        height=IMAGE_WH[1],
        params=[1.2 * max(IMAGE_WH), c[0], c[1]],
    )
    estimation = pycolmap.AbsolutePoseEstimationOptions()
    estimation.estimate_focal_length = True
    estimation.ransac.max_error = RANSAC_THRESHOLD_PX
    estimation.ransac.random_seed = seed
    refinement = pycolmap.AbsolutePoseRefinementOptions()
    refinement.refine_focal_length = True
    refinement.gradient_tolerance = 1e-12
    refinement.loss_function_scale = 1000.0
    out = pycolmap.estimate_and_refine_absolute_pose(
        problem.uv_px, problem.points_mm, camera, estimation, refinement
    )
    if out is None:
        return None
    M = out["cam_from_world"].matrix()
    return M[:, :3], M[:, 3], float(camera.params[0])


def run_opencv(problem):
    c = principal_point_of(IMAGE_WH)
    f0 = 1.2 * max(IMAGE_WH)
    K = np.array([[f0, 0.0, c[0]], [0.0, f0, c[1]], [0.0, 0.0, 1.0]])
    flags = (
        cv2.CALIB_USE_INTRINSIC_GUESS
        | cv2.CALIB_FIX_PRINCIPAL_POINT
        | cv2.CALIB_FIX_ASPECT_RATIO
        | cv2.CALIB_ZERO_TANGENT_DIST
        | cv2.CALIB_FIX_K1
        | cv2.CALIB_FIX_K2
        | cv2.CALIB_FIX_K3
    )
    criteria = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-15)
    try:
        _, K, _, rvecs, tvecs = cv2.calibrateCamera(
            [problem.points_mm.astype(np.float32)],
            [problem.uv_px.astype(np.float32)],
            IMAGE_WH,
            K,
            np.zeros(5),
            flags=flags,
            criteria=criteria,
        )
    except cv2.error:
        return None
    R, _ = cv2.Rodrigues(rvecs[0])
    return R, tvecs[0].ravel(), float(K[0, 0])


def evaluate(problems, method):
    """Per-problem (focal rel. error, rotation error deg, RMS px, seconds); NaN rows = failed."""
    rows = []
    for i, problem in enumerate(problems):
        start = time.perf_counter()
        out = method(problem, i)
        seconds = time.perf_counter() - start
        if out is None or not (0.0 < out[2] <= FOCAL_MAX_PX) or not np.all(np.isfinite(out[1])):
            rows.append((np.nan, np.nan, np.nan, seconds))
            continue
        R, t, f = out
        rows.append(
            (
                abs(f - problem.focal_px) / problem.focal_px,
                float(geodesic_angle_deg(R, problem.R)),
                rms_px(problem, R, t, f),
                seconds,
            )
        )
    return np.array(rows)


def bench_refine_batch(rng, population=100, n_points=20, repeats=20):
    """Median time (ms) of one warm-started ``refine_batch`` call over a population."""
    problems = []
    while len(problems) < population:
        p = make_problem(rng, 1.0)
        if len(p.points_mm) >= n_points:
            problems.append(p)
    uv = np.stack([p.uv_px[:n_points] for p in problems]) - principal_point_of(IMAGE_WH)
    X = np.stack([p.points_mm[:n_points] for p in problems])
    R_true = np.stack([p.R for p in problems])
    tilt = rng.normal(size=(population, 3))
    tilt *= np.radians(2.0) / np.linalg.norm(tilt, axis=1, keepdims=True)
    R0 = Rotation.from_rotvec(tilt).as_matrix() @ R_true
    t0 = np.stack([p.t for p in problems]) * rng.uniform(0.97, 1.03, (population, 1))
    f0 = np.array([p.focal_px for p in problems]) * rng.uniform(0.95, 1.05, population)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = refine_batch(uv, X, R0, t0, f0)
        times.append(time.perf_counter() - start)
    rms = np.sqrt(result.sq_err_px2.mean(axis=1))
    return float(np.median(times)) * 1e3, result.n_iterations, rms


#: POSEST settings tried on the SFO problems: ``rel`` = inlier threshold
#: ``max(floor, rel x spread)`` with ``spread`` the RMS distance (px) of the given landmarks from
#: their centroid (``floor`` 12 px unless given), ``n_candidates`` = MSAC hypotheses refined
#: (the choice among hypotheses: the refined one with the lowest MSAC cost wins),
#: ``local_rounds`` = refinements per hypothesis with re-classified inliers (local optimisation;
#: 1 = refine once on MSAC's inliers), ``refine_on`` = LM on the inliers or all points.
SFO_VARIANTS = {
    "posest": {},
    "rel0.1": {"rel": 0.1},
    "rel0.2": {"rel": 0.2},
    "cand16": {"n_candidates": 16},
    "lo1": {"local_rounds": 1},
    "all": {"refine_on": "all"},
    "rel0.1+cand16": {"rel": 0.1, "n_candidates": 16},
    "rel0.1+cand16+lo1": {"rel": 0.1, "n_candidates": 16, "local_rounds": 1},
    "rel0.1f6+cand16": {"rel": 0.1, "floor": 6.0, "n_candidates": 16},
    # The recommendation (docs/experiments.md): threshold max(6 px, 0.1 x spread), 16 refined
    # hypotheses, one refinement each.
    "rel0.1f6+cand16+lo1": {"rel": 0.1, "floor": 6.0, "n_candidates": 16, "local_rounds": 1},
    # The package's defaults before issue 27 (the refined hypothesis with the lowest MSAC cost
    # wins); every other row picks the one with the most inliers, as the package now does.
    "rel0.1f6+cand16+lo1+msac": {
        "rel": 0.1,
        "floor": 6.0,
        "n_candidates": 16,
        "local_rounds": 1,
        "select": "msac",
    },
}


def sfo_threshold_px(problem, rel=None, floor=RANSAC_THRESHOLD_PX):
    """Inlier threshold (px) of a variant: fixed, or relative to the landmarks' spread."""
    return RANSAC_THRESHOLD_PX if rel is None else max(floor, rel * problem.spread_px)


def run_posest_variant(
    problem, rel=None, floor=RANSAC_THRESHOLD_PX, n_candidates=4, local_rounds=4, **posest_kw
):
    """POSEST with one :data:`SFO_VARIANTS` setting (the unset ones as before the defaults
    changed: fixed 12 px, 4 hypotheses, 4 rounds); the camera or None."""
    ransac = RansacOptions(sfo_threshold_px(problem, rel, floor), n_candidates=n_candidates)
    options = PosestOptions(
        ransac=ransac, local_rounds=local_rounds, threshold_spread_fraction=None, **posest_kw
    )
    result = posest(problem.uv_px, problem.points_mm, problem.principal_point_px, options)
    return result.camera if result else None


def run_pycolmap_sfo(problem, seed):
    """pycolmap's absolute pose with focal refinement (default refinement); camera or None."""
    w, h = problem.image_size_wh
    c = problem.principal_point_px
    camera = pycolmap.Camera(
        model="SIMPLE_PINHOLE", width=w, height=h, params=[1.2 * max(w, h), *c]
    )
    estimation = pycolmap.AbsolutePoseEstimationOptions()
    estimation.estimate_focal_length = True
    estimation.ransac.max_error = RANSAC_THRESHOLD_PX
    estimation.ransac.random_seed = seed
    refinement = pycolmap.AbsolutePoseRefinementOptions()
    refinement.refine_focal_length = True
    out = pycolmap.estimate_and_refine_absolute_pose(
        problem.uv_px, problem.points_mm, camera, estimation, refinement
    )
    if out is None:
        return None
    f = float(camera.params[0])
    if not 0.0 < f <= FOCAL_MAX_PX:
        return None
    M = out["cam_from_world"].matrix()
    return Camera.from_rt(M[:, :3], M[:, 3], f, c)


def sfo_benchmark(n_subjects, n_photos, seed, headsq=None, mandible=True):
    """Print the SFO-problem table (BPE and failures per method and view); with ``headsq`` (a
    folder, built there by ``headsq_case`` when it holds no dataset yet) the same table for the
    headsq real-anatomy case after it, its complete and its mandible-less skull apart;
    ``mandible=False``: the generated skulls without the mandible, frontal photos only."""
    from sfo_problems import sfo_problems

    if n_subjects > 0:
        start = time.perf_counter()
        views = None if mandible else {"frontal"}
        problems = sfo_problems(n_subjects, n_photos, seed, mandible=mandible, views=views)
        kind = f"{n_photos} frontal + {n_photos} lateral" if mandible else f"{n_photos} frontal"
        skulls = "" if mandible else ", skulls without the mandible"
        print(
            f"SFO problems: {n_subjects} subjects x ({kind}){skulls}, "
            f"seed {seed}, Exp. C (+-5 px, axes set C1), generated in "
            f"{time.perf_counter() - start:.0f} s; {_points_range(problems)}"
        )
        sfo_table(problems, seed)
    if headsq is None:
        return
    import headsq_case
    import headsq_ct

    root = headsq_case.ensure_dataset(headsq, n_photos=n_photos, seed=seed)
    if root is None:
        print(f"\nheadsq: no CT at {headsq_ct.DEFAULT_DATA}; skipped")
        return
    for sid, label in (("hq", "complete skull"), ("hq_nm", "without mandible")):
        problems = headsq_case.sfo_problems_from_dataset(root, "C", 1, subjects=[sid])
        if not problems:
            continue
        print(
            f"\nheadsq real anatomy ({root}), {label} ({sid}): {len(problems)} photos, "
            f"Exp. C (+-5 px, axes set C1); {_points_range(problems)}"
        )
        sfo_table(problems, seed)


def _points_range(problems):
    views = np.array([p.view for p in problems])
    n_points = np.array([len(p.uv_px) for p in problems])
    parts = []
    for view in ("frontal", "lateral"):
        n = n_points[views == view]
        if len(n):
            parts.append(f"{view} {n.min()}-{n.max()}")
    return "points " + ", ".join(parts)


def sfo_table(problems, seed):
    """Print BPE and failures per method and view of a list of ``SfoProblem``."""
    views = np.array([p.view for p in problems])
    methods = {}
    if pycolmap is not None:
        methods["pycolmap"] = run_pycolmap_sfo
    else:
        print("pycolmap not installed (pip install lilium[bench]); no reference")
    for name, kw in SFO_VARIANTS.items():
        methods[name] = lambda p, i, kw=kw: run_posest_variant(p, **kw)
    bpe, ms = {}, {}
    for name, fn in methods.items():
        t0 = time.perf_counter()
        bpe[name] = np.array([p.bpe_mm(fn(p, seed * 100_000 + i)) for i, p in enumerate(problems)])
        ms[name] = 1e3 * (time.perf_counter() - t0) / len(problems)
    header = (
        f"{'method':>18} {'view':>8} {'n':>3} {'fail':>4} {'BPE mean':>9} {'BPE med':>8} "
        f"{'both solved: mean':>18} {'ref':>6} {'ratio':>6} {'ms':>6}"
    )
    print(header)
    print("-" * len(header))
    ref = bpe.get("pycolmap")
    for name in methods:
        for view in ("frontal", "lateral"):
            b = bpe[name][views == view]
            if len(b) == 0:
                continue
            line = (
                f"{name:>18} {view:>8} {len(b):3d} {int(np.isnan(b).sum()):4d} "
                f"{np.nanmean(b):9.2f} {np.nanmedian(b):8.2f}"
            )
            if ref is not None:
                r = ref[views == view]
                both = np.isfinite(b) & np.isfinite(r)
                mb, mr = (b[both].mean(), r[both].mean()) if both.any() else (np.nan, np.nan)
                line += f" {mb:18.2f} {mr:6.2f} {np.nanmean(b) / np.nanmean(r):6.2f}"
            print(line + f" {ms[name]:6.1f}")
    print(
        "fail = no camera or f > 10,000 px; BPE over the solved problems; 'both solved' = the"
        " problems this method and pycolmap both solved (ref = pycolmap's mean there); ratio ="
        " BPE mean / pycolmap's BPE mean"
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", type=int, default=200, help="problems per noise level")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--noise", type=float, nargs="+", default=[0.0, 1.0, 2.0])
    parser.add_argument("--sfo", action="store_true", help="SFO problems from the generator")
    parser.add_argument("--subjects", type=int, default=12, help="--sfo: generated subjects")
    parser.add_argument("--photos", type=int, default=4, help="--sfo: photos per view per subject")
    parser.add_argument(
        "--headsq",
        metavar="DIR",
        help="--sfo: also the headsq real-anatomy case (its dataset in DIR, built there if "
        "absent; benchmarks/datasets/headsq_case.py); --subjects 0 for headsq alone",
    )
    parser.add_argument(
        "--no-mandible",
        action="store_true",
        help="--sfo: the generated skulls without the mandible (as --no-mandible-share 1), "
        "frontal photos only",
    )
    args = parser.parse_args(argv)
    if args.sfo:
        sfo_benchmark(args.subjects, args.photos, args.seed, args.headsq, not args.no_mandible)
        return

    methods = {"posest": lambda p, i: run_posest(p), "opencv": lambda p, i: run_opencv(p)}
    if pycolmap is not None:
        methods["pycolmap"] = lambda p, i: run_pycolmap(p, args.seed + i)
    else:
        print("pycolmap not installed (pip install lilium[bench]); skipping it")

    print(
        f"{args.problems} problems per noise level, seed {args.seed}, Gaussian noise per "
        f"coordinate; image {IMAGE_WH[0]}x{IMAGE_WH[1]}, principal point at the centre"
    )
    header = (
        f"{'noise':>5} {'method':>9} {'fail':>4} {'f_err med':>10} {'f_err mean':>10} "
        f"{'rot med':>8} {'rot mean':>8} {'rms med':>9} {'rms mean':>9} {'ms med':>7}"
    )
    print(header)
    print("-" * len(header))
    comparisons = []
    for noise in args.noise:
        rng = np.random.default_rng([args.seed, int(round(noise * 1000))])
        problems = [make_problem(rng, noise) for _ in range(args.problems)]
        stats = {name: evaluate(problems, fn) for name, fn in methods.items()}
        for name, s in stats.items():
            print(
                f"{noise:5.1f} {name:>9} {int(np.isnan(s[:, 0]).sum()):4d} "
                f"{np.nanmedian(s[:, 0]):10.2e} {np.nanmean(s[:, 0]):10.2e} "
                f"{np.nanmedian(s[:, 1]):8.3f} {np.nanmean(s[:, 1]):8.3f} "
                f"{np.nanmedian(s[:, 2]):9.2e} {np.nanmean(s[:, 2]):9.2e} "
                f"{np.median(s[:, 3]) * 1e3:7.2f}"
            )
        refs = [stats[name][:, 2] for name in stats if name != "posest"]
        best = np.min(np.where(np.isnan(refs), np.inf, refs), axis=0)
        ours = stats["posest"][:, 2]
        both = np.isfinite(ours) & np.isfinite(best)
        ratio = ours[both] / np.maximum(best[both], 1e-300)
        comparisons.append((noise, both.sum(), ratio, ours[both] - best[both]))
    print()
    print("posest RMS vs the best reference, problems all solved (ratio = posest / best)")
    print(
        f"{'noise':>5} {'n':>4} {'ratio med':>10} {'ratio max':>10} {'>1.01':>6} "
        f"{'max diff px':>12}"
    )
    for noise, n, ratio, diff in comparisons:
        if noise == 0.0:
            # Noise-free: both are ~0, so a ratio means nothing; show the absolute gap.
            print(f"{noise:5.1f} {n:4d} {'-':>10} {'-':>10} {'-':>6} {diff.max():12.2e}")
        else:
            print(
                f"{noise:5.1f} {n:4d} {np.median(ratio):10.6f} {ratio.max():10.6f} "
                f"{int((ratio > 1.01).sum()):6d} {diff.max():12.2e}"
            )

    print()
    rng = np.random.default_rng([args.seed, 7])
    ms, iterations, rms = bench_refine_batch(rng)
    print("refine_batch, 100 warm-started problems x 20 points, 1 px noise")
    print(
        f"  {ms:.2f} ms per batch = {ms / 100:.4f} ms per problem, {iterations} iterations, "
        f"RMS median {np.median(rms):.3f} px, max {rms.max():.3f} px"
    )


if __name__ == "__main__":
    main()
