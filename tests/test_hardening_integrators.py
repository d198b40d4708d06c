"""Hardening of the integrators (issue 7): each test here failed before its fix.

Classes of defect, each tested on more than the example that revealed it: right-hand
sides that reuse one output buffer or modify their argument; implicit solves that depend on
the units of the state; the time grid; a default blow-up bound that called accurate runs
unstable; complex values dropped; implicit failures that lost the run; unbounded step
counts; unchecked ``jac``/``post_step``; ``last_valid`` after a stop.
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import course_lib as cl
from course_lib import fields, forces, implicit
from course_lib.systems import NewtonianSystem, stack_state
from course_lib.timegrid import grid_tolerance, time_grid

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

# --- f that reuses its output buffer, or scribbles over its argument ---------------------


def buffered(f):
    """The same f, writing every result into one preallocated array that it returns."""
    store = {}

    def g(t, y):
        out = np.asarray(f(t, y))
        buf = store.setdefault(out.shape, np.empty(out.shape, out.dtype))
        buf[...] = out
        return buf

    return g


def scribbling(f):
    """The same f, overwriting its argument with garbage after computing the result."""

    def g(t, y):
        out = np.array(f(t, y), copy=True)
        y[...] = -7.5e3
        return out

    return g


def linear_system(seed: int):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(2, 2))
    A[1, 0], A[1, 1] = -abs(A[1, 0]) - 0.5, -abs(A[1, 1])
    A[0] = [0.0, 1.0]                       # Newtonian: x' = v
    return lambda t, y: np.array([y[1], A[1] @ y + 0.3 * np.sin(y[0]) + 0.1 * t])


WRAPPERS = {"buffer": buffered, "scribble": scribbling,
            "both": lambda f: buffered(scribbling(f))}


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 10**6), method=st.sampled_from(cl.METHODS),
       wrap=st.sampled_from(sorted(WRAPPERS)))
def test_every_method_ignores_buffer_reuse_and_argument_changes(seed, method, wrap):
    f = linear_system(seed)
    y0 = np.array([0.7, -0.2])
    kept = y0.copy()
    fresh = cl.integrate(f, y0, (0.0, 1.0), 0.1, method)
    other = cl.integrate(WRAPPERS[wrap](f), y0, (0.0, 1.0), 0.1, method)
    np.testing.assert_array_equal(other.y, fresh.y)
    np.testing.assert_array_equal(y0, kept)
    one = getattr(cl, method)(WRAPPERS[wrap](f), 0.0, y0, 0.1)
    np.testing.assert_array_equal(one, fresh.y[1])
    np.testing.assert_array_equal(y0, kept)


@pytest.mark.parametrize("method", cl.METHODS)
def test_stored_rows_survive_an_f_that_scribbles(method):
    system = NewtonianSystem(forces.constant_gravity(1.0, [0.0, -9.81]), 1.0)
    y0 = stack_state([[0.0, 10.0]], [[1.0, 0.0]])
    fresh = cl.integrate(system, y0, (0.0, 0.5), 0.05, method)
    other = cl.integrate(scribbling(buffered(system)), y0, (0.0, 0.5), 0.05, method)
    np.testing.assert_array_equal(other.y, fresh.y)
    np.testing.assert_array_equal(y0, stack_state([[0.0, 10.0]], [[1.0, 0.0]]))


def test_finite_difference_jacobian_of_a_buffered_f_is_not_zero():
    A = np.array([[-2.0, 1.0], [0.5, -3.0]])
    f = lambda t, y: A @ y  # noqa: E731
    for g in (buffered(f), scribbling(f), buffered(scribbling(f))):
        J = implicit.finite_difference_jacobian(g, 0.0, np.array([1.0, 2.0]))
        np.testing.assert_allclose(J, A, rtol=1e-7)


def test_post_step_may_reuse_a_buffer_too():
    buf = np.empty(2)

    def clamp(t, y):
        buf[...] = np.minimum(y, 0.5)
        return buf

    traj = cl.integrate(lambda t, y: np.ones(2), [0.0, 0.2], (0.0, 1.0), 0.1, post_step=clamp)
    np.testing.assert_allclose(traj.y[:, 0], np.minimum(0.1 * np.arange(11), 0.5), rtol=1e-14)


# --- implicit solves do not depend on the units of the state ------------------------------


def cubic(t, y):
    return np.array([-y[0] ** 3 + y[1], -y[1] * y[0] ** 2 - y[0]])


@settings(max_examples=30, deadline=None)
@given(exponent=st.integers(-12, 12), method=st.sampled_from(["backward_euler", "trapezoidal"]))
def test_implicit_step_is_the_same_in_any_units(exponent, method):
    s = 10.0**exponent
    scaled = lambda t, y: s * cubic(t, y / s)  # noqa: E731  (y in units 1/s of the original)
    y0, dt = np.array([1.3, -0.4]), 0.3
    unit = cl.step(method, cubic, 0.0, y0, dt)
    other = cl.step(method, scaled, 0.0, s * y0, dt)
    np.testing.assert_allclose(other / s, unit, rtol=1e-12)
    if method == "backward_euler":   # and it solves its own equation to round-off
        residual = other - s * y0 - dt * scaled(dt, other)
        assert np.max(np.abs(residual)) <= 1e-13 * np.max(np.abs(other))


# --- the time grid lands exactly on t1 ------------------------------------------------------


def check_grid(t0, t1, dt):
    """The guarantees stated in course_lib.timegrid's docstring, for one grid; (n, last)."""
    t, last = time_grid((t0, t1), dt)
    tol = grid_tolerance(t0, t1)
    n = len(t) - 1
    assert t[0] == t0 and t[-1] == t1 and np.all(np.diff(t) > 0)
    np.testing.assert_array_equal(t[1:-1], t0 + dt * np.arange(1, n))  # as floats compute it
    taken = np.full(n, dt)
    taken[-1] = last
    assert last == dt or (last == t1 - t[-2] and 0 < last < dt - tol)
    assert np.all(np.abs(np.diff(t) - taken) <= tol)    # so every interval <= dt + tol
    assert n == 1 or t1 - t[-3] > dt + tol             # and no fewer steps would do
    return n, last


