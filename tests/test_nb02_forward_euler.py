"""Every number quoted in notebook 02 (forward Euler), and its exercise checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import course_lib as cl
from course_lib.check import FAILURES, RESULTS, evaluate
from course_lib.check import nb02 as check

J = np.array([[0.0, -1.0], [1.0, 0.0]])


@pytest.fixture(autouse=True)
def _first_attempt():
    """Every test sees the first attempt's hint (the nudge): no failures carried over."""
    for key in [k for k in FAILURES if k.startswith("nb02.")]:
        del FAILURES[key]


def drift_root(tol: float, per_step: float = 0.5) -> float:
    """The largest step for a drift budget, solved here from the formula with brentq (the
    checks' own solver is library code, which the checks refuse as an answer)."""
    return brentq(lambda dt: per_step * (2 * math.pi / dt) * math.log1p(dt * dt)
                  - math.log1p(tol), 1e-12, 1.0, xtol=1e-16, rtol=1e-14)


def vortex_convergence():
    """Section 4 of the notebook: error at T = π for N = 16 ... 2048 steps."""
    T = np.pi
    dts, errors = [], []
    for n in 2 ** np.arange(4, 12):
        traj = cl.integrate(cl.fields.vortex, [1.0, 0.0], (0.0, T), T / n)
        exact = np.array([np.cos(traj.t[-1]), np.sin(traj.t[-1])])
        dts.append(traj.dt)
        errors.append(np.linalg.norm(traj.y[-1] - exact))
    return np.array(dts), np.array(errors)


# --- Section 1: constant velocity is exact -------------------------------------------------


@pytest.mark.parametrize("dt", [0.5, 0.05])
def test_constant_wind_is_exact_for_any_step(dt):
    traj = cl.integrate(cl.fields.constant_wind((-1.0, -1.0)), [1.0, 2.0], (0.0, 0.5), dt)
    np.testing.assert_allclose(traj.y[-1], [0.5, 1.5], rtol=0, atol=1e-14)


def test_gust_rectangles():
    traj = cl.integrate(lambda t, x: np.cos(t) * np.ones_like(x), [0.0], (0.0, 2.0), 0.5)
    left = 0.5 * np.cos(np.array([0.0, 0.5, 1.0, 1.5]))
    assert traj.y[-1, 0] == pytest.approx(left.sum(), rel=1e-14)
    assert traj.y[-1, 0] == pytest.approx(1.244311, abs=5e-7)
    assert np.sin(2.0) == pytest.approx(0.909297, abs=5e-7)


# --- Section 2: the worked example ---------------------------------------------------------


def test_worked_example_vortex():
    traj = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 1.5), 0.5)
    expected = [[0.0, 1.0], [-0.5, 1.0], [-1.0, 0.75], [-1.375, 0.25]]
    np.testing.assert_allclose(traj.y, expected, rtol=0, atol=1e-15)
    radii = np.linalg.norm(traj.y, axis=1)
    np.testing.assert_allclose(radii, 1.25 ** (np.arange(4) / 2), rtol=1e-14)
    np.testing.assert_allclose(radii, [1.0, 1.118034, 1.25, 1.397542], atol=5e-7)
    assert traj.nfev == 3  # one evaluation per step


# --- Section 3: the step matrix --------------------------------------------------------------


@pytest.mark.parametrize("dt", [0.5, 0.25, 0.1])
def test_radius_factor_every_step(dt):
    n = round(4 * np.pi / dt)  # about two revolutions, in whole steps
    traj = cl.integrate(cl.fields.vortex, [1.0, 0.0], (0.0, n * dt), dt)
    r = np.linalg.norm(traj.y, axis=1)
    np.testing.assert_allclose(r[1:] / r[:-1], math.sqrt(1 + dt * dt), rtol=1e-13)


def test_printed_radius_factors():
    for dt, printed in [(0.5, 1.118033989), (0.25, 1.030776406), (0.1, 1.004987562)]:
        assert math.sqrt(1 + dt * dt) == pytest.approx(printed, abs=5e-10)


@pytest.mark.parametrize("dt", [0.5, 0.1, 0.01])
def test_step_matrix_and_amplification_factor(dt):
    A = np.eye(2) + dt * J
    y = np.array([0.3, -1.7])
    np.testing.assert_allclose(cl.forward_euler(cl.fields.vortex, 0.0, y, dt), A @ y, rtol=1e-15)
    eig = np.sort_complex(np.linalg.eigvals(A))
    np.testing.assert_allclose(eig, [1 - 1j * dt, 1 + 1j * dt], rtol=1e-14)
    assert abs(cl.amplification_factor("forward_euler", 1j * dt)) == pytest.approx(
        math.sqrt(1 + dt * dt), rel=1e-15)
    # a rotation by arctan(dt) scaled by sqrt(1 + dt^2)
    c, s = np.cos(np.arctan(dt)), np.sin(np.arctan(dt))
    np.testing.assert_allclose(A, math.sqrt(1 + dt * dt) * np.array([[c, -s], [s, c]]),
                               rtol=1e-14)


def test_angle_per_step():
    X1 = cl.forward_euler(cl.fields.vortex, 0.0, [0.0, 1.0], 0.5)
    turned = math.atan2(X1[1], X1[0]) - math.pi / 2
    assert turned == pytest.approx(math.atan(0.5), rel=1e-14)
    assert math.atan(0.5) == pytest.approx(0.4636, abs=5e-5)


def test_drift_per_revolution_is_about_pi_dt():
    for dt in [1e-2, 1e-3]:
        growth = (1 + dt * dt) ** (math.pi / dt)
        assert growth == pytest.approx(math.exp(math.pi * dt), rel=dt**3 * 2)
        assert growth - 1 == pytest.approx(math.pi * dt, rel=2 * dt)
    # one revolution simulated with dt = 2π/N matches the formula
    n = 64
    traj = cl.integrate(cl.fields.vortex, [1.0, 0.0], (0.0, 2 * np.pi), 2 * np.pi / n)
    assert traj.n_steps == n
    assert np.linalg.norm(traj.y[-1]) == pytest.approx(
        (1 + (2 * np.pi / n) ** 2) ** (n / 2), rel=1e-12)


