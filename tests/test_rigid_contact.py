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
    """No step raises the total energy by more than 0.1 % of m g h (8 seeds of 8; lifting a
    sunken corner back costs a little potential energy), and every box loses at least its
    height's worth minus the face it rests on."""
    g, h = 9.81, nb14.DROP["height"]
    for run in drops:
        total = nb14.energies(run)["total"]
        assert np.diff(total).max() < 1e-3 * g * h
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
