"""Hardening of runs (issue 7 §2, issue 8): stops, caps, argument checks, sparse Jacobians.

Each test failed before its fix: implicit methods lost the run on a NaN or a Newton
failure; absurd spans overflowed or allocated gigabytes; a non-callable ``jac`` or
``post_step`` failed obscurely; ``last_valid`` was one row short after a bound stop; the
implicit solves built a dense finite-difference Jacobian every Newton iteration.
"""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import course_lib as cl
from course_lib import implicit

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

IMPLICIT = sorted(cl.IMPLICIT_METHODS)


def nan_from(t_bad, f):
    """``f``, but NaN from time ``t_bad`` on (a model that breaks down)."""
    return lambda t, y: f(t, y) if t < t_bad else np.full(np.shape(y), np.nan)


# --- implicit methods honour on_blowup ------------------------------------------------------


@pytest.mark.parametrize("method", IMPLICIT)
def test_nan_in_an_implicit_step_keeps_the_good_steps(method, recwarn):
    f = nan_from(0.55, lambda t, y: -y)
    traj = cl.integrate(f, [1.0], (0.0, 1.0), 0.1, method)
    # the step to t = 0.6 is the first to evaluate f past 0.55
    assert traj.status == "unstable" and not traj.stable and traj.blowup_step == 6
    assert traj.message.startswith("unstable at step 6, t = 0.6 (")
    R = cl.amplification_factor(method, -0.1).real
    np.testing.assert_allclose(traj.y[:6, 0], R ** np.arange(6), rtol=1e-13)
    assert np.all(np.isnan(traj.y[6:])) and traj.last_valid == 5
    with pytest.raises(cl.BlowUpError, match="unstable at step 6"):
        cl.integrate(f, [1.0], (0.0, 1.0), 0.1, method, on_blowup="raise")
    assert len(recwarn) == 0


@pytest.mark.parametrize("method", IMPLICIT)
def test_newton_failure_is_reported_not_raised(method):
    # Y = 1 + 0.5 Y² (backward Euler on y' = y², dt = 0.5) has no real solution.
    traj = cl.integrate(lambda t, y: y**2, [1.0], (0.0, 2.0), 0.5, method)
    assert traj.status == "failed" and not traj.stable
    assert traj.blowup_step == 1 and traj.last_valid == 0 and traj.y[0, 0] == 1.0
    assert traj.message.startswith("stopped at step 1, t = 0.5 (Newton's method did not converge")
    with pytest.raises(cl.BlowUpError, match="Newton") as err:
        cl.integrate(lambda t, y: y**2, [1.0], (0.0, 2.0), 0.5, method, on_blowup="raise")
    assert isinstance(err.value.__cause__, cl.ConvergenceError)


def test_singular_newton_matrix_is_reported():
    # jac = 1/dt makes I - dt J singular.
    traj = cl.integrate(lambda t, y: 10.0 * y, [1.0], (0.0, 1.0), 0.1, "backward_euler",
                        jac=np.array([[10.0]]))
    assert traj.status == "failed" and "singular" in traj.message


# --- absurd spans and steps -----------------------------------------------------------------


@pytest.mark.parametrize("span,dt,match", [
    ((0.0, 1.0), 5e-324, "max_steps = 10,000,000"),
    ((0.0, 1.0), 1e-8, r"needs 1e\+08 steps"),
    ((-1e308, 1e308), 1.0, r"t1 - t0 overflows"),
    ((0.0, 1e300), 1e-300, "max_steps"),
    ((1e17, 1e17 + 64.0), 1.0, "float resolution"),
])
def test_absurd_spans_are_refused_with_the_reason(span, dt, match):
    with pytest.raises(ValueError, match=match):
        cl.integrate(lambda t, y: -y, 1.0, span, dt)


