"""Hardening of the particle models (issue 7 §2); each test failed before its fix.

Single particles stored as ``(d,)`` positions / ``(2, d)`` states broke ``constant_gravity``,
``NewtonianSystem.momentum`` and other functions that assumed an ``(N, d)`` particle axis;
a particle exactly at a sphere collider's centre stayed inside; degenerate collider
arguments gave NaN and warnings instead of errors.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import course_lib as cl
from course_lib import collisions, forces
from course_lib.systems import NewtonianSystem, split_particles, stack_state, sum_forces

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

rng = np.random.default_rng(7)


def factories(d: int):
    """Every force factory of course_lib.forces, for one particle in d dimensions."""
    out = {
        "constant_gravity": forces.constant_gravity(2.0, np.arange(1.0, d + 1)),
        "constant_gravity (1,) mass": forces.constant_gravity([2.0], np.arange(1.0, d + 1)),
        "drag": forces.drag(b=0.3, c=0.2, wind=np.full(d, 0.5)),
        "viscous_damping": forces.viscous_damping(0.7),
        "attractor": forces.attractor(np.ones(d), 2.0),
        "nbody_gravity": forces.nbody_gravity([1.0]),
        "sum_forces": sum_forces(forces.constant_gravity(1.0, np.ones(d)),
                                 forces.viscous_damping(0.1)),
    }
    if d == 3:
        out["magnetic"] = forces.magnetic(1.5, [0.0, 0.3, 1.0], E=[0.1, 0.0, 0.0])
        out["magnetic (1,) charge"] = forces.magnetic([1.5], [0.0, 0.3, 1.0])
    return out


@pytest.mark.parametrize("d", [1, 2, 3])
def test_every_force_takes_a_single_particle(d):
    x, v = rng.normal(size=d), rng.normal(size=d)
    for name, F in factories(d).items():
        if name.startswith("magnetic") and d != 3:
            continue
        one = F(0.0, x, v)
        assert np.shape(one) == (d,), name
        np.testing.assert_allclose(one, F(0.0, x[None], v[None])[0], rtol=1e-14, err_msg=name)


def test_force_functions_take_a_single_particle():
    v = np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(forces.linear_drag_force(v, [2.0]), -2.0 * v)
    np.testing.assert_allclose(forces.linear_drag_force(v, 2.0, wind=1.0), -2.0 * (v - 1.0))
    np.testing.assert_allclose(forces.lorentz_force(v, [2.0], [0, 0, 1.0]),
                               2.0 * np.cross(v, [0, 0, 1.0]))
    with pytest.raises(ValueError, match="b must be a scalar or have one entry per particle"):
        forces.linear_drag_force(np.ones((3, 2)), [1.0, 2.0])
    with pytest.raises(ValueError, match="mass"):
        forces.constant_gravity([1.0, 2.0], [0.0, -1.0])(0.0, np.ones((3, 2)), None)


@settings(max_examples=30, deadline=None)
@given(d=st.integers(1, 3), m=st.floats(0.1, 10.0), seed=st.integers(0, 1000))
def test_newtonian_system_single_particle_is_the_one_particle_system(d, m, seed):
    r = np.random.default_rng(seed)
    x, v = r.normal(size=d), r.normal(size=d)
    system = NewtonianSystem(sum_forces(forces.constant_gravity(m, np.ones(d)),
                                        forces.drag(b=0.4)), m)
    one = stack_state(x, v)                      # (2, d)
    many = stack_state(x[None], v[None])         # (2, 1, d)
    np.testing.assert_allclose(system(0.0, one), system(0.0, many)[:, 0], rtol=1e-14)
    np.testing.assert_allclose(system.momentum(one), m * v, rtol=1e-14)
    np.testing.assert_allclose(system.momentum(many), m * v, rtol=1e-14)
    assert system.kinetic_energy(one) == pytest.approx(0.5 * m * v @ v, rel=1e-14)
    traj = cl.integrate(system, one, (0.0, 0.5), 0.1, "velocity_verlet")
    traj_n = cl.integrate(system, many, (0.0, 0.5), 0.1, "velocity_verlet")
    np.testing.assert_allclose(traj.y, traj_n.y[:, :, 0], rtol=1e-14)
    assert system.momentum(traj.y).shape == (6, d)
    np.testing.assert_allclose(system.kinetic_energy(traj.y), system.kinetic_energy(traj_n.y))


def test_single_particle_free_fall_and_pin():
    system = NewtonianSystem(forces.constant_gravity(1.0), 1.0)
    traj = cl.integrate(system, stack_state([0.0, 10.0, 0.0], [1.0, 0.0, 0.0]), (0.0, 1.0), 0.1,
                        "velocity_verlet")
    np.testing.assert_allclose(traj.y[:, 0, 1], 10.0 - 0.5 * 9.81 * traj.t**2, rtol=1e-13)
    np.testing.assert_allclose(traj.y[:, 0, 0], traj.t, rtol=1e-13)
    pinned = NewtonianSystem(forces.constant_gravity(1.0), 1.0, pinned=[0])
    y = stack_state([0.0, 10.0, 0.0], [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(pinned(0.0, y), 0.0)


def test_newtonian_system_checks_masses_and_pins():
    with pytest.raises(ValueError, match="pinned indices"):
        NewtonianSystem(forces.viscous_damping(1.0), np.ones(3), pinned=[3])
    with pytest.raises(TypeError, match="pinned"):
        NewtonianSystem(forces.viscous_damping(1.0), np.ones(3), pinned=[0.5])
    with pytest.raises(ValueError, match="mass"):
        NewtonianSystem(forces.viscous_damping(1.0), np.ones((2, 2)))
    system = NewtonianSystem(forces.viscous_damping(1.0), np.ones(3))
    with pytest.raises(ValueError, match="mass has 3 entries but the state has 2"):
        system(0.0, np.ones((2, 2, 3)))


@pytest.mark.parametrize("d", [2, 3])
def test_angular_momentum_and_energy_of_single_particles(d):
    x, v, m = rng.normal(size=d), rng.normal(size=d), 1.7
    L1 = forces.angular_momentum(stack_state(x, v), m)
    Ln = forces.angular_momentum(stack_state(x[None], v[None]), [m])
    np.testing.assert_allclose(L1, Ln, rtol=1e-14)
    expected = m * (np.cross(x, v) if d == 3 else x[0] * v[1] - x[1] * v[0])
    np.testing.assert_allclose(L1, expected, rtol=1e-14)
    assert forces.nbody_energy(stack_state(x, v), m) == pytest.approx(0.5 * m * v @ v)
    traj = np.stack([stack_state(x, v)] * 4)                     # (4, 2, d)
    assert forces.angular_momentum(traj, m).shape == ((4,) if d == 2 else (4, 3))
    np.testing.assert_allclose(forces.nbody_energy(traj, m), 0.5 * m * v @ v)


def test_split_particles_layouts():
    for shape, out in [((2, 3), (1, 3)), ((2, 5, 3), (5, 3)), ((7, 2, 3), (7, 1, 3)),
                       ((7, 2, 5, 3), (7, 5, 3))]:
        x, v = split_particles(np.zeros(shape))
        assert x.shape == v.shape == out
    with pytest.raises(ValueError, match="particle state"):
        split_particles(np.zeros((3, 3)))


# --- colliders --------------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(d=st.sampled_from([2, 3]), frac=st.floats(0.0, 0.999), seed=st.integers(0, 10**6),
       radius=st.floats(1e-3, 1e3))
def test_sphere_pushes_every_inside_particle_to_its_surface(d, frac, seed, radius):
    r = np.random.default_rng(seed)
    c = r.normal(size=d)
    u = r.normal(size=(5, d))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    x = c + frac * radius * u
    x[0] = c                                                   # exactly at the centre
    v = r.normal(size=(5, d))
    out = collisions.sphere(c, radius)(0.0, stack_state(x, v))
    dist = np.linalg.norm(out[0] - c, axis=1)
    np.testing.assert_allclose(dist, radius, rtol=1e-12)
    assert np.all(np.isfinite(out))


def test_particle_at_the_centre_leaves_the_way_it_came():
    head = collisions.sphere((1.0, 2.0, 3.0), 0.5)
    y = head(0.0, stack_state([[1.0, 2.0, 3.0]], [[0.0, 0.0, -4.0]]))   # moving down z
    np.testing.assert_allclose(y[0, 0], [1.0, 2.0, 3.5])                 # back out at +z
    np.testing.assert_allclose(y[1, 0], [0.0, 0.0, 0.0])                 # inward speed removed
    y = head(0.0, stack_state([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]))         # at rest, single
    np.testing.assert_allclose(y[0], [1.0, 2.5, 3.0])                    # out along +y


@pytest.mark.parametrize("make", [lambda: collisions.plane((0.0, 1.0, 0.0), 0.2, 0.5, 0.3),
                                  lambda: collisions.sphere((0.0, 0.0, 0.0), 1.0, 0.3, 0.2)])
def test_colliders_take_a_single_particle(make):
    post = make()
    for x, v in [([0.3, -0.1, 0.2], [1.0, -2.0, 0.5]), ([0.1, 0.1, 0.1], [0.0, 0.0, 0.0]),
                 ([3.0, 3.0, 0.0], [1.0, 1.0, 1.0])]:
        one = post(0.0, stack_state(x, v))
        np.testing.assert_allclose(one, post(0.0, stack_state([x], [v]))[:, 0])


@pytest.mark.parametrize("make,match", [
    (lambda: collisions.plane((0.0, 0.0, 0.0)), "normal must not be the zero vector"),
    (lambda: collisions.plane((0.0, np.nan, 0.0)), "normal must be finite"),
    (lambda: collisions.plane((0.0, 1.0), offset=np.nan), "offset must be finite"),
    (lambda: collisions.plane((0.0, 1.0), restitution=np.nan), "restitution must be finite"),
    (lambda: collisions.plane((0.0, 1.0), restitution=1.5), r"restitution must lie in \[0, 1\]"),
    (lambda: collisions.plane((0.0, 1.0), friction=np.nan), "friction must be finite"),
    (lambda: collisions.plane((0.0, 1.0), friction=-0.1), "friction must be >= 0"),
    (lambda: collisions.plane([[0.0, 1.0]]), "normal must be a real vector"),
    (lambda: collisions.sphere(radius=0.0), "radius must be > 0"),
    (lambda: collisions.sphere(radius=-1.0), "radius must be > 0"),
    (lambda: collisions.sphere(radius=np.nan), "radius must be finite"),
    (lambda: collisions.sphere(radius=np.inf), "radius must be finite"),
    (lambda: collisions.sphere(center=(0.0, np.inf, 0.0)), "center must be finite"),
    (lambda: collisions.sphere(friction=np.inf), "friction must be finite"),
])
def test_degenerate_collider_arguments_are_named(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_colliders_check_the_state_dimension(recwarn):
    for post in (collisions.plane((0.0, 1.0)), collisions.sphere((0.0, 0.0))):
        with pytest.raises(ValueError, match=r"y must be a state \(2, N, 2\) or \(2, 2\)"):
            post(0.0, np.zeros((2, 4, 3)))
    with pytest.raises(TypeError, match="post_steps"):
        collisions.chain(collisions.plane(), "sphere")
    assert len(recwarn) == 0
