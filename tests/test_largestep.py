"""course_lib.largestep against independent references.

Local/global (Liu et al. 2013): its objective, computed here from the network's energy
and an assembled damping matrix, falls at every iteration; one iteration is the gradient
step preconditioned by the global matrix assembled here spring by spring; on a linear
problem one iteration is backward Euler exactly; the factorization is made once per
(step, pins). A spring's projection is the exact closest vector of rest length. XPBD's
stiffness does not depend on its iteration count once converged, PBD's does, as its
closed form says. Strain limiting meets its limit and moves no pinned particle.
"""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from course_lib import springs as S
from course_lib.largestep import (
    PBD,
    XPBD,
    ColouredSprings,
    FactorCache,
    FastMassSpring,
    StrainLimiter,
    independent_sets,
)
from course_lib.largestep import local_global as LG

G = np.array([0.0, -9.81, 0.0])


def small_cloth(n=6, k=400.0, c=0.05):
    x0, net = S.cloth_grid(n, n, 0.05, k_struct=k, k_shear=0.1 * k, k_bend=0.02 * k, c=c)
    return x0, net, np.full(n * n, 2e-3), [n * (n - 1), n * n - 1]


def objective(net, mass, x, y, x0, h):
    """g(x) = ½|x - y|²_M + h² E(x) + (h/2)(x - x0)ᵀ C(x0) (x - x0), from the assembled C."""
    C = -S.jacobian_v(net, x0).toarray()
    dx, r = (x - y).ravel(), (x - x0).ravel()
    return 0.5 * dx @ (np.repeat(mass, 3) * dx) + h * h * net.energy(x) + 0.5 * h * r @ C @ r


def global_matrix(net, mass, h):
    """M + Σ_s (h² k + h c)(e_i - e_j)(e_i - e_j)ᵀ, dense, one spring at a time."""
    A = np.diag(mass.astype(float))
    for i, j, k, c in zip(net.i, net.j, net.k, net.c, strict=True):
        w = h * h * k + h * c
        A[i, i] += w
        A[j, j] += w
        A[i, j] -= w
        A[j, i] -= w
    return A


@pytest.fixture(scope="module")
def deformed():
    x0, net, mass, pins = small_cloth()
    rng = np.random.default_rng(19)
    x = x0 + 0.01 * rng.normal(size=x0.shape)
    x[pins] = x0[pins]
    v = rng.normal(size=x0.shape)
    v[pins] = 0.0
    return net, mass, pins, x, v


@pytest.mark.roundoff
@pytest.mark.parametrize("memory", [0, 5])
def test_objective_falls_at_every_iteration(deformed, memory):
    net, mass, pins, x, v = deformed
    h = 1 / 60
    solver = FastMassSpring(net, mass, pinned=pins, gravity=G, iterations=15, memory=memory,
                            record=True)
    x1, v1 = solver.step(x, v, h)
    free = np.ones((len(x), 1))
    free[pins] = 0.0
    y = x + free * (h * v + h * h * G)
    g = solver.info.objective
    assert g[0] == pytest.approx(objective(net, mass, y, y, x, h), rel=1e-12)
    assert g[-1] == pytest.approx(objective(net, mass, x1, y, x, h), rel=1e-12)
    # Each iteration lowers g by more than round-off of g (|g| eps times a few terms).
    assert np.all(np.diff(g) < 0.0), np.diff(g)
    assert g[-1] < g[0]
    assert np.array_equal(x1[pins], x[pins]) and np.all(v1[pins] == 0.0)
    assert np.allclose(v1, (x1 - x) / h, rtol=0, atol=1e-12)


def test_one_local_global_iteration_is_a_preconditioned_gradient_step(deformed):
    net, mass, pins, x, v = deformed
    h = 0.01
    solver = FastMassSpring(net, mass, pinned=pins, gravity=G)
    free = np.setdiff1d(np.arange(len(x)), pins)
    y = x + h * v
    y[pins] = x[pins]
    xk = y + 0.002                                  # any point with the pins in place
    xk[pins] = x[pins]
    lin = net.linearize(x)
    new = solver.local_global(xk, y, x, h, lin)
    _, grad = solver.objective(xk, y, x, h, lin)
    # The gradient, independently: M (x - y) - h² F(x) + h C (x - x0).
    C = -S.jacobian_v(net, x).toarray()
    expected_grad = (mass[:, None] * (xk - y) - h * h * net.forces(xk)
                     + h * (C @ (xk - x).ravel()).reshape(x.shape))
    expected_grad[pins] = 0.0
    assert np.allclose(grad, expected_grad, rtol=1e-10, atol=1e-12 * np.abs(expected_grad).max())
    A = global_matrix(net, mass, h)[np.ix_(free, free)]
    step = np.linalg.solve(A, expected_grad[free])
    assert np.allclose(new[free], xk[free] - step, rtol=1e-10, atol=1e-13)
    assert np.array_equal(new[pins], xk[pins])