def test_max_steps_can_be_raised_or_lowered():
    with pytest.raises(ValueError, match="more than max_steps = 50"):
        cl.integrate(lambda t, y: -y, 1.0, (0.0, 1.0), 0.01, max_steps=50)
    assert cl.integrate(lambda t, y: -y, 1.0, (0.0, 1.0), 0.01, max_steps=100).n_steps == 100
    for bad, err in [(0, ValueError), (2.5, TypeError), ("10", TypeError), (True, TypeError)]:
        with pytest.raises(err, match="max_steps"):
            cl.integrate(lambda t, y: -y, 1.0, (0.0, 1.0), 0.1, max_steps=bad)


# --- jac and post_step are checked and named ---------------------------------------------------


@pytest.mark.parametrize("jac", ["J", 3.0, {"a": 1}, object()])
def test_non_callable_jac_is_named(jac):
    with pytest.raises(TypeError, match="jac must be callable"):
        cl.integrate(lambda t, y: -y, [1.0], (0.0, 1.0), 0.1, "backward_euler", jac=jac)


@pytest.mark.parametrize("post", ["clamp", 3, np.ones(2)])
def test_non_callable_post_step_is_named(post):
    with pytest.raises(TypeError, match="post_step must be callable"):
        cl.integrate(lambda t, y: -y, [1.0, 2.0], (0.0, 1.0), 0.1, post_step=post)


@pytest.mark.parametrize("post,err,match", [
    (lambda t, y: y[:1], ValueError, r"post_step must return an array of the state's shape \(2,\)"),
    (lambda t, y: np.ones((2, 2)), ValueError, "post_step must return an array"),
    (lambda t, y: 1.0, ValueError, "post_step must return an array"),
    (lambda t, y: None, TypeError, "post_step must return the new state, got None"),
    (lambda t, y: ["a", "b"], TypeError, "post_step must return numbers"),
])
def test_post_step_results_are_checked(post, err, match):
    for method in ("forward_euler", "backward_euler"):
        with pytest.raises(err, match=match):
            cl.integrate(lambda t, y: -y, [1.0, 2.0], (0.0, 1.0), 0.1, method, post_step=post)


def test_post_step_may_return_a_list_or_ints():
    traj = cl.integrate(lambda t, y: np.ones(2), [0.0, 0.0], (0.0, 1.0), 0.25,
                        post_step=lambda t, y: [int(v) for v in 4 * y])
    np.testing.assert_array_equal(traj.y[:, 0], [0, 1, 5, 21, 85])   # int(4 (y + 1/4))


# --- last_valid on every stop path ----------------------------------------------------------


@pytest.mark.parametrize("method", cl.METHODS)
def test_last_valid_after_a_bound_stop_is_the_kept_state(method):
    if method in cl.NEWTONIAN_METHODS:
        f, y0 = cl.systems.oscillator(1.0), [1.0, 0.0]
        dt = 2.5                                  # ω dt > 2: grows
    else:
        f, y0, dt = (lambda t, y: 2.0 * y), [1.0], 0.5
        if method in cl.IMPLICIT_METHODS:
            dt = 0.25
    traj = cl.integrate(f, y0, (0.0, 200 * dt), dt, method, blowup_bound=50.0)
    k = traj.blowup_step
    assert k is not None and traj.last_valid == k
    assert np.max(np.abs(traj.y[k])) > 50.0 and np.all(np.isfinite(traj.y[: k + 1]))
    assert np.max(np.abs(traj.y[k - 1])) <= 50.0 and np.all(np.isnan(traj.y[k + 1:]))


def test_last_valid_after_a_non_finite_stop_and_without_a_stop():
    traj = cl.integrate(lambda t, y: -y, [1.0], (0.0, 1.0), 0.1,
                        post_step=lambda t, y: y if t < 0.45 else y * np.nan)
    assert traj.blowup_step == 5 and traj.last_valid == 4
    assert np.all(np.isfinite(traj.y[:5])) and np.all(np.isnan(traj.y[5:]))
    ok = cl.integrate(lambda t, y: -y, [1.0], (0.0, 1.0), 0.1)
    assert ok.last_valid == ok.n_steps == 10


# --- sparse Jacobians: sparse solves, one Jacobian per step, never a dense one --------------


