"""course_lib.boids: Reynolds' rules, the two neighbour searches, order parameters."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from course_lib import boids as B


def test_rules_validate_their_arguments():
    with pytest.raises(ValueError, match="radius"):
        B.Rules(radius=0.0)
    with pytest.raises(ValueError, match="view_angle"):
        B.Rules(view_angle=7.0)
    with pytest.raises(ValueError, match="min_speed"):
        B.Rules(min_speed=3.0, max_speed=2.0)
    with pytest.raises(ValueError, match="box"):
        B.Rules(radius=2.0, box=3.0)
    with pytest.raises(ValueError, match="unknown method 'grid'"):
        B.steering(np.zeros((2, 2)), np.ones((2, 2)), B.Rules(), "grid")
    with pytest.raises(ValueError, match="dt"):
        B.step(np.zeros((2, 2)), np.ones((2, 2)), 0.0, B.Rules())


def test_three_boids_by_hand():
    # boids 0 and 1 fly +x one behind the other; boid 2, up and to the left, flies down.
    # With a 180° view each sees only what lies ahead of it: 0 sees 1; 1 sees nobody;
    # 2 sees both (they are below it).
    x = np.array([[0.0, 0.0], [1.0, 0.0], [-0.5, 1.0]])
    v = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, -1.0]])
    rules = B.Rules(radius=2.0, view_angle=np.pi)
    i, j, _ = B.all_pairs(x, v, rules)
    assert list(zip(i.tolist(), j.tolist(), strict=True)) == [(0, 1), (2, 0), (2, 1)]
    sep, ali, coh = B.steering(x, v, rules, "all_pairs")
    assert np.allclose(sep[0], [-1.0, 0.0]) and np.allclose(ali[0], 0.0)
    assert np.allclose(coh[0], [1.0, 0.0])
    for rule in (sep, ali, coh):
        assert np.array_equal(rule[1], [0.0, 0.0])                    # sees nobody
    d20, d21 = np.array([0.5, -1.0]), np.array([1.5, -1.0])
    assert np.allclose(sep[2], -(d20 / 1.25 + d21 / 3.25), rtol=1e-15)
    assert np.allclose(ali[2], [1.0, 1.0]) and np.allclose(coh[2], [1.0, -1.0])


@pytest.mark.roundoff
@pytest.mark.parametrize("box", [None, 10.0])
@pytest.mark.parametrize("view", [2 * np.pi, 1.5 * np.pi, np.radians(120.0)])
def test_all_pairs_and_tree_find_the_same_neighbours(box, view):
    rng = np.random.default_rng(11)
    rules = B.Rules(radius=1.5, view_angle=view, box=box)
    x, v = B.random_flock(300, 10.0, 1.3, rng)
    if box is None:
        x = x - 5.0                                       # open space: any coordinates
    a, t = B.all_pairs(x, v, rules), B.tree_pairs(x, v, rules)
    assert np.array_equal(a[0], t[0]) and np.array_equal(a[1], t[1])
    assert np.allclose(a[2], t[2], rtol=0, atol=1e-14)
    assert len(a[0]) > 300
    for sa, s_t in zip(B.steering(x, v, rules, "all_pairs"), B.steering(x, v, rules, "tree"),
                      strict=True):
        assert np.allclose(sa, s_t, rtol=1e-12, atol=1e-12)


def test_minimum_image_across_the_border():
    rules = B.Rules(radius=1.0, view_angle=2 * np.pi, box=10.0)
    x = np.array([[0.2, 5.0], [9.9, 5.0]])                # 0.3 m apart through the border
    v = np.ones((2, 2))
    i, _, d = B.tree_pairs(x, v, rules)
    assert i.tolist() == [0, 1] and np.allclose(d, [[-0.3, 0.0], [0.3, 0.0]])
    assert np.allclose(B.nearest_distances(x, 10.0), 0.3)


def test_step_clamps_speeds_and_wraps_positions():
    rng = np.random.default_rng(3)
    rules = B.Rules(box=8.0, separation=50.0)
    x, v = B.random_flock(100, 8.0, 0.1, rng)             # too slow at first
    x1, v1 = B.step(x, v, 0.1, rules)
    speed = np.linalg.norm(v1, axis=1)
    assert speed.min() >= rules.min_speed - 1e-12 and speed.max() <= rules.max_speed + 1e-12
    assert x1.min() >= 0.0 and x1.max() < 8.0
    golden = B.GOLDEN_ANGLE                                   # boid 1 at rest sets off at 1 m/s
    assert np.allclose(B.clamp_speed(np.array([[3.0, 4.0], [0.0, 0.0]]), 1.0, 2.0),
                       [[1.2, 1.6], [np.cos(golden), np.sin(golden)]])
    assert np.array_equal(B.clamp_speed(np.zeros((2, 2)), 0.0, 2.0), np.zeros((2, 2)))


def test_alignment_alone_decays_geometrically_and_keeps_the_mean():
    n, dt = 20, 0.1
    rules = B.Rules(separation=0.0, cohesion=0.0, alignment=12.5, radius=1e3,
                    view_angle=2 * np.pi, min_speed=0.0, max_speed=np.inf)
    rng = np.random.default_rng(7)
    x, v = B.random_flock(n, 5.0, 1.0, rng)
    mean = v.mean(axis=0)
    dev0 = v - mean
    for k in range(1, 6):
        x, v = B.step(x, v, dt, rules, "all_pairs")
        factor = 1 - 12.5 * dt * n / (n - 1)
        assert np.allclose(v - mean, factor**k * dev0, rtol=0, atol=1e-14)
    assert np.allclose(v.mean(axis=0), mean, rtol=0, atol=1e-15)


def test_order_parameters_and_their_random_values():
    assert B.polarization(np.array([[1.0, 0.0], [3.0, 0.0]])) == pytest.approx(1.0)
    assert B.polarization(np.array([[1.0, 0.0], [-2.0, 0.0]])) == pytest.approx(0.0, abs=1e-15)
    rng = np.random.default_rng(5)
    n = 300
    theta = rng.uniform(0, 2 * np.pi, (4000, n))
    pols = np.hypot(np.cos(theta).mean(axis=1), np.sin(theta).mean(axis=1))
    assert pols.mean() == pytest.approx(B.random_polarization(n), rel=0.02)
    box = 20.0
    nn = [B.nearest_distances(rng.uniform(0, box, (n, 2)), box).mean() for _ in range(300)]
    exact = B.random_nearest_distance(n, box)
    assert np.mean(nn) == pytest.approx(exact, rel=4 * np.std(nn) / np.sqrt(300) / exact)
    # the closed form (incomplete beta) is the integral
    from scipy.integrate import quad
    for n_pts, side in [(2, 5.0), (150, 20.0), (300, 28.0)]:
        area = side * side
        integral = quad(lambda r, a=area, m=n_pts: (1 - np.pi * r * r / a) ** (m - 1), 0, side / 2)[0]
        assert B.random_nearest_distance(n_pts, side) == pytest.approx(integral, rel=1e-12)
    # Clark & Evans (1954): 1/(2 sqrt(density)) for many points
    assert B.random_nearest_distance(100_000, 100.0) == pytest.approx(0.5 / np.sqrt(10.0), rel=1e-4)


def test_flee_points_away_and_stops_at_its_radius():
    x = np.array([[1.0, 0.0], [0.0, 2.0], [5.0, 5.0]])
    a = B.flee(x, [0.0, 0.0], radius=3.0, strength=4.0)
    assert np.allclose(a, [[4.0, 0.0], [0.0, 2.0], [0.0, 0.0]])
    wrapped = B.flee(np.array([[9.5, 0.0]]), [0.5, 0.0], radius=3.0, strength=1.0, box=10.0)
    assert np.allclose(wrapped, [[-1.0, 0.0]])                # through the border


def _steering_by_loops(x, v, rules):
    """The rules straight from their definition: a Python loop over every ordered pair."""
    n = len(x)
    sep, ali, coh = np.zeros((n, 2)), np.zeros((n, 2)), np.zeros((n, 2))
    half = np.cos(rules.view_angle / 2)
    for i in range(n):
        seen = []
        for j in range(n):
            d = x[j] - x[i]
            if rules.box is not None:
                d = d - rules.box * np.round(d / rules.box)
            r = np.hypot(*d)
            if i == j or r > rules.radius:
                continue
            if rules.view_angle < 2 * np.pi and d @ v[i] < half * r * np.hypot(*v[i]):
                continue
            seen.append((j, d))
        if seen:
            sep[i] = -sum(d / (d @ d) for _, d in seen)
            ali[i] = np.mean([v[j] for j, _ in seen], axis=0) - v[i]
            coh[i] = np.mean([d for _, d in seen], axis=0)
    return sep, ali, coh


@pytest.mark.parametrize("box", [None, 6.0])
@pytest.mark.parametrize("view", [2 * np.pi, 1.5 * np.pi, np.radians(120.0)])
def test_tree_steering_matches_a_loop_over_pairs(box, view):
    # the tree path computes each close pair's offset once and negates it for the other
    # direction, and sums column by column: the same numbers as the definition's loop
    rng = np.random.default_rng(3)
    rules = B.Rules(radius=1.2, view_angle=view, box=box)
    x, v = B.random_flock(120, 6.0, 1.3, rng)
    i, j, d = B.tree_pairs(x, v, rules)
    assert len(i) > 400 and np.all(i != j)
    for got, ref in zip(B.steering(x, v, rules, "tree"), _steering_by_loops(x, v, rules),
                        strict=True):
        assert np.max(np.abs(got - ref)) <= 1e-12 * max(1.0, np.max(np.abs(ref)))
    back = {(a, b): k for k, (a, b) in enumerate(zip(i.tolist(), j.tolist(), strict=True))}
    mutual = [(k, back[b, a]) for (a, b), k in back.items() if (b, a) in back]
    assert len(mutual) > 100 and all(np.array_equal(d[k], -d[m]) for k, m in mutual)


# --- one definition of a neighbour, finite rules for every finite state (issue 20) --------


def test_the_searches_agree_across_the_border_where_they_used_to_differ():
    # found by a search on the old code: the tree (on wrapped coordinates) and the raw
    # offsets (wrapped once more) rounded a pair at the radius (boids 3 and 11, 0.3 m
    # apart through the border) differently; now both judge the same offset
    x = np.array([[16.88637866020556, 0.0], [2.6999999999999997, 4.147350334098336],
                  [-5.532017307483322, 2.6999999999999997], [2.1, 0.15], [0.0, 0.75], [1.95, 0.6],
                  [-0.75, 3.6512009385486763], [0.6322018146359909, 1.65],
                  [-6.941664119816091, 1.7999999999999998], [2.85, -8.016766268949475],
                  [-1.124527143743009, 19.536913191921894], [2.1, -0.15]])
    rules = B.Rules(radius=0.3, view_angle=2 * np.pi, box=10.0)
    v = np.ones_like(x)
    a, t = B.all_pairs(x, v, rules), B.tree_pairs(x, v, rules)
    assert a[0].tolist() == [8, 9] and a[1].tolist() == [9, 8]     # 0.277 m through the border
    for got, ref in zip(t, a, strict=True):
        assert np.array_equal(got, ref)


@st.composite
def flocks(draw):
    """Boids at awkward places: on a lattice of spacing radius/2 (distances of exactly the
    radius), on top of each other, at the box's edges, many boxes away, nearly coincident
    (offsets of 1e-300 m), with speeds from zero and subnormal to 1e6 m/s."""
    radius = draw(st.sampled_from([0.3, 1.0, 2.0 / 3.0]))
    box = draw(st.one_of(st.none(), st.sampled_from([3.1, 4.0, 10.0])))
    side = 10.0 if box is None else box
    coordinate = st.one_of(st.floats(-side, 2 * side, allow_nan=False),
                           st.integers(-8, 24).map(lambda k: k * radius / 2),
                           st.sampled_from([0.0, side, np.nextafter(side, 0.0), -1e-300, 1e6 * side]))
    speed = st.one_of(st.floats(-1e6, 1e6, allow_nan=False), st.sampled_from([0.0, 5e-324, -1e-310]))
    n = draw(st.integers(1, 16))
    x = np.array(draw(st.lists(st.tuples(coordinate, coordinate), min_size=n, max_size=n)))
    v = np.array(draw(st.lists(st.tuples(speed, speed), min_size=n, max_size=n)))
    if n > 2 and draw(st.booleans()):
        x[1] = x[0]                                                   # coincident
        x[2] = x[0] + [1e-300, 0.0]                                   # nearly so
    view = draw(st.sampled_from([2 * np.pi, 1.5 * np.pi, np.radians(120.0)]))
    return x, v, B.Rules(radius=radius, view_angle=view, box=box)


@pytest.mark.roundoff
@settings(max_examples=100, deadline=None)  # make fuzz: x10
@given(flocks())
def test_both_searches_agree_and_the_rules_stay_finite(case):
    x, v, rules = case
    a, t = B.all_pairs(x, v, rules), B.tree_pairs(x, v, rules)
    for got, ref in zip(t, a, strict=True):
        assert np.array_equal(got, ref)
    assert np.all(np.any(a[2] != 0, axis=1))                   # nobody sees a boid on its spot
    for method in B.METHODS:
        for rule in B.steering(x, v, rules, method):
            assert np.all(np.isfinite(rule))
    x1, v1 = B.step(x, v, 0.1, rules)
    assert np.all(np.isfinite(x1)) and np.all(np.isfinite(v1))
    speed = np.hypot(v1[:, 0], v1[:, 1])
    assert np.all(speed >= rules.min_speed * (1 - 1e-12)) and np.all(speed <= rules.max_speed * (1 + 1e-12))


def test_coincident_boids_do_not_see_each_other_and_stay_finite():
    x = np.array([[1.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    v = np.ones((3, 2))
    rules = B.Rules(view_angle=2 * np.pi)
    i, j, _ = B.all_pairs(x, v, rules)
    assert (0, 1) not in set(zip(i.tolist(), j.tolist(), strict=True))
    sep = B.steering(x, v, rules, "tree")[0]
    assert np.allclose(sep[:2], [[-1.0, 0.0], [-1.0, 0.0]]) and np.allclose(sep[2], [2.0, 0.0])
    assert np.all(np.isfinite(B.step(x, v, 0.1, rules)[0]))


def test_a_boid_at_rest_sets_off_at_the_minimum_speed():
    x = np.array([[0.0, 0.0], [50.0, 50.0], [20.0, 0.0]])           # nobody near anybody
    x1, v1 = B.step(x, np.zeros((3, 2)), 0.1, B.Rules())
    assert np.allclose(np.hypot(v1[:, 0], v1[:, 1]), 1.0)
    assert len({tuple(np.round(h, 6)) for h in v1}) == 3               # three headings
    assert np.allclose(x1, x + 0.1 * v1)


def test_bad_states_get_a_clear_error():
    with pytest.raises(ValueError, match="same shape"):
        B.step(np.zeros((3, 2)), np.zeros((2, 2)), 0.1, B.Rules())
    with pytest.raises(ValueError, match="finite"):
        B.steering(np.array([[0.0, np.nan]]), np.ones((1, 2)), B.Rules())
    with pytest.raises(ValueError, match="extra"):
        B.step(np.zeros((2, 2)), np.ones((2, 2)), 0.1, B.Rules(), extra=[np.inf, 0.0])
    with pytest.raises(ValueError, match="alignment"):
        B.Rules(alignment=np.nan)


def test_steer_to_avoid():
    pillar, rho = np.array([[5.0, 0.0]]), np.array([1.0])
    x = np.array([[0.0, 0.0], [0.0, 0.5], [0.0, 3.0], [7.0, 0.0], [5.0, 0.5], [0.0, 0.0]])
    v = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    a = B.avoid(x, v, pillar, rho, lookahead=5.0, strength=2.0)
    assert np.allclose(a[0], [0.0, 2.0 * (1 - 5.0 / 6.0)])      # head-on: turn left
    assert a[1][0] == 0.0 and np.allclose(a[1][1], 2.0 * (1 - 5.0 / 6.0))      # away from the centre
    assert np.array_equal(a[2], [0.0, 0.0]) and np.array_equal(a[3], [0.0, 0.0])   # beside, behind
    assert np.allclose(a[4], [0.0, 2.0])                        # inside: straight out
    assert np.array_equal(a[5], [0.0, 0.0])                     # at rest: no heading
    # flown: a boid aimed at the pillar goes round it, one without the rule flies through
    rules = B.Rules(separation=0.0, alignment=0.0, cohesion=0.0, min_speed=1.0, max_speed=1.0)
    for strength, enters in ((4.0, False), (0.0, True)):
        xs, vs, inside = np.array([[0.0, 0.01]]), np.array([[1.0, 0.0]]), False
        for _ in range(100):
            xs, vs = B.step(xs, vs, 0.1, rules, extra=B.avoid(xs, vs, pillar, rho, 3.0, strength))
            inside |= bool(np.hypot(*(xs[0] - pillar[0])) < rho[0])
        assert inside == enters and xs[0, 0] > 8.0
    three_d = B.avoid(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), [[0.0, 0.0, 3.0]], [1.0], 4.0, 1.0)
    assert np.allclose(three_d[0, 2], 0.0) and np.isclose(np.linalg.norm(three_d), 1 - 3.0 / 5.0)


# --- step validates once per call, bit for bit the public pieces (issue 21) ------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("box", [12.0, None])
@pytest.mark.parametrize("method", ["tree", "all_pairs"])
def test_step_is_bit_for_bit_the_public_pieces(seed, box, method):
    """The fast path of step (validation once, no re-wrap inside the search) gives exactly
    the bits of steering + clamp_speed + wrap_positions, as step was written before."""
    rules = B.Rules(box=box)
    x, v = B.random_flock(60, 12.0, 1.5, np.random.default_rng(seed))
    for _ in range(25):
        sep, ali, coh = B.steering(x, v, rules, method)
        a = rules.separation * sep + rules.alignment * ali + rules.cohesion * coh
        v_ref = B.clamp_speed(v + 0.05 * a, rules.min_speed, rules.max_speed)
        x_ref = x + 0.05 * v_ref
        x_ref = x_ref if box is None else B.neighbors.wrap_positions(x_ref, box)
        x, v = B.step(x, v, 0.05, rules, method)
        assert np.array_equal(x, x_ref) and np.array_equal(v, v_ref)


def test_step_names_a_bad_method_and_stops_on_a_blow_up():
    x, v = B.random_flock(10, 12.0, 1.5, np.random.default_rng(0))
    with pytest.raises(ValueError, match="tree, all_pairs"):
        B.step(x, v, 0.1, B.Rules(), method="grid")
    with pytest.raises(ValueError, match="blew up"), np.errstate(over="ignore", invalid="ignore"):
        B.step(x, v, 0.1, B.Rules(max_speed=np.inf, separation=1e308, radius=20.0))
