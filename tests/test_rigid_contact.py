"""course_lib.rigid.body and .contact: Baraff's state, impulses, rolling, boxes at rest.

The sliding sphere is exact up to the step: the slip stops in the first step after
t = 2v₀/(7μg), and the final speed is 5/7 v₀ to round-off (the angular momentum about the
contact point is conserved by every friction impulse). Dropped boxes are judged as an
ensemble over seeds.
"""

import numpy as np
import pytest

from course_lib import rigid
from course_lib.integrators import BlowUpError
from course_lib.lessons import nb14_rigid_bodies as nb14
from course_lib.rigid import contact, inertia
from course_lib.rigid import quaternion as quat

EPS = np.finfo(float).eps


def test_state_and_derived_quantities():
    q = quat.from_axis_angle([1.0, 2.0, 0.5], 0.8)
    b = rigid.make("box", 2.0, (0.3, 0.2, 0.1), [[1.0, 2.0, 3.0]], q=q, v=[1.0, 0.0, -1.0],
                   omega=[0.5, -1.0, 2.0])
    assert np.allclose(b.v, [[1.0, 0.0, -1.0]]) and np.allclose(b.P, 2.0 * b.v)
    assert np.allclose(b.omega, [[0.5, -1.0, 2.0]], atol=1e-14)
    I_w = inertia.world_tensor(b.R, b.moments)
    assert np.allclose(b.L[0], I_w[0] @ b.omega[0], atol=1e-14)                  # L = I ω
    assert np.allclose(b.inv_inertia[0] @ I_w[0], np.eye(3), atol=1e-12)
    kinetic = 0.5 * 2.0 * 2.0 + 0.5 * b.omega[0] @ I_w[0] @ b.omega[0]
    assert b.kinetic_energy()[0] == pytest.approx(kinetic, rel=1e-13)
    x_dot, q_dot, P_dot, L_dot = rigid.body.derivative(b, np.ones((1, 3)), np.zeros((1, 3)))
    assert np.allclose(x_dot, b.v) and np.allclose(P_dot, 1.0) and np.allclose(L_dot, 0.0)
    assert np.allclose(q_dot, 0.5 * quat.multiply(np.r_[0.0, b.omega[0]], b.q), atol=1e-15)


