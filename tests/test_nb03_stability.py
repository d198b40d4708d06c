"""Every number quoted in notebook 03 (stability), against course_lib; and its checks."""

from __future__ import annotations

import numpy as np
import pytest

import course_lib as cl
from course_lib.check import RESULTS
from course_lib.check import nb03 as check
from course_lib.lessons import nb03_stability as ex


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
    check.largest_stable_dt(_largest_stable_dt)
    assert _status("largest_stable_dt") == "correct"
    check.largest_stable_dt(lambda *a: _largest_stable_dt(*a, dtype=np.float32))
    assert _status("largest_stable_dt") == "correct"
    capsys.readouterr()
    # the decay formula 2/k, which the old exercise accepted, is now simply wrong
    check.largest_stable_dt(lambda f, y0, method, dt_hi: 2.0)
    assert _status("largest_stable_dt") == "incorrect"
    assert "never saw an unstable run" in capsys.readouterr().out
    check.largest_stable_dt(lambda *a: _largest_stable_dt(*a, n_steps=20))
    assert _status("largest_stable_dt") == "incorrect"
    assert "too large" in capsys.readouterr().out
    check.largest_stable_dt(lambda *a: _largest_stable_dt(*a, growth=2.0))
    assert _status("largest_stable_dt") == "incorrect"
    assert "too small" in capsys.readouterr().out
    check.largest_stable_dt(lambda f, y0, method, dt_hi: "0.5")
    assert _status("largest_stable_dt") == "incorrect"
    check.largest_stable_dt(_pending)
    assert _status("largest_stable_dt") == "pending"


def _bounded(M):
    M = np.asarray(M, dtype=float)
    mu = np.linalg.eigvals(M)
    if np.max(np.abs(mu)) > 1 + 1e-7:
        return False
    if abs(mu[0] - mu[1]) < 1e-7 and abs(abs(mu[0]) - 1) < 1e-7:
        return bool(np.allclose(M, mu[0].real * np.eye(2), atol=1e-7))
    return True


def test_check_powers_stay_bounded(capsys):
    for _, M, expected, _ in check.MATRIX_CASES:
        assert check.bounded_reference(M) is expected
        if expected:  # bounded: the powers stay below a fixed size
            assert np.max(np.abs(np.linalg.matrix_power(np.array(M), 400))) < 1e3
        else:
            assert np.max(np.abs(np.linalg.matrix_power(np.array(M), 400))) > 50
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
    assert len(check.MATRIX_CASES) == 10           # "the check tries ten matrices"
