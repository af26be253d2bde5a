"""P_pll: curve detection, refinement, pairing and the three terms.

Hand-made cases with known answers check the production code (batched; one curve is a batch of
one); random cameras check it against the readable per-curve oracle, ``pll_oracle.py``.
"""

import numpy as np
import pytest

import pll_oracle as oracle
from lilium.fitness.curves import (
    CurveBatch,
    detect_curves_batch,
    face_curve_from_mask,
    join_fragments,
    join_fragments_batch,
    order_points,
    refine_curve,
)
from lilium.fitness.pll import (
    PLL_NO_CURVE,
    convergence_penalties,
    face_curve_index,
    pair_curves_batch,
    pll_penalty,
    trim_curves_batch,
)
from lilium.fitness.pll_context import PllContext
from lilium.imaging.raster import mesh_edge_topology

# A rectangle of pixel centres u = 11..30, v = 21..40.
RECT_UV = np.array([[10.5, 20.5], [30.5, 20.5], [30.5, 40.5], [10.5, 40.5]])
RECT = np.array([[0, 1, 2], [0, 2, 3]])


def line(u, v):
    u = np.atleast_1d(np.asarray(u, dtype=float))
    return np.column_stack([u, np.broadcast_to(np.asarray(v, dtype=float), u.shape)])


def detect_curve(uv, faces, view, span_v=None, image_shape=None):
    """The production skull curve of one projection (a batch of one), checked by the oracle."""
    batch = detect_curves_batch(
        np.asarray(uv, dtype=float)[None],
        view,
        topology=mesh_edge_topology(faces),
        span_v=None if span_v is None else [span_v],
        image_shape=image_shape,
    )
    assert len(batch) == 1
    curve = batch.curve(0)
    ref = oracle.detect_curve(uv, faces, view, span_v=span_v, image_shape=image_shape)
    np.testing.assert_array_equal(curve, ref)
    return curve


def pair_curves(skull, face):
    """The production pairs of one skull curve and a face curve, checked by the oracle."""
    pairs = pair_curves_batch(CurveBatch.from_curves([skull]), face_curve_index(face))
    for got, want in zip(
        (pairs.skull, pairs.face, pairs.distance), oracle.pair_curves(skull, face), strict=True
    ):
        np.testing.assert_array_equal(got, want)
    return pairs.skull, pairs.face, pairs.distance


def trim_curves(skull, face):
    """The production trimming of one skull curve and a face curve, checked by the oracle."""
    trimmed, lo, hi = trim_curves_batch(CurveBatch.from_curves([skull]), face_curve_index(face))
    s, p = trimmed.curve(0), np.asarray(face, dtype=float)[lo[0] : hi[0]]
    ref_s, ref_p = oracle.trim_curves(skull, face)
    np.testing.assert_array_equal(s, ref_s)
    np.testing.assert_array_equal(p, ref_p)
    return s, p


def convergence_penalty(d):
    """The production P_conv of one list of distances, checked by the oracle."""
    got = convergence_penalties(d, [0, len(d)])[0]
    assert got == oracle.convergence_penalty(d)
    return got


# --- detection -------------------------------------------------------------------------------


def test_frontal_curve_is_the_lowest_pixel_of_every_column():
    curve = detect_curve(RECT_UV, RECT, "frontal")
    assert np.array_equal(curve, line(np.arange(11, 31), 40))


def test_lateral_curves_are_the_anterior_pixel_of_every_row_inside_the_span():
    left = detect_curve(RECT_UV, RECT, "lateral_left", span_v=(30.2, 25))
    assert np.array_equal(left, np.column_stack([np.full(6, 11.0), np.arange(25, 31)]))
    right = detect_curve(RECT_UV, RECT, "lateral_right")
    assert np.array_equal(right, np.column_stack([np.full(20, 30.0), np.arange(21, 41)]))


def test_detection_drops_isolated_pixels_and_joins_steps():
    # A right triangle whose hypotenuse drops 2 rows per column, plus a far sliver triangle
    # that covers a single pixel centre (60, 60).
    uv = np.array(
        [[10.5, 10.5], [20.5, 10.5], [10.5, 30.5], [59.8, 59.8], [60.4, 59.8], [59.8, 60.4]]
    )
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    curve = detect_curve(uv, faces, "frontal")
    assert curve[:, 0].max() < 60
    steps = np.abs(np.diff(curve, axis=0)).max(axis=1)
    assert np.all(steps == 1)  # 8-connected
    # Hypotenuse v = 10.5 + 2 (20.5 - u): row 29 at u = 11, row 11 at u = 20.
    assert curve[0].tolist() == [11.0, 29.0] and curve[-1].tolist() == [20.0, 11.0]


