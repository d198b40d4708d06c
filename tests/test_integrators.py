"""The integrators against theory: worked numbers, orders, growth factors, limits."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import fields
from course_lib.systems import oscillator, oscillator_energy

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

# --- the syllabus' worked numbers -------------------------------------------------------

def test_constant_velocity_step_is_exact():
    wind = lambda t, X: np.array([-1.0, -1.0])  # noqa: E731
    traj = cl.integrate(wind, [1.0, 2.0], (0.0, 0.5), 0.5)
    np.testing.assert_array_equal(traj.y[-1], [0.5, 1.5])


def test_forward_euler_on_vortex_matches_syllabus():
    traj = cl.integrate(fields.vortex, [0.0, 1.0], (0.0, 1.5), 0.5)
    np.testing.assert_allclose(traj.t, [0.0, 0.5, 1.0, 1.5])
    np.testing.assert_allclose(
        traj.y, [[0, 1], [-0.5, 1], [-1, 0.75], [-1.375, 0.25]], rtol=0, atol=1e-15
    )


def test_forward_euler_decay_with_dt_3_flips_and_doubles():
    traj = cl.integrate(lambda t, x: -x, 1.0, (0.0, 12.0), 3.0)
    np.testing.assert_array_equal(traj.y, [1.0, -2.0, 4.0, -8.0, 16.0])


# --- convergence order on a non-autonomous problem with a known solution ------------------
# x'' + x = cos 2t, x(0) = 0, x'(0) = 1  =>  x = sin t + (cos t - cos 2t)/3.

def forced(t, y):
    return np.array([y[1], -y[0] + np.cos(2.0 * t)])


def forced_exact(t):
    return np.array([
        np.sin(t) + (np.cos(t) - np.cos(2 * t)) / 3.0,
        np.cos(t) + (-np.sin(t) + 2 * np.sin(2 * t)) / 3.0,
    ])


def observed_order(method, dts):
    errors = []
    for dt in dts:
        traj = cl.integrate(forced, [0.0, 1.0], (0.0, 2.0), dt, method)
        errors.append(np.max(np.abs(traj.y[-1] - forced_exact(traj.t[-1]))))
    slope = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    return slope


@pytest.mark.parametrize("method", cl.METHODS)
def test_observed_order_matches_theory(method):
    expected = cl.ORDER[method]
    dts = 2.0 / np.array([40, 80, 160, 320]) if expected < 4 else 2.0 / np.array([10, 20, 40, 80])
    assert observed_order(method, dts) == pytest.approx(expected, abs=0.06)


def test_orders_are_the_contract():
    assert [cl.ORDER[m] for m in cl.METHODS] == [1, 2, 2, 4, 1, 2, 1, 2]
    assert cl.METHODS == ("forward_euler", "midpoint", "heun", "rk4", "backward_euler",
                          "trapezoidal", "symplectic_euler", "velocity_verlet")


# --- one-step functions agree with the driver --------------------------------------------

@pytest.mark.parametrize("method", cl.METHODS)
def test_one_step_function_matches_integrate(method):
    stepper = getattr(cl, method)
    y0 = np.array([0.3, -0.7])
    one = stepper(forced, 0.2, y0, 0.1)
    traj = cl.integrate(forced, y0, (0.2, 0.3), 0.1, method)
    np.testing.assert_allclose(one, traj.y[-1], rtol=1e-13)


def test_explicit_methods_count_evaluations():
    for method, per_step in cl.EVALS_PER_STEP.items():
        traj = cl.integrate(oscillator(1.0), [1.0, 0.0], (0.0, 1.0), 0.1, method)
        assert traj.nfev == 10 * per_step, method


# --- implicit methods: Newton converges to round-off on linear problems -------------------

A = np.array([[-2.0, 1.0, 0.0], [1.0, -3.0, 0.5], [0.0, 0.5, -1.0]])


def linear(t, y):
    return A @ y


@pytest.mark.parametrize("jac", [None, lambda t, y: A])
def test_backward_euler_solves_linear_step_exactly(jac):
    y0 = np.array([1.0, -2.0, 0.5])
    dt = 0.7
    got = cl.backward_euler(linear, 0.0, y0, dt, jac=jac)
    want = np.linalg.solve(np.eye(3) - dt * A, y0)
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("jac", [None, lambda t, y: A])
def test_trapezoidal_solves_linear_step_exactly(jac):
    y0 = np.array([1.0, -2.0, 0.5])
    dt = 0.7
    got = cl.trapezoidal(linear, 0.0, y0, dt, jac=jac)
    want = np.linalg.solve(np.eye(3) - dt / 2 * A, (np.eye(3) + dt / 2 * A) @ y0)
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)


def test_implicit_methods_solve_nonlinear_equation():
    f = lambda t, y: -(y**3)  # noqa: E731
    y0, dt = np.array([1.5]), 0.5
    y1 = cl.backward_euler(f, 0.0, y0, dt)
    assert abs(y1[0] - y0[0] + dt * y1[0] ** 3) < 1e-14
    y1 = cl.trapezoidal(f, 0.0, y0, dt)
    assert abs(y1[0] - y0[0] + dt / 2 * (y0[0] ** 3 + y1[0] ** 3)) < 1e-14


# --- energy behaviour on the undamped oscillator ------------------------------------------

@pytest.mark.parametrize("omega,dt", [(1.0, 0.1), (2.0, 0.3), (5.0, 0.01)])
def test_forward_euler_energy_grows_by_one_plus_omega2_dt2(omega, dt):
    traj = cl.integrate(oscillator(omega), [1.0, 0.5], (0.0, 50 * dt), dt)
    energy = oscillator_energy(traj.y, omega)
    np.testing.assert_allclose(energy[1:] / energy[:-1], 1 + omega**2 * dt**2, rtol=1e-12)


@pytest.mark.parametrize("omega_dt", [0.1, 1.0, 1.9, 1.99])
def test_symplectic_euler_energy_bounded_below_omega_dt_2(omega_dt):
    omega = 2.0
    dt = omega_dt / omega
    y0 = np.array([1.0, 0.0])
    traj = cl.integrate(oscillator(omega), y0, (0.0, 2000 * dt), dt, "symplectic_euler")
    x, v = traj.y[:, 0], traj.y[:, 1]
    # The step conserves Q = v² + ω²x² - dt ω² x v exactly ...
    q = v**2 + omega**2 * x**2 - dt * omega**2 * x * v
    # ... to round-off: a few ulps per step, amplified by the ellipse's aspect ratio
    # 1/(1 - ωdt/2) (how much a perturbation of the state can change Q relative to it)
    tol = 4 * len(q) * np.finfo(float).eps / (1 - omega_dt / 2)
    np.testing.assert_allclose(q, q[0], rtol=tol)
    # ... so the energy E = (v² + ω²x²)/2 stays in [Q/(2(1 + ωdt/2)), Q/(2(1 - ωdt/2))].
    energy = oscillator_energy(traj.y, omega)
    assert traj.stable
    assert energy.max() <= q[0] / (2 * (1 - omega_dt / 2)) * (1 + tol)
    assert energy.min() >= q[0] / (2 * (1 + omega_dt / 2)) * (1 - tol)


def test_symplectic_euler_blows_up_above_omega_dt_2():
    traj = cl.integrate(oscillator(1.0), [1.0, 0.0], (0.0, 500 * 2.05), 2.05, "symplectic_euler",
                        blowup_bound=1e6)
    assert not traj.stable
    assert "unstable at step" in traj.message


@pytest.mark.parametrize("k", [0.5, 1.0, 10.0])
def test_forward_euler_decay_limit_is_2_over_k(k):
    f = lambda t, x: -k * x  # noqa: E731
    for factor, grows in [(0.99, False), (1.01, True)]:
        dt = factor * 2.0 / k
        traj = cl.integrate(f, 1.0, (0.0, 200 * dt), dt)
        ratio = traj.y[1:] / traj.y[:-1]
        np.testing.assert_allclose(ratio, 1 - k * dt, rtol=1e-12)
        assert (abs(traj.y[-1]) > 1.0) == grows


# --- blow-up handling -------------------------------------------------------------------

def test_blowup_stops_with_clear_message_and_no_warnings(recwarn):
    traj = cl.integrate(lambda t, y: 10.0 * y, [1.0, 2.0], (0.0, 1000.0), 1.0, blowup_bound=1e6)
    assert traj.status == "unstable" and not traj.stable
    assert traj.blowup_step == 6
    assert traj.message == "unstable at step 6, t = 6 (|y| > 1e+06)"
    assert traj.y.shape == (1001, 2) and traj.t.shape == (1001,)
    assert np.all(np.isnan(traj.y[7:]))
    np.testing.assert_array_equal(traj.y[:7], 11.0 ** np.arange(7)[:, None] * [1.0, 2.0])
    assert traj.last_valid == 6
    assert len(recwarn) == 0


def test_without_a_bound_only_overflow_stops_the_run(recwarn):
    # 11**k * 2 overflows a double after k = 295: the first non-finite state is step 296.
    traj = cl.integrate(lambda t, y: 10.0 * y, [1.0, 2.0], (0.0, 1000.0), 1.0)
    assert traj.blowup_step == 296 and traj.last_valid == 295
    assert traj.message == "unstable at step 296, t = 296 (non-finite state)"
    assert np.all(np.isfinite(traj.y[:296])) and np.all(np.isnan(traj.y[296:]))
    assert len(recwarn) == 0


def test_blowup_to_overflow_is_quiet(recwarn):
    traj = cl.integrate(lambda t, y: y * y, [10.0], (0.0, 100.0), 1.0, blowup_bound=1e300)
    assert not traj.stable and "non-finite" in traj.message
    assert len(recwarn) == 0


def test_blowup_can_raise():
    with pytest.raises(cl.BlowUpError, match="unstable at step"):
        cl.integrate(lambda t, y: -3.0 * y, 1.0, (0.0, 100.0), 1.0, on_blowup="raise",
                     blowup_bound=100.0)


def test_grid_lands_on_t1_with_a_shortened_last_step():
    traj = cl.integrate(lambda t, y: -y, 1.0, (0.0, 1.0), 0.3)
    assert traj.y.shape == (5,) and traj.t.shape == (5,)
    np.testing.assert_array_equal(traj.t, [0.0, 0.3, 0.6, 0.8999999999999999, 1.0])
    np.testing.assert_allclose(traj.y, [1.0, 0.7, 0.49, 0.343, 0.343 * (1 - (1.0 - 0.9))],
                               rtol=1e-13)


def test_state_of_any_shape():
    y0 = np.arange(24, dtype=float).reshape(2, 3, 4)
    traj = cl.integrate(lambda t, y: -y, y0, (0.0, 1.0), 0.25, "rk4")
    assert traj.y.shape == (5, 2, 3, 4)
    np.testing.assert_allclose(traj.y[-1], y0 * cl.amplification_factor("rk4", -0.25).real ** 4)


def test_post_step_is_applied():
    traj = cl.integrate(lambda t, y: np.ones(1), [0.0], (0.0, 1.0), 0.1,
                        post_step=lambda t, y: np.minimum(y, 0.5))
    assert traj.y.max() == 0.5
