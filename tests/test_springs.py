"""Unit tests of course_lib.springs (forces, energy, linearization, damping, step limits)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import course_lib as cl
from course_lib import springs as S
from course_lib import stability
from course_lib.lessons import nb07_springs as nb07


def _random_network(seed=1, n=7):
    rng = np.random.default_rng(seed)
    pairs = np.array([(a, b) for a in range(n) for b in range(a + 1, n)])
    net = S.SpringNetwork(pairs[:, 0], pairs[:, 1], rng.uniform(0.5, 1.5, len(pairs)),
                          rng.uniform(1.0, 50.0, len(pairs)), rng.uniform(0.0, 2.0, len(pairs)), n)
    return net, rng.normal(size=(n, 3)), rng.normal(size=(n, 3))


def test_forces_match_pair_formula():
    net, x, _ = _random_network()
    F = net.forces(x)
    expected = np.zeros_like(x)
    for s in range(net.n_springs):
        f = S.spring_force_pair(x[net.i[s]], x[net.j[s]], net.k[s], net.rest[s])
        expected[net.i[s]] += f
        expected[net.j[s]] -= f
    assert np.allclose(F, expected, rtol=1e-12, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_internal_forces_conserve_momentum_and_angular_momentum(seed):
    net, x, v = _random_network(seed)
    F = net.forces(x, v)                      # with damping along the springs too
    scale = np.abs(F).max()
    assert np.linalg.norm(F.sum(axis=0)) <= 1e-12 * scale
    assert np.linalg.norm(np.cross(x, F).sum(axis=0)) <= 1e-12 * scale * np.abs(x).max()


def test_force_is_minus_energy_gradient():
    net, x, _ = _random_network(3)
    h = 1e-6
    grad = np.zeros_like(x)
    for a in range(x.shape[0]):
        for p in range(3):
            e = np.zeros_like(x)
            e[a, p] = h
            grad[a, p] = (net.energy(x + e) - net.energy(x - e)) / (2 * h)
    assert np.allclose(net.forces(x), -grad, atol=1e-6)


def test_damping_ignores_rigid_motion():
    net, x, _ = _random_network(4)
    omega = np.array([0.3, -1.0, 0.5])
    v_rigid = np.array([1.0, 2.0, -0.5]) + np.cross(omega, x)
    assert np.allclose(net.forces(x, v_rigid), net.forces(x), atol=1e-12)


def test_stiffness_matrix_is_jacobian_of_forces():
    net, x, _ = _random_network(5)
    K = S.stiffness_matrix(net, x)
    assert np.allclose(K, K.T)
    h = 1e-6
    n = x.size
    J = np.zeros((n, n))
    for col in range(n):
        e = np.zeros(n)
        e[col] = h
        e = e.reshape(x.shape)
        J[:, col] = (net.forces(x + e) - net.forces(x - e)).ravel() / (2 * h)
    assert np.allclose(K, -J, atol=1e-5 * np.abs(K).max())


@pytest.mark.parametrize("n", [2, 5, 16])
def test_max_frequency_of_chain_matches_exact_formula(n):
    x0, net = S.hair_chain(n, 0.3, k_edge=2000.0)
    w = S.max_frequency(net, x0, 1e-4, pinned=[0])
    assert w == pytest.approx(S.chain_max_frequency(n - 1, 2000.0, 1e-4), rel=1e-12)
    assert S.chain_max_frequency(10_000, 1.0, 1.0) == pytest.approx(2.0, rel=1e-6)


def test_max_frequency_single_spring():
    _, _, net = S.anchored_spring(16.0, 4.0)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert S.max_frequency(net, x, 4.0, pinned=[0]) == pytest.approx(2.0, rel=1e-12)


def test_critical_damping_and_exact_solutions():
    k, m = 10.0, 1.0
    c = S.critical_damping(k, m)
    assert c == pytest.approx(2 * np.sqrt(10.0), rel=1e-15)
    t = np.linspace(0.0, 3.0, 3001)
    for cc in (0.3 * c, c, 3.0 * c):
        x = S.damped_oscillator(t, k, m, cc, 0.1, 0.2)
        v = S.damped_oscillator(t, k, m, cc, 0.1, 0.2, velocity=True)
        assert x[0] == pytest.approx(0.1) and v[0] == pytest.approx(0.2)
        a = np.gradient(v, t)
        assert np.allclose(m * a[5:-5] + cc * v[5:-5] + k * x[5:-5], 0.0, atol=1e-3)
        assert np.allclose(np.gradient(x, t)[5:-5], v[5:-5], atol=1e-4)
    # continuous through the critical value
    near = S.damped_oscillator(t, k, m, c * (1 + 1e-7), 0.1)
    assert np.allclose(near, S.damped_oscillator(t, k, m, c, 0.1), atol=1e-7)


def test_settling_time():
    t = np.linspace(0, 10, 1001)
    assert nb07.settling_time(t, np.exp(-t)) == pytest.approx(np.log(100), abs=0.011)
    assert nb07.settling_time(t, np.cos(t)) == np.inf


def test_bisect_stable_dt_and_brackets():
    got = stability.bisect_stable_dt(lambda dt: dt <= 1.2345, 1.0, 2.0, rtol=1e-9)
    assert got == pytest.approx(1.2345, rel=1e-8)
    with pytest.raises(ValueError):
        stability.bisect_stable_dt(lambda dt: False, 1.0, 2.0)
    with pytest.raises(ValueError):
        stability.bisect_stable_dt(lambda dt: True, 1.0, 2.0)


def test_spring_dt_max_matches_theory():
    assert nb07.spring_dt_max(9.0, 1.0) == pytest.approx(2.0 / 3.0, rel=2e-3)


def test_anchored_spring_is_the_1d_oscillator():
    system, y0, net = S.anchored_spring(10.0, 2.0, stretch=0.05)
    traj = cl.integrate(system, y0, (0.0, 2.0), 1e-3, method="velocity_verlet")
    s = net.lengths(cl.split_state(traj.y)[0])[:, 0] - 1.0
    assert np.allclose(s, S.damped_oscillator(traj.t, 10.0, 2.0, 0.0, 0.05), atol=1e-6)


def test_run_spring_energy_and_verdict():
    run = nb07.run_spring(k=10.0, c=0.0, dt=0.01, method="velocity_verlet", t_end=5.0)
    assert run.stable and np.allclose(run.energy, 0.5 * 10.0 * 0.1**2, rtol=1e-3)
    assert np.allclose(run.exact_energy, 0.05, rtol=1e-12)
    assert not nb07.run_spring(k=10.0, dt=0.65).stable


def test_hair_chain_families_and_zigzag():
    x0, net = S.hair_chain(6, 0.5, k_edge=100.0, k_bend=10.0, k_twist=1.0)
    assert [int(np.sum(net.kind == k)) for k in ("edge", "bend", "twist")] == [5, 4, 3]
    assert np.allclose(net.strain(x0), 0.0) and np.allclose(net.forces(x0), 0.0)
    xz, netz = S.hair_chain(6, 0.5, k_edge=100.0, k_bend=10.0, zigzag=0.3)
    assert np.allclose(xz[1::2, 1], 0.3 * 0.1) and np.allclose(netz.forces(xz), 0.0, atol=1e-12)
    sub = net.select("bend")
    assert sub.n_springs == 4 and np.all(net.with_stiffness(bend=0.0).k[net.kind == "bend"] == 0.0)


def test_chain_pairs():
    i, j = S.chain_pairs(5, 2)
    assert i.tolist() == [0, 1, 2] and j.tolist() == [2, 3, 4]
    with pytest.raises(ValueError):
        S.chain_pairs(1)
