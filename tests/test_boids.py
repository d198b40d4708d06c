"""course_lib.boids: Reynolds' rules, the two neighbour searches, order parameters."""

import time

import numpy as np
import pytest

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
    for sa, st in zip(B.steering(x, v, rules, "all_pairs"), B.steering(x, v, rules, "tree"),
                      strict=True):
        assert np.allclose(sa, st, rtol=1e-12, atol=1e-12)


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
    assert np.allclose(B.clamp_speed(np.array([[3.0, 4.0], [0.0, 0.0]]), 1.0, 2.0),
                       [[1.2, 1.6], [0.0, 0.0]])


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


def test_two_thousand_boids_step_in_under_20_ms():
    rng = np.random.default_rng(2026)
    box = np.sqrt(2000 / 0.375)
    rules = B.Rules(box=box)
    x, v = B.random_flock(2000, box, 1.0, rng)
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        B.step(x, v, 0.15, rules)
        best = min(best, time.perf_counter() - t0)
    assert best < 0.020


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
