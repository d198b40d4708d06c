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
    # R = 1 - k dt: 0 at dt = 1/k (no sign flips below), -1 at dt = 2/k
    assert cl.amplification_factor("forward_euler", -k * (1.0 / k)) == 0
    assert cl.amplification_factor("forward_euler", -k * (2.0 / k)) == -1
    assert cl.amplification_factor("forward_euler", -k * (0.5 / k)).real > 0
    assert cl.amplification_factor("forward_euler", -k * (1.5 / k)).real < 0


def test_regime_figure_factors():
    # legend of the first figure: dt = 0.5, 1.5, 3 with k = 1 give R = 0.5, -0.5, -2
    for dt, R in [(0.5, 0.5), (1.5, -0.5), (3.0, -2.0)]:
        assert cl.amplification_factor("forward_euler", -dt) == R


# --- section 2: regions ----------------------------------------------------------------------
RK4_REAL = np.roots([1, 4, 12, 24])


def test_rk4_real_boundary_is_root_of_cubic():
    real_root = RK4_REAL[np.abs(RK4_REAL.imag) < 1e-12].real[0]
    assert real_root == pytest.approx(-2.785293563405282, abs=1e-12)
    assert cl.max_stable_dt("rk4", -1.0) == pytest.approx(-real_root, rel=1e-10)
    assert abs(cl.amplification_factor("rk4", real_root)) == pytest.approx(1.0, abs=1e-12)
    assert round(-real_root, 3) == 2.785 and round(-real_root, 4) == 2.7853


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


def test_region_figure_verdicts():
    # z = -3 and z = 0.5i on the five regions, as the figure labels them
    expected = {"forward_euler": (False, False), "midpoint": (False, False),
                "rk4": (False, True), "backward_euler": (True, True),
                "trapezoidal": (True, True)}
    for method, (decay_ok, vortex_ok) in expected.items():
        assert bool(cl.is_stable(method, -3.0)) is decay_ok
        assert bool(cl.is_stable(method, 0.5j)) is vortex_ok


@pytest.mark.parametrize("theta", [0.01, 0.1, 0.5, 1.0, 3.0])
def test_imaginary_axis_moduli(theta):
    R = lambda m: abs(cl.amplification_factor(m, 1j * theta))  # noqa: E731
    assert R("forward_euler") == pytest.approx(np.sqrt(1 + theta**2), rel=1e-14)
    assert R("midpoint") ** 2 == pytest.approx(1 + theta**4 / 4, rel=1e-13)
    assert R("backward_euler") == pytest.approx(1 / np.sqrt(1 + theta**2), rel=1e-14)
    assert R("trapezoidal") == pytest.approx(1.0, abs=1e-14)
    assert R("rk4") ** 2 == pytest.approx(1 - theta**6 / 72 + theta**8 / 576, rel=1e-12)
    if theta <= 2:
        assert R("symplectic_euler") == pytest.approx(1.0, abs=1e-12)


def test_vortex_radius_grows_by_sqrt_1_plus_dt2():
    dt = 0.5
    traj = cl.integrate(cl.fields.vortex, [0.0, 1.0], (0.0, 5.0), dt)
    r = np.linalg.norm(traj.y, axis=1)
    assert np.allclose(r[1:] / r[:-1], np.sqrt(1 + dt**2), rtol=1e-13)


def test_energy_factor_exactly_1_plus_omega2_dt2_per_step():
    for omega, dt in [(2.0, 0.1), (1.0, 0.5), (3.0, 0.01)]:
        run = cl.integrate(cl.systems.oscillator(omega), [1.0, 0.0], (0.0, 5.0), dt)
        energy = cl.systems.oscillator_energy(run.y, omega)
        assert np.allclose(energy[1:] / energy[:-1], 1 + omega**2 * dt**2, rtol=1e-12)
    # ω = 2, dt = 0.1: 1.04 per step; the energy doubles after 18 steps (1.8 s)
    assert 1 + 2.0**2 * 0.1**2 == pytest.approx(1.04, abs=1e-15)
    assert int(np.ceil(np.log(2) / np.log(1.04))) == 18


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
    # "about two steps per period": 2π / 2.8 ≈ 2.2
    assert 2 < 2 * np.pi / 2.8 < 2.5


# --- the checks ------------------------------------------------------------------------------
def _status(name):
    return RESULTS[f"nb03.{name}"]["status"]


def _bisect(k, lo=0.0, hi=10.0, tol=1e-4):
    def stable(dt):
        return cl.integrate(lambda t, x: -k * x, [1.0], (0.0, 500 * dt), dt,
                            "forward_euler", blowup_bound=2.0).stable

    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def _pending(*args):
    raise NotImplementedError()


def test_check_largest_stable_dt(capsys):
    check.largest_stable_dt(_bisect)
    assert _status("largest_stable_dt") == "correct"
    check.largest_stable_dt(lambda k: 1.0 / k)
    assert _status("largest_stable_dt") == "incorrect"
    capsys.readouterr()
    check.largest_stable_dt(lambda k: 10.0)
    assert "never saw an unstable run" in capsys.readouterr().out
    check.largest_stable_dt(_pending)
    assert _status("largest_stable_dt") == "pending"


def test_check_largest_stable_dt_hint_for_one_over_k(capsys):
    check.largest_stable_dt(lambda k: 1.0 / k)
    out = capsys.readouterr().out
    assert "❌" in out and "limit for a run without sign flips" in out


