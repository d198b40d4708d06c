"""Every number quoted in notebook 03 (stability), against course_lib; and its checks."""

from __future__ import annotations

import numpy as np
import pytest

import course_lib as cl
from course_lib.check import FAILURES, REGISTRY, RESULTS, evaluate
from course_lib.check import nb03 as check
from course_lib.check._nb03_cases import SLOW_CASES
from course_lib.lessons import nb03_stability as ex


@pytest.fixture(autouse=True)
def _first_attempt():
    """Every test sees the first attempt's hint (the nudge): no failures carried over."""
    for key in [k for k in FAILURES if k.startswith("nb03.")]:
        del FAILURES[key]


# --- section 1: the decay ------------------------------------------------------------------
def test_forward_euler_dt3_sequence():
    traj = cl.integrate(lambda t, x: -x, [1.0], (0.0, 12.0), 3.0, "forward_euler")
    assert traj.y[:, 0].tolist() == [1.0, -2.0, 4.0, -8.0, 16.0]
    assert cl.amplification_factor("forward_euler", -3.0) == -2.0
    assert np.exp(-12.0) == pytest.approx(6e-6, rel=0.03)  # "≈ 6 × 10⁻⁶"


@pytest.mark.parametrize("k", [1.0, 4.0, 10.0, 0.5])
def test_forward_euler_limits_2_over_k_and_1_over_k(k):
    assert cl.max_stable_dt("forward_euler", -k) == pytest.approx(2.0 / k, rel=1e-12)
    # R = 1 - k dt: 0 at dt = 1/k (no sign flips below), -1 at dt = 2/k (bounded, flipping)
    assert cl.amplification_factor("forward_euler", -k * (1.0 / k)) == 0
    assert cl.amplification_factor("forward_euler", -k * (2.0 / k)) == -1
    assert cl.is_stable("forward_euler", -2.0)  # "bounded iff dt <= 2/k": the edge is in
    assert cl.amplification_factor("forward_euler", -k * (0.5 / k)).real > 0
    assert cl.amplification_factor("forward_euler", -k * (1.5 / k)).real < 0


def test_regime_figure_factors():
    # legends of the first figure: dt = 0.5, 1.5, 3 give R = 0.5, -0.5, -2, and the log
    # panel dt = 0.5, 1.8, 2, 2.1, 3 gives |R| = 0.5, 0.8, 1, 1.1, 2
    for dt, R in [(0.5, 0.5), (1.5, -0.5), (3.0, -2.0)]:
        assert cl.amplification_factor("forward_euler", -dt) == R
    for dt, R in [(0.5, 0.5), (1.8, 0.8), (2.0, 1.0), (2.1, 1.1), (3.0, 2.0)]:
        assert abs(cl.amplification_factor("forward_euler", -dt)) == pytest.approx(R, abs=1e-15)


# --- section 2: regions ----------------------------------------------------------------------
RK4_REAL = np.roots([1, 4, 12, 24])


def test_rk4_real_boundary_is_root_of_cubic_where_R_is_plus_one():
    real_root = RK4_REAL[np.abs(RK4_REAL.imag) < 1e-12].real[0]
    assert real_root == pytest.approx(-2.785293563405282, abs=1e-12)
    assert cl.max_stable_dt("rk4", -1.0) == pytest.approx(-real_root, rel=1e-10)
    # R = +1 there, not -1
    assert cl.amplification_factor("rk4", real_root) == pytest.approx(1.0, abs=1e-12)
    assert round(-real_root, 3) == 2.785 and round(-real_root, 4) == 2.7853


def test_R_minus_one_factorisations():
    z = np.linspace(-4, 1, 11) + 0.3j
    R = lambda m: cl.amplification_factor(m, z)  # noqa: E731
    assert np.allclose(R("midpoint") - 1, z * (1 + z / 2), rtol=1e-14)
    assert np.allclose(R("rk4") - 1, z / 24 * (z**3 + 4 * z**2 + 12 * z + 24), rtol=1e-13)
    assert cl.amplification_factor("midpoint", -2.0) == 1.0


def test_midpoint_and_rk4_are_positive_on_the_real_axis():
    x = np.linspace(-50, 5, 200001)
    mid = cl.amplification_factor("midpoint", x).real
    rk4 = cl.amplification_factor("rk4", x).real
    assert cl.amplification_factor("midpoint", -1.0) == 0.5           # R(-1) = 1/2, the minimum
    assert mid.min() >= 0.5 - 1e-12 and np.all(rk4 > 0.27)
    assert rk4.min() == pytest.approx(0.270, abs=5e-4)                # "about 0.270"
    assert x[np.argmin(rk4)] == pytest.approx(-1.596, abs=1e-3)       # "z ≈ -1.596"
    # R'(z) = 1 + z + z²/2 + z³/6 = 0 there
    roots = np.roots([1 / 6, 1 / 2, 1, 1])
    real = roots[np.abs(roots.imag) < 1e-12].real[0]
    assert real == pytest.approx(-1.5960716, abs=1e-6)