# --- Section 4: convergence ------------------------------------------------------------------


@pytest.mark.roundoff
def test_observed_order_is_one():
    dts, errors = vortex_convergence()
    order = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert order == pytest.approx(cl.ORDER["forward_euler"], abs=0.05)
    assert round(order, 3) == 1.025  # the value quoted in the prose
    halvings = np.log2(errors[:-1] / errors[1:])
    assert np.all(np.abs(halvings - 1) < 0.11)
    assert abs(halvings[-1] - 1) < 0.005
    assert errors[-1] == pytest.approx(2.4e-3, abs=0.05e-3)


@pytest.mark.roundoff
def test_convergence_errors_match_the_closed_form():
    # N steps of I + dt J from (1, 0) give (1 + i dt)^N in complex notation; the exact end
    # point is e^{i pi} = -1. So every plotted error has a closed form.
    dts, errors = vortex_convergence()
    n = np.round(np.pi / dts)
    theory = np.abs((1 + dts**2) ** (n / 2) * np.exp(1j * n * np.arctan(dts)) + 1)
    np.testing.assert_allclose(errors, theory, rtol=1e-9)
    # the halving orders printed by the notebook
    halvings = np.log2(theory[:-1] / theory[1:])
    np.testing.assert_array_equal(np.round(halvings, 3),
                                  [1.1, 1.053, 1.027, 1.014, 1.007, 1.003, 1.002])
    # the last error is mostly radius drift, e^{pi dt / 2} - 1 at T = pi
    assert errors[-1] == pytest.approx(math.expm1(math.pi * dts[-1] / 2), rel=2e-3)
    assert f"{errors[-1]:.1e}" == "2.4e-03"


# --- Exercise 3: the 1 % drift step ----------------------------------------------------------


def test_largest_one_percent_dt():
    def excess(dt):
        return (math.pi / dt) * math.log1p(dt * dt) - math.log(1.01)

    exact = brentq(excess, 1e-9, 1.0, xtol=1e-17, rtol=1e-15)
    assert exact == pytest.approx(0.0031673045681686, rel=1e-12)
    assert check.largest_drift_dt(0.01) == pytest.approx(exact, rel=1e-12)
    assert check.revolution_drift(exact) == pytest.approx(0.01, rel=1e-10)
    assert round(exact, 8) == 0.00316730
    assert round(2 * math.pi / exact) == 1984
    # it lies between the two linearised estimates quoted in the prose
    assert math.log(1.01) / math.pi < exact < 0.01 / math.pi
    assert round(math.log(1.01) / math.pi, 8) == 0.00316729
    assert round(0.01 / math.pi, 8) == 0.00318310
    assert check.revolution_drift(0.01 / math.pi) > 0.01
    assert check.largest_drift_dt(0.1) == pytest.approx(0.0303521, abs=5e-8)


# --- the exercise checks ---------------------------------------------------------------------


def verdict(run, answer, capsys, key):
    RESULTS.pop(f"nb02.{key}", None)
    run(answer)
    return RESULTS[f"nb02.{key}"]["status"], capsys.readouterr().out


def test_forward_euler_step_correct(capsys):
    status, out = verdict(check.forward_euler_step, lambda f, t, y, dt: y + dt * f(t, y),
                          capsys, "forward_euler_step")
    assert status == "correct", out
    assert RESULTS["nb02.forward_euler_step"]["total"] == 4


def _in_place(f, t, y, dt):
    y += dt * f(t, y)
    return y


@pytest.mark.parametrize("wrong, hint", [
    (lambda f, t, y, dt: y + dt * f(t + dt, y), "START of the step"),
    (lambda f, t, y, dt: y + dt * f(t + dt, y + dt * f(t, y)), "START of the step"),
    (lambda f, t, y, dt: y + f(t, y), "multiply the slope by dt"),
    (lambda f, t, y, dt: y - dt * f(t, y), "wrong sign"),
    (lambda f, t, y, dt: dt * f(t, y), "not only the change"),
    (_in_place, "in place"),
    (lambda f, t, y, dt: y + 0.5 * dt * f(t, y), "for the whole dt, not dt/2"),
    (lambda f, t, y, dt: y + 0.3 * dt * f(t, y), "follow the slope at the start of the step"),
    (lambda f, t, y, dt: y + dt * f(0.0, y), "pass the step's time t to f"),
])
def test_forward_euler_step_mistakes(wrong, hint, capsys):
    status, out = verdict(check.forward_euler_step, wrong, capsys, "forward_euler_step")
    assert status == "incorrect"
    assert hint in out


def _pending(*args):
    raise NotImplementedError()


@pytest.mark.parametrize("key", ["forward_euler_step", "radius_after", "drift_dt", "observed_order"])
def test_pending(key, capsys):
    status, out = verdict(getattr(check, key), _pending, capsys, key)
    assert status == "pending"
    assert "pending" in out


def _radius(r0, dt, n, k):
    return r0 * ((1 - k * dt) ** 2 + dt**2) ** (n / 2)


def test_radius_after_correct(capsys):
    status, out = verdict(check.radius_after, _radius, capsys, "radius_after")
    assert status == "correct", out
    # the step matrix's norm, applied as a power, is the same analysis
    status, out = verdict(check.radius_after, lambda r0, dt, n, k: r0 * np.linalg.norm(
        np.linalg.matrix_power(np.array([[1 - k * dt, -dt], [dt, 1 - k * dt]]), n) @ [1, 0]),
        capsys, "radius_after")
    assert status == "correct", out