def grid_or_refusal(t0, t1, dt):
    """check_grid, or the refusal that the rule promises for this (t0, t1, dt)."""
    tol = grid_tolerance(t0, t1)
    try:
        return check_grid(t0, t1, dt)
    except ValueError as err:
        if "float resolution" in str(err):
            assert dt <= 2 * tol
        else:
            assert "longer than the span" in str(err) and t1 - t0 < dt + tol
        return None


times = st.one_of(st.floats(-1e3, 1e3), st.floats(-1e15, 1e15),
                  st.sampled_from([0.0, 64.0, -64.0, 1e-300, 2.0**40, 1e9 + 0.1]))
steps = st.floats(1e-6, 1e3)


@settings(max_examples=150, deadline=None)
@given(t0=times, span=st.floats(1e-6, 1e6), dt=steps)
def test_any_grid_keeps_the_stated_bound(t0, span, dt):
    t1 = t0 + span
    assume(t1 > t0 and span / dt <= 1e5)    # (max_steps is tested in test_hardening_runs)
    got = grid_or_refusal(t0, t1, dt)
    if got is not None:
        n, _ = got
        tol = grid_tolerance(t0, t1)
        assert math.floor((t1 - t0 - tol) / dt) <= n <= math.ceil((t1 - t0 + tol) / dt)