def test_the_global_matrix_is_factored_once_per_step_and_pins(deformed, monkeypatch):
    net, mass, pins, x, v = deformed
    calls = []
    real = spla.splu
    monkeypatch.setattr(LG.spla, "splu", lambda *a, **k: calls.append(1) or real(*a, **k))
    cache = FactorCache()
    solver = FastMassSpring(net, mass, pinned=pins, gravity=G, iterations=3, cache=cache)
    for _ in range(10):
        x, v = solver.step(x, v, 1 / 60)
    assert cache.factorizations == 1 and len(calls) == 1
    solver.step(x, v, 1 / 30)
    solver.step(x, v, 1 / 60)
    assert cache.factorizations == 2 and len(calls) == 2
    other = FastMassSpring(net, mass, pinned=pins[:1], gravity=G, iterations=3, cache=cache)
    other.step(x, v, 1 / 60)
    assert cache.factorizations == 3 and len(calls) == 3


@pytest.mark.parametrize("c", [0.0, 4.0])
def test_linear_spring_one_iteration_is_backward_euler(c):
    # Motion along a spring: m s'' = -k s - c s' for the stretch s, which backward Euler
    # steps with (I - h J)^{-1}; g is quadratic there and A its exact Hessian.
    k, m, h, L = 80.0, 0.5, 0.05, 1.0
    net = S.SpringNetwork([1], [0], L, k, c, 2)
    x = np.array([[0.0, 0.0, 0.0], [L + 0.2, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [0.7, 0.0, 0.0]])
    solver = FastMassSpring(net, m, pinned=[0], iterations=1, memory=0)
    J = np.array([[0.0, 1.0], [-k / m, -c / m]])
    P = np.linalg.inv(np.eye(2) - h * J)
    state = np.array([0.2, 0.7])
    for _ in range(8):
        state = P @ state
        x, v = solver.step(x, v, h)
        assert np.allclose([x[1, 0] - L, v[1, 0]], state, rtol=1e-12, atol=1e-14)
        assert np.all(x[1, 1:] == 0.0)


def test_spring_projection_is_exact():
    rng = np.random.default_rng(7)
    x = rng.normal(size=(6, 3))
    net = S.SpringNetwork([0, 1, 2, 4], [3, 4, 5, 0], [0.5, 2.0, 1.0, 0.0], 10.0, 0.0, 6)
    p = net.project(x)
    d = x[net.i] - x[net.j]
    assert np.allclose(np.linalg.norm(p, axis=1), net.rest, rtol=1e-14)
    assert np.allclose(np.cross(p, d), 0.0, atol=1e-14) and np.all(np.einsum("sd,sd->s", p, d) >= 0)
    # No vector of the same length is closer: 20,000 random directions, none beats p.
    u = rng.normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    for s in range(net.n_springs):
        best = np.linalg.norm(d[s] - net.rest[s] * u, axis=1).min()
        assert np.linalg.norm(d[s] - p[s]) <= best + 1e-15
    # The summed form: Σ k (e_i - e_j) p = F(x) + L_k x, with L_k assembled spring by spring.
    total = S.Projection(net, net.k)(x)
    L = global_matrix(net, np.zeros(6), 1.0)        # h = 1, c = 0: the k-weighted Laplacian
    assert np.allclose(total, net.forces(x) + L @ x, rtol=1e-12, atol=1e-12)


def test_linearization_products_are_the_assembled_jacobians(deformed):
    net, _, _, x, v = deformed
    lin = net.linearize(x, v)
    K = -S.jacobian_x(net, x, definite=True).toarray()
    C = -S.jacobian_v(net, x).toarray()
    p = np.random.default_rng(3).normal(size=x.shape)
    got = lin.product(p, stiffness=0.3, damping=2.0)
    assert np.allclose(got.ravel(), (0.3 * K + 2.0 * C) @ p.ravel(), rtol=1e-12, atol=1e-10)
    assert np.allclose(lin.diagonal(0.3, 2.0).ravel(), np.diag(0.3 * K + 2.0 * C), rtol=1e-12)
    assert np.allclose(lin.force, net.forces(x, v), rtol=1e-13, atol=1e-12)
    energy, force = net.potential(x)
    assert energy == pytest.approx(float(net.energy(x)), rel=1e-12)
    assert np.allclose(force, net.forces(x), rtol=1e-13, atol=1e-12)


def hanging_chain(n=5, k=50.0, m=0.01, rest=0.1):
    x0 = np.zeros((n, 3))
    x0[:, 1] = -rest * np.arange(n)
    net = S.SpringNetwork(np.arange(n - 1), np.arange(1, n), rest, k, 0.0, n)
    return x0, net, m


def settle(solver, x, steps=1500, h=0.01, drag=0.98):
    v = np.zeros_like(x)
    for _ in range(steps):
        x, v = solver.step(x, v, h)
        v *= drag                                   # let it come to rest
    return x


@pytest.mark.roundoff
def test_xpbd_stiffness_does_not_depend_on_iterations_and_pbd_does():
    x0, net, m = hanging_chain()
    n, g = len(x0), 9.81
    # Static sag: spring s holds the n - 1 - s masses below it, stretched m g (n-1-s)/k.
    exact = np.cumsum(m * g * (n - 1 - np.arange(n - 1)) / net.k)
    sag = {}
    for its in (15, 40):
        x = settle(XPBD(net, m, pinned=[0], gravity=G, iterations=its), x0.copy(), steps=300,
                   drag=0.9)
        sag[its] = -(x[1:, 1] - x0[1:, 1])
        # converged iterations: the static sag of the springs' k, to round-off of the steps
        assert np.allclose(sag[its], exact, rtol=1e-9)
    pbd = {its: -(settle(PBD(net, m, pinned=[0], gravity=G, iterations=its, stiffness=0.5),
                         x0.copy(), steps=300, drag=0.9)[-1, 1] - x0[-1, 1]) for its in (2, 20)}
    assert pbd[2] > 10 * pbd[20]                    # more iterations, a stiffer PBD chain


@pytest.mark.parametrize("iterations", [1, 3, 10])
def test_pbd_single_spring_matches_its_closed_form(iterations):
    # One mass under one spring: each step adds g h² of stretch, then n corrections keep
    # (1 - s)^n of it, so at rest C = g h² q/(1 - q), q = (1 - s)^n: k_eff = m (1 - q)/(h² q).
    s, h, m, g = 0.3, 0.01, 0.02, 9.81
    net = S.SpringNetwork([1], [0], 0.2, 20.0, 0.0, 2)
    x0 = np.array([[0.0, 0.0, 0.0], [0.0, -0.2, 0.0]])
    x = settle(PBD(net, m, pinned=[0], gravity=G, iterations=iterations, stiffness=s), x0.copy(),
               steps=300, h=h, drag=0.8)
    q = (1 - s) ** iterations
    stretch = -(x[1, 1] - x0[1, 1])
    # at rest the step still predicts a fall of g h² that the corrections undo
    assert stretch == pytest.approx(g * h * h * q / (1 - q), rel=1e-9)
    xs = settle(XPBD(net, m, pinned=[0], gravity=G, iterations=iterations), x0.copy(),
                steps=300, h=h, drag=0.8)
    assert -(xs[1, 1] - x0[1, 1]) == pytest.approx(m * g / 20.0, rel=1e-9)


def test_independent_sets_share_no_particle_and_a_grid_needs_twelve():
    _x0, net, _, _ = small_cloth(9)
    sets = independent_sets(net.i, net.j, net.n_particles)
    assert len(sets) == 12
    assert np.array_equal(np.sort(np.concatenate(sets)), np.arange(net.n_springs))
    for s in sets:
        ends = np.r_[net.i[s], net.j[s]]
        assert np.unique(ends).size == ends.size
    rng = np.random.default_rng(5)
    i, j = rng.integers(0, 30, 200), rng.integers(0, 30, 200)
    keep = i != j
    sets = independent_sets(i[keep], j[keep], 30)
    for s in sets:
        ends = np.r_[i[keep][s], j[keep][s]]
        assert np.unique(ends).size == ends.size
    assert sum(len(s) for s in sets) == keep.sum()


def test_strain_limit_meets_its_bound_and_keeps_pins():
    x0, net, mass, pins = small_cloth(8)
    rng = np.random.default_rng(2)
    x = x0 * np.array([1.3, 1.0, 1.25]) + 0.002 * rng.normal(size=x0.shape)
    x[pins] = x0[pins]
    v = np.zeros_like(x)
    left = [StrainLimiter(net, mass, 0.02, pinned=pins).violation(x)]
    for sweeps in (5, 20, 80):
        limiter = StrainLimiter(net, mass, 0.02, pinned=pins, iterations=sweeps)
        y, w = limiter.apply(x, v, 0.01)
        left.append(limiter.last_violation)
        assert limiter.violation(y) == left[-1] == net.strain(y).max() - 0.02
    # Gauss–Seidel sweeps of conflicting corrections: the excess falls with every sweep.
    assert left[0] > 0.2 and np.all(np.diff(left) < 0) and left[-1] < 0.05 * left[0]
    assert np.array_equal(y[pins], x[pins])
    assert np.allclose(w, (y - x) / 0.01, rtol=0, atol=1e-12)
    # A single stretched spring is put exactly at its limit in one sweep, the ends moving
    # in inverse proportion to their masses; a compressed one is left alone.
    one = S.SpringNetwork([0], [1], 1.0, 5.0, 0.0, 2)
    a = np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0]])
    b, _ = StrainLimiter(one, np.array([1.0, 3.0]), 0.1, iterations=1).apply(a, np.zeros_like(a), 1.0)
    assert np.linalg.norm(b[1] - b[0]) == pytest.approx(1.1, rel=1e-14)
    assert (b[0, 0] - a[0, 0]) == pytest.approx(-3 * (b[1, 0] - a[1, 0]), rel=1e-12)
    short = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    assert np.array_equal(StrainLimiter(one, 1.0, 0.1).apply(short, np.zeros_like(short), 1.0)[0], short)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("tau", [0.005, 0.02, 0.1])