def test_radius_after_is_what_forward_euler_does_on_the_whirlpool():
    """The formula against runs of cl.integrate (the check asserts it too), and notebook
    01's 3 %: the ratio to the exact e^(-kt) after 628 steps of 0.01 s with k = 0.25 /s."""
    for r0, dt, n, k in [(1.0, 0.5, 3, 0.0), (2.0, 0.1, 63, 0.25), (1.5, 0.5, 6, 3.0)]:
        field = cl.fields.compose(cl.fields.vortex, cl.fields.scaled(cl.fields.radial, -k))
        run = cl.integrate(field, [0.0, r0], (0.0, n * dt), dt)
        assert np.linalg.norm(run.y[-1]) == pytest.approx(_radius(r0, dt, n, k), rel=1e-12)
    assert _radius(1.0, 0.01, 628, 0.25) * math.exp(0.25 * 6.28) == pytest.approx(1.03, abs=1e-4)


@pytest.mark.parametrize("wrong, hint", [
    (lambda r0, dt, n, k: r0 * (1 + dt**2) ** (n / 2), "ignores the pull k"),
    (lambda r0, dt, n, k: r0 * (1 - k * dt) ** n * (1 + dt**2) ** (n / 2),
     "lengths add in squares"),
    (lambda r0, dt, n, k: r0 * math.exp(-k * n * dt), "exact whirlpool's radius"),
    (lambda r0, dt, n, k: r0 * ((1 - k * dt) ** 2 + dt**2) ** n, "by its square root"),
    (lambda r0, dt, n, k: r0 * (1 - 2 * k * dt + dt**2) ** (n / 2), "(k dt)² is missing"),
    (lambda r0, dt, n, k: r0 * ((1 + k * dt) ** 2 + dt**2) ** (n / 2), "not 1 + k dt"),
    (lambda r0, dt, n, k: r0 * abs(1 - k * dt + dt) ** n, "not 1 - k dt + dt"),
    (lambda r0, dt, n, k: r0 * math.sqrt(max(1 + n * ((1 - k * dt) ** 2 + dt**2 - 1), 0)),
     "compound it n times"),
    (lambda r0, dt, n, k: ((1 - k * dt) ** 2 + dt**2) ** (n / 2), "starting radius r0"),
    (lambda r0, dt, n, k: r0 * math.exp(n * dt), "what does one step do to |X|?"),
])
def test_radius_after_mistakes(wrong, hint, capsys):
    status, out = verdict(check.radius_after, wrong, capsys, "radius_after")
    assert status == "incorrect"
    assert hint in out, out


def test_radius_after_hints_are_nudges_first():
    """The fallback hint asks a question first; the fuller one (still no formula) follows a
    second failure. No hint ever prints the answer's formula."""
    wrong = lambda r0, dt, n, k: r0 * math.exp(n * dt)     # noqa: E731
    first = "\n".join(evaluate(check.radius_after, wrong)["failed_cases"])
    FAILURES["nb02.radius_after"] = 1
    second = "\n".join(evaluate(check.radius_after, wrong)["failed_cases"])
    for text in (first, second):
        assert "((1 - k dt)² + dt²)^(n/2)" not in text and "(n/2)" not in text
    assert "what does one step do" in first and "two perpendicular parts" in second


def test_alike_printed_values_say_how_far_apart_they_are():
    """Review: e^(n dt²/2) printed "expected 1.318977, got 1.318977" for a million steps."""
    result = evaluate(check.radius_after, lambda r0, dt, n, k: r0 * math.exp(
        n * (((1 - k * dt) ** 2 + dt**2) - 1) / 2))
    text = next(c for c in result["failed_cases"] if "n = 1000000" in c)
    assert "alike to the printed digits, but" in text and "the check allows 1e-10" in text


def test_drift_dt_correct(capsys):
    status, out = verdict(check.drift_dt, drift_root, capsys, "drift_dt")
    assert status == "correct", out
    assert "(a tolerance the check draws)" in out  # a tolerance the text never quotes
    # brentq with its default tolerances, and a float32 answer, are right too
    status, out = verdict(check.drift_dt, lambda tol: brentq(
        lambda dt: (math.pi / dt) * math.log1p(dt * dt) - math.log1p(tol), 1e-9, 1.0), capsys,
        "drift_dt")
    assert status == "correct", out
    status, out = verdict(check.drift_dt, lambda tol: np.float32(drift_root(tol)),
                          capsys, "drift_dt")
    assert status == "correct", out
    status, out = verdict(check.drift_dt, lambda tol: np.array([drift_root(tol)]),
                          capsys, "drift_dt")
    assert status == "correct", out


@pytest.mark.parametrize("wrong, hint", [
    (lambda tol: tol / math.pi, "tol/π comes from linearising"),
    (lambda tol: math.log1p(tol) / math.pi, "ln(1 + tol)/π"),
    (lambda tol: drift_root(tol, per_step=1.0), "you compounded the factor 1 + dt²"),
    (lambda tol: 0.5 * drift_root(tol), "LARGEST"),
    # the old check's factor-1.25 window accepted these without solving anything
    (lambda tol: tol / 3.5, "LARGEST"),
    (lambda tol: 0.85 * drift_root(tol), "LARGEST"),
    (lambda tol: 1.1 * drift_root(tol), "with a root finder"),
    (lambda tol: -1.0, "expected a step dt > 0"),
    (lambda tol: drift_root(tol / 100), "tol is a fraction"),
    (lambda tol: brentq(lambda dt: (math.pi / dt) * math.log1p(dt * dt) - math.log1p(tol),
                        1e-9, 1.0, xtol=1e-6), "brentq's xtol is an absolute tolerance"),
    (lambda tol: "small", "expected one number"),
    (lambda tol: [0.1, 0.2], "expected one number"),
])
def test_drift_dt_mistakes(wrong, hint, capsys):
    status, out = verdict(check.drift_dt, wrong, capsys, "drift_dt")
    assert status == "incorrect"
    assert hint in out


