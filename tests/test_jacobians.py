"""Analytic spring Jacobians against finite differences and against their theory.

∂F/∂x (elastic) must be the symmetric Hessian of minus the energy, with its geometric term;
∂F/∂v must be symmetric negative semidefinite (damping only removes energy); with the
velocities, ∂F/∂x gains the non-symmetric derivative of the damping force. Networks are
random, with springs stretched and compressed (rest lengths 0.3–3 times the current
length), in 2D and 3D.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from course_lib import springs as S
from course_lib.systems import NewtonianSystem, stack_state

RTOL = 1e-6


def random_network(seed: int, n: int, dim: int, zero_rest: bool = False):
    """Random pairs (some repeated) with rest lengths from compressed to stretched."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, dim))
    m = int(rng.integers(1, 3 * n))
    i = rng.integers(0, n, m)
    j = (i + rng.integers(1, n, m)) % n
    length = np.linalg.norm(x[i] - x[j], axis=1)
    rest = np.zeros(m) if zero_rest else length * rng.uniform(0.3, 3.0, m)
    net = S.SpringNetwork(i, j, rest, rng.uniform(1.0, 100.0, m), rng.uniform(0.0, 3.0, m), n)
    return net, x, rng.normal(size=(n, dim))


def central_difference(func, z, h=1e-6):
    """Jacobian of ``func`` (array -> array) at ``z`` by central differences."""
    J = np.zeros((z.size, z.size))
    for col in range(z.size):
        e = np.zeros(z.size)
        e[col] = h
        e = e.reshape(z.shape)
        J[:, col] = (func(z + e) - func(z - e)).ravel() / (2 * h)
    return J


def assert_symmetric(A):
    """Symmetric to round-off (blocks of repeated pairs are summed in different orders)."""
    assert np.abs(A - A.T).max() <= 1e-14 * np.abs(A).max()


def assert_close(A, B):
    scale = max(np.abs(B).max(), 1e-300)
    assert np.abs(A - B).max() <= RTOL * scale, np.abs(A - B).max() / scale


networks = given(seed=st.integers(0, 100_000), n=st.integers(2, 7), dim=st.sampled_from([2, 3]))


@settings(max_examples=40, deadline=None)
@networks
def test_elastic_jacobian_matches_finite_differences_and_is_symmetric(seed, n, dim):
    net, x, _ = random_network(seed, n, dim)
    J = S.jacobian_x(net, x)
    assert sp.issparse(J) and J.shape == (n * dim, n * dim)
    J = J.toarray()
    assert_close(J, central_difference(lambda z: net.forces(z), x))
    assert_symmetric(J)


@settings(max_examples=40, deadline=None)
@networks
def test_full_position_jacobian_with_damping_matches_finite_differences(seed, n, dim):
    net, x, v = random_network(seed, n, dim)
    J = S.jacobian_x(net, x, v).toarray()
    assert_close(J, central_difference(lambda z: net.forces(z, v), x))


@settings(max_examples=40, deadline=None)
@networks
def test_velocity_jacobian_matches_and_is_symmetric_negative_semidefinite(seed, n, dim):
    net, x, v = random_network(seed, n, dim)
    Jv = S.jacobian_v(net, x).toarray()
    assert_close(Jv, central_difference(lambda z: net.forces(x, z), v))
    assert_symmetric(Jv)
    eig = np.linalg.eigvalsh(Jv)
    assert eig.max() <= 1e-12 * max(np.abs(eig).max(), 1.0)
    # Rigid translations are not damped: each row sums to zero per component.
    assert np.allclose(Jv @ np.tile(np.eye(dim), (n, 1)), 0.0, atol=1e-12 * np.abs(Jv).max())


@settings(max_examples=40, deadline=None)
@networks
def test_definite_option_makes_minus_jacobian_positive_semidefinite(seed, n, dim):
    net, x, _ = random_network(seed, n, dim)
    K = -S.jacobian_x(net, x, definite=True).toarray()
    eig = np.linalg.eigvalsh(K)
    assert eig.min() >= -1e-12 * max(np.abs(eig).max(), 1.0)
    # Only compressed springs change: with every spring stretched it is the exact Jacobian.
    stretched = S.SpringNetwork(net.i, net.j, 0.5 * net.lengths(x), net.k, net.c, n)
    assert np.array_equal(S.jacobian_x(stretched, x, definite=True).toarray(),
                          S.jacobian_x(stretched, x).toarray())


