"""The Baraff–Witkin implicit step against theory.

On a linear force it is backward Euler exactly (its step matrix ``(I - h A)^{-1}``); it is
stable on the stiffest cloth at 100 times the explicit step limit; without forcing it only
loses energy; pinned particles never move; its conjugate gradients reach the requested
tolerance of the system the paper writes, assembled here independently from the sparse
Jacobians.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from course_lib import springs as S
from course_lib.baraff_witkin import BaraffWitkin, StepInfo, baraff_witkin_step

G = np.array([0.0, -9.81, 0.0])


def backward_euler_matrix(k, m, c, h):
    """Step matrix of backward Euler on m x'' = -k x - c x' with state (x, v)."""
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    return np.linalg.inv(np.eye(2) - h * A)


def test_linear_spring_step_is_backward_euler_exactly():
    # A zero-rest-length spring to a pinned anchor is linear in every direction.
    k, m, h = 50.0, 2.0, 0.3
    net = S.SpringNetwork([1], [0], 0.0, k, 0.0, 2)
    x = np.array([[0.0, 0.0, 0.0], [0.3, -0.2, 0.5]])
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.4, -0.3]])
    solver = BaraffWitkin(net, m, pinned=[0], rtol=1e-14)
    P = backward_euler_matrix(k, m, 0.0, h)
    for _ in range(5):
        expected = P @ np.stack((x[1], v[1]))
        x, v = solver.step(x, v, h)
        assert np.allclose(np.stack((x[1], v[1])), expected, rtol=1e-13, atol=1e-15)
    assert np.all(x[0] == 0.0) and np.all(v[0] == 0.0)