def test_drift_dt_hidden_tolerance():
    """The third tolerance comes from the answers to the first two: the same for the same
    answers (so the grader's replay gives the check the same arguments as the student's
    kernel), between 2 % and 8 %, not moved by a last-bit difference, and its expected step
    is never printed, even when the answer is wrong."""
    right = [drift_root(0.01), drift_root(0.1)]
    tol = check.hidden_tol(right)
    assert tol == check.hidden_tol([float(np.float64(a)) for a in right])
    assert tol == check.hidden_tol([a * (1 + 4e-16) for a in right])
    assert 0.02 <= tol <= 0.08 and tol != check.hidden_tol([0.0031673046, 0.030352145])
    assert len({check.hidden_tol([a, 0.03]) for a in np.linspace(0.001, 0.01, 50)}) > 40
    best = check.largest_drift_dt(tol)
    result = evaluate(check.drift_dt, lambda t: 0.999 * drift_root(t))
    hidden = next(c for c in result["failed_cases"] if "the check draws" in c)
    assert f"tol = {tol:g}" not in hidden                 # other answers draw another tol
    drawn = float(hidden.split("tol = ")[1].split(" ")[0])
    assert f"{check.largest_drift_dt(drawn):.8g}" not in hidden and "expected" not in hidden
    assert "within the budget of" in hidden and "but a larger step would be too" in hidden
    assert "that is of" not in hidden and "step that is\n" not in hidden
    assert f"{best:.8g}" not in "\n".join(result["failed_cases"])


def test_drift_dt_tolerance_follows_from_the_problem():
    # a root finder gives the step to ~1e-10; the linearised ln(1.01)/π is 5e-6 off
    best = check.largest_drift_dt(0.01)
    assert abs(math.log1p(0.01) / math.pi / best - 1) > 2 * check.DRIFT_RTOL
    assert abs(math.log1p(0.01) / math.pi / best - 1) == pytest.approx(5e-6, rel=0.1)


# --- the forward Euler step: float32, reference from pristine copies -----------------------


def test_forward_euler_step_accepts_float32(capsys):
    status, out = verdict(check.forward_euler_step,
                          lambda f, t, y, dt: (y + dt * f(t, y)).astype(np.float32), capsys,
                          "forward_euler_step")
    assert status == "correct", out


def test_radius_after_accepts_float32_and_one_element_arrays(capsys):
    for answer in (lambda r0, dt, n, k: np.float32(_radius(r0, dt, n, k)),
                   lambda r0, dt, n, k: np.array([_radius(r0, dt, n, k)])):
        status, out = verdict(check.radius_after, answer, capsys, "radius_after")
        assert status == "correct", out


# --- Section 4: the local error, Section 5: the three-grid order ---------------------------


def test_local_error_slope_2_and_dt2_over_2():
    dts, _ = vortex_convergence()
    local = np.array([np.linalg.norm(cl.integrate(cl.fields.vortex, [1.0, 0.0], (0.0, dt), dt).y[-1]
                                     - [np.cos(dt), np.sin(dt)]) for dt in dts])
    # exactly |(1, dt) - (cos dt, sin dt)| = dt²/2 (1 + O(dt²))
    np.testing.assert_allclose(local, np.hypot(1 - np.cos(dts), dts - np.sin(dts)), rtol=1e-9)
    assert round(np.polyfit(np.log(dts), np.log(local), 1)[0], 3) == 2.000
    assert f"{local[-1]:.3e}" == "1.177e-06" and f"{dts[-1] ** 2 / 2:.3e}" == "1.177e-06"


def _gyre_ends():
    from course_lib.lessons import nb02_forward_euler as lesson

    counts = 50 * 2 ** np.arange(8)
    ends = lesson.euler_endpoints(lesson.double_gyre, np.array([0.6, 0.3]), 10.0, counts)
    ref = cl.integrate(lesson.double_gyre, [0.6, 0.3], (0.0, 10.0), 10.0 / 20000, "rk4").y[-1]
    orders = [lesson.three_grid_order(*ends[j:j + 3]) for j in range(6)]
    return counts, ends, ref, orders


@pytest.mark.roundoff
def test_three_grid_table_quoted():
    _, ends, ref, orders = _gyre_ends()
    assert [round(p, 4) for p in orders] == [-0.6716, 0.714, 1.1102, 1.1212, 1.0743, 1.0401]
    assert all(abs(p - 1) <= 0.13 for p in orders[2:])          # "within 0.13 of 1"
    estimate = [np.linalg.norm(ends[j + 1] - ends[j + 2]) for j in range(6)]
    true = [np.linalg.norm(ends[j + 2] - ref) for j in range(6)]
    assert round(100 * (estimate[2] / true[2] - 1)) == 13
    assert round(100 * (estimate[5] / true[5] - 1)) == 2
    assert f"{ends[0][0]:.2f}" == "1.05" and f"{ref[0]:.2f}" == "0.33"   # across the border
    # the RK4 reference is converged far below the errors it checks: halving its step
    # changes it by 15/16 of the coarser run's error, so this bounds the reference's error
    ref_half = cl.integrate(__import__("course_lib.lessons.nb02_forward_euler", fromlist=["x"])
                            .double_gyre, [0.6, 0.3], (0.0, 10.0), 10.0 / 10000, "rk4").y[-1]
    assert np.linalg.norm(ref_half - ref) < 1e-8


def test_double_gyre_is_divergence_free_with_wall_streamlines():
    from course_lib.lessons import nb02_forward_euler as lesson

    rng = np.random.default_rng(2026)
    X = rng.uniform([0, 0], [2, 1], size=(50, 2))
    h = 1e-6
    for t in (0.0, 1.7, 4.2):
        ex, ey = np.array([h, 0.0]), np.array([0.0, h])
        div = ((lesson.double_gyre(t, X + ex)[:, 0] - lesson.double_gyre(t, X - ex)[:, 0])
               + (lesson.double_gyre(t, X + ey)[:, 1] - lesson.double_gyre(t, X - ey)[:, 1])) / (2 * h)
        assert np.max(np.abs(div)) < 1e-7
        for wall in ([[0.3, 0.0], [1.2, 1.0]], [[0.0, 0.4], [2.0, 0.7]]):
            V = lesson.double_gyre(t, np.array(wall))
            normal = 1 if wall[0][1] in (0.0,) and wall[1][1] == 1.0 else 0
            assert np.allclose(V[:, normal], 0.0, atol=1e-15)
    # period 10 s
    np.testing.assert_allclose(lesson.double_gyre(13.0, X), lesson.double_gyre(3.0, X), atol=1e-12)