def test_strain_limit_guarantees_its_bound(seed, tau):
    # The guarantee: after apply no limited spring is strained beyond tau (1 + tolerance).
    # The pins hold two corners at their rest distance, so every limit can be met.
    x0, net, mass, pins = small_cloth(9)
    rng = np.random.default_rng(seed)
    x = x0 * rng.uniform(1.0, 1.4, 3) + 0.01 * rng.normal(size=x0.shape)
    x[pins] = x0[pins]
    # A cloth stretched by up to 40 % needs many sweeps (a sweep carries a correction a
    # spring or two): given enough it meets the bound.
    far = StrainLimiter(net, mass, tau, pinned=pins, iterations=3000)
    assert far.violation(x) > 2.5 * tau
    y, _ = far.apply(x, np.zeros_like(x), 0.01)
    assert far.converged and net.strain(y).max() <= tau * (1 + far.tolerance) + 1e-12
    assert far.last_violation == far.violation(y) <= tau * far.tolerance
    assert np.array_equal(y[pins], x[pins])
    # A step moves a limited cloth a little (here every particle up to a tenth of a
    # spring's length times tau): the default sweeps bring it back within the bound.
    z = y + 0.1 * tau * 0.05 * rng.normal(size=y.shape)
    z[pins] = y[pins]
    limiter = StrainLimiter(net, mass, tau, pinned=pins)
    assert limiter.violation(z) > 0.05 * tau
    w, _ = limiter.apply(z, np.zeros_like(z), 0.01)
    assert limiter.converged and 0 < limiter.sweeps < limiter.iterations
    assert net.strain(w).max() <= tau * (1 + limiter.tolerance) + 1e-12
    # a tighter tolerance takes more sweeps and meets it
    tight = StrainLimiter(net, mass, tau, pinned=pins, tolerance=1e-4, iterations=5000)
    w, _ = tight.apply(z, np.zeros_like(z), 0.01)
    assert tight.converged and tight.sweeps > limiter.sweeps
    assert net.strain(w).max() <= tau * (1 + 1e-4) + 1e-12