def test_edge_run_factors_quoted():
    assert cl.amplification_factor("forward_euler", -2.1) == pytest.approx(-1.1, abs=1e-15)
    assert cl.amplification_factor("midpoint", -2.1) == pytest.approx(1.105, abs=1e-14)
    assert cl.amplification_factor("rk4", -2.9).real == pytest.approx(1.187, abs=5e-4)
    assert cl.amplification_factor("rk4", -2.9).real == pytest.approx(
        1 - 2.9 + 2.9**2 / 2 - 2.9**3 / 6 + 2.9**4 / 24, rel=1e-15)


@pytest.mark.parametrize(("method", "limit"), [
    ("forward_euler", 2.0), ("midpoint", 2.0), ("heun", 2.0), ("rk4", 2.785293563405282),
    ("backward_euler", np.inf), ("trapezoidal", np.inf),
])
def test_real_axis_limits(method, limit):
    got = cl.max_stable_dt(method, -1.0, dt_max=1e3)
    if np.isinf(limit):
        assert got == 1e3
    else:
        assert got == pytest.approx(limit, rel=1e-10)


@pytest.mark.parametrize(("method", "limit"), [
    ("forward_euler", 0.0), ("midpoint", 0.0), ("rk4", 2 * np.sqrt(2)),
    ("backward_euler", np.inf), ("trapezoidal", np.inf),
    ("symplectic_euler", 2.0), ("velocity_verlet", 2.0),
])
def test_imaginary_axis_limits(method, limit):
    got = cl.max_stable_dt(method, 1j, dt_max=1e3)
    if np.isinf(limit):
        assert got == 1e3
    else:
        assert got == pytest.approx(limit, rel=1e-10, abs=1e-15)
    assert round(2 * np.sqrt(2), 3) == 2.828 and round(2 * np.sqrt(2), 4) == 2.8284


def test_rk4_imaginary_modulus_and_theta_squared_8():
    theta = np.linspace(0.01, 3.5, 400)
    R2 = np.abs(cl.amplification_factor("rk4", 1j * theta)) ** 2
    assert np.allclose(R2, 1 - theta**6 / 72 + theta**8 / 576, rtol=1e-12)
    assert np.all((R2 <= 1 + 1e-12) == (theta**2 <= 8))


def test_region_figure_verdicts():
    # z = -3 and z = 0.5i on the six panels, as the figure labels them
    expected = {"forward_euler": (False, False), "midpoint": (False, False),
                "rk4": (False, True), "backward_euler": (True, True),
                "trapezoidal": (True, True)}
    for method, (decay_ok, vortex_ok) in expected.items():
        assert bool(cl.is_stable(method, -3.0)) is decay_ok
        assert bool(cl.is_stable(method, 0.5j)) is vortex_ok
    assert bool(cl.is_stable("symplectic_euler", 0.5j))


@pytest.mark.parametrize("theta", [0.01, 0.1, 0.5, 1.0, 3.0])
def test_imaginary_axis_moduli(theta):
    R = lambda m: abs(cl.amplification_factor(m, 1j * theta))  # noqa: E731
    assert R("forward_euler") == pytest.approx(np.sqrt(1 + theta**2), rel=1e-14)
    assert R("midpoint") ** 2 == pytest.approx(1 + theta**4 / 4, rel=1e-13)
    assert R("backward_euler") == pytest.approx(1 / np.sqrt(1 + theta**2), rel=1e-14)
    assert R("trapezoidal") == pytest.approx(1.0, abs=1e-14)


def test_energy_factor_exactly_1_plus_omega2_dt2_per_step():
    for omega, dt in [(2.0, 0.1), (1.0, 0.5), (3.0, 0.01)]:
        run = cl.integrate(cl.systems.oscillator(omega), [1.0, 0.0], (0.0, 5.0), dt)
        energy = cl.systems.oscillator_energy(run.y, omega)
        assert np.allclose(energy[1:] / energy[:-1], 1 + omega**2 * dt**2, rtol=1e-12)
    # ω = 2, dt = 0.1: 1.04 per step; the energy doubles after 18 steps (1.8 s)
    assert 1 + 2.0**2 * 0.1**2 == pytest.approx(1.04, abs=1e-15)
    assert int(np.ceil(np.log(2) / np.log(1.04))) == 18