def test_three_grid_order_is_exact_for_a_pure_power_law():
    from course_lib.lessons import nb02_forward_euler as lesson

    X, C = np.array([1.0, 2.0]), np.array([0.3, -0.4])
    for p in (1, 2, 3.5):
        assert lesson.three_grid_order(X + C * 0.1**p, X + C * 0.05**p, X + C * 0.025**p) == \
            pytest.approx(p, rel=1e-10)


def _observed_order(step, f, y0, T, n, log=np.log2, invert=False, norm=np.linalg.norm,
                    same_n=False):
    ends = []
    for m in (n, 2 * n, 4 * n):
        y, dt, t = np.array(y0, dtype=float), T / m, 0.0
        for _ in range(n if same_n else m):
            y = step(f, t, y, dt)
            t += dt
        ends.append(y)
    a, b = norm(ends[0] - ends[1]), norm(ends[1] - ends[2])
    return float(log(b / a) if invert else log(a / b))


def test_observed_order_check_accepts_right_answers(capsys):
    for answer in (_observed_order, lambda *a: np.float32(_observed_order(*a)),
                   lambda *a: np.array([_observed_order(*a)])):
        status, out = verdict(check.observed_order, answer, capsys, "observed_order")
        assert status == "correct", out
    # the references are near the methods' orders 1, 2, 3, 2
    got = [check.order_reference(c[1], c[3], c[4], c[5], c[6]) for c in check.ORDER_CASES]
    assert np.allclose(got, [c[2] for c in check.ORDER_CASES], atol=0.05)


@pytest.mark.parametrize("wrong, hint", [
    (lambda *a: _observed_order(*a, invert=True), "upside down"),
    # (the natural log: a planted misconception below, with the same hint)
    (lambda *a: _observed_order(*a, log=np.log10), "not log10"),
    (lambda step, f, y0, T, n: {"forward_euler": 1}.get("forward_euler"),
     "not rounded to a whole order"),
    (lambda step, f, y0, T, n: np.nan, "expected one number"),
    (lambda step, f, y0, T, n: _observed_order(step, f, y0, T, n + 1),
     "run the method to the same end time T with three step sizes"),
    (lambda *a: _observed_order(*a, norm=lambda d: abs(d[0])), "not one component"),
    (lambda *a: _observed_order(*a, norm=lambda d: np.max(np.abs(d))), "not the largest component"),
    (lambda *a: _observed_order(*a, same_n=True), "not n steps of each size"),
])
def test_observed_order_check_rejects_wrong_answers(wrong, hint, capsys):
    status, out = verdict(check.observed_order, wrong, capsys, "observed_order")
    assert status == "incorrect"
    assert hint in out


def test_exercise_4_wording():
    # "a pendulum swinging to 115°" (θ0 = 2 rad), "orders 1, 2 and 3", "n = 50, ..., 6400"
    assert round(math.degrees(2.0)) == 115
    assert sorted({c[2] for c in check.ORDER_CASES}) == [1, 2, 3]
    assert list(50 * 2 ** np.arange(8))[-1] == 6400


# --- planted answers: one delegating call, one shortcut the data breaks, one misconception --


def planted(source: str, name: str):
    """A function defined as a notebook cell defines it (module ``__main__``), so that the
    checks read its bytecode and watch its calls exactly as in a student's kernel."""
    namespace = {"__name__": "__main__", "np": np, "cl": cl, "math": math, "brentq": brentq}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


_LOOP = ("    ends = []\n    for m in (n, 2 * n, 4 * n):\n"
         "        y, dt = np.array(y0, dtype=float), T / m\n"
         "        for k in range(m):\n            y = step(f, {t}, y, dt)\n"
         "        ends.append(y)\n")