def test_strain_limit_says_when_it_cannot_meet_its_bound():
    # Two pins 2 m apart joined by a chain of two 0.5 m springs: no position of the middle
    # particle brings both within 10 % (at best, in the middle, both are strained 100 %).
    # The limiter stops after its sweeps and says so.
    net = S.SpringNetwork([0, 1], [1, 2], 0.5, 10.0, 0.0, 3)
    x = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [2.0, 0.0, 0.0]])
    limiter = StrainLimiter(net, 1.0, 0.1, pinned=[0, 2], iterations=7)
    y, _ = limiter.apply(x, np.zeros_like(x), 0.1)
    assert not limiter.converged and limiter.sweeps == 7
    assert limiter.last_violation == limiter.violation(y) >= 1.0 - 0.1
    assert np.array_equal(y[[0, 2]], x[[0, 2]])
    for bad in ({"tolerance": -0.1}, {"iterations": 0}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            StrainLimiter(net, 1.0, 0.1, **bad)


def test_coloured_springs_skip_springs_between_pinned_particles():
    net = S.SpringNetwork([0, 1, 2], [1, 2, 3], 1.0, 1.0, 0.0, 4)
    sets = ColouredSprings(net, np.array([0.0, 0.0, 1.0, 1.0]))
    assert sets.n_springs == 2
