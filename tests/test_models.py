"""Fields, Newtonian systems, forces and spring networks: the physics they must respect."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import fields, forces, springs
from course_lib.systems import NewtonianSystem, stack_state, sum_forces

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

rng = np.random.default_rng(2026)


def test_syllabus_fields():
    X = np.array([[1.0, 2.0], [-3.0, 0.5]])
    np.testing.assert_array_equal(fields.radial(0.0, X), X)
    np.testing.assert_array_equal(fields.vortex(0.0, X), [[-2.0, 1.0], [-0.5, -3.0]])
    np.testing.assert_array_equal(fields.constant_wind()(0.0, X), [[7.0, 2.0], [7.0, 2.0]])
    both = fields.compose(fields.vortex, fields.constant_wind((1.0, -1.0)))
    np.testing.assert_array_equal(both(0.0, X[0]), [-1.0, 0.0])


def test_vortex_exact_flow_is_rotation():
    # RK4 follows the exact circle; after one turn of n steps of θ = 2π/n its phase lags by
    # n θ⁵/120 = 2π θ⁴/120 (R(iθ) = e^{iθ} (1 - iθ⁵/120 + ...)).
    theta = 2 * np.pi / 400
    traj = cl.integrate(fields.vortex, [0.0, 1.0], (0.0, 2 * np.pi), theta, "rk4")
    assert traj.y[-1, 0] == pytest.approx(2 * np.pi * theta**4 / 120, rel=1e-3)
    # ... and its radius shrinks by |R(iθ)|^n = (1 - θ⁶/72 + θ⁸/576)^(n/2) ≈ 1 - 2π θ⁵/144.
    assert 1.0 - np.linalg.norm(traj.y[-1]) == pytest.approx(2 * np.pi * theta**5 / 144, rel=1e-3)


def random_network(n=9, m=25, d=3):
    i = rng.integers(0, n, m)
    j = (i + rng.integers(1, n, m)) % n
    net = springs.SpringNetwork(i, j, rng.uniform(0.5, 1.5, m), rng.uniform(1, 100, m),
                                rng.uniform(0, 2, m), n)
    return net, rng.normal(size=(n, d)), rng.normal(size=(n, d))


@pytest.mark.parametrize("d", [2, 3])
def test_internal_spring_forces_conserve_momentum_and_angular_momentum(d):
    net, x, v = random_network(d=d)
    F = net.forces(x, v)
    np.testing.assert_allclose(F.sum(axis=0), 0.0, atol=1e-12)
    if d == 3:
        np.testing.assert_allclose(np.cross(x, F).sum(axis=0), 0.0, atol=1e-11)
    else:
        torque = x[:, 0] * F[:, 1] - x[:, 1] * F[:, 0]
        assert abs(torque.sum()) < 1e-11


def test_spring_forces_are_minus_energy_gradient():
    net, x, _ = random_network()
    F = net.forces(x)
    h = 1e-6
    grad = np.zeros_like(x)
    for a in range(x.shape[0]):
        for b in range(x.shape[1]):
            e = np.zeros_like(x)
            e[a, b] = h
            grad[a, b] = (net.energy(x + e) - net.energy(x - e)) / (2 * h)
    np.testing.assert_allclose(F, -grad, rtol=1e-6, atol=1e-6)


def test_pair_spring_matches_syllabus_formula():
    x1, x2 = np.array([1.0, 2.0, 2.0]), np.zeros(3)
    F1 = springs.spring_force_pair(x1, x2, k=10.0, rest=2.0)
    np.testing.assert_allclose(F1, -10.0 * (3.0 - 2.0) * x1 / 3.0)
    net = springs.SpringNetwork([0], [1], 2.0, 10.0, 0.0, 2)
    np.testing.assert_allclose(net.forces(np.stack((x1, x2))), [F1, -F1])


def test_damping_acts_only_along_the_spring():
    net = springs.SpringNetwork([0], [1], 1.0, 0.0, 3.0, 2)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    # relative velocity perpendicular to the spring: no damping force
    np.testing.assert_allclose(net.forces(x, np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])), 0.0)
    # separating at 2 m/s along it: force c * 2 pulling the ends together
    F = net.forces(x, np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    np.testing.assert_allclose(F, [[6.0, 0.0, 0.0], [-6.0, 0.0, 0.0]])


def test_hair_chain_structure():
    x0, net = springs.hair_chain(n=6, length=0.5, k_edge=100.0, k_bend=10.0, k_twist=1.0)
    assert x0.shape == (6, 3)
    counts = {k: int(np.sum(net.kind == k)) for k in ("edge", "bend", "twist")}
    assert counts == {"edge": 5, "bend": 4, "twist": 3}
    edges = net.select("edge")
    np.testing.assert_array_equal(edges.j - edges.i, 1)
    np.testing.assert_array_equal(net.select("bend").j - net.select("bend").i, 2)
    np.testing.assert_allclose(edges.rest, 0.1)
    np.testing.assert_allclose(net.forces(x0), 0.0, atol=1e-12)  # at rest


def test_cloth_grid_structure():
    x0, net = springs.cloth_grid(nx=4, ny=3, spacing=0.2)
    counts = {k: int(np.sum(net.kind == k)) for k in ("struct", "shear", "bend")}
    # struct: 3*3 + 4*2; shear: 2 per cell, 3*2 cells; bend: 2*3 + 4*1
    assert counts == {"struct": 17, "shear": 12, "bend": 10}
    np.testing.assert_allclose(net.select("shear").rest, 0.2 * np.sqrt(2))
    np.testing.assert_allclose(net.forces(x0), 0.0, atol=1e-12)


def test_nbody_forces_sum_to_zero_and_match_pair_law():
    x = rng.normal(size=(5, 3))
    m = rng.uniform(1, 2, 5)
    F = forces.nbody_gravity_force(x, m, G=2.0)
    np.testing.assert_allclose(F.sum(axis=0), 0.0, atol=1e-10)
    r = x[0] - x[1]
    pair = forces.nbody_gravity_force(x[:2], m[:2], G=2.0)[0]
    np.testing.assert_allclose(pair, -2.0 * m[0] * m[1] * r / np.linalg.norm(r) ** 3)


def test_newtonian_system_and_pinning():
    gravity = forces.constant_gravity(np.ones(3))
    net = springs.SpringNetwork([0, 1], [1, 2], 1.0, 50.0, 0.0, 3)
    system = NewtonianSystem(sum_forces(gravity, net.force), np.ones(3), pinned=[0])
    x0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    y0 = stack_state(x0, np.zeros_like(x0))
    traj = cl.integrate(system, y0, (0.0, 1.0), 1e-3, "symplectic_euler")
    assert traj.stable
    np.testing.assert_array_equal(traj.y[:, 0, 0], np.broadcast_to(x0[0], (traj.t.size, 3)))
    assert traj.y[-1, 0, 2, 1] < -0.1  # the free end fell


def test_free_fall_is_exact_for_verlet():
    system = NewtonianSystem(forces.constant_gravity(1.0), 1.0)
    y0 = stack_state([[0.0, 10.0, 0.0]], [[0.0, 0.0, 0.0]])
    traj = cl.integrate(system, y0, (0.0, 1.0), 0.1, "velocity_verlet")
    np.testing.assert_allclose(traj.y[:, 0, 0, 1], 10.0 - 0.5 * 9.81 * traj.t**2, rtol=1e-13)


def test_sphere_collision_projects_out_and_removes_inward_velocity():
    from course_lib import collisions

    post = collisions.sphere(center=(0.0, 0.0, 0.0), radius=1.0)
    x = np.array([[0.5, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]])
    v = np.array([[-1.0, 2.0, 0.0], [0.0, -3.0, 0.0], [0.0, 0.0, -1.0]])
    y = post(0.0, stack_state(x, v))
    np.testing.assert_allclose(y[0, 0], [1.0, 0.0, 0.0])      # projected to the surface
    np.testing.assert_allclose(y[1, 0], [0.0, 2.0, 0.0])      # only the tangential part stays
    np.testing.assert_array_equal(y[0, 1], x[1])              # on the surface: untouched
    np.testing.assert_array_equal(y[1, 1], v[1])
    np.testing.assert_array_equal(y[:, 2], np.stack((x[2], v[2])))  # outside: untouched


def test_ground_plane_bounce_keeps_restitution_fraction():
    from course_lib import collisions

    post = collisions.plane(restitution=0.8)
    y = post(0.0, stack_state([[0.3, -0.01, 0.0]], [[1.0, -5.0, 0.0]]))
    np.testing.assert_allclose(y[0, 0], [0.3, 0.0, 0.0])
    np.testing.assert_allclose(y[1, 0], [1.0, 4.0, 0.0])