#: (exercise, kind, source, verdict, what the first failure's hint (or message) must say)
PLANTED = [
    ("forward_euler_step", "delegating",
     "def forward_euler_step(f, t, y, dt):\n    return cl.step('forward_euler', f, t, y, dt)",
     "incorrect", "uses the reference: your function calls course_lib.steppers.step"),
    ("forward_euler_step", "shortcut: t frozen at 0 (the time-dependent wind breaks it)",
     "def forward_euler_step(f, t, y, dt):\n    return y + dt * f(0.0, y)",
     "incorrect", "pass the step's time t to f"),
    ("forward_euler_step", "misconception: the slope at the end",
     "def forward_euler_step(f, t, y, dt):\n    return y + dt * f(t + dt, y + dt * f(t, y))",
     "incorrect", "the slope must be taken at the START of the step"),
    ("radius_after", "delegating: a library run",
     "def radius_after(r0, dt, n, k):\n"
     "    field = lambda t, X: cl.fields.vortex(t, X) - k * X\n"
     "    run = cl.integrate(field, [r0, 0.0], (0.0, max(n, 1) * dt), dt)\n"
     "    return float(np.linalg.norm(run.y[n]))",
     "incorrect", "uses the reference: your function calls course_lib.integrators.integrate"),
    ("radius_after", "shortcut: a simulation of one's own (the prompt asks for the analysis)",
     "def radius_after(r0, dt, n, k):\n    X = np.array([r0, 0.0])\n    for _ in range(n):\n"
     "        X = X + dt * (np.array([-X[1], X[0]]) - k * X)\n"
     "    return float(np.linalg.norm(X))",
     "incorrect", "the exercise asks for the analysis, one formula for any n"),
    ("radius_after", "delegating: the step matrix to the n-th power, all n steps in one call",
     "def radius_after(r0, dt, n, k):\n"
     "    M = np.array([[1.0 - k * dt, -dt], [dt, 1.0 - k * dt]])\n"
     "    return float(np.linalg.norm(np.linalg.matrix_power(M, n) @ [r0, 0.0]))",
     "incorrect", "uses the reference: your function calls numpy.linalg.matrix_power"),
    ("radius_after", "the analysis through complex numbers, |R(z)|^n",
     "def radius_after(r0, dt, n, k):\n    return r0 * abs(complex(1 - k * dt, dt)) ** n",
     "correct", ""),
    ("radius_after", "shortcut: the vortex's formula (the cases with a pull break it)",
     "def radius_after(r0, dt, n, k):\n    return r0 * (1 + dt**2) ** (n / 2)",
     "incorrect", "your answer ignores the pull k"),
    ("radius_after", "misconception: the two factors multiplied",
     "def radius_after(r0, dt, n, k):\n    return r0 * (1 - k * dt) ** n * (1 + dt**2) ** (n / 2)",
     "incorrect", "lengths add in squares (Pythagoras)"),
    ("drift_dt", "delegating: the checks' own solver",
     "from course_lib.check.nb02 import largest_drift_dt\n"
     "def drift_dt(tol):\n    return largest_drift_dt(tol)",
     "incorrect", "uses the reference: your function calls course_lib.check.nb02.largest_drift_dt"),
    ("drift_dt", "shortcut: a table of the printed answers (the drawn tolerance breaks it)",
     "def drift_dt(tol):\n"
     "    return {0.01: 0.0031673046, 0.1: 0.030352145, 0.037: 0.011565586}.get(tol, 0.01)",
     "incorrect", "(a tolerance the check draws): your dt = 0.01 s lets the radius grow by"),
    ("drift_dt", "shortcut: a scan over a grid of steps (no root finder to blame)",
     "def drift_dt(tol):\n    grid = np.linspace(1e-4, 0.1, 200001)\n"
     "    ok = (np.pi / grid) * np.log1p(grid**2) <= np.log1p(tol)\n    return float(grid[ok][-1])",
     "incorrect", "not within 1e-6 relative: whatever finds it (a scan over steps, a bisection "
     "of your own) stops too far from the root"),
    ("drift_dt", "misconception: brentq asked for an absolute xtol of 1e-6",
     "def drift_dt(tol):\n"
     "    return brentq(lambda dt: (math.pi / dt) * math.log1p(dt * dt) - math.log1p(tol),"
     " 1e-9, 1.0, xtol=1e-6)",
     "incorrect", "brentq's xtol is an absolute tolerance"),
    ("drift_dt", "misconception: (1 + dt²) per step",
     "def drift_dt(tol):\n"
     "    return brentq(lambda dt: (2 * math.pi / dt) * math.log1p(dt * dt) - math.log1p(tol),"
     " 1e-9, 1.0, xtol=1e-15)",
     "incorrect", "you compounded the factor 1 + dt² per step"),
    ("observed_order", "delegating: the lesson's estimator",
     "from course_lib.lessons.nb02_forward_euler import three_grid_order\n"
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="k * dt")
     + "    return three_grid_order(*ends)",
     "incorrect", "uses the reference: your function calls "
     "course_lib.lessons.nb02_forward_euler.three_grid_order"),
    ("observed_order", "shortcut: t frozen at 0 (the gyre and the forced decay break it)",
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="0.0")
     + "    return float(np.log2(np.linalg.norm(ends[0] - ends[1]) "
     "/ np.linalg.norm(ends[1] - ends[2])))",
     "incorrect", "pass the time of each step to step(f, t, y, dt)"),
    ("observed_order", "misconception: the natural log",
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="k * dt")
     + "    return float(np.log(np.linalg.norm(ends[0] - ends[1]) "
     "/ np.linalg.norm(ends[1] - ends[2])))",
     "incorrect", "not the natural log"),
    ("observed_order", "misconception: the differences summed with their signs",
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="k * dt")
     + "    return float(np.log2(abs(np.sum(ends[0] - ends[1])) / abs(np.sum(ends[1] - ends[2]))))",
     "incorrect", "summing the components with their signs lets them cancel"),
    ("observed_order", "misconception: each run one step short of T",
     "def observed_order(step, f, y0, T, n):\n"
     + _LOOP.replace("range(m)", "range(m - 1)").format(t="k * dt")
     + "    return float(np.log2(np.linalg.norm(ends[0] - ends[1]) "
     "/ np.linalg.norm(ends[1] - ends[2])))",
     "incorrect", "your runs stop one step short of T"),
    ("observed_order", "misconception: the finest run taken as exact",
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="k * dt")
     + "    return float(np.log2(np.linalg.norm(ends[0] - ends[2]) "
     "/ np.linalg.norm(ends[1] - ends[2])))",
     "incorrect", "the finest run is not the exact answer"),
    ("observed_order", "the loop written right",
     "def observed_order(step, f, y0, T, n):\n" + _LOOP.format(t="k * dt")
     + "    return float(np.log2(np.linalg.norm(ends[0] - ends[1]) "
     "/ np.linalg.norm(ends[1] - ends[2])))",
     "correct", ""),
]


@pytest.mark.parametrize(("exercise", "kind", "source", "status", "says"), PLANTED,
                         ids=[f"{p[0]}: {p[1]}" for p in PLANTED])
def test_planted_answers(exercise, kind, source, status, says):
    result = evaluate(getattr(check, exercise), planted(source, exercise))
    assert result["status"] == status, (kind, result["failed_cases"])
    assert says in "\n".join(result["failed_cases"]), (kind, result["failed_cases"])


def test_every_exercise_has_its_three_plants():
    from course_lib.check import REGISTRY

    kinds = {}
    for exercise, kind, *_ in PLANTED:
        kinds.setdefault(exercise, set()).add(kind.split(":")[0])
    assert set(kinds) == {k.split(".")[1] for k in REGISTRY if k.startswith("nb02.")}
    for exercise, found in kinds.items():
        assert {"delegating", "shortcut", "misconception"} <= found, exercise