def laplacian(n: int, h: float) -> sp.csr_matrix:
    return sp.diags([np.ones(n - 1), -2.0 * np.ones(n), np.ones(n - 1)], [-1, 0, 1],
                    format="csr") / h**2


@pytest.mark.parametrize("method", IMPLICIT)
@pytest.mark.parametrize("kind", ["constant", "callable"])
def test_sparse_jac_gives_the_sparse_direct_solve(method, kind, monkeypatch):
    def no_dense(*args, **kwargs):
        raise AssertionError("a dense finite-difference Jacobian was built")

    monkeypatch.setattr(implicit, "finite_difference_jacobian", no_dense)
    n, dt = 500, 1e-4
    L = laplacian(n, 1.0 / (n + 1))
    x = np.linspace(0, 1, n + 2)[1:-1]
    y0 = np.sin(np.pi * x) + 0.3 * np.sin(7 * np.pi * x)
    jac = L if kind == "constant" else (lambda t, y: L)
    traj = cl.integrate(lambda t, y: L @ y, y0, (0.0, 10 * dt), dt, method, jac=jac)
    a = 1.0 if method == "backward_euler" else 0.5
    lhs = spla.splu((sp.identity(n) - a * dt * L).tocsc())
    y = y0
    for _ in range(10):
        y = lhs.solve(y + (1 - a) * dt * (L @ y))
    np.testing.assert_allclose(traj.y[-1], y, rtol=1e-12, atol=1e-14)


def test_constant_sparse_jac_is_factorized_once_per_run(monkeypatch):
    calls = []
    real = implicit.spla.splu
    monkeypatch.setattr(implicit.spla, "splu", lambda M: calls.append(1) or real(M))
    L = laplacian(100, 0.01)
    cl.integrate(lambda t, y: L @ y, np.ones(100), (0.0, 0.05), 1e-3, "backward_euler", jac=L)
    assert len(calls) == 1


@pytest.mark.parametrize("method", IMPLICIT)
def test_jacobian_is_evaluated_once_per_step_when_newton_converges_fast(method):
    count = [0]

    def jac(t, y):
        count[0] += 1
        return sp.csr_matrix(np.array([[-3 * y[0] ** 2, 1.0], [-1.0, -0.1]]))

    f = lambda t, y: np.array([-y[0] ** 3 + y[1], -y[0] - 0.1 * y[1]])  # noqa: E731
    traj = cl.integrate(f, [0.5, 0.0], (0.0, 1.0), 0.01, method, jac=jac)
    assert traj.stable and count[0] == traj.n_steps
    dense = cl.integrate(f, [0.5, 0.0], (0.0, 1.0), 0.01, method)
    np.testing.assert_allclose(traj.y, dense.y, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("method", IMPLICIT)
def test_newtonian_sparse_jac_is_solved_through_the_half_size_velocity_system(method,
                                                                              monkeypatch):
    n, c, dt = 300, 0.3, 0.05
    L = laplacian(n, 1.0 / (n + 1)) * 1e-4                      # x'' = L x - c v
    J = sp.bmat([[None, sp.identity(n)], [L, -c * sp.identity(n)]], format="csr")
    f = lambda t, y: np.stack((y[1], L @ y[0] - c * y[1]))  # noqa: E731
    sizes = []
    real = implicit.spla.splu
    monkeypatch.setattr(implicit.spla, "splu", lambda M: sizes.append(M.shape[0]) or real(M))
    x = np.linspace(0, 1, n + 2)[1:-1]
    y0 = np.stack((np.sin(np.pi * x), np.zeros(n)))
    traj = cl.integrate(f, y0, (0.0, 20 * dt), dt, method, jac=J)
    assert set(sizes) == {n}                                    # never the 2n system
    a = 1.0 if method == "backward_euler" else 0.5
    lhs = spla.splu((sp.identity(2 * n) - a * dt * J).tocsc())
    y = y0.ravel()
    for _ in range(20):
        y = lhs.solve(y + (1 - a) * dt * (J @ y))
    np.testing.assert_allclose(traj.y[-1].ravel(), y, rtol=1e-11, atol=1e-13)