def test_join_fragments_inserts_straight_segments():
    joined = join_fragments([[0, 0], [3, 0], [3, 0], [5, 2]])
    assert joined.tolist() == [[0, 0], [1, 0], [2, 0], [3, 0], [4, 1], [5, 2]]


def test_join_fragments_batch_keeps_the_curves_apart_and_equals_the_oracle():
    rng = np.random.default_rng(5)
    curves = [np.cumsum(rng.integers(-4, 5, (n, 2)), axis=0) for n in (7, 0, 1, 12, 2, 0)]
    batch = join_fragments_batch(*(lambda b: (b.points, b.offset))(CurveBatch.from_curves(curves)))
    assert len(batch) == len(curves)
    for m, c in enumerate(curves):
        np.testing.assert_array_equal(batch.curve(m), oracle.join_fragments(c))


def test_refine_orders_and_orients_a_shuffled_curve():
    pts = line(np.arange(20), 5)[np.random.default_rng(0).permutation(20)]
    assert np.array_equal(order_points(pts)[:, 0], np.arange(20)) or np.array_equal(
        order_points(pts)[:, 0], np.arange(20)[::-1]
    )
    refined = refine_curve(pts, "frontal", ordered=False)
    assert np.array_equal(refined, line(np.arange(20), 5))
    assert np.array_equal(refine_curve(line([9, 0], 5), "frontal"), line(np.arange(10), 5))


def test_face_curve_from_mask():
    mask = np.zeros((60, 60), bool)
    mask[10:46, 5:37] = True  # last face row 45, columns 5..36
    curve = face_curve_from_mask(mask, "frontal", {"cheilion_l": (30.4, 25), "cheilion_r": (8, 26)})
    assert np.array_equal(curve, line(np.arange(8, 31), 45))
    lat = face_curve_from_mask(mask, "lateral_left", {"glabella": (0, 30), "metopion": (0, 20)})
    assert np.array_equal(lat, np.column_stack([np.full(11, 5.0), np.arange(20, 31)]))
    lat = face_curve_from_mask(mask, "lateral_right", {"glabella": (0, 30), "metopion": (0, 20)})
    assert np.all(lat[:, 0] == 36)
    with pytest.raises(ValueError, match="cheilion_r is not marked; mark it"):
        face_curve_from_mask(mask, "frontal", {"cheilion_l": (1, 1)})
    with pytest.raises(ValueError, match="view must be one of"):
        face_curve_from_mask(mask, "oblique", {})


# --- terms -----------------------------------------------------------------------------------


def test_parallel_curves_have_zero_penalty():
    terms = pll_penalty(line(np.arange(10), 100), line(np.arange(10), 105), "frontal")
    assert (terms.delta_d, terms.p_conv, terms.p_int, terms.total) == (0, 0, 0, 0)
    assert terms.n_pairs == 10 and terms


def test_parallel_curves_of_different_lengths_are_trimmed_to_zero():
    terms = pll_penalty(line(np.arange(10, 30), 100), line(np.arange(0, 40), 106), "frontal")
    assert terms.total == 0.0


def test_crossing_curves_count_every_violating_pair():
    skull = line(np.arange(10), 100)
    face = np.vstack([line(np.arange(5), 105), line(np.arange(5, 10), 95)])
    terms = pll_penalty(skull, face, "frontal", trim=False)
    assert terms.p_int == 5000.0  # u = 5..9: s.v = 100 >= p.v = 95
    assert terms.delta_d == 0.0 and terms.p_conv == 0.0 and terms.total == 5000.0


def test_lateral_violations_depend_on_the_looking_direction():
    skull = np.column_stack([[50.0, 52, 48], [10.0, 11, 12]])
    face = np.column_stack([[45.0, 45, 45], [10.0, 11, 12]])
    # lateral_left: face points to -u, the skin is at smaller u: s.u <= p.u is wrong.
    assert pll_penalty(skull, face, "lateral_left", trim=False).p_int == 0.0
    assert pll_penalty(skull, face, "lateral_right", trim=False).p_int == 3000.0
    assert pll_penalty(skull - [10, 0], face, "lateral_left", trim=False).p_int == 3000.0