# --- A-stability, L-stability and the symplectic segment -----------------------------------
def test_l_stability_backward_euler_vs_trapezoid():
    # "R(-100) = -49/51 ≈ -0.96" for the trapezoid; backward Euler's R -> 0, the trapezoid's -> -1
    assert cl.amplification_factor("trapezoidal", -100.0) == pytest.approx(-49 / 51, rel=1e-15)
    assert round(-49 / 51, 2) == -0.96
    assert abs(cl.amplification_factor("backward_euler", -1e8)) == pytest.approx(0.0, abs=1e-7)
    assert cl.amplification_factor("trapezoidal", -1e8) == pytest.approx(-1.0, abs=1e-7)
    rng = np.random.default_rng(2026)
    z = -rng.exponential(5.0, 2000) + 1j * rng.normal(0.0, 20.0, 2000)
    z = np.concatenate([z, 1j * np.linspace(-50, 50, 201)])
    for m in ("backward_euler", "trapezoidal"):
        assert np.all(cl.is_stable(m, z))


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_symplectic_step_matrix_trace_det_and_jordan_edge(method):
    for theta in (0.5, 1.0, 1.9, 2.0, 2.1):
        M = ex.step_matrix(method, "oscillator", 1.0, theta)
        assert np.trace(M) == pytest.approx(2 - theta**2, abs=1e-12)
        assert np.linalg.det(M) == pytest.approx(1.0, abs=1e-12)
    for theta in (0.5, 1.0, 1.9):
        assert abs(cl.amplification_factor(method, 1j * theta)) == pytest.approx(1.0, abs=1e-12)
        assert cl.is_stable(method, 1j * theta)
    assert not cl.is_stable(method, 2.0j) and not cl.is_stable(method, 2.1j)
    # ω dt = 2: M = -(I + N) with N² = 0, so M^n = (-1)^n (I + n N)
    M = ex.step_matrix(method, "oscillator", 1.0, 2.0)
    N = -M - np.eye(2)
    assert np.allclose(N @ N, 0.0, atol=1e-12) and not np.allclose(N, 0.0)
    for n in (1, 2, 5, 40):
        assert np.allclose(np.linalg.matrix_power(M, n), (-1) ** n * (np.eye(2) + n * N))


def test_symplectic_euler_cell_matrices_and_2_1_eigenvalues():
    M = ex.step_matrix("symplectic_euler", "oscillator", 1.0, 2.0)
    assert np.allclose(M, [[-3.0, 2.0], [-2.0, 1.0]], atol=1e-14)
    mu = np.linalg.eigvals(ex.step_matrix("symplectic_euler", "oscillator", 1.0, 2.1))
    assert sorted(np.round(mu.real, 4)) == [-1.8773, -0.5327]
    assert abs(cl.amplification_factor("symplectic_euler", 2.1j)) == pytest.approx(1.8773, abs=1e-4)


# --- section 3: the explorer's key states ----------------------------------------------------
def test_key_states_quoted():
    a = ex.run_experiment("decay", "forward_euler", dt=1.9)
    b = ex.run_experiment("decay", "forward_euler", dt=2.1)
    assert a.stable and a.R == pytest.approx(-0.9, abs=1e-14)
    assert not b.stable and b.R == pytest.approx(-1.1, abs=1e-14) and b.blowup_step == 8
    assert b.bound == 2.0
    c = ex.run_experiment("oscillator", "rk4", dt=2.8)
    d = ex.run_experiment("oscillator", "rk4", dt=2.9)
    assert c.stable and not d.stable and d.blowup_step == 4
    assert 2.8 < 2 * np.sqrt(2) < 2.9
    assert 2 < 2 * np.pi / 2.8 < 2.5  # "about two steps per period"


# --- the checks ------------------------------------------------------------------------------
def _status(name):
    return RESULTS[f"nb03.{name}"]["status"]


def _pending(*args):
    raise NotImplementedError()


def _stability_function(step, z, dtype=complex):
    z = np.asarray(z, dtype=dtype)
    return step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0)


def test_check_stability_function_accepts_right_answers(capsys):
    check.stability_function(_stability_function)
    assert _status("stability_function") == "correct"
    check.stability_function(lambda step, z: _stability_function(step, z, np.complex64))  # float32
    assert _status("stability_function") == "correct"
    # λ = 1 and dt = z is the same product z = λ dt: also right
    check.stability_function(lambda step, z: step(lambda t, y: y, 0.0,
                                                  np.ones(np.shape(z), complex), np.asarray(z)))
    assert _status("stability_function") == "correct"
    # a scalar answer as a (1,) array is judged on its value
    check.stability_function(lambda step, z: np.atleast_1d(_stability_function(step, z)))
    assert _status("stability_function") == "correct"


