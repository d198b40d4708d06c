"""Every number quoted in notebook 04 (beyond Euler), and its exercise checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

import course_lib as cl
from course_lib.check import FAILURES, REGISTRY, RESULTS, evaluate
from course_lib.check import nb04 as check


@pytest.fixture(autouse=True)
def _first_attempt():
    """Every test sees the first attempt's hint (the nudge): no failures carried over."""
    for key in [k for k in FAILURES if k.startswith("nb04.")]:
        del FAILURES[key]

ONE_STEP = ["forward_euler", "midpoint", "heun", "rk4", "backward_euler", "trapezoidal"]
J = np.array([[0.0, -1.0], [1.0, 0.0]])


def closed_form_radius_factor(method: str, th: float) -> float:
    """The |R(iθ)| column of the notebook's table."""
    return {
        "forward_euler": math.sqrt(1 + th**2),
        "midpoint": math.sqrt(1 + th**4 / 4),
        "heun": math.sqrt(1 + th**4 / 4),
        "rk4": math.sqrt(1 - th**6 / 72 + th**8 / 576),
        "backward_euler": 1 / math.sqrt(1 + th**2),
        "trapezoidal": 1.0,
    }[method]


def exact_pulsing(t):
    phi = t + 0.5 * np.sin(t)
    return np.array([np.cos(phi), np.sin(phi)])


def convergence_study(method: str):
    """Section 4: the pulsing vortex over T = 2π, as in the notebook."""
    T = 2 * np.pi
    top = {"rk4": 9, "trapezoidal": 11, "backward_euler": 12}.get(method, 13)  # as step_counts
    counts = 2 ** np.arange(3 if method == "rk4" else 5, top)
    dts, errors, nfev = [], [], []
    for n in counts:
        traj = cl.integrate(check.pulsing_vortex, [1.0, 0.0], (0.0, T), T / n, method=method)
        dts.append(traj.dt)
        errors.append(np.linalg.norm(traj.y[-1] - exact_pulsing(traj.t[-1])))
        nfev.append(traj.nfev)
    dts, errors, nfev = map(np.array, (dts, errors, nfev))
    order = np.polyfit(np.log(dts[-4:]), np.log(errors[-4:]), 1)[0]
    return dts, errors, nfev, order


@pytest.fixture(scope="module")
def study():
    return {m: convergence_study(m) for m in ONE_STEP}


# --- Section 1: the methods ----------------------------------------------------------------


def test_pulsing_vortex_exact_solution():
    from scipy.integrate import solve_ivp

    sol = solve_ivp(check.pulsing_vortex, (0.0, 2 * np.pi), [1.0, 0.0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(sol.y[:, -1], exact_pulsing(2 * np.pi), atol=1e-9)
    np.testing.assert_allclose(exact_pulsing(2 * np.pi), [1.0, 0.0], atol=1e-15)


def test_rk4_written_out_matches_course_lib():
    def rk4_step(f, t, y, dt):
        k1 = f(t, y)
        k2 = f(t + dt / 2, y + dt / 2 * k1)
        k3 = f(t + dt / 2, y + dt / 2 * k2)
        k4 = f(t + dt, y + dt * k3)
        return y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    y0 = np.array([0.0, 1.0])
    mine = rk4_step(check.pulsing_vortex, 0.3, y0, 0.5)
    np.testing.assert_allclose(mine, cl.rk4(check.pulsing_vortex, 0.3, y0, 0.5), rtol=1e-14)
    np.testing.assert_allclose(mine, [-0.65104, 0.757852], atol=5e-7)


def test_implicit_steps_on_the_vortex():
    X = np.array([0.0, 1.0])
    be = cl.backward_euler(cl.fields.vortex, 0.0, X, 0.5)
    trap = cl.trapezoidal(cl.fields.vortex, 0.0, X, 0.5)
    np.testing.assert_allclose(be, [-0.4, 0.8], rtol=1e-12)
    np.testing.assert_allclose(trap, [-8 / 17, 15 / 17], rtol=1e-12)
    assert np.linalg.norm(be) == pytest.approx(0.894427, abs=5e-7)
    assert np.linalg.norm(trap) == pytest.approx(1.0, rel=1e-12)


def test_newton_needs_few_iterations_on_linear_field():
    # per step: 1 evaluation for the guess (or f0), then 3 per Newton iteration in 2D
    for m in ["backward_euler", "trapezoidal"]:
        traj = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 10 * np.pi), 0.5, method=m)
        assert traj.nfev <= traj.n_steps * (1 + 3 * 3)


def test_orders_and_costs_table():
    assert [cl.ORDER[m] for m in ONE_STEP] == [1, 2, 2, 4, 1, 2]
    assert [cl.EVALS_PER_STEP[m] for m in ONE_STEP[:4]] == [1, 2, 2, 4]
    assert not {"backward_euler", "trapezoidal"} & set(cl.EVALS_PER_STEP)
    f = cl.fields.vortex
    for m in ONE_STEP[:4]:
        traj = cl.integrate(f, [0.0, 1.0], (0.0, 5.0), 0.5, method=m)
        assert traj.nfev == cl.EVALS_PER_STEP[m] * traj.n_steps


# --- Sections 2 and 3: radius drift per step ------------------------------------------------


@pytest.mark.parametrize("method", ONE_STEP)
@pytest.mark.parametrize("th", [0.5, 0.1, 1.0, 2.0])
def test_closed_form_equals_amplification_factor(method, th):
    R = cl.amplification_factor(method, 1j * th)
    assert abs(R) == pytest.approx(closed_form_radius_factor(method, th), rel=1e-14)


@pytest.mark.parametrize("method", ONE_STEP)
def test_measured_radius_ratio(method):
    dt = 0.5
    traj = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 63 * dt), dt, method=method)
    assert traj.n_steps == 63 and 63 * dt / (2 * np.pi) == pytest.approx(5.0, abs=0.02)
    r = np.linalg.norm(traj.y, axis=1)
    np.testing.assert_allclose(r[1:] / r[:-1], closed_form_radius_factor(method, dt), rtol=1e-10)


def test_quoted_factors_at_half_a_second():
    f = {m: closed_form_radius_factor(m, 0.5) for m in ONE_STEP}
    assert f["forward_euler"] == pytest.approx(1.11803399, abs=5e-9)
    assert round(100 * (f["forward_euler"] - 1), 1) == 11.8
    assert f["midpoint"] == pytest.approx(1.00778222, abs=5e-9)
    assert round(100 * (f["midpoint"] - 1), 2) == 0.78
    assert f["rk4"] == pytest.approx(0.99989488, abs=5e-9)
    assert round(100 * (1 - f["rk4"]), 4) == 0.0105
    assert f["backward_euler"] == pytest.approx(0.89442719, abs=5e-9)
    assert f["trapezoidal"] == 1.0
    # over the five revolutions (63 steps)
    assert f["forward_euler"] ** 63 == pytest.approx(1130, rel=0.001)
    assert f["midpoint"] ** 63 == pytest.approx(1.63, abs=0.005)
    assert f["rk4"] ** 63 == pytest.approx(0.9934, abs=5e-5)


def test_rk4_shrinks_below_sqrt8():
    th = np.linspace(0.05, math.sqrt(8) - 1e-6, 500)
    assert np.all(np.abs(cl.amplification_factor("rk4", 1j * th)) < 1)
    assert abs(cl.amplification_factor("rk4", 1j * math.sqrt(8))) == pytest.approx(1, rel=1e-14)
    assert cl.max_stable_dt("rk4", 1j) == pytest.approx(math.sqrt(8), rel=1e-10)


def test_departure_from_one_reveals_the_order():
    th = 1e-2
    assert math.sqrt(1 + th**2) - 1 == pytest.approx(th**2 / 2, rel=1e-3)
    assert math.sqrt(1 + th**4 / 4) - 1 == pytest.approx(th**4 / 8, rel=1e-3)
    assert 1 - math.sqrt(1 - th**6 / 72 + th**8 / 576) == pytest.approx(th**6 / 144, rel=1e-3)