def test_compressed_spring_has_negative_sideways_stiffness():
    # One spring along x at length 1 with rest length 2: sideways K = k (1 - L/ℓ) = -k.
    net = S.SpringNetwork([0], [1], [2.0], [5.0], 0.0, 2)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    K = S.stiffness_matrix(net, x)
    assert np.allclose(K[:3, :3], np.diag([5.0, -5.0, -5.0]), rtol=1e-15, atol=0)
    assert np.allclose(S.stiffness_matrix(net, x, definite=True)[:3, :3], np.diag([5.0, 0, 0]),
                       rtol=1e-15, atol=0)


def test_stiffness_matrix_dense_and_sparse_agree():
    net, x, _ = random_network(7, 6, 3)
    K = S.stiffness_matrix(net, x)
    assert isinstance(K, np.ndarray)
    assert np.array_equal(K, S.stiffness_matrix(net, x, sparse=True).toarray())
    assert np.array_equal(K, -S.jacobian_x(net, x).toarray())


def test_jacobians_of_zero_rest_springs_are_exact_constants():
    net, x, _ = random_network(11, 5, 3, zero_rest=True)
    lap = np.zeros((5, 5))
    for a, b, k in zip(net.i, net.j, net.k, strict=True):
        lap[[a, b], [a, b]] += k
        lap[a, b] -= k
        lap[b, a] -= k
    assert np.allclose(S.jacobian_x(net, x).toarray(), -np.kron(lap, np.eye(3)), rtol=1e-13,
                       atol=1e-13 * lap.max())


def test_newtonian_jacobian_matches_finite_differences_of_the_system():
    net, x, v = random_network(5, 5, 3)
    mass = np.linspace(1.0, 2.0, 5)
    system = NewtonianSystem(net.force, mass, pinned=[1])
    y = stack_state(x, v)
    jac = S.newtonian_jacobian(net, mass, pinned=[1])
    J = jac(0.0, y)
    assert sp.issparse(J) and J.shape == (30, 30)
    assert_close(J.toarray(), central_difference(lambda z: system(0.0, z), y))


def test_assemble_adds_every_block_in_place():
    net = S.SpringNetwork([0, 0, 2], [1, 1, 0], 1.0, 1.0, 0.0, 3)      # (0, 1) twice
    blocks = np.arange(3 * 4, dtype=float).reshape(3, 2, 2)
    A = S.assemble(net, blocks).toarray()
    expected = np.zeros((6, 6))
    for (a, b), G in zip(zip(net.i, net.j, strict=True), blocks, strict=True):
        for p, q, sign in ((a, a, 1), (a, b, -1), (b, a, -1), (b, b, 1)):
            expected[2 * p:2 * p + 2, 2 * q:2 * q + 2] += sign * G
    assert np.array_equal(A, expected)
    with pytest.raises(ValueError, match="blocks"):
        S.assemble(net, blocks[:2])


def test_max_frequency_sparse_path_matches_dense(monkeypatch):
    # A smaller limit sends a 12 × 12 cloth (432 dofs) down the sparse eigensolver's path.
    monkeypatch.setattr(S.jacobian, "DENSE_LIMIT", 300)
    x, net = S.cloth_grid(12, 12, 0.05)
    x = x + 1e-3 * np.random.default_rng(0).normal(size=x.shape)
    assert x.size > S.jacobian.DENSE_LIMIT
    w = S.max_frequency(net, x, 1e-3, pinned=[0, 11])
    exact = np.sqrt(np.linalg.eigvalsh(_free_block(net, x, [0, 11]) / 1e-3).max())
    assert w == pytest.approx(exact, rel=1e-8)


def _free_block(net, x, pinned):
    n, dim = x.shape
    free = np.setdiff1d(np.arange(n), pinned)
    dofs = (free[:, None] * dim + np.arange(dim)).ravel()
    return S.stiffness_matrix(net, x)[np.ix_(dofs, dofs)]