def test_check_stability_function_rejects_wrong_answers(capsys):
    capsys.readouterr()
    check.stability_function(lambda step, z: _stability_function(step, z) - 1)
    assert _status("stability_function") == "incorrect"
    assert "change R - 1" in capsys.readouterr().out
    check.stability_function(lambda step, z: 1 + np.asarray(z, dtype=complex))
    assert "forward Euler's 1 + z" in capsys.readouterr().out
    check.stability_function(lambda step, z: _stability_function(step, z).real)
    assert "imaginary part is lost" in capsys.readouterr().out
    check.stability_function(lambda step, z: _stability_function(step, z) ** 2)
    assert "one step, not two" in capsys.readouterr().out
    check.stability_function(lambda step, z: cl.amplification_factor("rk4", z))
    assert _status("stability_function") == "incorrect"
    check.stability_function(lambda step, z: [1, 2])
    assert _status("stability_function") == "incorrect"
    assert "expected shape" in capsys.readouterr().out
    check.stability_function(_pending)
    assert _status("stability_function") == "pending"


def _largest_stable_dt(f, y0, method, dt_hi, n_steps=2000, growth=1e3, dtype=float):
    y0 = np.asarray(y0, dtype=float)
    bound = growth * np.max(np.abs(y0))

    def stable(dt):
        return cl.integrate(f, y0, (0.0, n_steps * dt), dt, method, blowup_bound=bound).stable

    lo, hi = 0.0, dt_hi
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return np.asarray(lo, dtype=dtype)


def test_check_largest_stable_dt_limits_come_from_theory():
    limits = [check.theory_limit(A, m) for _, A, _, m, _ in check.LIMIT_CASES]
    assert limits[0] == pytest.approx(0.5, rel=1e-12)           # 2 |Re λ| / |λ|² = 2/4
    assert limits[1] == pytest.approx(2.785293563405282 / 3, rel=1e-10)
    assert 0.40 < limits[2] < 0.45                              # no closed form in the text
    lam = -0.5 + 3j                                              # x'' = -9.25 x - x'
    assert abs(cl.amplification_factor("midpoint", lam * limits[2])) == pytest.approx(1.0, abs=1e-9)
    assert abs(cl.amplification_factor("midpoint", lam * limits[2] * 1.01)) > 1


def test_check_largest_stable_dt(capsys):
    # (the float64 search is a planted answer below)
    check.largest_stable_dt(lambda *a: _largest_stable_dt(*a, dtype=np.float32))
    assert _status("largest_stable_dt") == "correct"
    capsys.readouterr()
    # the decay formula 2/k, which the old exercise accepted, is now simply wrong
    check.largest_stable_dt(lambda f, y0, method, dt_hi: 2.0)
    assert _status("largest_stable_dt") == "incorrect"
    assert "your function ran no simulation" in capsys.readouterr().out
    check.largest_stable_dt(lambda f, y0, method, dt_hi: "0.5")
    assert _status("largest_stable_dt") == "incorrect"
    check.largest_stable_dt(_pending)
    assert _status("largest_stable_dt") == "pending"


@pytest.mark.parametrize(("kwargs", "says", "never"), [
    # too few steps: the runs above the limit end before they grow to the bound
    ({"n_steps": 20}, "took 20 steps: too few for a run above the limit", "bound is too"),
    # a bound that only an overflow reaches: the runs grow enormously and still pass
    ({"growth": 1e300, "n_steps": 400}, "the blow-up bound is too high", "steps:"),
    # a bound at twice |y0|: a stable run's transient crosses it (early: 300 steps show it)
    ({"growth": 2.0, "n_steps": 300}, "is stable (|R| = 0.9", "bound is too high"),
])
def test_largest_stable_dt_hints_name_the_mistake_the_runs_show(kwargs, says, never):
    """Issue 23: the old check told a search with too few steps, or too high a bound, to
    "start the bracket at dt_hi", which it already did. The check now reads the runs the
    search made (it hands over an f that records them) and names the cause."""
    result = evaluate(check.largest_stable_dt, lambda *a: _largest_stable_dt(*a, **kwargs))
    text = "\n".join(result["failed_cases"])
    assert result["status"] == "incorrect" and says in text, text
    assert never not in text and "start the bracket" not in text