@settings(max_examples=150, deadline=None)
@given(t0=times, dt=steps, n=st.integers(1, 5000))
def test_spans_made_of_n_steps_take_n_steps_of_dt(t0, dt, n):
    """Both ways of writing 'n steps' give n steps of dt: t1 = t0 + n dt, dt = span / n."""
    t1 = t0 + n * dt
    assume(t1 > t0 and dt > 2 * grid_tolerance(t0, t1))
    assert check_grid(t0, t1, dt) == (n, dt)
    other = (t1 - t0) / n
    assume(other > 2 * grid_tolerance(t0, t1))
    assert check_grid(t0, t1, other) == (n, other)


@pytest.mark.parametrize("t0,t1,dt,n,last", [
    (0.0, 1.0, 0.1, 10, 0.1), (0.0, 0.3, 0.1, 3, 0.1), (64.0, 65.0, 1e-3, 1000, 1e-3),
    (64.0, 64.0 + 0.1 * 7, 0.1, 7, 0.1), (-64.0, 64.0, 0.5, 256, 0.5),
    (1e9, 1e9 + 1.0, 0.25, 4, 0.25), (1e-300, 1.0, 0.125, 8, 0.125),
    # not a whole number of steps: the last step is what is left to t1
    (0.0, 1.0, 0.3, 4, 0.1), (64.0, 64.25, 0.1, 3, 0.05), (1e9, 1e9 + 1.0, 0.3, 4, 0.1),
    (0.0, 1.0, 1.0 - 1e-9, 2, 1e-9), (-1e-300, 1e-300, 1.5e-300, 2, 0.5e-300),
])
def test_hand_picked_grids(t0, t1, dt, n, last):
    got_n, got_last = check_grid(t0, t1, dt)
    assert got_n == n
    # the only rounding in `last` is that of the times t0 + k dt: up to tol
    assert abs(got_last - last) <= grid_tolerance(t0, t1)
    traj = cl.integrate(lambda t, y: np.ones(1), [0.0], (t0, t1), dt)
    np.testing.assert_array_equal(traj.t, time_grid((t0, t1), dt)[0])
    # forward Euler on y' = 1 adds up the steps taken: the span, to tol plus n roundings
    assert abs(traj.y[-1, 0] - (t1 - t0)) <= grid_tolerance(t0, t1) + n * 2**-53 * (t1 - t0)


@pytest.mark.parametrize("n,dt", [(3, 0.1), (7, 0.3), (1000, 1e-3), (10, 2 * np.pi / 10)])
def test_whole_number_of_steps_uses_dt_itself(n, dt):
    traj = cl.integrate(lambda t, y: -y, 1.0, (0.0, n * dt), dt)
    assert traj.n_steps == n and traj.t[-1] == n * dt
    np.testing.assert_array_equal(traj.t[:-1], dt * np.arange(n))
    ys = [1.0]
    for _ in range(n):                      # the loop a student writes, with dt each step
        ys.append(ys[-1] + dt * -ys[-1])
    np.testing.assert_array_equal(traj.y, ys)


def test_one_gyration_period_ends_on_the_period():
    q, B, m = 2.0, np.array([0.0, 0.0, 1.5]), 1.0
    period = 2 * np.pi * m / (q * 1.5)
    system = NewtonianSystem(forces.magnetic(q, B), m)
    y0 = stack_state([[1.0, 0.0, 0.0]], [[0.0, -3.0, 0.2]])
    traj = cl.integrate(system, y0, (0.0, period), 1e-3, "rk4")
    assert traj.t[-1] == period
    # after exactly one period the charge is back over its start, risen by v_z T, to RK4's
    # error: per step e^(ih) - R(ih) = (ih)^5/5! + ..., h = ω dt (ω = qB/m), on a circle of
    # radius r = m v⊥/(qB) = 1 m, over n steps; and round-off, a few ulps a step
    omega, n = q * 1.5 / m, traj.n_steps
    truncation = n * (omega * 1e-3) ** 5 / 120 * 1.0
    np.testing.assert_allclose(traj.y[-1, 0, 0], [1.0, 0.0, 0.2 * period],
                               atol=2 * truncation + 8 * n * np.finfo(float).eps)