def test_trapezoid_angle_per_step():
    dt = 0.5
    X1 = cl.trapezoidal(cl.fields.vortex, 0.0, [1.0, 0.0], dt)
    assert math.atan2(X1[1], X1[0]) == pytest.approx(2 * math.atan(dt / 2), rel=1e-12)
    assert 2 * math.atan(dt / 2) != pytest.approx(dt, rel=1e-3)


def test_cayley_transform_is_a_rotation():
    dt = 0.7
    A = np.linalg.solve(np.eye(2) - dt / 2 * J, np.eye(2) + dt / 2 * J)
    np.testing.assert_allclose(A.T @ A, np.eye(2), atol=1e-15)


# --- Section 4: observed orders and costs ---------------------------------------------------


@pytest.mark.roundoff
@pytest.mark.parametrize("method, quoted", [
    ("forward_euler", 1.009), ("midpoint", 2.000), ("heun", 2.000), ("rk4", 3.998),
    ("backward_euler", 0.982), ("trapezoidal", 2.000),
])
def test_observed_orders(study, method, quoted):
    order = study[method][3]
    assert order == pytest.approx(cl.ORDER[method], abs=0.05)
    assert round(order, 3) == quoted


@pytest.mark.roundoff
def test_backward_euler_order_mirrors_forward_eulers_at_the_same_steps(study):
    """Section 4: backward Euler's fit stops at n = 2048, where forward Euler's fit over the
    same four steps gives 1.018; both orders miss 1 by the same amount (the next error
    term, of relative size ~dt, enters with opposite signs)."""
    dts, errors = study["forward_euler"][0][-5:-1], study["forward_euler"][1][-5:-1]
    fe_same_steps = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    np.testing.assert_allclose(dts, study["backward_euler"][0][-4:], rtol=1e-12)
    assert round(fe_same_steps, 3) == 1.018
    assert fe_same_steps - 1 == pytest.approx(1 - study["backward_euler"][3], abs=2e-3)


@pytest.mark.roundoff
def test_cost_for_target_error(study):
    need = {}
    for m in ["forward_euler", "midpoint", "heun", "rk4"]:
        _, errors, nfev, _ = study[m]
        slope, icpt = np.polyfit(np.log(nfev[-4:]), np.log(errors[-4:]), 1)
        need[m] = math.exp((math.log(1e-4) - icpt) / slope)
    assert need["rk4"] == pytest.approx(150, rel=0.05)
    assert need["midpoint"] == pytest.approx(1500, rel=0.05)
    assert need["heun"] == pytest.approx(1500, rel=0.05)
    assert need["forward_euler"] == pytest.approx(210_000, rel=0.05)


def test_midpoint_and_heun_nearly_equal(study):
    e_mid, e_heun = study["midpoint"][1], study["heun"][1]
    np.testing.assert_allclose(e_mid[-4:], e_heun[-4:], rtol=1e-5)   # "less than 0.001 %"
    assert not np.array_equal(e_mid, e_heun)


# --- Exercise 2 aftermath: decay with k dt = 3 ----------------------------------------------


def test_decay_large_step():
    k, dt, n = 1.0, 3.0, 4
    closed = cl.amplification_factor("backward_euler", -k * dt).real ** np.arange(n + 1)
    np.testing.assert_allclose(closed, [1, 0.25, 0.0625, 0.015625, 0.00390625], rtol=1e-15)
    np.testing.assert_allclose(check.linear_newton([[-k]], [1.0], dt, n)[:, 0], closed,
                               rtol=1e-12)
    fe = cl.integrate(lambda t, x: -k * x, [1.0], (0.0, n * dt), dt).y[:, 0]
    np.testing.assert_allclose(fe, [1, -2, 4, -8, 16], rtol=1e-15)
    assert cl.amplification_factor("forward_euler", -3.0) == -2
    assert cl.amplification_factor("backward_euler", -3.0) == pytest.approx(0.25)


# --- the exercise checks ---------------------------------------------------------------------


def verdict(run, answer, capsys, key):
    RESULTS.pop(f"nb04.{key}", None)
    run(answer)
    return RESULTS[f"nb04.{key}"]["status"], capsys.readouterr().out


def _midpoint(f, t, y, dt):
    y_mid = y + 0.5 * dt * f(t, y)
    return y + dt * f(t + 0.5 * dt, y_mid)


def test_midpoint_step_correct(capsys):
    status, out = verdict(check.midpoint_step, _midpoint, capsys, "midpoint_step")
    assert status == "correct", out
    assert RESULTS["nb04.midpoint_step"]["total"] == 4


def _in_place(f, t, y, dt):
    k1 = f(t, y)
    y_mid = y + 0.5 * dt * k1
    y += dt * f(t + 0.5 * dt, y_mid)
    return y


@pytest.mark.parametrize("wrong, hint", [
    (lambda f, t, y, dt: y + dt * f(t, y), "start slope"),
    (lambda f, t, y, dt: y + dt * f(t, y + 0.5 * dt * f(t, y)), "not at t"),
    (lambda f, t, y, dt: y + dt * f(t + dt, y + 0.5 * dt * f(t, y)), "not t + dt"),
    (lambda f, t, y, dt: y + dt * f(t + 0.5 * dt, y + dt * f(t, y)), "half a step away"),
    (lambda f, t, y, dt: y + 0.5 * dt * (f(t, y) + f(t + dt, y + dt * f(t, y))), "Heun"),
    (lambda f, t, y, dt: y + 0.5 * dt * f(t, y), "half-step prediction"),
    (_in_place, "in place"),
    (lambda f, t, y, dt: y + 0.5 * dt * f(t + 0.5 * dt, y + 0.5 * dt * f(t, y)),
     "the whole dt with the midpoint slope"),
    (lambda f, t, y, dt: y + 0.5 * dt * (f(t, y) + f(t + 0.5 * dt, y + 0.5 * dt * f(t, y))),
     "you averaged the start slope with the midpoint slope"),
    (lambda f, t, y, dt: y + dt * f(0.5 * dt, y + 0.5 * dt * f(0.0, y)), "pass the step's time"),
    (lambda f, t, y, dt: y + dt * f(t + 0.3 * dt, y + 0.5 * dt * f(t, y)),
     "predict the state half a step ahead"),
])
def test_midpoint_step_mistakes(wrong, hint, capsys):
    status, out = verdict(check.midpoint_step, wrong, capsys, "midpoint_step")
    assert status == "incorrect"
    assert hint in out


@pytest.mark.parametrize("key", ["midpoint_step", "backward_euler_linear", "implicit_midpoint_step"])
def test_pending(key, capsys):
    def stub(*args):
        raise NotImplementedError()

    status, out = verdict(getattr(check, key), stub, capsys, key)
    assert status == "pending"
    assert "pending" in out


def _be_linear(A, x0, dt, n):
    A, x = np.asarray(A, dtype=float), np.asarray(x0, dtype=float)
    states = [x]
    for _ in range(n):
        states.append(np.linalg.solve(np.eye(len(x)) - dt * A, states[-1]))
    return np.array(states)


def test_backward_euler_linear_correct(capsys):
    status, out = verdict(check.backward_euler_linear, _be_linear, capsys, "backward_euler_linear")
    assert status == "correct", out
    assert "Newton" in out and RESULTS["nb04.backward_euler_linear"]["total"] == 5

    def inverse_once(A, x0, dt, n):  # the inverse, computed once and applied n times, is as good
        M = np.linalg.inv(np.eye(len(x0)) - dt * np.asarray(A))
        out = np.empty((n + 1, len(x0)))
        out[0] = x0
        for k in range(n):
            out[k + 1] = M @ out[k]
        return out.tolist()

    status, out = verdict(check.backward_euler_linear, inverse_once, capsys, "backward_euler_linear")
    assert status == "correct", out


def _wrap(step):
    """An answer that applies ``step(A, dt, x)`` n times from float or integer x0."""
    def answer(A, x0, dt, n):
        out = [np.asarray(x0, dtype=float)]
        for _ in range(n):
            out.append(step(np.asarray(A), dt, out[-1]))
        return np.array(out)
    return answer


