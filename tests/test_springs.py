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


# --- issue 7 §2: coincident ends, bad arguments ------------------------------------------

import warnings  # noqa: E402

from course_lib.springs import layout  # noqa: E402


def _coincident_network(rest, c=0.0, d=3):
    """Three particles; particles 0 and 1 sit on top of each other."""
    net = S.SpringNetwork([0, 1, 0], [1, 2, 2], rest, [10.0, 20.0, 30.0], c, 3)
    x = np.zeros((3, d))
    x[2, 0] = 1.5
    v = np.arange(3 * d, dtype=float).reshape(3, d)
    return net, x, v


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("c", [0.0, 2.0])
def test_zero_rest_length_spring_at_coincidence_exerts_exactly_zero(d, c):
    net, x, v = _coincident_network([0.0, 1.0, 1.0], c, d)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                   # no RuntimeWarning either
        f = net.spring_forces(x, v)
        F = net.forces(x, v)
    assert np.all(f[0] == 0.0)
    # The other two springs are untouched by the coincident pair.
    expected = np.zeros_like(x)
    for s in (1, 2):
        fs = S.spring_force_pair(x[net.i[s]], x[net.j[s]], net.k[s], net.rest[s])
        dv = v[net.i[s]] - v[net.j[s]]
        u = (x[net.i[s]] - x[net.j[s]]) / np.linalg.norm(x[net.i[s]] - x[net.j[s]])
        fs = fs - c * (dv @ u) * u
        expected[net.i[s]] += fs
        expected[net.j[s]] -= fs
    assert np.allclose(F, expected, rtol=1e-14, atol=1e-14)