def test_the_probe_reads_each_run():
    A, y0 = np.array([[0.0, 1.0], [-4.0, -2.0]]), np.array([1.0, 0.0])
    for method, n in (("forward_euler", 37), ("midpoint", 12), ("rk4", 5)):
        probe = check.Probe(A, y0, method)
        cl.integrate(probe, y0, (0.0, n * 0.01), 0.01, method)
        cl.integrate(probe, y0, (1.5, 1.5 + 3 * 0.2), 0.2, method)     # any start time
        probe(0.0, np.array([1e-7, 0.0]))                                # a Jacobian probe
        runs = probe.runs()
        assert [(round(d, 12), k) for d, k, _ in runs] == [(0.01, n), (0.2, 3)], (method, runs)


def _bounded(M):
    M = np.asarray(M, dtype=float)
    mu = np.linalg.eigvals(M)
    if np.max(np.abs(mu)) > 1 + 1e-7:
        return False
    if abs(mu[0] - mu[1]) < 1e-7 and abs(abs(mu[0]) - 1) < 1e-7:
        return bool(np.allclose(M, mu[0].real * np.eye(2), atol=1e-7))
    return True


def test_check_powers_stay_bounded(capsys):
    for _, M, expected, _, _ in check.MATRIX_CASES:
        assert check.bounded_reference(M) is expected
    for what, M, expected, _, kind in check.MATRIX_CASES:
        if kind == "overflow":
            continue  # below
        with np.errstate(over="ignore", invalid="ignore"):
            norms = [np.max(np.abs(np.linalg.matrix_power(np.array(M), n))) for n in (400, 10**6)]
        if what in SLOW_CASES:
            # 400 steps say the opposite of the truth, a million say it
            assert bool(norms[0] < 50) is (not expected) and bool(norms[1] < 50) is expected, what
        elif expected:  # bounded: the powers stay below a fixed size
            assert norms[0] < 1e3, what
        else:
            assert norms[0] > 50, what
    # the two harmless matrices whose transient passes the largest float: the quoted peaks
    # (exact, from the closed forms of M^n), and the powers near them overflow
    big = np.finfo(float).max
    n = np.arange(1, 20_000)
    # in units of 1e308, which the peaks themselves would overflow
    peak1 = np.max(n * 0.999 ** (n - 1)) * 1e-2            # [[a, c], [0, a]]^n: n a^(n-1) c
    peak2 = np.max((0.9999**n - 0.9998**n) / 1e-4) * 1e-3  # c (a^n - b^n) / (a - b)
    assert peak1 > big / 1e308 and round(peak1, 1) == 3.7 and round(big / 1e308, 1) == 1.8
    assert round(peak2, 1) == 2.5 and abs(int(n[np.argmax(0.9999**n - 0.9998**n)]) - 7000) < 100
    assert abs(int(n[np.argmax(n * 0.999 ** (n - 1))]) - 1000) <= 1
    for what, M, expected, _, kind in check.MATRIX_CASES:
        if kind == "overflow":
            assert expected and big < 4e308
            with np.errstate(over="ignore", invalid="ignore"):
                P = np.linalg.matrix_power(np.array(M), 2**13)
            assert not np.all(np.isfinite(P)), what
    # the quoted numbers of the two slow cases
    jordan = np.array([[0.99999, 1.0], [0.0, 0.99999]])
    peak = max(np.linalg.matrix_power(jordan, n)[0, 1] for n in (50_000, 100_000, 200_000))
    assert peak == pytest.approx(100_000 * 0.99999**99_999, rel=1e-9)
    assert round(peak, -3) == 37_000
    assert 1.00001 ** 230_000 == pytest.approx(10, rel=0.01)
    check.powers_stay_bounded(_bounded)
    assert _status("powers_stay_bounded") == "correct"
    check.powers_stay_bounded(lambda M: np.bool_(_bounded(M)))
    assert _status("powers_stay_bounded") == "correct"
    capsys.readouterr()
    check.powers_stay_bounded(lambda M: bool(np.max(np.abs(np.linalg.eigvals(M))) <= 1 + 1e-9))
    assert _status("powers_stay_bounded") == "incorrect"
    assert "Jordan block" in capsys.readouterr().out
    check.powers_stay_bounded(lambda M: bool(np.max(np.abs(np.linalg.eigvals(M))) < 1 - 1e-9))
    assert "neither grows nor decays" in capsys.readouterr().out
    check.powers_stay_bounded(lambda M: bool(np.linalg.norm(M, 2) <= 1 + 1e-9))
    assert _status("powers_stay_bounded") == "incorrect"
    out = capsys.readouterr().out
    # the verdicts are exactly the norm rule's: its own hint (escalated: a repeated failure)
    assert "a large norm may be only a transient" in out and "fixed" not in out
    # |tr| < 2 and |det| <= 1 (true only for det = 1 matrices): both of its mistakes are named
    check.powers_stay_bounded(lambda M: bool(abs(np.trace(M)) < 2 and abs(np.linalg.det(M)) <= 1))
    out = capsys.readouterr().out
    assert "an eigenvalue of modulus above 1" in out and "|μ| = 1 neither grows" in out
    check.powers_stay_bounded(lambda M: 1)
    assert "expected True or False" in capsys.readouterr().out
    check.powers_stay_bounded(_pending)
    assert _status("powers_stay_bounded") == "pending"