def test_one_converging_end_costs_four_times_its_deviation():
    skull = line([0, 10, 20, 30, 40], 100)
    face = np.array([[0, 110], [10, 110], [20, 110], [30, 110], [40, 102.0]])
    s, p, d = pair_curves(skull, face)
    assert np.allclose(d, [10, 10, 10, 10, 2])
    terms = pll_penalty(skull, face, "frontal", trim=False)
    # mean 8.4: delta_1 = 1.6 <= 2.1, delta_N = 6.4 > 2.1
    assert terms.p_conv == pytest.approx(4 * 6.4)
    assert terms.delta_d == pytest.approx(8.0)
    assert terms.total == pytest.approx(8.0 + 25.6)


def test_convergence_formula():
    assert convergence_penalty([1, 10, 10, 10, 1]) == pytest.approx(2 * (5.4 + 5.4))
    assert convergence_penalty([1, 10, 10, 10, 10]) == pytest.approx(4 * 7.2)
    assert convergence_penalty([5, 5, 5]) == 0.0
    assert convergence_penalty([0, 0]) == 0.0


def test_unpaired_face_points_are_paired_to_the_nearest_skull_point_in_curve_order():
    skull = line([10, 11, 12], 100)
    face = line([8, 9, 10, 11, 12, 13], 103)
    s, p, d = pair_curves(skull, face)
    assert p[:, 0].tolist() == [8, 9, 10, 11, 12, 13]
    assert s[:, 0].tolist() == [10, 10, 10, 11, 12, 12]
    assert d[0] == pytest.approx(np.hypot(2, 3))


def test_trimming_uses_the_end_normals_of_the_other_curve():
    skull = line(np.arange(10, 21), 100)
    face = line(np.arange(0, 31), 110)
    s, p = trim_curves(skull, face)
    assert np.array_equal(s, skull)
    assert p[0, 0] == 10 and p[-1, 0] == 20


def test_empty_curve_fails_as_a_value():
    terms = pll_penalty(np.zeros((0, 2)), line([1, 2], 3), "frontal")
    assert not terms and terms.total == PLL_NO_CURVE and np.isnan(terms.delta_d)
    terms = pll_penalty(line([1, 2], 3), np.zeros((0, 2)), "frontal")
    assert not terms and terms.total == PLL_NO_CURVE and terms.n_pairs == 0


def test_hand_made_terms_equal_the_oracle():
    skull = line([0, 10, 20, 30, 40], 100)
    face = np.array([[0, 110], [10, 110], [20, 110], [30, 110], [40, 102.0]])
    cases = [
        (skull, face, "frontal", False),
        (line(np.arange(10, 30), 100), line(np.arange(0, 40), 106), "frontal", True),
        (line(np.arange(10), 100), line(np.arange(12), 95), "frontal", True),
        (
            np.column_stack([[50.0, 52, 48], [10.0, 11, 12]]),
            np.column_stack([[45.0, 45, 45], [10.0, 11, 12]]),
            "lateral_right",
            False,
        ),
        (line([3.5, 4.2, 7.9], 10.5), line(np.arange(12), 12), "frontal", True),  # off the grid
    ]
    for s, p, view, trim in cases:
        got = pll_penalty(s, p, view, trim=trim)
        assert got == oracle.pll_penalty(s, p, view, trim=trim)


def test_context_end_to_end_on_a_projected_rectangle():
    mask = np.zeros((60, 60), bool)
    mask[15:46, 5:37] = True
    face = face_curve_from_mask(mask, "frontal", {"cheilion_l": (8, 25), "cheilion_r": (33, 25)})
    ctx = PllContext.build(RECT, face, "frontal", image_shape=mask.shape)
    terms = ctx.evaluate(RECT_UV)
    assert terms.total == 0.0 and terms.n_pairs == 20
    # Push the skull 10 px down: it now lies below the chin: 20 violations, d = 5 everywhere.
    terms = ctx.evaluate(RECT_UV + [0, 10])
    assert terms.p_int == 20_000.0 and terms.delta_d == 0.0
    assert ctx.evaluate_batch(np.stack([RECT_UV, RECT_UV + [0, 10]])).tolist() == [0.0, 20_000.0]


def test_context_end_to_end_lateral_left_with_span():
    mask = np.zeros((60, 60), bool)
    mask[10:50, 5:37] = True  # anterior (smallest u) face column: 5
    span = {"glabella": (20, 36), "metopion": (20, 24)}
    face = face_curve_from_mask(mask, "lateral_left", span)
    ctx = PllContext.build(RECT, face, "lateral_left", image_shape=mask.shape)
    terms = ctx.evaluate(RECT_UV, span_v=(24, 36))
    assert terms.total == 0.0 and terms.n_pairs == 13  # rows 24..36, 6 px apart
    # Skull pushed 8 px anterior (to -u): it pokes out of the forehead by 2 px everywhere.
    terms = ctx.evaluate(RECT_UV - [8, 0], span_v=(24, 36))
    assert terms.p_int == 13_000.0 and terms.delta_d == 0.0