@pytest.mark.parametrize("c", [0.0, 3.0, 40.0])
def test_damped_spring_along_its_axis_is_backward_euler_exactly(c):
    # Motion along a spring with rest length L is m s'' = -k s - c s' for the stretch s.
    k, m, h, L = 50.0, 2.0, 0.2, 1.0
    net = S.SpringNetwork([1], [0], L, k, c, 2)
    x = np.array([[0.0, 0.0, 0.0], [1.2, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [0.7, 0.0, 0.0]])
    solver = BaraffWitkin(net, m, pinned=[0], rtol=1e-14)
    state = np.array([0.2, 0.7])
    P = backward_euler_matrix(k, m, c, h)
    for _ in range(6):
        state = P @ state
        x, v = solver.step(x, v, h)
        assert np.allclose([x[1, 0] - L, v[1, 0]], state, rtol=1e-12, atol=1e-15)
        assert np.all(x[1, 1:] == 0.0)


def test_two_free_particles_keep_their_momentum():
    # No pins, no gravity: the spring forces are internal, so the step conserves momentum.
    net = S.SpringNetwork([0], [1], 1.0, 30.0, 2.0, 2)
    x = np.array([[0.0, 0.0, 0.0], [1.5, 0.3, 0.0]])
    v = np.array([[0.0, 1.0, 0.0], [0.5, 0.0, -1.0]])
    mass = np.array([1.0, 3.0])
    solver = BaraffWitkin(net, mass, rtol=1e-14)
    p0 = mass @ v
    for _ in range(10):
        x, v = solver.step(x, v, 0.1)
    assert np.allclose(mass @ v, p0, rtol=0, atol=1e-13)


def stiff_cloth(n=12, k=1e4):
    x0, net = S.cloth_grid(n, n, 0.05, k_struct=k, k_shear=k, k_bend=k, c=0.0)
    return x0, net, [n * (n - 1), n * n - 1]                 # two top corners pinned


def energy(net, x, v, mass, g=None):
    e = net.energy(x) + 0.5 * mass * np.sum(v * v)
    return e - mass * np.sum(x @ g) if g is not None else e


def test_stable_at_100_times_the_explicit_limit_on_the_stiffest_cloth():
    x0, net, pinned = stiff_cloth()
    mass = 1e-3
    dt = 100 * 2.0 / S.max_frequency(net, x0, mass, pinned)
    solver = BaraffWitkin(net, mass, pinned=pinned, gravity=G, rtol=1e-8)
    x, v = x0.copy(), np.zeros_like(x0)
    e0 = energy(net, x, v, mass, G)
    for _ in range(60):
        x, v = solver.step(x, v, dt)
        assert solver.info.converged
        assert energy(net, x, v, mass, G) <= e0 + 1e-12 * abs(e0)
    # It hangs below its pins, stretched by a fraction of a percent, not blown up.
    assert np.all(np.isfinite(x)) and np.abs(net.strain(x)).max() < 0.01
    assert x[:, 1].max() <= x0[:, 1].max() + 1e-9


@pytest.mark.parametrize("factor", [0.5, 10.0, 100.0])
def test_energy_decreases_monotonically_without_forcing(factor):
    x0, net, pinned = stiff_cloth(8, 1e3)
    mass = 1e-3
    dt = factor * 2.0 / S.max_frequency(net, x0, mass, pinned)
    rng = np.random.default_rng(4)
    x = x0 + 0.01 * rng.normal(size=x0.shape)
    x[pinned] = x0[pinned]
    v = np.zeros_like(x0)
    solver = BaraffWitkin(net, mass, pinned=pinned, rtol=1e-10)
    e = [energy(net, x, v, mass)]
    for _ in range(40):
        x, v = solver.step(x, v, dt)
        e.append(energy(net, x, v, mass))
    assert np.all(np.diff(e) < 0.0), np.diff(e).max()
    assert e[-1] < 0.5 * e[0]


def test_pinned_particles_never_move():
    x0, net = S.cloth_grid(10, 10, 0.05, c=0.2)
    pinned = [0, 9, 45]
    v0 = np.random.default_rng(1).normal(size=x0.shape)
    v0[pinned] = 0.0
    solver = BaraffWitkin(net, 2e-3, pinned=pinned, gravity=G, rtol=1e-6)
    xs, vs, infos = solver.run(x0, v0, 0.01, 30)
    assert np.array_equal(xs[:, pinned], np.broadcast_to(x0[pinned], xs[:, pinned].shape))
    assert np.all(vs[:, pinned] == 0.0)
    assert all(isinstance(i, StepInfo) and i.converged for i in infos)
    assert not np.allclose(xs[-1], x0)                     # the rest does move


def assembled_system(net, x, v, dt, mass, pinned, g):
    """The paper's system from the sparse Jacobians: A Δv = b, filtered for the pins."""
    n, dim = x.shape
    M = sp.identity(n * dim) * mass
    Jx = S.jacobian_x(net, x, definite=True)
    Jv = S.jacobian_v(net, x)
    A = (M - dt * Jv - dt * dt * Jx).toarray()
    b = dt * ((net.forces(x, v) + mass * g).ravel() + dt * (Jx @ v.ravel()))
    free = np.ones(n * dim, dtype=bool)
    for p in pinned:
        free[p * dim:(p + 1) * dim] = False
    A[~free] = 0.0
    A[:, ~free] = 0.0
    A[~free, ~free] = 1.0
    b[~free] = 0.0
    return A, b


@pytest.mark.parametrize("rtol", [1e-3, 1e-6, 1e-10])
def test_conjugate_gradients_reach_the_requested_tolerance(rtol):
    x0, net = S.cloth_grid(9, 7, 0.05, k_struct=2e3, k_shear=200.0, k_bend=20.0, c=0.3)
    rng = np.random.default_rng(2)
    x = x0 + 0.005 * rng.normal(size=x0.shape)
    v = rng.normal(size=x0.shape)
    pinned, mass, dt = [0, 8], 1e-3, 0.02
    x[pinned], v[pinned] = x0[pinned], 0.0
    solver = BaraffWitkin(net, mass, pinned=pinned, gravity=G, rtol=rtol, warm_start=False)
    x1, v1 = solver.step(x, v, dt)
    A, b = assembled_system(net, x, v, dt, mass, pinned, G)
    dv = (v1 - v).ravel()
    assert np.linalg.norm(b - A @ dv) <= rtol * np.linalg.norm(b)
    assert solver.info.converged and solver.info.residual <= rtol
    assert np.allclose(x1, x + dt * v1, rtol=1e-15, atol=1e-15)
    # The matrix-free operator is the assembled matrix.
    op, b_op, _ = solver.system(x, v, dt)
    p = rng.normal(size=b.size)
    assert np.allclose(op @ p, A @ p, rtol=1e-12, atol=1e-12 * np.abs(A).max())
    assert np.allclose(b_op, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())


def test_exact_linearization_option_matches_the_full_jacobian():
    # With definite=False the matrix uses the exact elastic ∂F/∂x, compressed springs too.
    net = S.SpringNetwork([0, 1], [1, 2], [2.0, 0.5], [10.0, 20.0], 0.0, 3)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [1.8, 0.0, 0.3]])
    v = np.zeros_like(x)
    solver = BaraffWitkin(net, 1.0, definite=False, rtol=1e-12)
    op, _, _ = solver.system(x, v, 0.1)
    A = np.eye(9) - 0.01 * S.jacobian_x(net, x).toarray()
    assert np.allclose(op @ np.eye(9), A, rtol=1e-13, atol=1e-13)