def test_kernel_free_player_quoted():
    # "eleven steps of forward Euler on the decay, from dt = 0.05 s to 4 s"
    from course_lib.lessons import kernel_free

    assert len(kernel_free.STABILITY_DTS) == 11
    assert min(kernel_free.STABILITY_DTS) == 0.05 and max(kernel_free.STABILITY_DTS) == 4.0
    dts = kernel_free.STABILITY_DTS
    assert min(dts) < 2.0 < max(dts) and any(d in dts for d in (1.9, 2.1))


def test_exercise_wording():
    assert len(check.HIDDEN_METHODS) == 3          # "three methods this notebook never shows"
    assert check.LIMIT_RTOL == 0.02                # "within 2 % of the true limit"
    assert len(check.LIMIT_CASES) == 3             # "three linear systems"
    assert len(check.MATRIX_CASES) == 14           # "the check tries fourteen matrices"
    assert sum(c[4] == "overflow" for c in check.MATRIX_CASES) == 2   # "two harmless matrices"


# --- planted answers: one delegating call, one shortcut the data breaks, one misconception --


def planted(source: str, name: str):
    """A function defined as a notebook cell defines it (module ``__main__``), so that the
    checks read its bytecode and watch its calls exactly as in a student's kernel."""
    namespace = {"__name__": "__main__", "np": np, "cl": cl}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


_SEARCH = ("def largest_stable_dt(f, y0, method, dt_hi):\n"
           "    y0 = np.asarray(y0, dtype=float)\n    lo, hi = 0.0, dt_hi\n"
           "    while hi - lo > 1e-3 * hi:\n        mid = 0.5 * (lo + hi)\n"
           "        run = cl.integrate(f, y0, (0.0, {n} * mid), mid, method,\n"
           "                           blowup_bound={bound} * np.max(np.abs(y0)))\n"
           "        lo, hi = (mid, hi) if run.stable else (lo, mid)\n    return lo")
_JACOBIAN = ("    A = np.column_stack([f(0.0, e) for e in np.eye(len(y0))])\n"
             "    lams = np.linalg.eigvals(A)\n")

