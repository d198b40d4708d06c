"""course_lib against references it did not write.

- every explicit method rebuilt from its Butcher tableau, the implicit ones from theirs
  (stage equations solved by ``scipy.optimize.root``), the symplectic pair from its
  defining formulas, compared step for step;
- observed orders against ``scipy.integrate.solve_ivp`` (DOP853 at tight tolerance);
- the Kepler problem (orbit, energy, period) against DOP853 and Kepler's third law;
- Robertson's stiff chemical kinetics against Radau: mass conservation to round-off,
  positivity, the state at t = 40, backward Euler's first order;
- a stiff linear system against its exact solution ``expm(A t) y0``.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.integrate import solve_ivp
from scipy.optimize import root

import course_lib as cl
from course_lib import events, forces
from course_lib.systems import NewtonianSystem, stack_state

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

# --- methods rebuilt from their tableaux --------------------------------------------------------

TABLEAUX = {  # (c, A, b)
    "forward_euler": ([0], [[0]], [1]),
    "midpoint": ([0, 1 / 2], [[0, 0], [1 / 2, 0]], [0, 1]),
    "heun": ([0, 1], [[0, 0], [1, 0]], [1 / 2, 1 / 2]),
    "rk4": ([0, 1 / 2, 1 / 2, 1], [[0, 0, 0, 0], [1 / 2, 0, 0, 0], [0, 1 / 2, 0, 0], [0, 0, 1, 0]],
            [1 / 6, 1 / 3, 1 / 3, 1 / 6]),
    "backward_euler": ([1], [[1]], [1]),
    "trapezoidal": ([0, 1], [[0, 0], [1 / 2, 1 / 2]], [1 / 2, 1 / 2]),   # Lobatto IIIA
}


def rk_step(f, t, y, h, tableau):
    """One Runge-Kutta step from a tableau; implicit stages by scipy.optimize.root."""
    c, A, b = (np.asarray(v, dtype=float) for v in tableau)
    s, n = len(c), y.size

    def stages(K):
        K = K.reshape(s, n)
        return np.concatenate([K[i] - f(t + c[i] * h, y + h * A[i] @ K) for i in range(s)])

    if np.allclose(np.triu(A), 0):                 # explicit: fill the stages in order
        K = np.zeros((s, n))
        for i in range(s):
            K[i] = f(t + c[i] * h, y + h * A[i] @ K)
    else:
        K = root(stages, np.tile(f(t, y), s), method="hybr", tol=1e-15).x
        assert np.max(np.abs(stages(K))) < 1e-13   # the stage equations hold to round-off
        K = K.reshape(s, n)
    return y + h * b @ K


def duffing(t, y):
    """A forced, damped Duffing oscillator: nonlinear and non-autonomous, y = (x, v)."""
    return np.array([y[1], -0.2 * y[1] - y[0] - 0.5 * y[0] ** 3 + 0.8 * np.cos(1.3 * t)])


@pytest.mark.parametrize("method", sorted(TABLEAUX))
def test_each_method_is_its_butcher_tableau(method):
    dt, n = 0.05, 60
    traj = cl.integrate(duffing, [1.0, -0.3], (0.0, n * dt), dt, method)
    y = np.array([1.0, -0.3])
    rtol = 1e-13 if method not in cl.IMPLICIT_METHODS else 1e-11
    for k in range(n):
        y = rk_step(duffing, traj.t[k], traj.y[k], dt, TABLEAUX[method])
        np.testing.assert_allclose(traj.y[k + 1], y, rtol=rtol, atol=rtol)


def kick(t, y):
    return np.array([y[1], -np.sin(y[0]) - 0.1 * np.cos(t) * y[0]])


def test_symplectic_pair_is_its_defining_formulas():
    dt, n = 0.1, 50
    a = lambda t, x: kick(t, np.array([x, 0.0]))[1]  # noqa: E731  (position-dependent)
    se = cl.integrate(kick, [1.0, 0.5], (0.0, n * dt), dt, "symplectic_euler")
    vv = cl.integrate(kick, [1.0, 0.5], (0.0, n * dt), dt, "velocity_verlet")
    x, v = 1.0, 0.5
    for k in range(n):                      # symplectic Euler: kick with a(x_n), then drift
        t = k * dt
        v = v + dt * a(t, x)
        x = x + dt * v
        np.testing.assert_allclose(se.y[k + 1], [x, v], rtol=1e-14, atol=1e-15)
    x, v = 1.0, 0.5
    for k in range(n):                      # Verlet = half step of symplectic Euler, then its
        t = k * dt                          # adjoint (drift, then kick): Hairer et al. (2006)
        v = v + dt / 2 * a(t, x)
        x = x + dt / 2 * v
        x = x + dt / 2 * v
        v = v + dt / 2 * a(t + dt, x)
        np.testing.assert_allclose(vv.y[k + 1], [x, v], rtol=1e-13, atol=1e-14)


# --- observed orders against solve_ivp ----------------------------------------------------------


def forced_duffing(t, y):
    """Undamped (position-dependent force: Verlet's order is 2) and forced."""
    return np.array([y[1], -y[0] - 0.5 * y[0] ** 3 + 0.8 * np.cos(1.3 * t)])


@pytest.fixture(scope="module")
def duffing_reference():
    sol = solve_ivp(forced_duffing, (0.0, 2.0), [1.0, -0.3], method="DOP853", rtol=1e-13,
                    atol=1e-13)
    return sol.y[:, -1]


@pytest.mark.parametrize("method", cl.METHODS)
def test_observed_order_against_dop853(method, duffing_reference):
    dts = 2.0 / np.array([20, 40, 80, 160])
    errors = [np.max(np.abs(cl.integrate(forced_duffing, [1.0, -0.3], (0.0, 2.0), dt,
                                         method).y[-1] - duffing_reference)) for dt in dts]
    slope = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert slope == pytest.approx(cl.ORDER[method], abs=0.12)


# --- Kepler ------------------------------------------------------------------------------------

E_KEPLER, PERIOD = 0.6, 2 * np.pi        # GM = 1, a = 1: T = 2π a^{3/2} / sqrt(GM)


def kepler_system():
    return NewtonianSystem(forces.attractor((0.0, 0.0), 1.0, softening=0.0), 1.0)


def kepler_start():
    r = 1.0 - E_KEPLER                                   # perihelion, velocity ⟂ radius
    return stack_state([[r, 0.0]], [[0.0, np.sqrt((1 + E_KEPLER) / r)]])


def kepler_energy(y):
    x, v = y[..., 0, 0, :], y[..., 1, 0, :]
    return 0.5 * np.sum(v * v, axis=-1) - 1.0 / np.linalg.norm(x, axis=-1)


@pytest.fixture(scope="module")
def kepler_reference():
    f = kepler_system()

    def upward(t, y):                                    # y-coordinate crossing zero upwards
        return y[1]

    upward.direction = 1
    return solve_ivp(lambda t, y: f(t, y.reshape(2, 1, 2)).ravel(), (0.0, 1.25 * PERIOD),
                     kepler_start().ravel(), method="DOP853", rtol=1e-13, atol=1e-13,
                     dense_output=True, events=upward)


def test_kepler_rk4_follows_dop853_at_fourth_order(kepler_reference):
    errors = []
    for n in (2000, 4000):
        traj = cl.integrate(kepler_system(), kepler_start(), (0.0, PERIOD), PERIOD / n, "rk4")
        ref = kepler_reference.sol(traj.t).T.reshape(-1, 2, 1, 2)
        errors.append(np.max(np.abs(traj.y - ref)))
    assert errors[0] < 1e-7 and errors[0] / errors[1] == pytest.approx(16, rel=0.15)
    # after one period the orbit closes: back at perihelion (Kepler's third law)
    np.testing.assert_allclose(kepler_reference.sol(PERIOD), kepler_start().ravel(), atol=1e-10)


def test_kepler_energy_and_period_with_velocity_verlet(kepler_reference):
    periods, measured = 5, []
    for n_per in (2000, 4000):
        traj = cl.integrate(kepler_system(), kepler_start(), (0.0, periods * PERIOD),
                            PERIOD / n_per, "velocity_verlet")
        measured.append(events.measured_period(traj.t, traj.y[:, 0, 0, 1]))
        drift = np.abs(kepler_energy(traj.y) + 0.5)      # E = -GM / 2a exactly
        assert drift.max() < 8e-4 * (2000 / n_per) ** 2  # a bounded oscillation, O(dt²) ...
        half = len(drift) // 2                           # ... without drift:
        assert drift[half:].max() == pytest.approx(drift[:half].max(), rel=0.05)
    # Kepler's third law holds for the reference, and Verlet's period error is O(dt²)
    assert kepler_reference.t_events[0][-1] == pytest.approx(PERIOD, rel=1e-11)
    errors = [abs(p / PERIOD - 1) for p in measured]
    assert errors[0] < 1.2e-4 and errors[0] / errors[1] == pytest.approx(4.0, rel=0.05)


# --- Robertson's stiff kinetics -------------------------------------------------------------------


def robertson(t, y):
    y1, y2, y3 = y
    return np.array([-0.04 * y1 + 1e4 * y2 * y3,
                     0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2 * y2,
                     3e7 * y2 * y2])


def robertson_jac(t, y):
    _, y2, y3 = y
    return np.array([[-0.04, 1e4 * y3, 1e4 * y2],
                     [0.04, -1e4 * y3 - 6e7 * y2, -1e4 * y2],
                     [0.0, 6e7 * y2, 0.0]])


@pytest.fixture(scope="module")
def robertson_at_40():
    sol = solve_ivp(robertson, (0.0, 40.0), [1.0, 0.0, 0.0], method="Radau", rtol=1e-12,
                    atol=1e-16, jac=robertson_jac)
    return sol.y[:, -1]


@pytest.mark.parametrize("method,dt,jac,rtol", [
    ("backward_euler", 0.02, None, 4e-4),
    ("backward_euler", 0.02, robertson_jac, 4e-4),
    ("trapezoidal", 0.01, robertson_jac, 1e-6),
])
def test_robertson_conserves_mass_stays_positive_and_matches_radau(method, dt, jac, rtol,
                                                                   robertson_at_40):
    traj = cl.integrate(robertson, [1.0, 0.0, 0.0], (0.0, 40.0), dt, method, jac=jac)
    assert traj.stable
    np.testing.assert_allclose(traj.y.sum(axis=1), 1.0, rtol=0, atol=1e-13)
    assert traj.y.min() >= 0.0
    np.testing.assert_allclose(traj.y[-1], robertson_at_40, rtol=rtol)


def test_robertson_backward_euler_is_first_order(robertson_at_40):
    err = [np.abs(cl.integrate(robertson, [1.0, 0.0, 0.0], (0.0, 40.0), dt, "backward_euler",
                               jac=robertson_jac).y[-1] / robertson_at_40 - 1).max()
           for dt in (0.04, 0.02)]
    assert err[0] / err[1] == pytest.approx(2.0, rel=0.05)


def test_robertson_trapezoid_with_a_large_step_rings_and_stops_cleanly():
    # Not L-stable: the fast species oscillates (R(-inf) = -1), turns negative, and the
    # implicit equation loses its real root; the run keeps its good steps and says why.
    traj = cl.integrate(robertson, [1.0, 0.0, 0.0], (0.0, 40.0), 0.04, "trapezoidal",
                        jac=robertson_jac)
    assert traj.status == "failed" and "Newton" in traj.message
    good = traj.y[: traj.last_valid + 1]
    assert good[:, 1].min() < 0 and np.all(np.isfinite(good))


# --- a stiff linear system ---------------------------------------------------------------------


def stiff_matrix():
    Q, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    return Q @ np.diag([-1.0, -100.0, -1e4]) @ Q.T, Q


@pytest.mark.parametrize("method", sorted(cl.IMPLICIT_METHODS))
def test_stiff_linear_system_step_is_the_exact_rational_function(method):
    A, Q = stiff_matrix()
    y0 = np.array([1.0, 2.0, -1.0])
    dt, n = 0.1, 30
    traj = cl.integrate(lambda t, y: A @ y, y0, (0.0, n * dt), dt, method)
    # in the eigenbasis each mode is multiplied by R(λ dt) every step
    R = cl.amplification_factor(method, np.array([-1.0, -100.0, -1e4]) * dt).real
    modes = (traj.y @ Q) / (y0 @ Q)
    np.testing.assert_allclose(modes, R ** np.arange(n + 1)[:, None], rtol=1e-9, atol=1e-14)
    # against the exact solution: the slow mode (λ = -1) at the method's order; the stiff
    # ones are killed by backward Euler (L-stable) but kept, sign-flipping, by the trapezoid
    exact = (sla.expm(A * n * dt) @ y0) @ Q
    got = traj.y[-1] @ Q
    slow, stiff = abs(got[0] - exact[0]), np.abs(got[1:] - exact[1:]).max()
    c0 = abs((y0 @ Q)[0])
    assert slow == pytest.approx(c0 * abs(R[0] ** n - np.exp(-n * dt)), rel=1e-8)
    if method == "backward_euler":
        assert slow < 0.02 and stiff < 1e-15
    else:
        assert slow < 3e-4 and stiff > 0.1


def test_explicit_limit_on_the_stiff_system_is_its_fastest_mode():
    A, _ = stiff_matrix()
    limit = cl.max_stable_dt("forward_euler", -1e4)
    assert limit == pytest.approx(2e-4, rel=1e-14)
    for factor, stable in [(0.99, True), (1.01, False)]:
        dt = factor * limit
        traj = cl.integrate(lambda t, y: A @ y, np.ones(3), (0.0, 3000 * dt), dt,
                            blowup_bound=10.0)
        assert traj.stable == stable