def test_functional_form_and_bad_arguments():
    x0, net = S.cloth_grid(3, 3, 0.1)
    _, v1, info = baraff_witkin_step(net, x0, np.zeros_like(x0), 0.01, 1e-3, gravity=G)
    assert info.converged and np.all(v1[:, 1] < 0.0)
    with pytest.raises(TypeError, match="network"):
        BaraffWitkin("cloth", 1.0)
    with pytest.raises(ValueError, match="mass"):
        BaraffWitkin(net, -1.0)
    with pytest.raises(ValueError, match="mass"):
        BaraffWitkin(net, np.ones(4))
    with pytest.raises(ValueError, match="pinned"):
        BaraffWitkin(net, 1.0, pinned=[9])
    with pytest.raises(ValueError, match="dt"):
        BaraffWitkin(net, 1.0).step(x0, np.zeros_like(x0), 0.0)
    with pytest.raises(ValueError, match="x"):
        BaraffWitkin(net, 1.0).step(x0[:4], np.zeros_like(x0), 0.1)
    with pytest.raises(TypeError, match="external"):
        BaraffWitkin(net, 1.0, external=3.0)
    with pytest.raises(ValueError, match="gravity"):
        BaraffWitkin(net, 1.0, gravity=[0.0, -9.81]).step(x0, np.zeros_like(x0), 0.1)


def test_external_force_is_added_like_gravity():
    x0, net = S.cloth_grid(4, 4, 0.1, c=0.1)
    v0 = np.random.default_rng(3).normal(size=x0.shape)
    with_g = BaraffWitkin(net, 2e-3, pinned=[0], gravity=G, rtol=1e-12)
    with_ext = BaraffWitkin(net, 2e-3, pinned=[0], rtol=1e-12,
                            external=lambda t, x, v: np.full_like(x, 2e-3) * G)
    a, b = with_g.step(x0, v0, 0.02), with_ext.step(x0, v0, 0.02)
    assert np.allclose(a[0], b[0], rtol=1e-13, atol=1e-15)
    assert np.allclose(a[1], b[1], rtol=1e-12, atol=1e-13)


# --- issue 20: every solver entry point checks its input and fails before any work -------

def _solvers(net, pinned):
    from course_lib.largestep import PBD, XPBD, FastMassSpring

    return {"baraff_witkin": BaraffWitkin(net, 1e-3, pinned=pinned, gravity=G),
            "fast_mass_spring": FastMassSpring(net, 1e-3, pinned=pinned, gravity=G),
            "xpbd": XPBD(net, 1e-3, pinned=pinned, gravity=G),
            "pbd": PBD(net, 1e-3, pinned=pinned, gravity=G)}