def test_the_analysis_budget_is_lines_not_seconds():
    """A formula runs a few lines for a million steps; a loop is stopped at the budget (at
    once, whatever the machine), and the line count ignores NumPy's own Python code."""
    formula = planted("def radius_after(r0, dt, n, k):\n"
                      "    mu = np.linalg.eigvals(np.array([[1.0 - k * dt, -dt], [dt, 1.0 - k * dt]]))\n"
                      "    return float(r0 * np.abs(mu[0]) ** n)", "radius_after")
    assert evaluate(check.radius_after, formula)["status"] == "correct"
    caught = planted("def radius_after(r0, dt, n, k):\n    r = r0\n    for _ in range(n):\n"
                     "        try:\n            r *= math.sqrt((1 - k * dt) ** 2 + dt * dt)\n"
                     "        except BaseException:\n            pass\n    return r",
                     "radius_after")
    result = evaluate(check.radius_after, caught)
    assert result["status"] == "incorrect"
    assert "more than 2000 lines" in "\n".join(result["failed_cases"])
    assert check.RADIUS_LINE_BUDGET == 2000


# --- the spiral explorer (Section 4): dt against the spiral and the convergence plot -------


def test_spiral_experiment_against_the_theory():
    from course_lib.lessons import nb02_forward_euler as lesson

    n = 16
    r = lesson.spiral_experiment(2 * np.pi / n)                   # a whole number of steps
    assert len(r.t) == n + 1
    assert r.growth == pytest.approx((1 + (2 * np.pi / n) ** 2) ** (n / 2), rel=1e-12)
    for dt in (0.01, 0.037, 0.25, 1.0):                          # a shortened last step
        r = lesson.spiral_experiment(dt)
        assert r.t[-1] == pytest.approx(2 * np.pi, rel=1e-14)
        assert r.growth == pytest.approx(r.growth_theory, rel=1e-12)
        assert r.local == pytest.approx(dt**2 / 2, rel=dt**2)   # dt²/2 (1 + O(dt²))
        assert f"×{r.growth:.4f}" in r.verdict
    # "about dt = 0.01 s: a radius 3 % too large after one turn"
    assert round(100 * (lesson.spiral_experiment(0.01).growth - 1)) == 3
    with pytest.raises(ValueError, match="dt must lie in"):
        lesson.spiral_experiment(2.0)


def test_convergence_curves_are_the_runs_of_section_4():
    from course_lib.lessons import nb02_forward_euler as lesson

    _, error, local = lesson.convergence_curves()
    for n in (1, 3, 16, 100, 2048):
        run = cl.integrate(cl.fields.vortex, [1.0, 0.0], (0.0, np.pi), np.pi / n)
        assert run.n_steps == n
        # n steps: round-off grows like n ε relative (here n < 1e4, so 1e-9 is generous)
        assert error[n - 1] == pytest.approx(np.linalg.norm(run.y[-1] - [-1.0, 0.0]), rel=1e-9)
        assert local[n - 1] == pytest.approx(
            np.linalg.norm(run.y[1] - [np.cos(np.pi / n), np.sin(np.pi / n)]), rel=1e-9)
    assert lesson.spiral_experiment(np.pi / 64).error == pytest.approx(error[63], rel=1e-9)


@pytest.fixture(scope="module")
def spiral_view_module():
    import matplotlib

    matplotlib.use("Agg")
    from course_lib.lessons import nb02_spiral_view

    return nb02_spiral_view


def test_spiral_explorer_answers_a_slider(spiral_view_module):
    view = spiral_view_module.spiral_explorer(dt=0.25)
    first = view.image.value
    assert first[:8] == b"\x89PNG\r\n\x1a\n" and view.result.dt == 0.25
    view.controls["dt"].value = 0.05
    assert view.result.dt == pytest.approx(0.05) and view.image.value != first
    assert view.status.value == ""                              # "computing" is cleared
    assert "Spiral explorer (interactive)" in view._repr_mimebundle_()["text/plain"]


def test_spiral_plot_blit_draws_what_a_full_redraw_draws(spiral_view_module):
    from io import BytesIO

    from PIL import Image

    from course_lib.lessons.nb02_forward_euler import spiral_experiment

    fast = spiral_view_module.SpiralPlot(blit=True)
    fast(spiral_experiment(0.7))
    fast.png()                                                  # background cached at 0.7
    fast(spiral_experiment(0.1))
    full = spiral_view_module.SpiralPlot(blit=False)
    full(spiral_experiment(0.1))
    a, b = (np.asarray(Image.open(BytesIO(p.png())).convert("L"), dtype=float)
            for p in (fast, full))
    assert a.shape == b.shape
    assert np.mean(np.abs(a - b) > 40) < 0.002                   # anti-aliasing only


def test_spiral_player(spiral_view_module):
    from course_lib.lessons.nb02_forward_euler import spiral_experiment

    player = spiral_view_module.spiral_player(dts=(0.05, 0.5))
    assert player.labels == ["dt = 0.05 s", "dt = 0.5 s"]
    assert player.captions == [spiral_experiment(d).verdict for d in (0.05, 0.5)]
    assert len(spiral_view_module.SPIRAL_DTS) == 9              # "nine steps from 0.01 s to 1 s"
    assert min(spiral_view_module.SPIRAL_DTS) == 0.01 and max(spiral_view_module.SPIRAL_DTS) == 1.0
    assert player.nbytes < 300_000


def test_the_budget_reads_the_same_in_the_grader():
    """The grader's recorder hands the check a copy of what the answer raised, an Exception
    of the same name: the check still reads it as the budget overrun it was."""
    copy = type("TooManyLines", (Exception,), {})

    def replayed(r0, dt, n, k):
        if n > 1000:
            raise copy("your function ran more than 2000 lines of Python here")
        return _radius(r0, dt, n, k)

    result = evaluate(check.radius_after, replayed)
    text = "\n".join(result["failed_cases"])
    assert result["status"] == "incorrect" and "asks for the analysis" in text
    assert "raised" not in text