@pytest.mark.parametrize("span,dt", [((0.0, 1.0), 1.9), ((0.0, 1.0), 1.0 + 1e-9), ((5.0, 6.0), 3.0)])
def test_dt_longer_than_the_span_says_so(span, dt):
    with pytest.raises(ValueError, match=r"dt = .* is longer than the span t1 - t0 = 1"):
        cl.integrate(lambda t, y: -y, 1.0, span, dt)


# --- no default bound: an accurate run is never called unstable ----------------------------


def test_rk4_on_the_radial_field_to_t_20_is_accurate_not_unstable():
    traj = cl.integrate(fields.radial, [1.0, -0.5], (0.0, 20.0), 0.01, "rk4")
    assert traj.stable and traj.message == "ok"
    # RK4's R(h) = e^h - h^5/5! + ...: a relative error n h^5/120 after n steps, and
    # round-off of a few ulps a step
    n, h = traj.n_steps, 0.01
    np.testing.assert_allclose(traj.y[-1], np.exp(20.0) * np.array([1.0, -0.5]),
                               rtol=2 * n * h**5 / 120 + 8 * n * np.finfo(float).eps)


@pytest.mark.parametrize("method", ["velocity_verlet", "symplectic_euler", "rk4"])
def test_a_long_free_fall_is_not_a_blow_up(method):
    system = NewtonianSystem(forces.constant_gravity(2.0), 2.0)
    traj = cl.integrate(system, stack_state([[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]]),
                        (0.0, 1000.0), 0.5, method)
    assert traj.stable
    assert traj.y[-1, 0, 0, 1] == pytest.approx(-0.5 * 9.81 * 1000.0**2, rel=1e-3)


@pytest.mark.parametrize("method", cl.METHODS)
def test_non_finite_state_stops_cleanly_with_no_warning(method, recwarn):
    if method in cl.NEWTONIAN_METHODS:
        f, y0 = (lambda t, y: np.array([y[1], y[0] ** 3])), [1.0, 1.0]
    else:
        f, y0 = (lambda t, y: y**2), [1.0]
    traj = cl.integrate(f, y0, (0.0, 3.0), 0.01, method, blowup_bound=None)
    assert not traj.stable and traj.blowup_step is not None
    assert traj.message.startswith(("unstable at step", "stopped at step"))
    assert np.all(np.isfinite(traj.y[: traj.last_valid + 1]))
    assert np.all(np.isnan(traj.y[traj.last_valid + 1:]))
    assert len(recwarn) == 0


# --- complex values ---------------------------------------------------------------------------


@pytest.mark.parametrize("method", cl.METHODS)
def test_complex_f_on_a_real_state_is_a_type_error(method):
    f = lambda t, y: np.array([y[1], -y[0]]) + 0.5j  # noqa: E731
    with pytest.raises(TypeError, match="complex"):
        cl.integrate(f, [1.0, 0.0], (0.0, 1.0), 0.1, method)
    with pytest.raises(TypeError, match="complex"):
        cl.step(method, f, 0.0, [1.0, 0.0], 0.1)


def test_post_step_returning_complex_is_a_type_error():
    with pytest.raises(TypeError, match="post_step returned complex"):
        cl.integrate(lambda t, y: -y, [1.0], (0.0, 1.0), 0.1, post_step=lambda t, y: y + 1j)


@pytest.mark.parametrize("method", [m for m in cl.METHODS if m not in cl.NEWTONIAN_METHODS])
def test_complex_state_follows_its_amplification_factor(method):
    lam, dt, n = -0.3 + 2.0j, 0.05, 40
    traj = cl.integrate(lambda t, y: lam * y, [1.0 + 0.5j], (0.0, n * dt), dt, method)
    R = cl.amplification_factor(method, lam * dt)
    np.testing.assert_allclose(traj.y[:, 0], (1.0 + 0.5j) * R ** np.arange(n + 1), rtol=1e-12)