def _int_states(A, x0, dt, n):
    out = np.zeros((n + 1, len(x0)), dtype=np.asarray(x0).dtype)   # int when x0 is [1, 0]
    out[0] = x0
    for k in range(n):
        out[k + 1] = np.linalg.solve(np.eye(len(x0)) - dt * A, out[k])
    return out


@pytest.mark.parametrize("wrong, hint", [
    (_wrap(lambda A, dt, x: x + dt * A @ x), "FORWARD Euler"),
    (_wrap(lambda A, dt, x: (np.eye(len(x)) - dt * A) @ x), "SOLVE that system"),
    (_wrap(lambda A, dt, x: np.linalg.solve(np.eye(len(x)) + dt * A, x)), "not (I + dt A)"),
    (_wrap(lambda A, dt, x: np.linalg.solve(1 - dt * A, x)), "np.eye(d)"),
    (_wrap(lambda A, dt, x: x @ np.linalg.inv(np.eye(len(x)) - dt * A)), "matrix on the left"),
    (_wrap(lambda A, dt, x: x / (1 - dt * np.diag(A))), "only when A is diagonal"),
    (_int_states, "rounded to whole numbers"),
    (lambda A, x0, dt, n: _be_linear(A, x0, dt, n)[1:], "include the initial state"),
    (lambda A, x0, dt, n: _be_linear(A, x0, dt, n)[:-1], "the last state x_n is missing"),
    (lambda A, x0, dt, n: _be_linear(A, x0, dt, n)[-1], "not only the last one"),
    (lambda A, x0, dt, n: _be_linear(A, x0, dt, n).T, "one row per state"),
    (_wrap(lambda A, dt, x: np.linalg.solve(np.eye(len(x)) - 0.5 * dt * A, x)),
     "how is x_next related to x?"),
])
def test_backward_euler_linear_mistakes(wrong, hint, capsys):
    status, out = verdict(check.backward_euler_linear, wrong, capsys, "backward_euler_linear")
    assert status == "incorrect"
    assert hint in out, out


def test_backward_euler_linear_exact_solution_is_named():
    from scipy.linalg import expm

    def exact(A, x0, dt, n):
        return np.array([expm(np.asarray(A) * dt * k) @ np.asarray(x0, float) for k in range(n + 1)])

    result = evaluate(check.backward_euler_linear, exact)
    assert result["status"] == "incorrect"
    assert "that is the exact solution" in "\n".join(result["failed_cases"])


def test_backward_euler_linear_fallback_escalates():
    wrong = _wrap(lambda A, dt, x: np.linalg.solve(np.eye(len(x)) - 0.5 * dt * A, x))
    first = "\n".join(evaluate(check.backward_euler_linear, wrong)["failed_cases"])
    assert "how is x_next related to x?" in first and "np.linalg.solve" not in first
    FAILURES["nb04.backward_euler_linear"] = 1
    second = "\n".join(evaluate(check.backward_euler_linear, wrong)["failed_cases"])
    assert "(I - dt A) x_next = x" in second


# --- numbers and claims added in review ------------------------------------------------------


def test_backward_euler_radius_is_2_over_sqrt5():
    be = cl.backward_euler(cl.fields.vortex, 0.0, np.array([0.0, 1.0]), 0.5)
    assert np.linalg.norm(be) == pytest.approx(2 / math.sqrt(5), rel=1e-12)  # printed 0.894427
    assert f"{2 / math.sqrt(5):.6f}" == "0.894427"


@pytest.mark.roundoff
def test_printed_costs_for_target_error(study):
    printed = {"forward_euler": 214470, "midpoint": 1508, "heun": 1508, "rk4": 149}
    for m, quoted in printed.items():
        _, errors, nfev, _ = study[m]
        slope, icpt = np.polyfit(np.log(nfev[-4:]), np.log(errors[-4:]), 1)
        assert round(math.exp((math.log(1e-4) - icpt) / slope)) == quoted