# --- batched evaluation ----------------------------------------------------------------------


def _bumpy_sheet(n=14, rng=0):
    """A bumpy triangulated sheet (K, 3) mm and its faces."""
    rng = np.random.default_rng(rng)
    x, y = np.meshgrid(np.linspace(-30, 30, n), np.linspace(-20, 20, n))
    z = 3 * np.sin(x / 7) * np.cos(y / 5) + rng.normal(0, 0.3, x.shape)
    verts = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]
    faces = np.vstack(
        [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    )
    # Drop a few faces: holes and isolated slivers make the rasters less regular.
    keep = rng.random(len(faces)) > 0.05
    return verts, faces[keep]


def _random_projections(verts, S, rng, spread):
    from scipy.spatial.transform import Rotation

    R = Rotation.from_rotvec(np.deg2rad(spread) * rng.standard_normal((S, 3))).as_matrix()
    t = np.array([0.0, 0.0, 400.0]) + 5 * rng.standard_normal((S, 3))
    f = 1500 * (1 + 0.1 * rng.standard_normal(S))
    X = verts @ np.swapaxes(R, 1, 2) + t[:, None]
    return np.array([320.0, 240.0]) + f[:, None, None] * X[..., :2] / X[..., 2:3]


@pytest.mark.parametrize("view", ["frontal", "lateral_left", "lateral_right"])
def test_batched_pll_equals_the_reference_on_random_cameras(view):
    rng = np.random.default_rng(7)
    verts, faces = _bumpy_sheet()
    uv = _random_projections(verts, 40, rng, spread=12.0)
    ref_curve = detect_curve(uv[0] + [3.0, 6.0], faces, view)
    ctx = PllContext.build(faces, ref_curve, view, image_shape=(480, 640))
    uv[1] = np.nan  # behind the camera: no curve
    uv[2, :5] = np.nan  # partly behind
    uv[3] += 5000.0  # far off the image: the clipped-window path
    uv[4] = uv[4, :1]  # collapsed to a point
    span_v = None
    if view != "frontal":
        span_v = np.column_stack([uv[:, 0, 1] + 40, uv[:, -1, 1] - 40])
    ref = np.array(
        [
            oracle.pll_penalty(
                oracle.detect_curve(
                    u,
                    faces,
                    view,
                    span_v=None if span_v is None else span_v[i],
                    image_shape=(480, 640),
                ),
                ctx.face_curve,
                view,
            ).total
            for i, u in enumerate(uv)
        ]
    )
    batch = ctx.evaluate_batch(uv, span_v)
    np.testing.assert_array_equal(batch, ref)
    terms = ctx.terms_batch(uv, span_v)
    for i, u in enumerate(uv):
        span = None if span_v is None else span_v[i]
        want = oracle.pll_penalty(
            oracle.detect_curve(u, faces, view, span_v=span, image_shape=(480, 640)),
            ctx.face_curve,
            view,
        )
        got = terms.member(i)
        assert got == ctx.evaluate(u, span) or np.isnan(got.delta_d)
        np.testing.assert_array_equal(
            [got.delta_d, got.p_conv, got.p_int, got.total, got.n_pairs],
            [want.delta_d, want.p_conv, want.p_int, want.total, want.n_pairs],
        )
    assert ref[1] == PLL_NO_CURVE and np.isfinite(ref).all()
    assert (ref < PLL_NO_CURVE).sum() >= 30


def test_batched_curves_equal_the_oracle():
    rng = np.random.default_rng(3)
    verts, faces = _bumpy_sheet(rng=3)
    uv = _random_projections(verts, 25, rng, spread=20.0)
    topo = PllContext.build(faces, line(np.arange(5), 0), "frontal").topology
    uv[1] = np.nan
    uv[2] += 5000.0  # clipped window
    for view in ("frontal", "lateral_left", "lateral_right"):
        batch = detect_curves_batch(uv, view, topology=topo, image_shape=(480, 640))
        assert len(batch) == len(uv)
        for i in range(len(uv)):
            ref = oracle.detect_curve(uv[i], faces, view, image_shape=(480, 640))
            np.testing.assert_array_equal(batch.curve(i), ref)


def test_pairing_ties_go_to_the_lowest_index():
    # (5, 10) is 2 px from both (3, 10) and (7, 10): the first face point wins.
    s, p, d = pair_curves([[5.0, 10.0]], [[3.0, 10.0], [7.0, 10.0]])
    assert p[0].tolist() == [3.0, 10.0] and d[0] == 2.0