def test_coincident_spring_with_rest_length_gives_a_finite_documented_answer():
    net, x, v = _coincident_network([0.7, 1.0, 1.0], 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f = net.spring_forces(x, v)
        K = S.stiffness_matrix(net, x)
    assert np.all(f[0] == 0.0)                            # no direction: no force
    assert np.all(np.isfinite(K))
    # The coincident spring's block is k I (the zero-rest-length stiffness).
    alone = S.SpringNetwork([0], [1], [0.7], [10.0], 0.0, 2)
    assert np.array_equal(S.stiffness_matrix(alone, np.zeros((2, 3)))[:3, :3], 10.0 * np.eye(3))


def test_stiffness_matrix_of_zero_rest_springs_is_exact_everywhere():
    # A zero-rest-length spring is linear, F_i = -k (x_i - x_j): K = k [[I, -I], [-I, I]].
    net = S.SpringNetwork([0], [1], [0.0], [4.0], 0.0, 2)
    expected = 4.0 * np.kron(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.eye(3))
    for x in (np.zeros((2, 3)), np.array([[0.0, 0.0, 0.0], [1.0, -2.0, 0.5]])):
        assert np.allclose(S.stiffness_matrix(net, x), expected, rtol=1e-15, atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_networks_with_coincident_particles_stay_finite(seed):
    rng = np.random.default_rng(seed)
    net, x, v = _random_network(seed, 6)
    x[rng.integers(0, 6)] = x[rng.integers(0, 6)]         # maybe merge two particles
    x[1] = x[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        F = net.forces(x, v)
        K = S.stiffness_matrix(net, x)
    assert np.all(np.isfinite(F)) and np.all(np.isfinite(K))
    assert np.linalg.norm(F.sum(axis=0)) <= 1e-12 * max(np.abs(F).max(), 1.0)


@pytest.mark.parametrize(("kind", "error"), [
    (["edge"], ValueError),                      # too short
    (["edge", "bend", "bend"], ValueError),      # too long
    ([["edge", "bend"]], ValueError),            # 2-D
    ([1, 2], TypeError),                         # not strings
    ([1.5, None], TypeError),
])
def test_bad_kind_lists_are_rejected_by_name(kind, error):
    with pytest.raises(error, match="kind"):
        S.SpringNetwork([0, 1], [1, 2], 1.0, 1.0, 0.0, 3, kind)


def test_good_kind_lists_and_default():
    assert S.SpringNetwork([0, 1], [1, 2], 1.0, 1.0, 0.0, 3, ["a", "b"]).kind.tolist() == ["a", "b"]
    assert S.SpringNetwork([0, 1], [1, 2], 1.0, 1.0, 0.0, 3).kind.tolist() == ["spring"] * 2


@pytest.mark.parametrize(("kwargs", "name", "error"), [
    ({"i": [0.5, 1.0]}, "i", TypeError),
    ({"j": [[1, 2]]}, "j", ValueError),
    ({"j": [1, 2, 0]}, "equal length", ValueError),
    ({"rest": [1.0, 2.0, 3.0]}, "rest", ValueError),
    ({"k": -1.0}, "k", ValueError),
    ({"c": np.nan}, "c", ValueError),
    ({"n_particles": 0}, "n_particles", ValueError),
    ({"n_particles": 2.0}, "n_particles", TypeError),
    ({"j": [1, 5]}, "indices", ValueError),
    ({"j": [0, 2]}, "i != j", ValueError),
])
def test_bad_network_arguments_name_the_argument(kwargs, name, error):
    args = {"i": [0, 1], "j": [1, 2], "rest": 1.0, "k": 1.0, "c": 0.0, "n_particles": 3, **kwargs}
    with pytest.raises(error, match=name):
        S.SpringNetwork(**args)


@pytest.mark.parametrize(("func", "kwargs", "name", "error"), [
    (S.hair_chain, {"k_edge": 0.0}, "k_edge", ValueError),
    (S.hair_chain, {"k_edge": -5.0}, "k_edge", ValueError),
    (S.hair_chain, {"k_bend": -1.0}, "k_bend", ValueError),
    (S.hair_chain, {"k_twist": np.inf}, "k_twist", ValueError),
    (S.hair_chain, {"c_edge": -0.1}, "c_edge", ValueError),
    (S.hair_chain, {"c_bend": "a"}, "c_bend", TypeError),
    (S.hair_chain, {"n": 1}, "n", ValueError),
    (S.hair_chain, {"n": 4.0}, "n", TypeError),
    (S.hair_chain, {"length": 0.0}, "length", ValueError),
    (S.hair_chain, {"direction": (0.0, 0.0, 0.0)}, "direction", ValueError),
    (S.hair_chain, {"direction": (1.0, 0.0)}, "direction", ValueError),
    (S.hair_chain, {"root": (0.0, np.nan, 0.0)}, "root", ValueError),
    (S.hair_chain, {"curl": np.nan}, "curl", ValueError),
    (S.hair_chain, {"zigzag": None}, "zigzag", TypeError),
    (S.cloth_grid, {"nx": 1}, "nx", ValueError),
    (S.cloth_grid, {"ny": 2.5}, "ny", TypeError),
    (S.cloth_grid, {"spacing": -0.1}, "spacing", ValueError),
    (S.cloth_grid, {"k_struct": 0.0}, "k_struct", ValueError),
    (S.cloth_grid, {"k_shear": -1.0}, "k_shear", ValueError),
    (S.cloth_grid, {"k_bend": np.nan}, "k_bend", ValueError),
    (S.cloth_grid, {"c": -1.0}, "c", ValueError),
    (S.chain_pairs, {"n": 5, "offset": 0}, "offset", ValueError),
    (S.chain_pairs, {"n": True}, "n", TypeError),
    (S.anchored_spring, {"k": 0.0}, "k", ValueError),
    (S.anchored_spring, {"k": 1.0, "m": -1.0}, "m", ValueError),
    (S.anchored_spring, {"k": 1.0, "c": -1.0}, "c", ValueError),
    (S.anchored_spring, {"k": 1.0, "stretch": -2.0}, "stretch", ValueError),
])
def test_builders_reject_invalid_arguments_by_name(func, kwargs, name, error):
    if func is S.chain_pairs and "n" not in kwargs:
        kwargs = {"n": 5, **kwargs}
    with pytest.raises(error, match=rf"\b{name}\b"):
        func(**kwargs)


def test_hair_chain_families_can_be_omitted_but_edges_cannot():
    _, net = S.hair_chain(5, k_edge=1.0, k_bend=0.0, k_twist=0.0)
    assert set(net.kind) == {"edge"} and net.n_springs == 4
    _, net2 = S.hair_chain(2, k_edge=1.0, k_bend=3.0, k_twist=3.0)   # too short for them
    assert net2.kind.tolist() == ["edge"]


# --- the band layout gives the same forces as gathering every spring ----------------------


def _all_gathered(net):
    return S.SpringNetwork(net.i, net.j, net.rest, net.k, net.c, net.n_particles, net.kind)


@pytest.mark.parametrize("build", [
    lambda: S.cloth_grid(7, 5, 0.1, c=0.3),
    lambda: S.hair_chain(30, 0.5, k_edge=100.0, k_bend=10.0, k_twist=1.0, c_edge=0.2),
    lambda: (np.random.default_rng(3).normal(size=(9, 3)), _random_network(3, 9)[0]),
])
def test_band_and_gathered_layouts_agree(build, monkeypatch):
    x0, net = build()
    rng = np.random.default_rng(0)
    x = x0 + 0.05 * rng.normal(size=x0.shape)
    v = rng.normal(size=x0.shape)
    monkeypatch.setattr(layout, "MIN_FILL", np.inf)       # no bands at all
    gathered = _all_gathered(net)
    assert not gathered.layout.bands and gathered.layout.lo.size == net.n_springs
    F = net.forces(x, v)
    assert np.allclose(F, gathered.forces(x, v), rtol=0, atol=1e-13 * np.abs(F).max())
    assert np.allclose(net.spring_forces(x, v), gathered.spring_forces(x, v), rtol=1e-13, atol=1e-13)


def test_chains_and_grids_use_bands():
    _, cloth = S.cloth_grid(6, 4, 0.1)
    assert sorted(o for o, _, _ in cloth.layout.bands) == [1, 2, 5, 6, 7, 12]
    assert cloth.layout.lo.size == 0
    _, hair = S.hair_chain(20, k_edge=1.0, k_bend=1.0)
    assert [o for o, _, _ in hair.layout.bands] == [1, 2]


def test_duplicate_and_reversed_springs_each_count():
    x = np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [3.0, 0.5, 0.0]])
    one = S.SpringNetwork([0, 1], [1, 2], 1.0, 10.0, 0.0, 3)
    twice = S.SpringNetwork([0, 1, 1, 2], [1, 2, 0, 1], 1.0, 10.0, 0.0, 3)  # each pair twice
    assert np.allclose(twice.forces(x), 2.0 * one.forces(x), rtol=1e-15, atol=1e-15)


def test_forces_out_argument_and_work_arrays_are_not_shared():
    x0, net = S.cloth_grid(4, 4, 0.1, c=0.1)
    x, v = x0 + 0.01, np.ones_like(x0)
    out = np.empty_like(x0)
    F1 = net.forces(x, v, out=out)
    assert F1 is out
    F2 = net.forces(2 * x0, v)
    assert F2 is not out and not np.allclose(F1, F2)
    assert np.array_equal(out, net.forces(x, v))          # a later call did not touch it


def test_network_arrays_are_read_only_and_with_stiffness_names_unknown_kinds():
    _, net = S.hair_chain(5, k_edge=1.0, k_bend=2.0)
    with pytest.raises(ValueError, match="read-only"):
        net.k[0] = 5.0
    stiffer = net.with_stiffness(edge=3.0)
    assert np.all(stiffer.k[stiffer.kind == "edge"] == 3.0) and np.all(net.k[net.kind == "edge"] == 1.0)
    with pytest.raises(ValueError, match="twist"):
        net.with_stiffness(twist=1.0)