def test_check_euler_dt_limits(capsys):
    check.euler_dt_limits(lambda k: (2 / k, 1 / k))
    assert _status("euler_dt_limits") == "correct"
    check.euler_dt_limits(lambda k: (1 / k, 2 / k))
    assert _status("euler_dt_limits") == "incorrect"
    assert "swapped" in capsys.readouterr().out
    check.euler_dt_limits(lambda k: (2 * k, k))
    assert "scale like 1/k" in capsys.readouterr().out
    check.euler_dt_limits(_pending)
    assert _status("euler_dt_limits") == "pending"


def _classify(pairs, strict=False, implicit_always=False):
    out = []
    for m, z in pairs:
        a = abs(cl.amplification_factor(m, z))
        ok = a < 1 if strict else a <= 1 + 1e-12
        if implicit_always and m in cl.IMPLICIT_METHODS:
            ok = True
        out.append(bool(ok))
    return out


def test_check_classify_stability(capsys):
    check.classify_stability(_classify)
    assert _status("classify_stability") == "correct"
    check.classify_stability(lambda p: np.array(_classify(p)))  # numpy bools are fine
    assert _status("classify_stability") == "correct"
    capsys.readouterr()
    check.classify_stability(lambda p: _classify(p, strict=True))
    assert _status("classify_stability") == "incorrect"
    out = capsys.readouterr().out
    assert "you used |R| < 1" in out and "forward_euler at z = -2.0" in out
    check.classify_stability(lambda p: _classify(p, implicit_always=True))
    assert "implicit methods are not stable everywhere" in capsys.readouterr().out

    def divides_by_zero(pairs):
        return [abs(1 / (1 - complex(z))) <= 1 if m == "backward_euler" else True
                for m, z in pairs]

    check.classify_stability(divides_by_zero)
    assert _status("classify_stability") == "incorrect"
    assert "pole" in capsys.readouterr().out
    check.classify_stability(lambda p: [1] * len(p))
    assert "list of booleans" in capsys.readouterr().out
    check.classify_stability(_pending)
    assert _status("classify_stability") == "pending"


def test_classification_reference_matches_is_stable():
    assert check.classification_answer() == [bool(cl.is_stable(m, z)) for m, z in check.PAIRS]
    # the pairs contain boundary cases and both poles
    assert abs(cl.amplification_factor("trapezoidal", 2j)) == 1.0
    assert np.isinf(cl.amplification_factor("backward_euler", 1.0))
    assert np.isinf(cl.amplification_factor("trapezoidal", 2.0))


# --- A-stability, L-stability and the symplectic segment (section 2 prose) -----------------
def test_l_stability_backward_euler_vs_trapezoid():
    # "R(-100) = -49/51 ≈ -0.96" for the trapezoid; backward Euler's R -> 0, the trapezoid's -> -1
    assert cl.amplification_factor("trapezoidal", -100.0) == pytest.approx(-49 / 51, rel=1e-15)
    assert round(-49 / 51, 2) == -0.96
    assert abs(cl.amplification_factor("backward_euler", -1e8)) == pytest.approx(0.0, abs=1e-7)
    assert cl.amplification_factor("trapezoidal", -1e8) == pytest.approx(-1.0, abs=1e-7)
    # both A-stable: |R| <= 1 on a sample of the closed left half-plane
    rng = np.random.default_rng(2026)
    z = -rng.exponential(5.0, 2000) + 1j * rng.normal(0.0, 20.0, 2000)
    z = np.concatenate([z, 1j * np.linspace(-50, 50, 201)])
    for m in ("backward_euler", "trapezoidal"):
        assert np.all(cl.is_stable(m, z))


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_symplectic_segment_edge_is_linear_growth(method):
    for theta in (0.5, 1.0, 1.9):
        assert abs(cl.amplification_factor(method, 1j * theta)) == pytest.approx(1.0, abs=1e-12)
    assert abs(cl.amplification_factor(method, 2.1j)) > 1
    # ω dt = 2: a double eigenvalue -1 (a Jordan block), so y_n = (-1)^n (y_0 + n N y_0):
    # a run from a generic start grows linearly, without bound
    run = cl.integrate(cl.systems.oscillator(1.0), [1.0, 0.5], (0.0, 400.0), 2.0, method)
    even = run.y[::2]
    assert np.allclose(np.diff(even, axis=0), even[1] - even[0], rtol=1e-9, atol=1e-9)
    assert np.linalg.norm(run.y[-1]) > 50


def test_region_table_printed_values():
    # the table of section 2 prints "z = -2.0000", "z = -2.7853", "z = i·2.8284", "no limit"
    assert f"{cl.max_stable_dt('forward_euler', -1.0):.4f}" == "2.0000"
    assert f"{cl.max_stable_dt('midpoint', -1.0):.4f}" == "2.0000"
    assert f"{cl.max_stable_dt('rk4', -1.0):.4f}" == "2.7853"
    assert f"{cl.max_stable_dt('rk4', 1j):.4f}" == "2.8284"
    for m in ("backward_euler", "trapezoidal"):
        assert cl.max_stable_dt(m, -1.0) >= 1e3 and cl.max_stable_dt(m, 1j) >= 1e3
    for m in ("forward_euler", "midpoint"):
        assert cl.max_stable_dt(m, 1j) == 0.0