def test_make_validates():
    with pytest.raises(ValueError, match="shape"):
        rigid.make("cone", 1.0, 0.1, [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="mass"):
        rigid.make("sphere", -1.0, 0.1, [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="x"):
        rigid.make("sphere", 1.0, 0.1, [[0.0, 0.0]])
    b = rigid.make("sphere", 1.0, 0.1, [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="dt"):
        rigid.simulate(b, 0.0, 3)
    with pytest.raises(ValueError, match="method"):
        rigid.simulate(b, 0.1, 3, method="euler")
    with pytest.raises(ValueError, match="restitution"):
        contact.Ground(restitution=1.5)
    with pytest.raises(ValueError, match="friction"):
        contact.Ground(friction=-0.1)
    with pytest.raises(ValueError, match="normal"):
        contact.Ground(normal=(0.0, 0.0, 0.0))


def test_simulate_stops_on_a_non_finite_state():
    b = rigid.make("sphere", 1.0, 0.1, [[0.0, 0.0, 0.0]])
    with pytest.raises(BlowUpError, match="not finite"):
        rigid.simulate(b, 0.1, 3, forces=lambda b: (np.full((1, 3), np.inf), np.zeros((1, 3))))


def test_normal_impulse_reverses_the_normal_velocity():
    """Applying j n at r gives u_n' = −e u_n, for tilted normals and off-centre points."""
    rng = np.random.default_rng(5)
    for e in (0.0, 0.4, 1.0):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        mass = 1.7
        inv_I = inertia.world_inverse(quat.to_matrix(quat.normalize(rng.normal(size=4))),
                                      inertia.box_moments(mass, (0.3, 0.2, 0.1)))
        r, v, w = rng.normal(size=3) * 0.2, -2.0 * n + rng.normal(size=3), rng.normal(size=3)
        u_n = (v + np.cross(w, r)) @ n
        assert u_n < 0
        j = float(contact.normal_impulse(mass, inv_I, r, n, v, w, e))
        v1, w1 = v + j * n / mass, w + inv_I @ np.cross(r, j * n)
        assert (v1 + np.cross(w1, r)) @ n == pytest.approx(-e * u_n, abs=1e-13 * abs(u_n))
        assert float(contact.normal_impulse(mass, inv_I, r, -n, v, w, e)) == 0.0   # separating


def test_friction_impulse_stops_the_slip_or_takes_mu_j():
    """Applying J_t at r: when |u_t|/K_t ≤ μ j_n the point stops sliding (u_t' = 0, u_n kept
    where r × t does not turn it); otherwise |J_t| = μ j_n against the slip. No slip, or no
    normal impulse: no friction."""
    rng = np.random.default_rng(6)
    for _ in range(6):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        mass = float(rng.uniform(0.5, 3.0))
        inv_I = inertia.world_inverse(quat.to_matrix(quat.normalize(rng.normal(size=4))),
                                      inertia.box_moments(mass, rng.uniform(0.1, 0.5, 3)))
        r, v, w = rng.normal(size=3) * 0.2, rng.normal(size=3), rng.normal(size=3)
        u = v + np.cross(w, r)
        u_t = u - (u @ n) * n
        for j_n, stops in ((1e3, True), (1e-4, False)):
            J = contact.friction_impulse(mass, inv_I, r, n, v, w, j_n, 0.5)
            assert abs(J @ n) < 1e-15 and J @ u_t < 0                           # in the plane, against
            v1, w1 = v + J / mass, w + inv_I @ np.cross(r, J)
            u1 = v1 + np.cross(w1, r)
            if stops:
                # K along t: the slip along t is gone (a slanted K can leave some across t)
                assert abs((u1 - u) @ u_t / np.linalg.norm(u_t) + np.linalg.norm(u_t)) < 1e-12
            else:
                assert np.linalg.norm(J) == pytest.approx(0.5 * j_n, rel=1e-12)
    ball = np.eye(3) / (0.4 * 0.01)
    rolling = contact.friction_impulse(1.0, ball, [0, -0.1, 0], [0, 1, 0], [1, -0.3, 0], [0, 0, -10],
                                       1.0, 0.5)
    assert np.array_equal(rolling, np.zeros(3))
    assert np.array_equal(contact.friction_impulse(1.0, ball, [0, -0.1, 0], [0, 1, 0], [1, 0, 0],
                                                   [0, 0, 0], 0.0, 0.5), np.zeros(3))


def test_a_balls_k_t_is_seven_halves_over_m():
    """At a ball's lowest point K_t = 1/m + R²/(⅖ m R²) = 7/(2m): the impulse that stops a
    slip u is 2 m u / 7, leaving the centre 5/7 of its speed."""
    m, R = 1.3, 0.07
    J = contact.friction_impulse(m, np.eye(3) / (0.4 * m * R * R), [0, -R, 0], [0, 1, 0],
                                 [2.0, 0.0, 0.0], np.zeros(3), 1e9, 1.0)
    assert np.allclose(J, [-2 * m * 2.0 / 7, 0, 0], rtol=1e-14)


@pytest.mark.roundoff
@pytest.mark.parametrize("mu", [0.3, 0.1, 0.8])
def test_slide_to_roll_written_out_is_the_library_run(mu):
    """The notebook's check runs a ball with friction_impulse step by step; with the
    library's impulse it is rigid.simulate's run to round-off (the ball's friction does not
    touch its normal speed, so one Gauss–Seidel visit is exact)."""
    mine, lib = nb14.slide_to_roll(mu=mu), nb14.rolling_sphere(mu=mu)
    n = min(len(mine["v"]), len(lib["v"]))
    tol = 16 * EPS * n * mine["v0"]
    assert mine["k_roll"] == lib["k_roll"]
    assert np.allclose(mine["v"][:n], lib["v"][:n], rtol=0, atol=tol)
    assert np.allclose(mine["rim"][:n], lib["rim"][:n], rtol=0, atol=tol)
    assert abs(mine["v"][-1] / mine["v_roll"] - 1) < 8 * EPS * (len(mine["v"]) - 1)


def _flat_landing(iterations=50):
    """Section 5's box landing flat at 1 m/s (0.2 m/s sideways), e = 0.5, no friction,
    solved by the library's sequential impulses with at most ``iterations`` sweeps."""
    box = rigid.make("box", 1.0, (0.3, 0.2, 0.1), [[0.0, 0.05, 0.0]], v=[0.2, -1.0, 0.0])
    ground = contact.Ground(restitution=0.5, friction=0.0, iterations=iterations)
    corners, r = ground.points(box)
    bottom = corners[0, :, 1] < 1e-12
    ground(box, 1e-3)
    u = (box.v[0] + np.cross(box.omega[0], r[0, bottom]))[:, 1]
    return box, ground, np.abs(u - 0.5).max()


def test_sequential_impulses_on_a_flat_landing():
    """Four corners at once: the velocities converge to v = (0.2, 0.5, 0) m/s without spin,
    each corner taking a quarter of (1 + e) m |u| = 1.5 N s; each sweep cuts the largest
    miss by about three (Gauss–Seidel), and the solver stops after 28 sweeps (its relative
    change below 1e-13), well inside its 50."""
    box, ground, miss = _flat_landing()
    assert np.allclose(box.v[0], [0.2, 0.5, 0.0], rtol=0, atol=1e-13)
    assert np.abs(box.omega[0]).max() < 1e-12
    impulses = -np.array(list(ground._warm[1].values()))     # the library's n points into the ground
    assert np.allclose(impulses[:, 1], 0.375, rtol=1e-12) and len(impulses) == 4
    misses = {k: _flat_landing(k)[2] for k in (1, 10, 20, 27, 28)}
    assert misses[1] == pytest.approx(1.0, abs=0.01)
    assert 2.5 < (misses[10] / misses[20]) ** 0.1 < 3.5                     # "about three"
    assert misses[27] > misses[28] == pytest.approx(miss, abs=0.0)         # stops at 28


@pytest.fixture(scope="module")
def roll():
    return nb14.rolling_sphere()


@pytest.mark.roundoff
def test_sliding_into_rolling_is_exact_up_to_the_step(roll):
    dt, steps = roll["dt"], len(roll["t"]) - 1
    t_measured = roll["t"][roll["k_roll"]]
    assert roll["t_roll"] <= t_measured <= roll["t_roll"] + dt            # first step after
    assert t_measured == pytest.approx(0.195) and roll["t_roll"] == pytest.approx(0.19417, abs=5e-6)
    # Angular momentum about the contact point is kept by friction: round-off per step.
    tol = 16 * EPS * steps * roll["v0"]
    assert abs(roll["v"][-1] - 5 / 7 * roll["v0"]) < tol
    assert abs(roll["rim"][-1] - 5 / 7 * roll["v0"]) < tol
    sliding = roll["t"] < roll["t_roll"]
    assert np.allclose(roll["v"][sliding], roll["v0"] - roll["mu"] * 9.81 * roll["t"][sliding], atol=tol)
    assert np.abs(roll["height"]).max() < tol * dt                        # never leaves the floor


def test_rolling_holds_for_other_friction():
    r = nb14.rolling_sphere(mu=0.1, v0=1.0, dt=2e-3)
    assert r["t_roll"] <= r["t"][r["k_roll"]] <= r["t_roll"] + r["dt"]
    assert r["v"][-1] == pytest.approx(5 / 7, abs=1e-12)


def test_a_flat_box_bounces_with_e_squared_height():
    """Dropped flat and without spin, all four bottom corners hit at once: each bounce
    leaves with e times the speed of arrival (the speed before the impact step's kick)."""
    e, g = 0.5, 9.81
    b = rigid.make("box", 1.0, (0.3, 0.2, 0.1), [[0.0, 0.5, 0.0]])
    ground = contact.Ground(restitution=e, friction=0.5, rest_speed=0.05)
    dt = 1e-3
    run = rigid.simulate(b, dt, 800, nb14.gravity, ground)
    vy = run.P[:, 0, 1]
    up = np.flatnonzero((vy[1:] > 0) & (vy[:-1] < 0))                   # bounce steps
    assert len(up) >= 3
    for k in up[:3]:
        assert vy[k + 1] == pytest.approx(-e * vy[k], abs=g * dt)
    # Gauss–Seidel visits the corners one after the other: what it leaves unconverged
    # (50 sweeps) is far below anything visible.
    assert np.allclose(run.x[:, 0, [0, 2]], 0.0, atol=1e-6)                # no sideways motion
    assert np.allclose(run.q[:, 0], quat.IDENTITY, atol=1e-6)              # no spin


@pytest.fixture(scope="module")
def drops():
    return [nb14.drop_box(seed, t_end=2.5, every=1) for seed in range(8)]


def test_dropped_boxes_come_to_rest_on_a_face(drops):
    """8 seeds of 8: each box ends at rest (kinetic energy < 1 μJ) lying on a face."""
    verdicts = [nb14.at_rest_on_a_face(run) for run in drops]
    assert all(v[0] for v in verdicts), verdicts


def test_dropped_boxes_never_gain_energy(drops):
    """No step raises the total energy by more than a step in flight loses, ½ m g² Δt² (8
    seeds of 8: the contact steps' error can go either way, but stays of that size), and
    every box loses at least its height's worth minus the face it rests on."""
    g, h, dt = 9.81, nb14.DROP["height"], nb14.DROP["dt"]
    for run in drops:
        total = nb14.energies(run)["total"]
        assert np.diff(total).max() < 0.5 * nb14.DROP["mass"] * g**2 * dt**2
        assert total[0] - total[-1] > g * (h - 0.5 * max(nb14.DROP["sides"]))


def test_head_on_spheres_keep_momentum_and_restitution():
    b = rigid.make("sphere", [1.0, 3.0], 0.1, [[-0.2, 0.0, 0.0], [0.1005, 0.0, 0.0]],
                   v=[[2.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    pairs = contact.SpherePairs(restitution=0.6, friction=0.4)
    run = rigid.simulate(b, 1e-3, 200, contact=pairs)
    P = run.P.sum(axis=1)
    assert np.allclose(P, P[0], atol=1e-14)
    v = run.P[-1, :, 0] / np.array([1.0, 3.0])
    assert v[1] - v[0] == pytest.approx(0.6 * 3.0, rel=1e-12)              # separation = e × approach
    assert np.allclose(run.L, 0.0, atol=1e-15)                            # head on: no spin