#: (exercise, kind, source, verdict, what the first failure's hint (or message) must say)
PLANTED = [
    ("stability_function", "delegating",
     "def stability_function(step, z):\n    return cl.amplification_factor('rk4', z)",
     "incorrect", "uses the reference: your function calls "
     "course_lib.stability.amplification_factor"),
    ("stability_function", "shortcut: forward Euler's formula (hidden methods break it)",
     "def stability_function(step, z):\n    return 1 + np.asarray(z, dtype=complex)",
     "incorrect", "you returned forward Euler's 1 + z"),
    ("stability_function", "shortcut: a real state (the in-place method breaks it)",
     "def stability_function(step, z):\n    z = np.asarray(z)\n"
     "    return step(lambda t, y: z * y, 0.0, np.ones(z.shape), 1.0)",
     "incorrect", "this method updates a copy of y in place"),
    ("stability_function", "shortcut: one call of step per z, in a loop (the prompt: one call)",
     "def stability_function(step, z):\n    z = np.asarray(z, dtype=complex)\n"
     "    out = np.empty_like(z)\n    for i, zi in np.ndenumerate(z):\n"
     "        out[i] = step(lambda t, y: zi * y, 0.0, np.ones(1, dtype=complex), 1.0)[0]\n"
     "    return out",
     "incorrect", "your function called step 6 times for 6 values of z; the exercise asks for "
     "a single call"),
    ("stability_function", "misconception: the modulus |R|",
     "def stability_function(step, z):\n    z = np.asarray(z, dtype=complex)\n"
     "    return np.abs(step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0))",
     "incorrect", "you returned |R(z)|, the modulus"),
    ("stability_function", "misconception: the change in one step, not the new state",
     "def stability_function(step, z):\n    z = np.asarray(z, dtype=complex)\n"
     "    y0 = np.ones_like(z)\n    return step(lambda t, y: z * y, 0.0, y0, 1.0) - y0",
     "incorrect", "you returned the change R - 1"),
    ("largest_stable_dt", "delegating: the library's limit, from the Jacobian",
     "def largest_stable_dt(f, y0, method, dt_hi):\n" + _JACOBIAN
     + "    return min(cl.max_stable_dt(method, lam) for lam in lams)",
     "incorrect", "uses the reference: your function calls course_lib.stability.max_stable_dt"),
    ("largest_stable_dt", "shortcut: the decay formula 2/|λ| (the spring and RK4 break it)",
     "def largest_stable_dt(f, y0, method, dt_hi):\n" + _JACOBIAN
     + "    return 2 / np.max(np.abs(lams))",
     "incorrect", "your function ran no simulation"),
    ("largest_stable_dt", "shortcut: right by analysis, but no experiment",
     "def largest_stable_dt(f, y0, method, dt_hi):\n" + _JACOBIAN
     + "    R = {'forward_euler': lambda z: 1 + z,\n"
     "         'midpoint': lambda z: 1 + z + z**2 / 2,\n"
     "         'rk4': lambda z: 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24}[method]\n"
     "    lo, hi = 0.0, dt_hi\n"
     "    for _ in range(60):\n        mid = 0.5 * (lo + hi)\n"
     "        ok = np.all(np.abs(R(lams * mid)) <= 1 + 1e-12)\n"
     "        lo, hi = (mid, hi) if ok else (lo, mid)\n    return lo",
     "incorrect", "found without a single run: the exercise asks for the limit by experiment"),
    ("largest_stable_dt", "misconception: a few steps are enough",
     _SEARCH.format(n=20, bound=1e3), "incorrect", "took 20 steps: too few for a run above"),
    ("largest_stable_dt", "shortcut: a scan of 50 steps from dt_hi down (too coarse)",
     "def largest_stable_dt(f, y0, method, dt_hi):\n    y0 = np.asarray(y0, dtype=float)\n"
     "    for dt in np.linspace(dt_hi, dt_hi / 50, 50):\n"
     "        run = cl.integrate(f, y0, (0.0, 500 * dt), dt, method,\n"
     "                           blowup_bound=1e3 * np.max(np.abs(y0)))\n"
     "        if run.stable:\n            return dt\n    return 0.0",
     "incorrect", "below the limit: your search tried no step between"),
    ("largest_stable_dt", "the experiment done right",
     _SEARCH.format(n=2000, bound=1e3), "correct", ""),
    ("powers_stay_bounded", "delegating: the checks' own judge",
     "from course_lib.check.nb03 import bounded_reference\n"
     "def powers_stay_bounded(M):\n    return bounded_reference(M)",
     "incorrect", "uses the reference: your function calls "
     "course_lib.check.nb03.bounded_reference"),
    ("powers_stay_bounded", "shortcut: M^n for a fixed n (the slow cases break it)",
     "def powers_stay_bounded(M):\n    P = np.array(M)\n"
     "    with np.errstate(all='ignore'):\n        for _ in range(12):\n            P = P @ P\n"
     "    return bool(np.max(np.abs(P)) < 1e3)",
     "incorrect", "a slow growth (|μ| = 1.00001) or a long transient fooled your test"),
    ("powers_stay_bounded", "shortcut: M^(2^40) by 40 squarings (the overflow cases break it)",
     "def powers_stay_bounded(M):\n    P = np.array(M)\n"
     "    with np.errstate(all='ignore'):\n        for _ in range(40):\n            P = P @ P\n"
     "    return bool(np.all(np.isfinite(P)) and np.max(np.abs(P)) < 1e3)",
     "incorrect", "a harmless matrix whose transient passes the largest float"),
    ("powers_stay_bounded", "shortcut: a step-by-step loop",
     "def powers_stay_bounded(M):\n    P = np.eye(2)\n    for _ in range(10_000):\n"
     "        P = P @ M\n    return bool(np.max(np.abs(P)) < 1e3)",
     "incorrect", "decide from the eigenvalues and eigenvectors of M"),
    ("powers_stay_bounded", "shortcut: NumPy's matrix_power",
     "def powers_stay_bounded(M):\n"
     "    return bool(np.max(np.abs(np.linalg.matrix_power(M, 1000))) < 1e3)",
     "incorrect", "uses the reference: your function calls numpy.linalg.matrix_power"),
    ("powers_stay_bounded", "misconception: a norm at most 1",
     "def powers_stay_bounded(M):\n    return bool(np.linalg.norm(M, 2) <= 1)",
     "incorrect", "a norm above 1 does not mean growth: [[0.5, 100], [0, 0.5]] has norm 100"),
    ("powers_stay_bounded", "misconception: a determinant at most 1",
     "def powers_stay_bounded(M):\n    return bool(abs(np.linalg.det(M)) <= 1)",
     "incorrect", "|det M| is the product of the eigenvalues' moduli: diag(1.01, 0.2)"),
    ("powers_stay_bounded", "misconception: the spectral radius is all",
     "def powers_stay_bounded(M):\n"
     "    return bool(np.max(np.abs(np.linalg.eigvals(M))) <= 1 + 1e-7)",
     "incorrect", "spectral radius ≤ 1 is not enough"),
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
    assert set(kinds) == {k.split(".")[1] for k in REGISTRY if k.startswith("nb03.")}
    for exercise, found in kinds.items():
        assert {"delegating", "shortcut", "misconception"} <= found, exercise


def test_explorer_bullet_midpoint_on_the_oscillator():
    """"At dt = 0.5 the log panel shows the size rising by about half over the window
    (|R| = 1.008 per step) ... at θ = 0.1 the size grows by only 0.3 % over the window"."""
    from course_lib.lessons import nb03_stability as lesson

    wide = lesson.run_experiment("oscillator", "midpoint", dt=0.5, rate=1.0)
    small = lesson.run_experiment("oscillator", "midpoint", dt=0.1, rate=1.0)
    assert not wide.stable and not small.stable
    assert abs(cl.amplification_factor("midpoint", 0.5j)) == pytest.approx(1.008, abs=5e-4)
    assert 1.4 < wide.size[-1] < 1.6                                   # "about half"
    assert small.size[-1] - 1 == pytest.approx(0.003, abs=5e-4)        # "only 0.3 %"
    assert small.size[-1] == pytest.approx((1 + 0.1**4 / 4) ** ((small.size.size - 1) / 2),
                                           rel=1e-12)                 # |R|^n, |R|² = 1 + θ⁴/4


def test_midpoint_boundary_hugs_the_imaginary_axis():
    """"at z = 0.5i its boundary passes only 0.007 to the left of the axis ... |R(0.5i)| =
    1.0078", and the inset shows that value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.optimize import brentq

    from course_lib.lessons import nb03_regions as regions

    x = brentq(lambda x: abs(cl.amplification_factor("midpoint", complex(x, 0.5))) - 1, -0.1, 0)
    assert f"{-x:.3f}" == "0.007"
    assert f"{abs(cl.amplification_factor('midpoint', 0.5j)):.4f}" == "1.0078"
    fig, ax = plt.subplots()
    inset = regions.zoom_inset(ax, "midpoint", 0.5j)
    assert inset.get_xlim() == pytest.approx((-0.03, 0.03)) and x > -0.03
    assert any("1.0078" in t.get_text() for t in inset.texts)
    plt.close(fig)


def test_the_growth_quoted_is_what_the_answers_own_run_shows():
    """The hint quotes the growth of the run's states, max|y_k| / max|y0| (the norm of the
    blow-up bound), which the student can reproduce from the trajectory; the recorded
    evaluations also hold RK4's stages, which grow further (2.8e6 against 9.8e5 here)."""
    FAILURES["nb03.largest_stable_dt"] = 1              # the fuller hint, with the numbers
    result = evaluate(check.largest_stable_dt,
                      lambda *a: _largest_stable_dt(*a, n_steps=20, growth=1e6))
    text = next(c for c in result["failed_cases"] if c.startswith("RK4"))
    assert "2.8e+06" not in text
    quoted = float(text.split("its states reached ")[1].split(" max|y0|")[0])
    A, y0 = check.LIMIT_CASES[1][1], np.array(check.LIMIT_CASES[1][2])
    dt = float(_largest_stable_dt(lambda t, y: A @ y, y0, "rk4", 3.0, n_steps=20, growth=1e6))
    assert f"your run at dt = {dt:.4g} s" in text
    run = cl.integrate(lambda t, y: A @ y, y0, (0.0, 20 * dt), dt, "rk4",
                       blowup_bound=1e6 * np.max(np.abs(y0)))
    assert run.stable
    assert quoted == pytest.approx(np.max(np.abs(run.y)) / np.max(np.abs(y0)), rel=1e-2)
    assert quoted < 1e6 and "took 20 steps" in text


def test_two_matrix_hints_are_two_sentences():
    """Two kinds of mistake give two sentences, "... eigenvectors. Also: ...", the kind
    judged wrong most often first."""
    FAILURES.pop("nb03.powers_stay_bounded", None)
    answer = planted("def powers_stay_bounded(M):\n"
                     "    return bool(abs(np.trace(M)) < 2 and abs(np.linalg.det(M)) <= 1)",
                     "powers_stay_bounded")
    text = "\n".join(evaluate(check.powers_stay_bounded, answer)["failed_cases"])
    hint = text.split("hint: ")[1]
    assert "eigenvectors Also" not in hint and ". Also: " in hint
    assert hint.startswith("an eigenvalue of modulus above 1")    # wrong on 2, the other on 1