def test_the_spiral_explorer_takes_its_sliders_ends():
    from course_lib.lessons import nb02_forward_euler as lesson

    # a FloatLogSlider at an end holds 10**log10(end), one rounding below or above it
    lo, hi = lesson.SPIRAL_DT_RANGE
    for end in (10 ** np.log10(lo), 10 ** np.log10(hi)):
        assert lesson.spiral_experiment(end) is not None
    with pytest.raises(ValueError, match="dt"):
        lesson.spiral_experiment(hi * 2)


def test_a_near_miss_blames_brentq_only_if_the_answer_calls_it():
    """"brentq's xtol" is named for an answer whose code calls brentq; a scan over steps or a
    bisection of one's own is told that whatever finds the step stops too far from the root,
    and an answer whose code cannot be read (the grader's replay) gets that neutral hint."""
    scan = planted("def drift_dt(tol):\n    grid = np.linspace(1e-4, 0.1, 200001)\n"
                   "    ok = (np.pi / grid) * np.log1p(grid**2) <= np.log1p(tol)\n"
                   "    return float(grid[ok][-1])", "drift_dt")
    bisect = planted("def drift_dt(tol):\n    lo, hi = 1e-9, 1.0\n    while hi - lo > 1e-7:\n"
                     "        mid = (lo + hi) / 2\n"
                     "        if (np.pi / mid) * np.log1p(mid**2) <= np.log1p(tol):\n"
                     "            lo = mid\n        else:\n            hi = mid\n    return lo",
                     "drift_dt")

    class Replay:  # stands in for the answer in the grader: no code to read
        def __call__(self, tol):
            return scan(tol)

    for answer in (scan, bisect, Replay()):
        text = "\n".join(evaluate(check.drift_dt, answer)["failed_cases"])
        assert "xtol" not in text and "root finder converged" not in text
        assert "stops too far from the root" in text


def _implicit_midpoint(f, t, y, dt):
    """Y = y + dt f(t + dt/2, (y + Y)/2) by fixed-point iteration (a contraction here)."""
    Y = y.copy()
    for _ in range(200):
        Y = y + dt * f(t + dt / 2, (y + Y) / 2)
    return Y


def test_which_implicit_step_keeps_the_radius():
    """Section 3: the trapezoid keeps |X| on the vortex and on any constant linear field that
    keeps |X| (here a faster vortex, V = 3 (-y, x)), but not on a
    vortex whose rate changes in time, nor on the nonlinear swirl; the implicit midpoint rule
    keeps |X| on all of them (each field's velocity is perpendicular to X)."""
    from course_lib.check.nb04 import pulsing_vortex, swirl

    constant = [cl.fields.vortex, lambda t, X: 3.0 * cl.fields.vortex(t, X)]
    changing = [pulsing_vortex, swirl]
    X0, T, n = np.array([0.8, -0.6]), 2 * np.pi, 32
    for f in constant + changing:
        X, grows = X0.copy(), []
        for k in range(n):
            X = _implicit_midpoint(f, k * T / n, X, T / n)
            grows.append(abs(np.linalg.norm(X) - 1.0))
        assert max(grows) < 1e-12
        for k in range(3):  # the field is perpendicular to X at every point and time
            assert abs(np.dot(f(0.7 * k, X0), X0)) < 1e-15
    for f in constant:
        run = cl.integrate(f, X0, (0.0, T), T / n, "trapezoidal")
        assert np.max(np.abs(np.linalg.norm(run.y, axis=1) - 1.0)) < 1e-12
    for f in changing:  # the trapezoid drifts by about 1 % in one turn: far above round-off
        run = cl.integrate(f, X0, (0.0, T), T / n, "trapezoidal")
        assert np.max(np.abs(np.linalg.norm(run.y, axis=1) - 1.0)) > 1e-3
    # and the notebook says so: the trapezoid's claim is scoped to constant coefficients
    from pathlib import Path

    import nbformat
    nb = nbformat.read(Path(__file__).resolve().parents[1] / "solutions" / "02_forward_euler.ipynb",
                       as_version=4)
    text = " ".join(" ".join(c.source.split()) for c in nb.cells if c.cell_type == "markdown")
    assert "on *linear* fields such as the vortex" not in text
    assert "any linear field with constant coefficients, $V = AX$ with a fixed matrix $A$" in text
    assert "quadratic invariants such as $|X|^2$ on any field" not in text


def test_exercise_4_names_forward_euler_among_the_three_methods_it_measures(capsys):
    """Cell 28 (fifth review): the order-1 method of the check is forward Euler, the subject of
    the notebook, so the text may say "never shows" only of the other two. Every method the
    check's own report names must be named in the exercise text, the order-1 one must step
    exactly as ``cl.forward_euler``, and the two called new must appear in no earlier cell."""
    import re
    from pathlib import Path

    import nbformat

    from course_lib.check import _nb02_cases as cases

    nb = nbformat.read(Path(__file__).resolve().parents[1] / "solutions" / "02_forward_euler.ipynb",
                       as_version=4)
    at = next(i for i, c in enumerate(nb.cells) if "### Exercise 4" in c.source)
    text = " ".join(nb.cells[at].source.split())
    earlier = " ".join(c.source for c in nb.cells[:at])
    assert "three methods the notebook never shows, of orders 1, 2 and 3" not in text
    # the report's lines, from the model answer: "<method> on <problem>, n = ... (theory: order p)"
    status, out = verdict(check.observed_order, _observed_order, capsys, "observed_order")
    assert status == "correct"
    reported = {re.match(r"\s*✓ (.+?) on ", line).group(1): int(re.search(r"order (\d)", line)[1])
                for line in out.splitlines() if "theory: order" in line}
    assert reported == {"forward Euler": 1, "Ralston's method": 2,
                        "Kutta's third-order method": 3}
    for name in reported:
        assert name in text, name
    assert "forward Euler and two the notebook never shows" in text
    for name in ("Ralston", "Kutta"):
        assert name not in earlier, name
    f, y = (lambda t, y: np.array([y[1], -np.sin(y[0])])), np.array([2.0, 0.0])
    np.testing.assert_array_equal(cases._euler(f, 0.3, y, 0.1), cl.forward_euler(f, 0.3, y, 0.1))