def test_midpoint_and_heun_identical_on_constant_linear_field():
    # both are X -> (I + dt A + dt²/2 A²) X when V = A X
    dt = 0.5
    step = np.eye(2) + dt * J + dt**2 / 2 * J @ J
    X = np.array([0.3, -1.2])
    for m in ("midpoint", "heun"):
        np.testing.assert_allclose(cl.step(m, cl.fields.vortex, 0.0, X, dt), step @ X,
                                   rtol=1e-15, atol=1e-15)
    a = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 63 * dt), dt, method="midpoint")
    b = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 63 * dt), dt, method="heun")
    np.testing.assert_allclose(a.y, b.y, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(("method", "p"), [("forward_euler", 1), ("midpoint", 2), ("rk4", 4)])
def test_leading_error_term_and_radius_order(method, p):
    # R(z) = e^z - z^(p+1)/(p+1)! + ...; for even p that term is imaginary on z = iθ (phase),
    # and the radius error starts at θ^(p+2); for p = 1 it is real and starts at θ^2
    th = 1e-2
    z = 1j * th
    lead = (cl.amplification_factor(method, z) - np.exp(z)) / z ** (p + 1)
    assert lead == pytest.approx(-1 / math.factorial(p + 1), rel=2e-2)
    if p % 2 == 0:
        assert abs((z ** (p + 1)).real) < 1e-30
    radius_power = 2 if p == 1 else p + 2
    ratio = (abs(cl.amplification_factor(method, 2 * z)) - 1) / (
        abs(cl.amplification_factor(method, z)) - 1)
    assert ratio == pytest.approx(2.0**radius_power, rel=2e-2)


def test_trapezoid_keeps_quadratic_invariant_only_on_linear_fields():
    def swirl(t, X):  # |X| is a quadratic invariant of this nonlinear field
        return (1.0 + X[0]) * (J @ X)

    X = np.array([1.0, 0.5])
    dt = 0.4
    Y = cl.trapezoidal(swirl, 0.0, X, dt)
    assert abs(np.linalg.norm(Y) - np.linalg.norm(X)) > 1e-4  # lost on a nonlinear field
    Y_lin = cl.trapezoidal(cl.fields.vortex, 0.0, X, dt)
    assert np.linalg.norm(Y_lin) == pytest.approx(np.linalg.norm(X), rel=1e-13)
    # the implicit midpoint rule Y = X + dt f((X + Y)/2) keeps it (fixed-point iteration)
    Ym = X.copy()
    for _ in range(200):
        Ym = X + dt * swirl(0.0, (X + Ym) / 2)
    assert np.linalg.norm(Ym) == pytest.approx(np.linalg.norm(X), rel=1e-12)


# --- Section 3: the leading error term of R, method by method ------------------------------


@pytest.mark.parametrize(("method", "p", "C"), [
    ("forward_euler", 1, -1 / 2), ("midpoint", 2, -1 / 6), ("heun", 2, -1 / 6),
    ("rk4", 4, -1 / 120), ("backward_euler", 1, 1 / 2), ("trapezoidal", 2, 1 / 12),
])
def test_leading_constant_C(method, p, C):
    # R(z) = e^z + C z^(p+1) + ...: C = -1/(p+1)! only for the explicit methods with as many
    # stages as order; backward Euler has +1/2, the trapezoid +1/12
    for z in (1e-2, 1e-2j, -1e-2 + 5e-3j):
        lead = (cl.amplification_factor(method, z) - np.exp(z)) / z ** (p + 1)
        assert lead == pytest.approx(C, rel=0.05)
    if method in ("backward_euler", "trapezoidal"):
        assert C != -1 / math.factorial(p + 1)


# --- Section 5: the stiff follower -----------------------------------------------------------


@pytest.fixture(scope="module")
def stiff():
    from course_lib.lessons import nb04_beyond_euler as lesson

    counts = 2 ** np.arange(4, 15)
    methods = ["forward_euler", "midpoint", "rk4", "backward_euler", "trapezoidal"]
    rows = (lesson.cost_study(methods[:3], counts)
            + lesson.cost_study(methods[3:], counts[counts <= 1024]))
    return lesson, rows


def test_follower_exact_solution_solves_the_ode():
    from course_lib.lessons import nb04_beyond_euler as lesson

    f, jac, exact = lesson.follower()
    X0, h = np.array([0.0, 0.0]), 1e-7
    for t in (1e-4, 2e-3, 0.5, 3.0):
        dX = (exact(t + h, X0) - exact(t - h, X0)) / (2 * h)
        np.testing.assert_allclose(dX, f(t, exact(t, X0)), rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(exact(0.0, X0), X0, atol=1e-15)
    np.testing.assert_allclose(jac, -1000.0 * np.eye(2))
    # after the catch-up the particle lags the target by about 1/κ rad
    late = exact(2.0, X0)
    lag = 2.0 - math.atan2(late[1], late[0])
    assert lag == pytest.approx(math.atan(1 / 1000), rel=1e-9)
    with pytest.raises(ValueError, match="kappa"):
        lesson.follower(0.0)


def test_stiff_limits_quoted():
    assert 2 * math.pi * 1000 / 2.785293563405282 == pytest.approx(2256, abs=0.5)
    assert 1000 * 2 * math.pi / 4096 == pytest.approx(1.5, abs=0.04)        # "κ dt ≈ 1.5"
    assert 1000 * 2 * math.pi / 2048 > 2.785                             # RK4 unstable at 2048
    z = -1000 * 2 * math.pi / 64
    assert round(-z) == 98
    assert cl.amplification_factor("trapezoidal", z).real == pytest.approx(-0.96, abs=0.001)
    assert -48 / 50 == -0.96
    assert cl.amplification_factor("backward_euler", z).real == pytest.approx(1 / 99, rel=0.01)


#: Section 5's table: the fewest steps (and f-evaluations) for an error below each target.
FEWEST = {
    1e-4: {"forward_euler": (3147, 3147), "midpoint": (3157, 6314), "rk4": (2266, 9064),
           "backward_euler": (32, 64), "trapezoidal": (121, 363)},
    1e-5: {"forward_euler": (3148, 3148), "midpoint": (3292, 6584), "rk4": (2343, 9372),
           "backward_euler": (315, 630), "trapezoidal": (135, 405)},
}


@pytest.fixture(scope="module")
def fewest(stiff):
    """The notebook's bisection: between the grid run that meets a target and the one before."""
    lesson, rows = stiff
    out = {}
    for target in FEWEST:
        for m in FEWEST[target]:
            hi = lesson.cheapest(rows, m, target).steps
            out[m, target] = lesson.fewest_steps(m, target, hi // 2, hi)
    return out


@pytest.mark.roundoff
def test_stiff_grid_brackets(stiff):
    """On the power-of-two grid every explicit run below 4096 steps blows up (the next point
    down, 2048, has κ dt = 3.07, past every explicit limit); the cheapest grid runs are the
    brackets the bisection starts from."""
    lesson, rows = stiff
    for m in ("forward_euler", "midpoint", "rk4"):
        for r in rows:
            if r.method == m:
                assert np.isfinite(r.error) == (r.steps >= 4096), (m, r)
    assert 1000 * 2 * math.pi / 2048 > 2.786
    grid = {"forward_euler": 4096, "midpoint": 4096, "rk4": 4096, "backward_euler": 32,
            "trapezoidal": 128}
    for m, steps in grid.items():
        assert lesson.cheapest(rows, m, 1e-4).steps == steps


@pytest.mark.roundoff
def test_fewest_steps_quoted(fewest):
    """The table's counts are true minima: n meets the target and n - 1 misses it, each by a
    margin (at least 0.04 % of the target) that no rounding of these runs can close: their
    round-off is about 1e-13 m, 1e-8 of the smallest target."""
    for target, table in FEWEST.items():
        for m, (steps, nfev) in table.items():
            best, before = fewest[m, target]
            assert (best.steps, best.nfev) == (steps, nfev), (m, target, best)
            assert before.steps == steps - 1
            assert best.error <= target * (1 - 4e-4) and before.error >= target * (1 + 4e-4), (
                m, target, best.error, before.error)


def test_fewest_steps_is_not_fooled_by_a_local_wiggle(fewest, stiff):
    """Bisection assumes the error crosses the target once: check the neighbourhood of every
    answer (three counts either side; the runs the bisection made come from cost_study's
    cache) and the bracket ends."""
    lesson, _ = stiff
    for (m, target), (best, _) in fewest.items():
        n = best.steps
        rows = lesson.cost_study([m], range(n - 3, n + 4))
        assert all(r.error > target for r in rows[:3]) and all(r.error <= target for r in rows[3:]), m
    with pytest.raises(ValueError, match="need error"):
        lesson.fewest_steps("backward_euler", 1e-4, 64, 128)      # both ends meet the target


def test_cost_study_cache_returns_what_a_fresh_run_gives(stiff):
    """cost_study keeps its rows: a second call returns the same row without running again,
    and that row is what integrate gives (the follower's f matches -κ (X - P(t)) bit for bit)."""
    lesson, rows = stiff
    first = rows[0]
    assert lesson.cost_study([first.method], [first.steps])[0] is first
    f, jac, exact = lesson.follower()
    for m, n in (("rk4", 4096), ("trapezoidal", 128)):
        kw = {"jac": jac} if m == "trapezoidal" else {}
        run = cl.integrate(f, [0.0, 0.0], (0.0, 2 * np.pi), 2 * np.pi / n, m, blowup_bound=1e3,
                           **kw)
        row = next(r for r in rows if (r.method, r.steps) == (m, n))
        error = float(np.linalg.norm(run.y[-1] - exact(2 * np.pi, [0.0, 0.0])))
        assert (row.nfev, row.error) == (run.nfev, error)
    rng = np.random.default_rng(4)
    for t, X in zip(rng.uniform(0.0, 7.0, 200), rng.normal(size=(200, 2)), strict=True):
        want = -lesson.KAPPA * (X - np.array([np.cos(t), np.sin(t)]))
        np.testing.assert_array_equal(f(t, X), want)
    with pytest.raises(ValueError):
        lesson.cost_study(["rk4"], [16], X0=("a", 0.0))


def test_explicit_counts_sit_just_above_the_stability_limits():
    n_fe = math.pi * 1000                                       # κ dt < 2
    n_rk4 = 2 * math.pi * 1000 / cl.max_stable_dt("rk4", -1.0)   # κ dt < 2.785
    assert f"{n_fe:.1f}" == "3141.6" and f"{n_rk4:.1f}" == "2255.8"
    assert round(n_fe) == 3142 and round(n_rk4) == 2256
    for m, limit in (("forward_euler", n_fe), ("midpoint", n_fe), ("rk4", n_rk4)):
        for target in FEWEST:
            steps = FEWEST[target][m][0]
            assert limit < steps < 1.05 * limit, (m, target)


def test_quoted_savings():
    """"49 times fewer ... 142 times fewer"; at 1e-5 "5 times ... (15 against RK4)"."""
    a, b = FEWEST[1e-4], FEWEST[1e-5]
    assert round(a["forward_euler"][1] / a["backward_euler"][1]) == 49
    assert round(a["rk4"][1] / a["backward_euler"][1]) == 142
    assert round(b["forward_euler"][1] / b["backward_euler"][1]) == 5
    assert round(b["rk4"][1] / b["backward_euler"][1]) == 15
    assert b["forward_euler"][0] == a["forward_euler"][0] + 1          # "one step more"


def test_backward_euler_error_falls_like_one_over_n(fewest):
    """"its error falls like 1/n": n × error is the same at both counts within 1 %."""
    a, b = fewest["backward_euler", 1e-4][0], fewest["backward_euler", 1e-5][0]
    assert a.steps * a.error == pytest.approx(b.steps * b.error, rel=0.01)


def test_trapezoid_error_is_the_leftover_gap(fewest):
    """"Its error here is the catch-up gap that its zig-zag has not yet removed,
    |R(-κ dt)|^n": the measured error at each quoted count, within 2 %."""
    from course_lib.lessons import nb04_beyond_euler as lesson

    gap = abs(lesson.KAPPA / (lesson.KAPPA + 1j))              # |X0 - κ/(κ + i)|, X0 = 0
    for target in FEWEST:
        row = fewest["trapezoidal", target][0]
        R = cl.amplification_factor("trapezoidal", -lesson.KAPPA * 2 * math.pi / row.steps).real
        assert row.error == pytest.approx(abs(R) ** row.steps * gap, rel=0.02)


def test_trapezoid_flips_the_catch_up_gap(stiff):
    lesson, _ = stiff
    f, jac, exact = lesson.follower()
    run = cl.integrate(f, [0.0, 0.0], (0.0, 2 * np.pi), 2 * np.pi / 64, "trapezoidal", jac=jac)
    gap = run.y[:8, 0] - exact(run.t[:8], [0.0, 0.0])[:, 0]
    assert np.all(np.sign(gap[1:-1]) != np.sign(gap[2:]))      # flips every step
    assert abs(gap[6]) > 0.7                                      # and hardly decays
    be = cl.integrate(f, [0.0, 0.0], (0.0, 2 * np.pi), 2 * np.pi / 64, "backward_euler", jac=jac)
    assert abs(be.y[1, 0] - exact(be.t[1], [0.0, 0.0])[0]) < 0.02  # gone after one step


# --- Exercise 3: the implicit midpoint rule ----------------------------------------------------


def _imr_newton(f, t, y, dt):
    y = np.asarray(y, dtype=float)

    def residual(Y):
        return Y - y - dt * f(t + 0.5 * dt, 0.5 * (y + Y))

    Y = y + dt * f(t, y)
    for _ in range(30):
        r = residual(Y)
        if np.max(np.abs(r)) < 1e-14:
            break
        jac = np.empty((y.size, y.size))
        for j in range(y.size):
            e = np.zeros(y.size)
            e[j] = 1e-7
            jac[:, j] = (residual(Y + e.reshape(y.shape)) - r).ravel() / 1e-7
        Y = Y - np.linalg.solve(jac, r.ravel()).reshape(y.shape)
    return Y


def _trapezoid_newton(f, t, y, dt):
    y = np.asarray(y, dtype=float)
    f0 = f(t, y)
    return _newton(lambda Y: Y - y - 0.5 * dt * (f0 + f(t + dt, Y)), y + dt * f0)


def _newton(residual, Y):
    for _ in range(30):
        r = residual(Y)
        if np.max(np.abs(r)) < 1e-14:
            break
        jac = np.empty((Y.size, Y.size))
        for j in range(Y.size):
            e = np.zeros(Y.size)
            e[j] = 1e-7
            jac[:, j] = (residual(Y + e.reshape(Y.shape)) - r).ravel() / 1e-7
        Y = Y - np.linalg.solve(jac, r.ravel()).reshape(Y.shape)
    return Y


def _imr_fixed_point(f, t, y, dt, iterations=200):
    Y = np.array(y, dtype=float)
    with np.errstate(all="ignore"):
        for _ in range(iterations):
            Y = y + dt * f(t + 0.5 * dt, 0.5 * (y + Y))
    return Y


def _imr_half_step(f, t, y, dt):
    """The substitution of the notebook's aftermath, Z = (y + Y)/2 solved by Newton as one
    backward Euler half step, written out (no library call): also right."""
    y = np.asarray(y, dtype=float)

    def residual(Z):
        return Z - y - 0.5 * dt * f(t + 0.5 * dt, Z)

    Z = y.copy()
    for _ in range(30):
        r = residual(Z)
        if np.max(np.abs(r)) < 1e-15:
            break
        jac = np.empty((y.size, y.size))
        for j in range(y.size):
            e = np.zeros(y.size)
            e[j] = 1e-7
            jac[:, j] = (residual(Z + e.reshape(y.shape)) - r).ravel() / 1e-7
        Z = Z - np.linalg.solve(jac, r.ravel()).reshape(y.shape)
    return 2 * Z - y


def test_implicit_midpoint_accepts_right_answers(capsys):
    for answer in (_imr_newton, _imr_half_step,
                   lambda f, t, y, dt: _imr_newton(f, t, y, dt).astype(np.float32)):
        status, out = verdict(check.implicit_midpoint_step, answer, capsys,
                              "implicit_midpoint_step")
        assert status == "correct", out
    assert "(and |Y| = |y|)" in out


def test_implicit_midpoint_refuses_the_library_identity(capsys):
    """Issue 23: ``2 * cl.backward_euler(f, t, y, dt/2) - y`` passed; it calls the library."""
    status, out = verdict(check.implicit_midpoint_step,
                          lambda f, t, y, dt: 2 * cl.backward_euler(f, t, y, dt / 2) - y,
                          capsys, "implicit_midpoint_step")
    assert status == "incorrect" and "uses the reference" in out


def test_implicit_midpoint_keeps_the_swirls_radius_and_solves_its_equation():
    for what, f, t, y, dt, keeps in check.MIDPOINT_RULE_CASES:
        y = np.asarray(y, dtype=float)
        Y = check.implicit_midpoint_reference(f, t, y, dt)
        res = Y - y - dt * f(t + 0.5 * dt, 0.5 * (y + Y))
        assert np.max(np.abs(res)) < 1e-12, what
        if keeps:
            assert np.linalg.norm(Y) == pytest.approx(np.linalg.norm(y), rel=1e-12), what
    # on the swirl the trapezoid does not keep it (Section 3's claim)
    y = np.array([1.0, 0.5])
    assert abs(np.linalg.norm(cl.trapezoidal(check.swirl, 0.0, y, 0.4)) - np.linalg.norm(y)) > 1e-4
    # stiff decay: R = (1 + z/2)/(1 - z/2) at z = -25, and fixed point diverges (12.5 > 1)
    Y = check.implicit_midpoint_reference(lambda t, u: -50.0 * u, 0.0, np.array([1.0]), 0.5)
    assert Y[0] == pytest.approx(-11.5 / 13.5, rel=1e-12)
    assert np.abs(_imr_fixed_point(lambda t, u: -50.0 * u, 0.0, np.array([1.0]), 0.5)[0]) > 1e100


@pytest.mark.parametrize("wrong, hint", [
    (_imr_fixed_point, "diverged"),
    (lambda f, t, y, dt: _trapezoid_newton(f, t, y, dt), "that is the trapezoid"),
    (lambda f, t, y, dt: cl.trapezoidal(f, t, y, dt), "uses the reference"),
    (lambda f, t, y, dt: _imr_newton(lambda s, u: f(s - t, u), t, y, dt), "pass the step's time"),
    (lambda f, t, y, dt: y + dt * f(t + 0.5 * dt, y + 0.5 * dt * f(t, y)), "EXPLICIT midpoint"),
    (lambda f, t, y, dt: _imr_newton(lambda s, u: f(t, u), t, y, dt), "time t + dt/2"),
    (lambda f, t, y, dt: _imr_fixed_point(f, t, y, dt, iterations=2), "residual"),
])
def test_implicit_midpoint_rejects_wrong_answers(wrong, hint, capsys):
    status, out = verdict(check.implicit_midpoint_step, wrong, capsys, "implicit_midpoint_step")
    assert status == "incorrect"
    assert hint in out


def _one_newton_iteration(f, t, y, dt):
    """One Newton step with a finite-difference Jacobian: close, but not at round-off."""
    y = np.asarray(y, dtype=float)

    def residual(Y):
        return Y - y - dt * f(t + 0.5 * dt, 0.5 * (y + Y))

    Y = y + dt * f(t, y)
    r = residual(Y)
    jac = np.empty((y.size, y.size))
    for j in range(y.size):
        e = np.zeros(y.size)
        e[j] = 1e-7
        jac[:, j] = (residual(Y + e.reshape(y.shape)) - r).ravel() / 1e-7
    return Y - np.linalg.solve(jac, r.ravel()).reshape(y.shape)


def test_implicit_midpoint_reports_the_residual_even_where_the_values_print_alike():
    """Review: one Newton iteration on the stiff decay printed "expected [-0.851852], got
    [-0.851852]". Every case that misses now reports its residual, against round-off."""
    result = evaluate(check.implicit_midpoint_step, _one_newton_iteration)
    assert result["status"] == "incorrect"
    failed = "\n".join(result["failed_cases"])
    stiff = next(c for c in result["failed_cases"] if c.startswith("a stiff decay"))
    assert "residual of" in stiff and "expected [" not in stiff
    assert "iterate until the residual is at round-off" in failed


def test_alike_values_say_how_far_apart_they_are():
    from course_lib.check import Checker
    from course_lib.check._answers import close

    ck = Checker("x")
    close(ck, [-0.8518518], [-0.85185185185], "a case", rtol=1e-9)
    assert "alike to the printed digits, but 6.1e-08 apart" in ck.failed[0]   # 5.2e-8 / 0.85
    assert "the check allows 1e-09" in ck.failed[0]



def test_midpoint_step_accepts_float32(capsys):
    status, out = verdict(check.midpoint_step, lambda f, t, y, dt: _midpoint(f, t, y, dt).astype(
        np.float32), capsys, "midpoint_step")
    assert status == "correct", out


# --- planted answers: one delegating call, one shortcut the data breaks, one misconception --


def planted(source: str, name: str):
    """A function defined as a notebook cell defines it (module ``__main__``), so that the
    checks read its bytecode and watch its calls exactly as in a student's kernel."""
    namespace = {"__name__": "__main__", "np": np, "cl": cl}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


_NEWTON = ("def implicit_midpoint_step(f, t, y, dt):\n    y = np.asarray(y, dtype=float)\n"
           "    def residual(Y):\n        return Y - y - dt * f({time}, 0.5 * (y + Y))\n"
           "    Y = y + dt * f(t, y)\n    for _ in range(20):\n        r = residual(Y)\n"
           "        jac = np.empty((y.size, y.size))\n        for j in range(y.size):\n"
           "            e = np.zeros(y.size)\n            e[j] = 1e-7\n"
           "            jac[:, j] = (residual(Y + e.reshape(y.shape)) - r).ravel() / 1e-7\n"
           "        Y = Y - np.linalg.solve(jac, r.ravel()).reshape(y.shape)\n    return Y")

#: (exercise, kind, source, verdict, what the first failure's hint (or message) must say)
PLANTED = [
    ("midpoint_step", "delegating",
     "def midpoint_step(f, t, y, dt):\n    return cl.step('midpoint', f, t, y, dt)",
     "incorrect", "uses the reference: your function calls course_lib.steppers.step"),
    ("midpoint_step", "shortcut: t frozen at 0 (the pulsing vortex breaks it)",
     "def midpoint_step(f, t, y, dt):\n"
     "    return y + dt * f(0.5 * dt, y + 0.5 * dt * f(0.0, y))",
     "incorrect", "pass the step's time to f"),
    ("midpoint_step", "misconception: Heun's average of two slopes",
     "def midpoint_step(f, t, y, dt):\n    k1 = f(t, y)\n"
     "    return y + 0.5 * dt * (k1 + f(t + dt, y + dt * k1))",
     "incorrect", "that is Heun's method"),
    ("backward_euler_linear", "delegating: the library's implicit solver",
     "def backward_euler_linear(A, x0, dt, n):\n"
     "    run = cl.integrate(lambda t, x: A @ x, x0, (0.0, max(n, 1) * dt), dt,\n"
     "                       method='backward_euler')\n    return run.y[: n + 1]",
     "incorrect", "uses the reference: your function calls course_lib.integrators.integrate"),
    ("backward_euler_linear", "delegating: SciPy's root finder (one solve needs no Newton)",
     "from scipy.optimize import fsolve\n"
     "def backward_euler_linear(A, x0, dt, n):\n    xs = [np.asarray(x0, float)]\n"
     "    for _ in range(n):\n"
     "        xs.append(fsolve(lambda u: u - xs[-1] - dt * A @ u, xs[-1]))\n"
     "    return np.array(xs)",
     "incorrect", "uses the reference: your function calls scipy.optimize"),
    ("backward_euler_linear", "shortcut: a division per component (the coupled cases break it)",
     "def backward_euler_linear(A, x0, dt, n):\n"
     "    factor = 1 / (1 - dt * np.diag(A))\n"
     "    return np.asarray(x0, float) * factor ** np.arange(n + 1)[:, None]",
     "incorrect", "only when A is diagonal"),
    ("backward_euler_linear", "misconception: multiply by (I - dt A) instead of solving",
     "def backward_euler_linear(A, x0, dt, n):\n    xs = [np.asarray(x0, float)]\n"
     "    for _ in range(n):\n        xs.append((np.eye(len(x0)) - dt * A) @ xs[-1])\n"
     "    return np.array(xs)",
     "incorrect", "SOLVE that system"),
    ("implicit_midpoint_step", "delegating: half a backward Euler step, then extrapolate",
     "def implicit_midpoint_step(f, t, y, dt):\n"
     "    return 2 * cl.backward_euler(f, t, y, dt / 2) - y",
     "incorrect", "uses the reference: your function calls course_lib.steppers.backward_euler"),
    ("implicit_midpoint_step", "delegating: SciPy's solver (Newton is the exercise)",
     "from scipy.optimize import fsolve\n"
     "def implicit_midpoint_step(f, t, y, dt):\n    y = np.asarray(y, dtype=float)\n"
     "    g = lambda Y: (Y.reshape(y.shape) - y - dt * f(t + dt / 2, (y + Y.reshape(y.shape)) / 2)).ravel()\n"
     "    return fsolve(g, y.ravel(), xtol=1e-14).reshape(y.shape)",
     "incorrect", "uses the reference: your function calls scipy.optimize"),
    ("implicit_midpoint_step", "shortcut: fixed-point iteration (the stiff decay breaks it)",
     "def implicit_midpoint_step(f, t, y, dt):\n    y = np.asarray(y, dtype=float)\n"
     "    Y = y.copy()\n    with np.errstate(all='ignore'):\n        for _ in range(60):\n"
     "            Y = y + dt * f(t + dt / 2, (y + Y) / 2)\n    return Y",
     "incorrect", "your iteration diverged"),
    ("implicit_midpoint_step", "misconception: the explicit midpoint",
     "def implicit_midpoint_step(f, t, y, dt):\n"
     "    return y + dt * f(t + dt / 2, y + dt / 2 * f(t, y))",
     "incorrect", "that is the EXPLICIT midpoint"),
    ("implicit_midpoint_step", "misconception: forward Euler (on the stiff decay it lands far out)",
     "def implicit_midpoint_step(f, t, y, dt):\n    return y + dt * f(t, y)",
     "incorrect", "that is forward Euler, y + dt f(t, y)"),
    ("implicit_midpoint_step", "shortcut: Newton written for a state of one axis (the five "
     "particles break it)",
     _NEWTON.format(time="t + 0.5 * dt").replace("e = np.zeros(y.size)", "e = np.zeros(len(y))")
     .replace("e.reshape(y.shape)", "e").replace("np.empty((y.size, y.size))",
                                                "np.empty((len(y), len(y)))")
     .replace("r.ravel()).reshape(y.shape)", "r)").replace(" - r).ravel() / 1e-7", " - r) / 1e-7"),
     "incorrect", "y may have any shape, here (5, 2): do the Newton solve on the flattened state"),
    ("implicit_midpoint_step", "misconception: t frozen at 0",
     _NEWTON.format(time="0.5 * dt"), "incorrect", "pass the step's time to f"),
    ("implicit_midpoint_step", "Newton written out", _NEWTON.format(time="t + 0.5 * dt"),
     "correct", ""),
]


@pytest.mark.parametrize(("exercise", "kind", "source", "status", "says"), PLANTED,
                         ids=[f"{p[0]}: {p[1]}" for p in PLANTED])
def test_planted_answers(exercise, kind, source, status, says):
    result = evaluate(getattr(check, exercise), planted(source, exercise))
    assert result["status"] == status, (kind, result["failed_cases"])
    assert says in "\n".join(result["failed_cases"]), (kind, result["failed_cases"])


def test_every_exercise_has_its_three_plants():
    kinds = {}
    for exercise, kind, *_ in PLANTED:
        kinds.setdefault(exercise, set()).add(kind.split(":")[0])
    assert set(kinds) == {k.split(".")[1] for k in REGISTRY if k.startswith("nb04.")}
    for exercise, found in kinds.items():
        assert {"delegating", "shortcut", "misconception"} <= found, exercise


# --- the follower explorer (Section 5): κ dt against the first steps and R(-κ dt) ---------


def test_follower_experiment_against_the_theory():
    from course_lib.lessons import nb04_beyond_euler as lesson

    f, jac, exact = lesson.follower()
    for kappa_dt in (0.1, 1.5, 2.1, 2.9, 100.0):
        r = lesson.follower_experiment(kappa_dt)
        assert r.dt == pytest.approx(kappa_dt / 1000.0, rel=1e-15)
        np.testing.assert_allclose(r.x_exact[[0, -1]], exact(np.array([0.0, 40 * r.dt]),
                                                              [0.0, 0.0])[:, 0], rtol=1e-12)
        for m in lesson.FOLLOWER_METHODS:
            assert r.R[m] == pytest.approx(cl.amplification_factor(m, -kappa_dt).real, rel=1e-14)
            assert r.stable[m] == (abs(r.R[m]) <= 1)
            kw = {"jac": jac} if m in ("backward_euler", "trapezoidal") else {}
            run = cl.integrate(f, [0.0, 0.0], (0.0, 40 * r.dt), r.dt, m, blowup_bound=1e3, **kw)
            np.testing.assert_array_equal(r.x[m][: len(run.t)], run.y[:, 0])
            assert np.all(np.isnan(r.x[m][len(run.t):]))
    # the limits the prose names: forward Euler overshoots past 1, forward Euler and
    # midpoint blow up past 2 (midpoint without flipping sign), RK4 past 2.785
    assert lesson.follower_experiment(0.9).R["forward_euler"] > 0
    assert lesson.follower_experiment(1.1).R["forward_euler"] < 0
    r = lesson.follower_experiment(2.1)
    assert not r.stable["forward_euler"] and not r.stable["midpoint"] and r.stable["rk4"]
    assert r.R["forward_euler"] < -1 and r.R["midpoint"] > 1
    assert not lesson.follower_experiment(2.8).stable["rk4"]
    assert lesson.follower_experiment(2.78).stable["rk4"]
    r = lesson.follower_experiment(100.0)                     # "R ≈ -0.96" for the trapezoid
    assert round(r.R["trapezoidal"], 2) == -0.96 and r.R["backward_euler"] == pytest.approx(1 / 101)
    # backward Euler "follows the target from the first step"
    assert np.max(np.abs(r.x["backward_euler"][1:] - exact(r.n[1:] * r.dt, [0.0, 0.0])[:, 0])) < 0.02
    with pytest.raises(ValueError, match="kappa_dt must lie in"):
        lesson.follower_experiment(500.0)


@pytest.fixture(scope="module")
def follower_view_module():
    import matplotlib

    matplotlib.use("Agg")
    from course_lib.lessons import nb04_follower_view

    return nb04_follower_view


def test_follower_explorer_answers_a_slider(follower_view_module):
    view = follower_view_module.follower_explorer(kappa_dt=1.5)
    first = view.image.value
    assert first[:8] == b"\x89PNG\r\n\x1a\n" and view.result.kappa_dt == 1.5
    view.controls["kappa_dt"].value = 2.9
    assert view.result.kappa_dt == pytest.approx(2.9) and view.image.value != first
    assert not view.result.stable["rk4"] and view.result.stable["backward_euler"]
    assert "Follower explorer (interactive)" in view._repr_mimebundle_()["text/plain"]


def test_follower_plot_blit_draws_what_a_full_redraw_draws(follower_view_module):
    from io import BytesIO

    from PIL import Image

    from course_lib.lessons.nb04_beyond_euler import follower_experiment

    fast = follower_view_module.FollowerPlot(blit=True)
    fast(follower_experiment(50.0))
    fast.png()
    fast(follower_experiment(1.9))
    full = follower_view_module.FollowerPlot(blit=False)
    full(follower_experiment(1.9))
    a, b = (np.asarray(Image.open(BytesIO(p.png())).convert("L"), dtype=float)
            for p in (fast, full))
    assert a.shape == b.shape and np.mean(np.abs(a - b) > 40) < 0.002


def test_follower_player(follower_view_module):
    from course_lib.lessons.nb04_beyond_euler import follower_experiment

    player = follower_view_module.follower_player(kappa_dts=(1.9, 2.1))
    assert player.labels == ["κ dt = 1.9", "κ dt = 2.1"]
    assert player.captions == [follower_experiment(k).verdict for k in (1.9, 2.1)]
    assert "all five stable" not in player.captions[1] and "forward Euler" in player.captions[1]
    dts = follower_view_module.FOLLOWER_KAPPA_DTS
    assert len(dts) == 9 and min(dts) == 0.2 and max(dts) == 100.0    # "nine values"
    assert player.nbytes < 300_000
    width, height = follower_view_module.FollowerPlot().fig.canvas.get_width_height()
    assert f'width="{width}" height="{height}"' in player.html       # blitted frames, full size


def test_follower_player_over_its_budget_is_drawn_smaller(follower_view_module, monkeypatch):
    """The blitted player has no resolution knob: over the size budget it hands the same
    values to parameter_player, which redraws the frames at a lower dpi until they fit
    (tested with the players)."""
    calls = []

    def fake_parameter_player(compute, draw, param, values, **kwargs):
        calls.append((param, list(values), kwargs["max_bytes"]))
        return "smaller player"

    monkeypatch.setattr(follower_view_module, "MAX_BYTES", 1_000)
    monkeypatch.setattr(follower_view_module, "parameter_player", fake_parameter_player)
    assert follower_view_module.follower_player(kappa_dts=(2.1,)) == "smaller player"
    assert calls == [("kappa_dt", [2.1], 1_000)]


def test_todays_default_is_an_embedded_pair():
    """Section 4: the default of solve_ivp is Dormand & Prince's fifth-order pair (with a
    fourth-order error estimate), and DOP853 its eighth-order sibling."""
    import inspect

    from scipy.integrate import DOP853, RK45, solve_ivp

    assert inspect.signature(solve_ivp).parameters["method"].default == "RK45"
    assert RK45.order == 5 and RK45.error_estimator_order == 4
    assert DOP853.order == 8


def test_the_follower_explorer_takes_its_sliders_ends():
    from course_lib.lessons import nb04_beyond_euler as lesson

    # a FloatLogSlider at an end holds 10**log10(end), one rounding below or above it
    lo, hi = lesson.KAPPA_DT_RANGE
    for end in (10 ** np.log10(lo), 10 ** np.log10(hi)):
        assert lesson.follower_experiment(end) is not None
    with pytest.raises(ValueError, match="kappa_dt"):
        lesson.follower_experiment(lo / 2)


def test_an_explicit_step_is_not_told_its_iteration_diverged():
    """On the stiff decay the explicit midpoint lands at 288.5 and forward Euler at -24, far
    outside |y| = 1: the check used to call that a diverged iteration. An explicit step is
    named as such on every case, the stiff one included; an answer that evaluates f once or
    twice and matches no known method is told it ran no iteration; a fixed-point iteration
    that blows up is still told it diverged."""
    for source, says in (
            ("def implicit_midpoint_step(f, t, y, dt):\n"
             "    return y + dt * f(t + dt / 2, y + dt / 2 * f(t, y))", "that is the EXPLICIT midpoint"),
            ("def implicit_midpoint_step(f, t, y, dt):\n    return y + dt * f(t, y)",
             "that is forward Euler"),
            ("def implicit_midpoint_step(f, t, y, dt):\n    k1 = f(t, y)\n"
             "    return y + dt / 2 * (k1 + f(t + dt, y + dt * k1))", "that is Heun's explicit method"),
            ("def implicit_midpoint_step(f, t, y, dt):\n    return y + 2 * dt * f(t + dt, y)",
             "your step evaluated f only 1 time(s)")):
        failed = evaluate(check.implicit_midpoint_step,
                          planted(source, "implicit_midpoint_step"))["failed_cases"]
        stiff = next(c for c in failed if c.startswith("a stiff decay"))
        assert says in stiff and "diverged" not in stiff, (source, stiff)
    fixed_point = evaluate(check.implicit_midpoint_step, _imr_fixed_point)["failed_cases"]
    assert "diverged" in next(c for c in fixed_point if c.startswith("a stiff decay"))


def test_a_one_axis_answer_is_told_about_shapes():
    """Newton written for y of shape (d,) fails on five particles, y of shape (5, 2): the hint
    says to flatten the state, whether the answer raises or returns the wrong shape."""
    def flat_only(f, t, y, dt):
        return _imr_newton(lambda s, u: f(s, u.reshape(-1, 2)).ravel(), t, np.ravel(y), dt)

    for answer in (flat_only, planted(PLANTED[-3][2], "implicit_midpoint_step")):
        failed = evaluate(check.implicit_midpoint_step, answer)["failed_cases"]
        particles = [c for c in failed if c.startswith("5 particles")]
        assert len(particles) == 1 and "do the Newton solve on the flattened state" in particles[0]


def test_trapezoid_and_implicit_midpoint_coincide_only_with_constant_coefficients():
    """Section 3: "On linear fields with constant coefficients ... the trapezoid coincides
    with the implicit midpoint rule"; on the pulsing vortex (linear, changing in time) and
    on the swirl (nonlinear) the two differ, and the trapezoid loses |X| while the implicit
    midpoint keeps it."""
    y = np.array([0.8, -0.6])
    A = np.array([[-0.3, -2.0], [1.5, -0.1]])                  # constant, not a rotation
    for f in (cl.fields.vortex, lambda t, X: A @ X):
        for t, dt in ((0.0, 0.5), (0.7, 1.3)):
            np.testing.assert_allclose(cl.trapezoidal(f, t, y, dt),
                                       _imr_newton(f, t, y, dt), rtol=1e-12, atol=1e-14)
    for f in (check.pulsing_vortex, check.swirl):
        trap, imr = cl.trapezoidal(f, 0.7, y, 0.4), _imr_newton(f, 0.7, y, 0.4)
        assert np.max(np.abs(trap - imr)) > 1e-4
        assert abs(np.linalg.norm(trap) - 1.0) > 1e-5
        assert np.linalg.norm(imr) == pytest.approx(1.0, rel=1e-12)


def test_prose_after_the_second_read():
    """The attribution of the tableau, the scope of the trapezoid sentence and of C, and the
    stiff figure's runs that blew up drawn in a strip of their own, not at invented errors."""
    import pathlib

    import nbformat

    nb = nbformat.read(pathlib.Path(__file__).resolve().parents[1] / "solutions"
                       / "04_beyond_euler.ipynb", as_version=4)
    text = " ".join(" ".join(c.source.split()) for c in nb.cells if c.cell_type == "markdown")
    assert "Butcher (2016) arranges" not in text and "(Butcher 1963;" in text
    assert "On linear fields with constant coefficients, $V = AX$ with a fixed matrix $A$, the " \
           "trapezoid coincides with the implicit midpoint rule" in text
    assert "the two differ only on nonlinear problems" not in text
    assert "$C = -1/(p+1)!$ only for" not in text and "$+1/12$ for the trapezoid" in text
    code = next(c.source for c in nb.cells if c.cell_type == "code" and "stiff_rows" in c.source)
    assert "blew_up_at" not in code and "ax_b.plot" in code and "ylim=(1e-12, 10)" in code


def test_follower_legend_is_below_both_panels(follower_view_module):
    """The player's legend names the exact curve of the left panel: it sits below both panels
    (a figure legend), not inside the |R| panel, and the exact curve is drawn on top."""
    plot = follower_view_module.FollowerPlot()
    assert plot.ax_r.get_legend() is None and plot.ax_x.get_legend() is None
    (legend,) = plot.fig.legends
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels[0] == "exact x(t) (left panel)" and len(labels) == 6
    assert plot.exact.get_zorder() > max(line.get_zorder() for line in plot.lines.values())
    assert plot.dynamic.index(plot.exact) > max(plot.dynamic.index(line)
                                                for line in plot.lines.values())


# --- fifth blind read (2026-11-28): cells 8, 18 and 25 ---------------------------------------

def _nb04_markdown() -> str:
    import pathlib

    import nbformat

    nb = nbformat.read(pathlib.Path(__file__).resolve().parents[1] / "solutions"
                       / "04_beyond_euler.ipynb", as_version=4)
    return " ".join(" ".join(c.source.split()) for c in nb.cells if c.cell_type == "markdown")


@pytest.mark.parametrize("n", [50, 64, 100])
def test_trapezoid_radius_on_the_pulsing_vortex_wobbles_above_1_and_returns(n):
    """Cell 8: on the pulsing vortex the trapezoid does not lose |X|. Its step
    (I - a_{k+1} J) X_{k+1} = (I + a_k J) X_k with a_k = dt ω(t_k)/2 keeps |X_k| √(1 + a_k²),
    so with ω(0) = 1.5 its largest value the radius stays in [1, 1 + dt²/4] (√((1 + (3dt/4)²) /
    (1 + (dt/4)²)) ≤ 1 + dt²/4) over two periods, rises above 1 + dt²/8 in each, and is 1 again
    at t = 2π and 4π. The tolerance is Newton's: each step is solved to an update below 1e-13
    relative, so n steps leave at most ~n · 1e-13; we allow ten times that."""
    dt = 4 * np.pi / n
    run = cl.integrate(check.pulsing_vortex, [1.0, 0.0], (0.0, 4 * np.pi), dt, "trapezoidal")
    r, tol = np.linalg.norm(run.y, axis=1), 10 * n * 1e-13
    a = dt * (1.0 + 0.5 * np.cos(run.t)) / 2
    np.testing.assert_allclose(r * np.sqrt(1 + a**2), np.sqrt(1 + a[0] ** 2), rtol=tol, atol=0)
    assert r.min() >= 1 - tol and r.max() <= 1 + dt**2 / 4 + tol
    for half in (r[: n // 2 + 1], r[n // 2:]):
        assert half.max() > 1 + dt**2 / 8
    assert run.t[n // 2] == pytest.approx(2 * np.pi) and run.t[-1] == pytest.approx(4 * np.pi)
    assert abs(r[n // 2] - 1) <= tol and abs(r[-1] - 1) <= tol
    text = _nb04_markdown()
    assert "the trapezoid loses $|X|$" not in text
    assert ("no longer keeps $|X|$ step by step: on the pulsing vortex its radius wobbles above "
            "1 and comes back to 1 each period") in text
    assert "it keeps $|X_n|\\sqrt{1 + a_n^2}$ instead" in text


@pytest.mark.parametrize("how", ["solve", "inv", "lu"])
def test_exercise_2_text_and_check_agree_on_solve_inverse_and_factors(how, capsys):
    """Cell 25: the text offers a solve per step, factors reused, or an inverse computed once;
    the check accepts each, and still refuses a product with I - dt A (not a solve)."""
    import scipy.linalg

    def answer(A, x0, dt, n):
        A, x = np.asarray(A, dtype=float), np.asarray(x0, dtype=float)
        M = np.eye(len(x)) - dt * A
        if how == "inv":
            Mi = np.linalg.inv(M)
        elif how == "lu":
            lu = scipy.linalg.lu_factor(M)

        def step(x):
            if how == "solve":
                return np.linalg.solve(M, x)
            return Mi @ x if how == "inv" else scipy.linalg.lu_solve(lu, x)

        out = [x]
        for _ in range(n):
            out.append(step(out[-1]))
        return np.array(out)

    status, out = verdict(check.backward_euler_linear, answer, capsys, "backward_euler_linear")
    assert status == "correct", out
    text = _nb04_markdown()
    assert "(`np.linalg.solve`; the matrix is the same at every step)" not in text
    for name in ("`np.linalg.solve`", "`scipy.linalg.lu_factor`", "`lu_solve`", "`np.linalg.inv`",
                 "the check accepts each of the three"):
        assert name in text, name