BAD_STATES = {
    "v of the wrong width": (lambda x, v: (x, v[:, :2]), "v"),
    "v for too few particles": (lambda x, v: (x, v[:-1]), "v"),
    "x of the wrong width": (lambda x, v: (x[:, :2], v[:, :2]), "gravity"),
    "x for too many particles": (lambda x, v: (np.vstack((x, x[:1])), np.vstack((v, v[:1]))), "x"),
    "NaN in x": (lambda x, v: (np.where(np.arange(len(x))[:, None] == 3, np.nan, x), v), "x"),
    "inf in v": (lambda x, v: (x, np.where(np.arange(len(x))[:, None] == 5, np.inf, v)), "v"),
    "complex v": (lambda x, v: (x, v + 1j), "v"),
    "text in x": (lambda x, v: (x.astype(str), v), "x"),
}


@pytest.mark.parametrize("case", sorted(BAD_STATES))
@pytest.mark.parametrize("method", ["baraff_witkin", "fast_mass_spring", "xpbd", "pbd"])
def test_bad_states_fail_at_once_naming_the_argument(method, case, monkeypatch):
    import scipy.sparse.linalg as spla

    calls = []
    monkeypatch.setattr(spla, "cg", lambda *a, **k: calls.append(1))
    monkeypatch.setattr(spla, "splu", lambda *a, **k: calls.append(1))
    x0, net = S.cloth_grid(4, 4, 0.1, c=0.1)
    solver = _solvers(net, [0, 3])[method]
    make, name = BAD_STATES[case]
    x, v = make(x0, np.zeros_like(x0))
    with pytest.raises((ValueError, TypeError), match=name):
        solver.step(x, v, 0.01)
    assert not calls                                  # no solve was started


@pytest.mark.parametrize("dt", [0.0, -0.1, np.nan, np.inf, "0.1", None])
@pytest.mark.parametrize("method", ["baraff_witkin", "fast_mass_spring", "xpbd", "pbd"])
def test_bad_steps_and_times_are_named(method, dt):
    x0, net = S.cloth_grid(3, 3, 0.1)
    solver = _solvers(net, [0])[method]
    with pytest.raises((ValueError, TypeError), match="dt"):
        solver.step(x0, np.zeros_like(x0), dt)
    with pytest.raises((ValueError, TypeError), match="t must"):
        solver.step(x0, np.zeros_like(x0), 0.01, t=np.nan)


@pytest.mark.parametrize("kwargs, name", [
    ({"mass": np.nan}, "mass"), ({"mass": [1.0, 2.0]}, "mass"), ({"pinned": [[0, 1]]}, "pinned"),
    ({"pinned": [0.5]}, "pinned"), ({"gravity": [[0.0, -9.8, 0.0]]}, "gravity"),
    ({"gravity": [0.0, np.nan, 0.0]}, "gravity"), ({"external": "wind"}, "external"),
])
def test_bad_solver_arguments_are_named(kwargs, name):
    from course_lib.largestep import XPBD, FastMassSpring

    _, net = S.cloth_grid(3, 3, 0.1)
    args = {"mass": 1e-3, **kwargs}
    mass = args.pop("mass")
    for cls in (BaraffWitkin, FastMassSpring, XPBD):
        with pytest.raises((ValueError, TypeError), match=name):
            cls(net, mass, **args)
    with pytest.raises(ValueError, match="rtol"):
        BaraffWitkin(net, 1.0, rtol=-1.0)
    with pytest.raises((ValueError, TypeError), match="iterations"):
        FastMassSpring(net, 1.0, iterations=0)
    with pytest.raises(ValueError, match="memory"):
        FastMassSpring(net, 1.0, memory=-1)
    with pytest.raises((ValueError, TypeError), match="substeps"):
        XPBD(net, 1.0, substeps=1.5)


def test_external_forces_that_are_not_finite_are_named():
    x0, net = S.cloth_grid(3, 3, 0.1)
    solver = BaraffWitkin(net, 1e-3, external=lambda t, x, v: np.full_like(x, np.nan))
    with pytest.raises(ValueError, match="external"):
        solver.step(x0, np.zeros_like(x0), 0.01)
