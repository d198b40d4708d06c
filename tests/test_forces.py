"""Unit tests of course_lib.forces, collisions, events and demos against theory."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from course_lib import collisions, events, forces
from course_lib.lessons import nb05_newton as nb05
from course_lib.lessons import nb06_forces as nb06

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding


def test_nbody_third_law_and_potential_gradient():
    rng = np.random.default_rng(1)
    x, m = rng.normal(size=(6, 3)), rng.uniform(0.5, 2.0, 6)
    for eps in (0.0, 0.2):
        F = forces.nbody_gravity_force(x, m, G=1.3, softening=eps)
        assert np.allclose(F.sum(axis=0), 0.0, atol=1e-12)
        # F = -grad U, by central differences
        h = 1e-6
        grad = np.zeros_like(x)
        for i in range(6):
            for d in range(3):
                xp, xm = x.copy(), x.copy()
                xp[i, d] += h
                xm[i, d] -= h
                grad[i, d] = (forces.nbody_potential_energy(xp, m, 1.3, eps)
                              - forces.nbody_potential_energy(xm, m, 1.3, eps)) / (2 * h)
        assert np.allclose(F, -grad, rtol=1e-6, atol=1e-8)


def test_nbody_two_bodies_inverse_square():
    F = forces.nbody_gravity_force([[0.0, 0.0], [2.0, 0.0]], [3.0, 5.0], G=1.0)
    assert np.allclose(F, [[15.0 / 4, 0.0], [-15.0 / 4, 0.0]])


def test_drag_forces():
    v = np.array([[1.0, 2.0], [-3.0, 0.5]])
    w = np.array([0.5, 0.0])
    assert np.allclose(forces.drag(b=2.0, wind=w)(0, None, v), -2.0 * (v - w))
    assert np.allclose(forces.linear_drag_force(v, [1.0, 2.0]), -np.array([[1.0], [2.0]]) * v)
    q = forces.quadratic_drag_force(v, 0.3, w)
    rel = v - w
    assert np.allclose(q, -0.3 * np.linalg.norm(rel, axis=1)[:, None] * rel)
    assert np.allclose(forces.viscous_damping(0.7)(0, None, v), -0.7 * v)


def test_lorentz_force_does_no_work():
    rng = np.random.default_rng(2)
    v = rng.normal(size=(10, 3))
    F = forces.lorentz_force(v, 2.0, [0.3, -1.0, 2.0])
    assert np.allclose(np.einsum("nd,nd->n", F, v), 0.0)
    assert np.allclose(forces.lorentz_force([[1.0, 0, 0]], 1.0, [0, 0, 2.0]), [[0, -2.0, 0]])


def test_attractor_points_to_center():
    F = forces.attractor((1.0, 1.0), 2.0, softening=0.0)(0.0, np.array([[1.0, 3.0]]), None)
    assert np.allclose(F, [[0.0, -2.0 / 4]])     # strength / r² toward the centre


def test_plane_restitution_and_friction():
    ground = collisions.plane(normal=(0.0, 1.0), restitution=0.5, friction=0.0)
    y = np.array([[[0.0, -0.1]], [[1.0, -4.0]]])
    out = ground(0.0, y)
    assert np.allclose(out[0], [[0.0, 0.0]]) and np.allclose(out[1], [[1.0, 2.0]])
    sticky = collisions.plane(normal=(0.0, 1.0), restitution=0.0, friction=1.0)
    out = sticky(0.0, np.array([[[0.0, -0.1]], [[1.0, -4.0]]]))
    assert np.allclose(out[1], [[0.0, 0.0]])      # friction stops it, never reverses it
    out = sticky(0.0, np.array([[[0.0, -0.1]], [[5.0, -1.0]]]))
    assert np.allclose(out[1], [[4.0, 0.0]])      # tangential speed drops by mu |dv_n|


def test_sphere_projects_to_surface():
    head = collisions.sphere(center=(0.0, 0.0, 0.0), radius=1.0)
    y = np.array([[[0.5, 0.0, 0.0], [2.0, 0.0, 0.0]], [[-1.0, 1.0, 0.0], [0.0, 0.0, 0.0]]])
    out = head(0.0, y)
    assert np.allclose(out[0], [[1.0, 0, 0], [2.0, 0, 0]])
    assert np.allclose(out[1], [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])


@settings(max_examples=50, deadline=None)
@given(st.floats(0.1, 100), st.floats(-20, 20), st.floats(0.5, 20))
def test_crossing_ballistic_solves_the_quadratic(h, v, g):
    s = events.crossing_ballistic(h, v, -g)
    assert s > 0
    assert h + v * s - 0.5 * g * s * s == pytest.approx(0.0, abs=1e-9 * (1 + h + v * v / g))


def test_crossings():
    assert events.crossing_ballistic(10.0, 0.0, -9.81) == pytest.approx(np.sqrt(20 / 9.81))
    assert events.crossing_ballistic(3.0, -2.0, 0.0) == pytest.approx(1.5)
    assert np.isnan(events.crossing_ballistic(1.0, 1.0, 0.0))         # moving away, no pull
    assert events.crossing_linear(0.0, 1.0, 1.0, -3.0) == pytest.approx(0.25)
    assert np.isnan(events.first_crossing([0, 1, 2], [3.0, 2.0, 1.0]))
    with pytest.raises(ValueError):
        events.first_crossing([0, 1], [1.0, -1.0], rule="ballistic")
    t = np.linspace(0, 10, 1001)
    times = events.upward_crossings(t, np.sin(2 * np.pi * t / 2.5))
    assert np.allclose(times, 2.5 * np.arange(1, 4), atol=1e-6)
    assert events.measured_period(t, np.sin(2 * np.pi * t / 2.5)) == pytest.approx(2.5, rel=1e-8)


def test_local_maxima_exact_on_parabola_and_fit_circle():
    t = np.linspace(0, 1, 11)
    tp, hp = events.local_maxima(t, 2.0 - 3.0 * (t - 0.437) ** 2)
    assert tp == pytest.approx([0.437]) and hp == pytest.approx([2.0])
    phi = np.linspace(0, 1.0, 7)
    c, r = events.fit_circle(np.column_stack((3 + 0.7 * np.cos(phi), -1 + 0.7 * np.sin(phi))))
    assert np.allclose(c, [3.0, -1.0]) and r == pytest.approx(0.7)


def test_demo_helpers():
    assert nb05.euler_apple_height(15) == pytest.approx(10 - 9.81 * 0.01 * 105)
    assert nb05.symplectic_apple_height(14) == pytest.approx(10 - 9.81 * 0.01 * 105)
    m, y0 = nb06.cluster()
    assert forces.angular_momentum(y0, m).shape == ()
    E = forces.nbody_energy(y0, m, softening=0.1)
    assert np.isfinite(E) and E < 0                                   # bound cluster
    _x, v = nb06.linear_drag_exact([0.0, 1e3], [0, 0], [1, 1], 2.0, 0.5, wind=[3.0, 0.0])
    assert np.allclose(v[0], [1, 1]) and np.allclose(v[1], [3.0, -9.81 * 4])
    _t, h, v = nb06.bouncing_ball(restitution=0.0, t_end=2.0)
    assert h[-1] == 0.0 and v[-1] == 0.0                               # comes to rest
