"""Every number quoted in notebook 05 (Newton's second law), and its exercise checks."""

import numpy as np
import pytest
from notebook_helpers import drive_kept_figure, printed_holds
from planted import Plant, define, judge

import course_lib as cl
from course_lib import events
from course_lib.check import FAILURES, RESULTS
from course_lib.check import nb05 as check
from course_lib.lessons import nb05_newton as nb05

G, DT, H0 = 9.81, 0.1, 10.0
T_EXACT = np.sqrt(2 * H0 / G)


@pytest.fixture(scope="module")
def runs():
    return {m: nb05.apple_drop(m, dt=DT, h0=H0, t_end=2.0)
            for m in ("forward_euler", "symplectic_euler", "velocity_verlet", "midpoint",
                      "heun", "rk4")}


def heights(traj):
    return traj.y[:, 0, 0, 1]


def test_one_step_of_each_method():
    apple = cl.newtonian(cl.forces.constant_gravity(1.0, g=[0.0, -G]), mass=1.0)
    y0 = cl.stack_state([[0.0, H0]], [[0.0, 0.0]])
    fe = cl.forward_euler(apple, 0.0, y0, DT)
    se = cl.symplectic_euler(apple, 0.0, y0, DT)
    vv = cl.velocity_verlet(apple, 0.0, y0, DT)
    assert fe[0, 0, 1] == H0
    assert se[0, 0, 1] == pytest.approx(H0 - 0.0981, abs=1e-12)
    assert vv[0, 0, 1] == pytest.approx(H0 - 0.04905, abs=1e-12)
    for y in (fe, se, vv):
        assert y[1, 0, 1] == pytest.approx(-0.981, abs=1e-12)


def test_exact_impact_time():
    assert T_EXACT == pytest.approx(1.428, abs=5e-4)
    assert round(T_EXACT, 4) == 1.4278


def test_impact_times_linear_rule(runs):
    lin = {m: events.first_crossing(tr.t, heights(tr)) for m, tr in runs.items()}
    assert round(lin["forward_euler"], 3) == 1.478
    assert round(lin["symplectic_euler"], 3) == 1.378
    assert round(lin["velocity_verlet"], 4) == 1.4272
    assert round(lin["midpoint"], 4) == 1.4272
    # about dt/2 late and early
    assert lin["forward_euler"] - T_EXACT == pytest.approx(0.05, abs=1e-3)
    assert lin["symplectic_euler"] - T_EXACT == pytest.approx(-0.05, abs=1e-3)
    # the chord error of Verlet's exact samples
    assert T_EXACT - lin["velocity_verlet"] == pytest.approx(0.0007, abs=5e-5)
    # the first step below the ground, as printed in the table
    first_below = {m: int(np.flatnonzero(heights(tr) < 0)[0]) for m, tr in runs.items()}
    assert first_below["forward_euler"] == 15 and first_below["symplectic_euler"] == 14
    assert first_below["velocity_verlet"] == 15 and first_below["midpoint"] == 15


def test_ballistic_rule_is_exact_for_verlet_and_midpoint(runs):
    for m in ("velocity_verlet", "midpoint", "heun", "rk4"):
        tr = runs[m]
        t_star = events.first_crossing(tr.t, heights(tr), rule="ballistic",
                                       v=tr.y[:, 1, 0, 1], a=-G)
        assert t_star == pytest.approx(T_EXACT, rel=1e-13)
    fe, se = runs["forward_euler"], runs["symplectic_euler"]
    assert round(events.first_crossing(fe.t, heights(fe), rule="ballistic",
                                       v=fe.y[:, 1, 0, 1], a=-G), 4) == 1.4761
    assert round(events.first_crossing(se.t, heights(se), rule="ballistic",
                                       v=se.y[:, 1, 0, 1], a=-G), 4) == 1.3816


def test_step_points_exact_for_quadratic_methods(runs):
    n = np.arange(21)
    for m in ("velocity_verlet", "midpoint", "heun", "rk4"):
        assert np.allclose(heights(runs[m]), H0 - 0.5 * G * (n * DT) ** 2, rtol=0, atol=1e-12)


def test_closed_forms_of_euler_heights(runs):
    n = np.arange(21)
    h_fe = H0 - G * DT**2 * n * (n - 1) / 2
    h_se = H0 - G * DT**2 * n * (n + 1) / 2
    assert np.allclose(heights(runs["forward_euler"]), h_fe, rtol=0, atol=1e-12)
    assert np.allclose(heights(runs["symplectic_euler"]), h_se, rtol=0, atol=1e-12)
    assert np.allclose(nb05.euler_apple_height(n, DT, H0, G), h_fe)
    assert np.allclose(nb05.symplectic_apple_height(n, DT, H0, G), h_se)
    # the exact parabola delayed (FE) / advanced (SE) by dt/2 and raised by g dt²/8
    assert np.allclose(h_fe, H0 + G * DT**2 / 8 - 0.5 * G * (n * DT - DT / 2) ** 2)
    assert np.allclose(h_se, H0 + G * DT**2 / 8 - 0.5 * G * (n * DT + DT / 2) ** 2)
    assert G * DT**2 / 8 == pytest.approx(0.012, abs=5e-4)
    assert round(h_fe[14], 4) == 1.0729 and round(h_fe[15], 4) == -0.3005


def test_halving_dt_halves_euler_impact_error():
    errs = []
    for dt in (0.1, 0.05):
        tr = nb05.apple_drop("forward_euler", dt=dt)
        errs.append(events.first_crossing(tr.t, heights(tr)) - T_EXACT)
    assert errs[1] == pytest.approx(0.025, abs=1e-3)
    assert errs[0] / errs[1] == pytest.approx(2.0, rel=0.02)


def test_apple_energy_drift(runs):
    per_step = 0.5 * G**2 * DT**2
    assert round(per_step, 3) == 0.481 and round(per_step, 4) == 0.4812
    for m, sign in (("forward_euler", 1), ("symplectic_euler", -1), ("velocity_verlet", 0)):
        x, v = cl.split_state(runs[m].y)
        E = 0.5 * v[:, 0, 1] ** 2 + G * x[:, 0, 1]
        assert E[0] == pytest.approx(98.1)
        assert np.allclose(np.diff(E), sign * per_step, rtol=0, atol=1e-10)


@pytest.fixture(scope="module")
def osc_runs():
    f = cl.systems.oscillator(1.0)
    return {m: cl.integrate(f, [1.0, 0.0], (0.0, 1257 * 0.1), 0.1, m)
            for m in ("forward_euler", "symplectic_euler", "velocity_verlet", "rk4")}


def test_forward_euler_energy_factor(osc_runs):
    tr = osc_runs["forward_euler"]
    assert tr.n_steps == 1257
    E = cl.systems.oscillator_energy(tr.y, 1.0)
    assert np.allclose(E[1:] / E[:-1], 1.01, rtol=1e-12, atol=0)
    assert E[-1] / E[0] == pytest.approx(1.01**1257, rel=1e-9)
    assert E[-1] / E[0] == pytest.approx(2.704e5, rel=1e-3)


def test_modified_energies_are_conserved(osc_runs):
    se = nb05.symplectic_modified_energy(osc_runs["symplectic_euler"].y, 1.0, 0.1)
    vv = nb05.verlet_modified_energy(osc_runs["velocity_verlet"].y, 1.0, 0.1)
    assert np.ptp(se) < 1e-12 and np.ptp(vv) < 1e-12
    # the sign of the dt term matters: with + it is not conserved
    wrong = cl.systems.oscillator_energy(osc_runs["symplectic_euler"].y) + 0.05 * np.prod(
        osc_runs["symplectic_euler"].y, axis=-1)
    assert np.ptp(wrong) > 1e-2


def test_energy_bands(osc_runs):
    E_se = cl.systems.oscillator_energy(osc_runs["symplectic_euler"].y)
    E_vv = cl.systems.oscillator_energy(osc_runs["velocity_verlet"].y)
    lo, hi = 0.5 / 1.05, 0.5 / 0.95
    assert (round(lo, 5), round(hi, 5)) == (0.47619, 0.52632)
    assert lo - 1e-12 <= E_se.min() <= lo + 1e-6 and hi - 1e-6 <= E_se.max() <= hi + 1e-12
    assert abs(hi / 0.5 - 1) == pytest.approx(0.05, abs=3e-3)      # "about ±5 %"
    assert abs(lo / 0.5 - 1) == pytest.approx(0.05, abs=3e-3)
    assert round(100 * (1 - lo / 0.5), 1) == 4.8                   # "4.8 % below"
    assert round(100 * (hi / 0.5 - 1), 1) == 5.3                   # "5.3 % above"
    # the symplectic band follows from omega |x v| <= E: modified energy within (1 -/+ dt/2) E
    y = osc_runs["symplectic_euler"].y
    Et = nb05.symplectic_modified_energy(y, 1.0, 0.1)
    assert np.all(np.abs(Et - E_se) <= 0.05 * E_se + 1e-15)
    vv_lo = 0.5 * (1 - 0.01 / 4)
    assert round(vv_lo, 5) == 0.49875 and 1 - vv_lo / 0.5 == pytest.approx(0.0025)
    assert vv_lo - 1e-12 <= E_vv.min() <= vv_lo + 1e-6
    assert 0.5 - 1e-6 <= E_vv.max() <= 0.5 + 1e-12


def test_twenty_periods_is_a_whole_number_of_steps(osc_runs):
    assert 1257 * 0.1 == pytest.approx(40 * np.pi, abs=0.04)         # "20 periods (125.66 s)"
    assert np.allclose(np.diff(osc_runs["symplectic_euler"].t), 0.1, rtol=1e-9)


def test_phase_error(osc_runs):
    w_tilde = nb05.discrete_frequency(1.0, 0.1)
    assert np.cos(w_tilde * 0.1) == pytest.approx(1 - 0.01 / 2, rel=1e-15)
    assert f"{w_tilde - 1:.4e}" == "4.1714e-04" and f"{0.01 / 24:.4e}" == "4.1667e-04"
    t_end = 1257 * 0.1
    assert round((w_tilde - 1) * t_end, 4) == 0.0524                     # theory after 20 periods
    assert np.degrees((w_tilde - 1) * t_end) == pytest.approx(3.0, abs=0.05)   # "3°"
    # the same trace for both symplectic methods: the same frequency
    for m in ("symplectic_euler", "velocity_verlet"):
        A = np.column_stack([cl.step(m, cl.systems.oscillator(1.0), 0.0, e, 0.1) for e in np.eye(2)])
        assert np.trace(A) == pytest.approx(2 - 0.01, rel=1e-15)
        assert np.linalg.det(A) == pytest.approx(1.0, rel=1e-15)
    printed = {m: round(nb05.phase_error(tr.t, tr.y)[-1], 4) for m, tr in osc_runs.items()}
    assert printed == {"forward_euler": -0.4165, "symplectic_euler": 0.0529,
                       "velocity_verlet": 0.0523, "rk4": -0.0001}
    # forward Euler turns by arctan(w dt) per step
    assert 1257 * (np.arctan(0.1) - 0.1) == pytest.approx(-0.4165, abs=5e-4)
    # Verlet's phase follows (w~ - w) t; symplectic Euler's wobbles by up to about w dt / 2
    vv = osc_runs["velocity_verlet"]
    assert np.abs(nb05.phase_error(vv.t, vv.y) - (w_tilde - 1) * vv.t).max() < 2e-3
    se = osc_runs["symplectic_euler"]
    wobble = nb05.phase_error(se.t, se.y) - (w_tilde - 1) * se.t
    assert wobble.min() > -1e-3 and wobble.max() == pytest.approx(0.05, abs=5e-3)


def test_stormer_form_is_verlet():
    accel = lambda th: -9.81 * np.sin(th)   # noqa: E731
    x = nb05.stormer_verlet(accel, 1.0, 0.0, 0.01, 200)
    vv = cl.integrate(nb05.pendulum(9.81), [1.0, 0.0], (0.0, 2.0), 0.01, "velocity_verlet")
    assert np.abs(x - vv.y[:, 0]).max() < 1e-13
    assert np.abs((x[2:] - x[:-2]) / 0.02 - vv.y[1:-1, 1]).max() < 1e-12
    orders = {}
    for start in ("taylor", "euler"):
        orders[start], _ = nb05.three_grid_order(
            lambda h, start=start: nb05.stormer_verlet(accel, 1.0, 0.0, h, round(2.0 / h), start)[-1],
            0.0025)
    assert f"{orders['taylor']:.3f}" == "2.000" and f"{orders['euler']:.3f}" == "0.998"


def test_local_and_global_orders():
    dts = 0.01 / 2.0 ** np.arange(5)
    printed = {"forward_euler": ("2.000", "1.027"), "symplectic_euler": ("2.000", "1.003"),
               "velocity_verlet": ("3.000", "2.000")}
    f = nb05.pendulum()
    three = {"forward_euler": ("1.086", "1.022"), "symplectic_euler": ("1.012", "1.003"),
             "velocity_verlet": ("2.000", "2.000")}
    for m, (loc_s, glob_s) in printed.items():
        local, glob = nb05.step_errors(m, dts)
        s_loc = np.polyfit(np.log(dts), np.log(local), 1)[0]
        s_glob = np.polyfit(np.log(dts), np.log(glob), 1)[0]
        assert (f"{s_loc:.3f}", f"{s_glob:.3f}") == (loc_s, glob_s)
        assert s_loc == pytest.approx(cl.ORDER[m] + 1, abs=0.01)
        assert s_glob == pytest.approx(cl.ORDER[m], abs=0.03)
        end = lambda h, m=m: cl.integrate(f, [1.0, 0.0], (0.0, 2.0), h, m).y[-1]   # noqa: E731
        got = tuple(f"{nb05.three_grid_order(end, h)[0]:.3f}" for h in (0.01, 0.0025))
        assert got == three[m]
    # the three-grid error estimate is the finest run's true error (Verlet, asymptotic)
    end = lambda h: cl.integrate(f, [1.0, 0.0], (0.0, 2.0), h, "velocity_verlet").y[-1]   # noqa: E731
    _, err = nb05.three_grid_order(end, 0.01)
    true = np.linalg.norm(end(0.0025) - nb05.reference_run(f, np.array([1.0, 0.0]), 2.0))
    assert err == pytest.approx(true, rel=2e-3)


def test_local_errors_of_the_two_eulers_coincide():
    """Section 6's figure: one step from rest, forward and symplectic Euler are off by
    ½ dt² a in θ in opposite directions (printed: agree to 0.009 %); at T = 2 s forward
    Euler's error is about 35 times symplectic Euler's."""
    dts = 0.01 / 2.0 ** np.arange(5)
    fe, se = nb05.step_errors("forward_euler", dts), nb05.step_errors("symplectic_euler", dts)
    same = np.abs(fe[0] / se[0] - 1).max()
    # the leading terms are equal; the next ones differ by O(dt) relative: 9e-5 at dt = 0.01
    assert same < 0.01 * 0.01
    printed_holds(100 * same, ".3f", "0.009", 1e-7)
    ratio = fe[1] / se[1]
    assert np.all((ratio > 34) & (ratio < 37))                # "about 35 times"
    # the one-step errors in θ: exactly -½ dt² a and +½ dt² a to leading order
    f = nb05.pendulum()
    a0 = -9.81 * np.sin(1.0)
    for name, sign in (("forward_euler", -1), ("symplectic_euler", 1)):
        y1 = cl.integrators.step(name, f, 0.0, np.array([1.0, 0.0]), 1e-3)
        exact = nb05.reference_run(f, np.array([1.0, 0.0]), 1e-3, 200)
        assert y1[0] - exact[0] == pytest.approx(sign * 0.5 * 1e-6 * a0, rel=1e-2)


def test_symplectic_euler_mean_phase_offset(osc_runs):
    """Cell 25: the mean over a period runs ω dt/4 above the theory line (printed 0.0250)."""
    tr = osc_runs["symplectic_euler"]
    phase = nb05.phase_error(tr.t, tr.y, 1.0)
    w_tilde = nb05.discrete_frequency(1.0, 0.1)
    mean = np.convolve(phase, np.ones(63) / 63, mode="valid")
    offset = mean - (w_tilde - 1.0) * tr.t[31:][:mean.size]
    assert np.median(offset) == pytest.approx(0.1 / 4, rel=0.01)
    assert np.ptp(offset) < 0.01 * 0.025 * 20      # parallel: the offset does not drift
    # 1257 steps: round-off in the phase ~1e-13 rad
    printed_holds(np.median(offset), ".4f", "0.0250", 1e-10)
    printed_holds(0.1 / 4, ".4f", "0.0250", 0.0)


def test_exercise_5_answer():
    """The folded answer: 1.4781 s at dt = 0.1 s, 1.4530 s at 0.05 s, exact 1.4278 s;
    errors 0.050 and 0.025 s."""
    times = {}
    for dt in (0.1, 0.05):
        run = nb05.apple_drop("forward_euler", dt=dt, h0=10.0, t_end=2.0)
        times[dt] = cl.events.first_crossing(run.t, run.y[:, 0, 0, 1], rule="linear")
    # closed form: exact heights of a parabola delayed by dt/2 — the crossing is exact arithmetic
    printed_holds(times[0.1], ".4f", "1.4781", 1e-12)
    printed_holds(times[0.05], ".4f", "1.4530", 1e-12)
    printed_holds(T_EXACT, ".4f", "1.4278", 0.0)
    assert f"{times[0.1] - T_EXACT:.3f}" == "0.050" and f"{times[0.05] - T_EXACT:.3f}" == "0.025"
    assert (times[0.1] - T_EXACT) / (times[0.05] - T_EXACT) == pytest.approx(2.0, rel=0.01)


def test_implicit_last_half_kick_keeps_second_order():
    """Explicit Verlet with drag is first order in v; solving the last half kick is second."""
    b, m, g = 0.5, 1.0, 9.81

    def run(h, implicit):
        x, v = 0.0, 0.0
        for _ in range(round(4.0 / h)):
            v_half = v + 0.5 * h * (-g - b / m * v)
            x = x + h * v_half
            if implicit:   # v = v_half + h/2 (-g - b v / m), solved for v
                v = (v_half - 0.5 * h * g) / (1 + 0.5 * h * b / m)
            else:
                v = v_half + 0.5 * h * (-g - b / m * v_half)
        return np.array([x, v])

    exact_v = -m * g / b * (1 - np.exp(-b * 4.0 / m))
    errs = {imp: [abs(run(h, imp)[1] - exact_v) for h in (0.02, 0.01)] for imp in (False, True)}
    assert errs[False][0] / errs[False][1] == pytest.approx(2.0, rel=0.02)
    assert errs[True][0] / errs[True][1] == pytest.approx(4.0, rel=0.02)


# --- the energy-band explorer -----------------------------------------------------------


def test_energy_bands_are_integrate_to_round_off():
    for dt in (0.1, 0.7):
        res = nb05.energy_bands(dt, periods=3)
        n = res.t.size - 1
        for m in nb05.BAND_METHODS:
            tr = cl.integrate(cl.systems.oscillator(1.0), [1.0, 0.0], (0.0, n * dt), dt, m)
            E = cl.systems.oscillator_energy(tr.y, 1.0) / 0.5
            # matrix powers and step-by-step runs round differently: ~ n ulp of the energy
            assert np.allclose(res.ratio[m], E, rtol=64 * n * np.finfo(float).eps, atol=0)


@pytest.mark.parametrize("dt", [0.02, 0.1, 0.5, 1.5])
def test_energy_bands_fill_their_theory_band(dt):
    res = nb05.energy_bands(dt)
    assert res.stable and res.verdict.startswith("stable")
    for m in ("symplectic_euler", "velocity_verlet"):
        (lo, hi), (low, high) = res.band[m], res.spread[m]
        # inside the band to round-off, and reaching within the sampling of its edges: a
        # step turns the state by ω~ dt, so the nearest sample misses an extreme of E by at
        # most a fraction (ω~ dt / 2)² of the band's width
        width, turn = hi - lo, nb05.discrete_frequency(1.0, dt) * dt
        tol = 1e-12 * n_steps(res)
        assert lo - tol <= low and high <= hi + tol
        assert low - lo <= width * (0.5 * turn) ** 2 + tol and hi - high <= width * (0.5 * turn) ** 2 + tol
    # forward Euler multiplies E by (1 + ω² dt²) every step
    n = n_steps(res)
    assert res.ratio["forward_euler"][n] == pytest.approx((1 + dt**2) ** n, rel=1e-9) or (
        not np.isfinite(res.ratio["forward_euler"][n]) and (1 + dt**2) ** n > 1e12)


def n_steps(res):
    return res.t.size - 1


def test_energy_bands_past_the_limit_and_bad_input():
    res = nb05.energy_bands(2.1)
    assert not res.stable and res.verdict.startswith("unstable: ω dt > 2")
    # exactly at the limit: a Jordan block. Symplectic Euler grows linearly; from (1, 0),
    # Verlet's eigenvector there, Verlet's energy stays E0 (it flips sign), and from any
    # other start it grows linearly too
    edge = nb05.energy_bands(2.0)
    assert not edge.stable and edge.verdict.startswith("marginal: ω dt = 2")
    assert edge.spread["velocity_verlet"] == pytest.approx((1.0, 1.0), abs=1e-12)
    se = edge.ratio["symplectic_euler"]
    n = np.arange(se.size)
    assert np.all(np.diff(se) >= 0) and se[-1] > 1e3
    assert np.sqrt(se[-1]) / n[-1] == pytest.approx(np.sqrt(se[-2]) / n[-2], rel=0.02)  # linear
    S = cl.lessons.nb07_spring_runs.step_matrix("velocity_verlet", 1.0, 1.0, 0.0, 2.0)
    assert np.allclose(S @ [1.0, 0.0], [-1.0, 0.0], atol=1e-15)
    assert np.linalg.norm(np.linalg.matrix_power(S, 40) @ [0.0, 1.0]) > 30   # generic start grows
    assert np.isnan(res.ratio["symplectic_euler"][-1])          # stopped past 1e12
    assert nb05.energy_bands(1.99).stable
    with pytest.raises(ValueError, match="dt"):
        nb05.energy_bands(0.0)
    # the theory bands of the verdict: ω dt = 0.1 gives [0.952, 1.05] and 0.25 %
    assert "[0.952, 1.05]" in nb05.energy_bands(0.1).verdict and "0.25 %" in nb05.energy_bands(0.1).verdict


def test_rk4_energy_drift(osc_runs):
    """'falls a little every step, by |R(iω dt)|² ≈ 1 - (ω dt)^6/72, 1.7e-5 in these 20
    periods': printed E/E0 = 0.999983 and the theory's value."""
    E = cl.systems.oscillator_energy(osc_runs["rk4"].y)
    R = abs(cl.amplification_factor("rk4", 0.1j))
    assert R**2 == pytest.approx(1 - 0.1**6 / 72 + 0.1**8 / 576, rel=1e-14)   # exactly
    assert np.all(np.diff(E) < 0)
    assert E[-1] / 0.5 == pytest.approx(R ** (2 * 1257), rel=1e-12)
    assert f"{E[-1] / 0.5:.6f}" == "0.999983" and f"{R ** (2 * 1257):.6f}" == "0.999983"
    assert round(1 - E[-1] / 0.5, 6) == pytest.approx(1.7e-5, abs=5e-7)


def test_band_widths_quoted_in_the_key_states():
    # "band width 0.05 at dt = 0.05 s, 0.1 at dt = 0.1 s, ratio 2.00" and Verlet's
    # "0.000625 ... 0.0025 ..., ratio 4.00": theory h / (1 - h²/4) and h²/4, sampled
    widths = {h: {m: np.ptp(nb05.energy_bands(h).ratio[m]) for m in ("symplectic_euler",
                                                                       "velocity_verlet")}
              for h in (0.05, 0.1)}
    for h in (0.05, 0.1):
        assert widths[h]["symplectic_euler"] == pytest.approx(h / (1 - h * h / 4), rel=1e-4)
        assert widths[h]["velocity_verlet"] == pytest.approx(h * h / 4, rel=1e-4)
    assert [f"{widths[h]['symplectic_euler']:.3g}" for h in (0.05, 0.1)] == ["0.05", "0.1"]
    assert [f"{widths[h]['velocity_verlet']:.3g}" for h in (0.05, 0.1)] == ["0.000625", "0.0025"]
    se = widths[0.1]["symplectic_euler"] / widths[0.05]["symplectic_euler"]
    vv = widths[0.1]["velocity_verlet"] / widths[0.05]["velocity_verlet"]
    assert (f"{se:.2f}", f"{vv:.2f}") == ("2.00", "4.00")


def test_energy_explorer_view_and_player():
    from course_lib.lessons import nb05_energy_view as view05

    view = view05.energy_explorer()
    assert view.result.stable and view.figure is not None
    view.controls["dt"].value = 2.2
    assert not view.result.stable
    plot = view05.EnergyBandPlot()
    fig = plot(nb05.energy_bands(2.2))
    assert fig.axes[0].get_yscale() == "log"
    fig = plot(nb05.energy_bands(0.2))
    assert fig.axes[0].get_yscale() == "linear"
    dots = {m: plot.dots[m].get_ydata()[0] for m in view05.WIDTH_METHODS}
    assert dots["velocity_verlet"] == pytest.approx(0.01, rel=1e-3)      # ω² dt² / 4
    # the review's cell 23: at ω dt = 1.9 the bands are wide (0.1 to 20), so the energy panel
    # goes to a log scale on which Verlet's band shows; the width panel has no Euler growth
    fig = plot(nb05.energy_bands(1.9))
    assert fig.axes[0].get_yscale() == "log"
    low, high = fig.axes[0].get_ylim()
    assert low < 1 - 0.25 * 1.9**2 and high > 1 / (1 - 0.5 * 1.9)
    assert set(plot.widths) == {"symplectic_euler", "velocity_verlet"}
    player = view05.energy_player(dts=(0.5, 2.1))
    assert player.labels == ["dt = 0.5 s", "dt = 2.1 s"]
    assert player.captions[0].startswith("stable") and player.captions[1].startswith("unstable")


def test_energy_widget_redraws_only_the_curves_and_its_picture_is_right():
    """Driven through its slider: small changes of dt reuse the kept background (axes,
    ticks, legends), a change of scale or limits redraws it, and each picture equals a
    full redraw of the figure; the energy panel holds the bands."""
    from course_lib.lessons import nb05_energy_view as view05

    view = view05.energy_explorer(dt=0.1)
    redrawn = []
    moves = [("dt", dt) for dt in (0.101, 0.102, 0.1035, 1.9, 2.2, 0.01)]
    for _, dt, res, fresh in drive_kept_figure(view, moves):
        redrawn.append(fresh)
        ax_e = view.figure.axes[0]
        assert ax_e.get_xlim()[1] >= res.t[-1] * res.omega / (2 * np.pi)
        if res.stable:
            low, high = ax_e.get_ylim()
            assert all(low <= res.band[m][0] and res.band[m][1] <= high
                       for m in view05.WIDTH_METHODS)
            assert ax_e.get_yscale() == ("log" if dt == 1.9 else "linear")
        else:
            assert ax_e.get_yscale() == "log"
    assert sum(redrawn) <= 4      # 0.101 and 0.102 reuse the background


# --- the checks: planted answers (tests/planted.py) ---------------------------------------

SE_RIGHT = """def symplectic_euler_step(f, t, y, dt):
    v = y[1] + dt * f(t, y)[1]
    return np.stack((y[0] + dt * v, v))"""
VV_RIGHT = """def velocity_verlet_step(f, t, y, dt):
    x, v = y[0], y[1]
    v_half = v + 0.5 * dt * f(t, y)[1]
    x_new = x + dt * v_half
    return np.stack((x_new, v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v_half)))[1]))"""
IMPACT_RIGHT = """def impact_time(t, h):
    k = np.flatnonzero(h < 0)[0]
    return t[k - 1] + (t[k] - t[k - 1]) * h[k - 1] / (h[k - 1] - h[k])"""
ORDER_RIGHT = """def observed_order(run, dt):
    a, b, c = (np.asarray(run(h), dtype=float) for h in (dt, dt / 2, dt / 4))
    d1, d2 = np.linalg.norm(a - b), np.linalg.norm(b - c)
    p = np.log2(d1 / d2)
    return p, d2 / (2**p - 1)"""


def _order_variant(body: str) -> str:
    return ORDER_RIGHT.replace("    return p, d2 / (2**p - 1)", body)


PLANTS = [
    Plant("symplectic_euler_step", "other", "right", SE_RIGHT, "correct", ""),
    Plant("symplectic_euler_step", "other", "right, in float32",
          SE_RIGHT.replace("return np.stack((y[0] + dt * v, v))",
                           "return np.stack((y[0] + dt * v, v)).astype(np.float32)"), "correct", ""),
    Plant("symplectic_euler_step", "delegating", "cl.symplectic_euler",
          "def symplectic_euler_step(f, t, y, dt):\n    return cl.symplectic_euler(f, t, y, dt)",
          "incorrect", "course_lib.steppers.symplectic_euler"),
    Plant("symplectic_euler_step", "delegating", "integrate one step",
          "def symplectic_euler_step(f, t, y, dt):\n"
          "    return cl.integrate(f, y, (t, t + dt), dt, 'symplectic_euler').y[-1]",
          "incorrect", "uses the reference"),
    Plant("symplectic_euler_step", "shortcut", "force at t = 0 (time frozen)",
          SE_RIGHT.replace("f(t, y)", "f(0.0, y)"), "incorrect",
          "your function evaluated f at time 0; the step starts at t = 0.7 s"),
    Plant("symplectic_euler_step", "misconception", "forward Euler (old velocity)",
          "def symplectic_euler_step(f, t, y, dt):\n"
          "    return np.stack((y[0] + dt * y[1], y[1] + dt * f(t, y)[1]))",
          "incorrect", "this is forward Euler"),
    Plant("symplectic_euler_step", "other", "updates y in place",
          "def symplectic_euler_step(f, t, y, dt):\n    y[1] += dt * f(t, y)[1]\n"
          "    y[0] += dt * y[1]\n    return y", "incorrect", "changed its input"),
    Plant("symplectic_euler_step", "other", "acceleration without the velocity (position only)",
          SE_RIGHT.replace("f(t, y)[1]", "f(t, np.stack((y[0], 0 * y[1])))[1]"), "incorrect",
          "your acceleration ignores the velocity"),
    Plant("symplectic_euler_step", "other", "velocity update off by a factor (evidence: v wrong)",
          SE_RIGHT.replace("v = y[1] + dt * f(t, y)[1]", "v = y[1] + 2 * dt * f(t, y)[1]"),
          "incorrect", "your positions follow from your velocities"),
    Plant("symplectic_euler_step", "other", "returns NaN", "def symplectic_euler_step(f, t, y, dt):"
          "\n    return np.full_like(y, np.nan)", "incorrect", "returned NaN or inf"),
    Plant("symplectic_euler_step", "other", "blank", "def symplectic_euler_step(f, t, y, dt):\n"
          "    raise NotImplementedError()", "pending", ""),
    Plant("velocity_verlet_step", "other", "right", VV_RIGHT, "correct", ""),
    Plant("velocity_verlet_step", "delegating", "cl.velocity_verlet",
          "def velocity_verlet_step(f, t, y, dt):\n    return cl.velocity_verlet(f, t, y, dt)",
          "incorrect", "course_lib.steppers.velocity_verlet"),
    Plant("velocity_verlet_step", "delegating", "half steps of cl.symplectic_euler",
          "def velocity_verlet_step(f, t, y, dt):\n    return cl.symplectic_euler(f, t, y, dt)",
          "incorrect", "uses the reference"),
    Plant("velocity_verlet_step", "shortcut", "old velocity in the new force (breaks with drag)",
          VV_RIGHT.replace("np.stack((x_new, v_half)))[1]", "np.stack((x_new, v)))[1]"),
          "incorrect", "you passed the OLD velocity v"),
    Plant("velocity_verlet_step", "misconception", "whole kicks instead of half kicks",
          "def velocity_verlet_step(f, t, y, dt):\n    a = f(t, y)[1]\n"
          "    return np.stack((y[0] + dt * (y[1] + dt * a), y[1] + dt * a))",
          "incorrect", "use half kicks"),
    Plant("velocity_verlet_step", "other", "second kick with the old acceleration",
          "def velocity_verlet_step(f, t, y, dt):\n    a = f(t, y)[1]\n"
          "    v_half = y[1] + 0.5 * dt * a\n"
          "    return np.stack((y[0] + dt * v_half, v_half + 0.5 * dt * a))",
          "incorrect", "acceleration at the NEW position"),
    Plant("velocity_verlet_step", "other", "new force at t instead of t + dt",
          VV_RIGHT.replace("f(t + dt,", "f(t,"), "incorrect", "END of the step"),
    Plant("velocity_verlet_step", "other", "scipy's solve_ivp across the step",
          "def velocity_verlet_step(f, t, y, dt):\n    from scipy.integrate import solve_ivp\n"
          "    sol = solve_ivp(lambda s, z: f(s, z.reshape(y.shape)).ravel(), (t, t + dt), "
          "np.ravel(y), rtol=1e-12, atol=1e-12)\n    return sol.y[:, -1].reshape(y.shape)",
          "incorrect", "different times: one step of this method evaluates it at t and t + dt only"),
    Plant("velocity_verlet_step", "other", "a whole first kick, half last kick",
          VV_RIGHT.replace("v_half = v + 0.5 * dt * f(t, y)[1]", "v_half = v + dt * f(t, y)[1]"),
          "incorrect", "the first kick is a HALF kick"),
    Plant("velocity_verlet_step", "other", "the implicit last kick, solved by iteration",
          VV_RIGHT.replace(
              "    return np.stack((x_new, v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v_half)))[1]))",
              "    v_new = v_half\n    for _ in range(100):\n"
              "        v_new = v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v_new)))[1]\n"
              "    return np.stack((x_new, v_new))"),
          "incorrect", "that is the implicit last kick of section 2"),
    Plant("velocity_verlet_step", "other", "old velocity in the new force, second try: more said",
          VV_RIGHT.replace("np.stack((x_new, v_half)))[1]", "np.stack((x_new, v)))[1]"),
          "incorrect", "the velocity after the first half kick", attempt=1),
    Plant("impact_time", "other", "right", IMPACT_RIGHT, "correct", ""),
    Plant("impact_time", "other", "right, returned as float32",
          IMPACT_RIGHT.replace("    return t[k - 1]", "    return np.float32(t[k - 1]")
          .replace("h[k])", "h[k]))"), "correct", ""),
    Plant("impact_time", "delegating", "cl.events.first_crossing",
          "def impact_time(t, h):\n    return cl.events.first_crossing(t, h)",
          "incorrect", "course_lib.events.first_crossing"),
    Plant("impact_time", "delegating", "cl.events.crossing_linear",
          "def impact_time(t, h):\n    k = np.flatnonzero(h < 0)[0]\n"
          "    return cl.events.crossing_linear(t[k - 1], h[k - 1], t[k], h[k])",
          "incorrect", "uses the reference"),
    Plant("impact_time", "shortcut", "np.interp on the reversed samples (finds the last crossing)",
          "def impact_time(t, h):\n    return np.interp(0.0, h[::-1], t[::-1])",
          "incorrect", "LAST crossing"),
    Plant("impact_time", "shortcut", "last sample at or above 0 in the whole run: no np.interp hint",
          "def impact_time(t, h):\n    k = np.flatnonzero(h >= 0)[-1]\n"
          "    return t[k] + (t[k + 1] - t[k]) * h[k] / (h[k] - h[k + 1])",
          "incorrect", "LAST crossing", avoid="np.interp"),
    Plant("impact_time", "shortcut", "step taken as t[1] - t[0] (assumes even steps)",
          IMPACT_RIGHT.replace("(t[k] - t[k - 1])", "(t[1] - t[0])"), "incorrect",
          "not evenly spaced"),
    Plant("impact_time", "shortcut", "first sign change (assumes h starts above 0)",
          IMPACT_RIGHT.replace("k = np.flatnonzero(h < 0)[0]",
                               "k = np.flatnonzero(np.diff(np.sign(h)))[0] + 1"),
          "incorrect", "a sign change from 0 to + is the throw"),
    Plant("impact_time", "misconception", "time of the first sample below ground",
          "def impact_time(t, h):\n    return t[np.flatnonzero(h < 0)[0]]", "incorrect",
          "first sample below ground"),
    Plant("impact_time", "other", "h[k] in the numerator",
          IMPACT_RIGHT.replace("h[k - 1] / (h", "h[k] / (h"), "incorrect",
          "you put h[k] on top"),
    Plant("impact_time", "other", "returns the index", "def impact_time(t, h):\n"
          "    return int(np.flatnonzero(h < 0)[0])", "incorrect", "you returned an index"),
    Plant("impact_time", "other", "returns a list", "def impact_time(t, h):\n    return [1.0, 2.0]",
          "incorrect", "expected one number"),
    Plant("observed_order", "other", "right", ORDER_RIGHT, "correct", ""),
    Plant("observed_order", "delegating", "lesson.three_grid_order",
          "def observed_order(run, dt):\n    return lesson05.three_grid_order(run, dt)",
          "incorrect", "course_lib.lessons.nb05_newton.three_grid_order"),
    Plant("observed_order", "shortcut", "rounds p to a whole number",
          _order_variant("    return round(p), d2 / (2**round(p) - 1)"), "incorrect",
          "you rounded p"),
    Plant("observed_order", "shortcut", "largest entry instead of the norm (breaks on arrays)",
          ORDER_RIGHT.replace("np.linalg.norm(a - b), np.linalg.norm(b - c)",
                              "np.abs(a - b).max(), np.abs(b - c).max()"), "incorrect",
          "Euclidean norm"),
    Plant("observed_order", "shortcut", "abs of the difference (assumes a number)",
          ORDER_RIGHT.replace("np.linalg.norm(a - b), np.linalg.norm(b - c)",
                              "abs(a - b), abs(b - c)"), "incorrect",
          "reduce each difference to one number"),
    Plant("observed_order", "misconception", "the ratio itself, no logarithm",
          ORDER_RIGHT.replace("np.log2(d1 / d2)", "d1 / d2"), "incorrect",
          "the order is in its exponent"),
    Plant("observed_order", "other", "the ratio itself: the error follows it, fix p first",
          ORDER_RIGHT.replace("np.log2(d1 / d2)", "d1 / d2"), "incorrect",
          "fix the order first"),
    Plant("observed_order", "other", "signed sums instead of norms",
          ORDER_RIGHT.replace("np.linalg.norm(a - b), np.linalg.norm(b - c)",
                              "abs(np.sum(a - b)), abs(np.sum(b - c))"), "incorrect",
          "not a signed sum"),
    Plant("observed_order", "other", "finest difference taken as the error, second try: no formula",
          _order_variant("    return p, d2"), "incorrect", "which multiple", avoid="2^p - 1",
          attempt=1),
    Plant("observed_order", "other", "finest difference over 2^p (not 2^p - 1)",
          _order_variant("    return p, d2 / 2**p"), "incorrect",
          "is not 2^p times the finest run's error"),
    Plant("observed_order", "other", "finest difference over 2^p, second try: a question",
          _order_variant("    return p, d2 / 2**p"), "incorrect", "what is left?", attempt=1),
    Plant("observed_order", "other", "natural logarithm",
          ORDER_RIGHT.replace("np.log2(d1 / d2)", "np.log(d1 / d2)"), "incorrect",
          "base-2 logarithm"),
    Plant("observed_order", "other", "error of the middle run",
          _order_variant("    return p, d1 / (2**p - 1)"), "incorrect", "MIDDLE run"),
    Plant("observed_order", "other", "finest difference taken as the error",
          _order_variant("    return p, d2"), "incorrect", "not the finest run's own error"),
    Plant("observed_order", "other", "upside-down ratio",
          ORDER_RIGHT.replace("np.log2(d1 / d2)", "np.log2(d2 / d1)"), "incorrect", "upside down"),
    Plant("observed_order", "other", "coarser grids", "def observed_order(run, dt):\n"
          "    a, b, c = (np.asarray(run(h)) for h in (4 * dt, 2 * dt, dt))\n"
          "    p = np.log2(np.linalg.norm(a - b) / np.linalg.norm(b - c))\n"
          "    return p, np.linalg.norm(b - c) / (2**p - 1)", "incorrect",
          "run the three grids dt, dt/2 and dt/4"),
    Plant("observed_order", "other", "never runs", "def observed_order(run, dt):\n    return 2.0, 0.0",
          "incorrect", "never called run"),
    Plant("observed_order", "other", "returns p only",
          _order_variant("    return p"), "incorrect", "return a pair (p, error)"),
]


@pytest.mark.parametrize("plant", PLANTS, ids=lambda p: f"{p.exercise}: {p.label}")
def test_planted_answer(plant):
    judge(check, plant)


def test_every_exercise_has_the_three_kinds_of_plants():
    for exercise in ("symplectic_euler_step", "velocity_verlet_step", "impact_time", "observed_order"):
        kinds = {p.kind for p in PLANTS if p.exercise == exercise}
        assert {"delegating", "shortcut", "misconception"} <= kinds, exercise


def test_hints_escalate_in_a_kernel(capsys):
    """The nudge first; a stronger nudge after a second wrong attempt, never the code."""
    forward = define(PLANTS[5].source, "symplectic_euler_step")
    FAILURES.pop(check.symplectic_euler_step.key, None)
    check.symplectic_euler_step(forward)
    first = capsys.readouterr().out
    assert "this is forward Euler" in first and "update the velocity first" not in first
    check.symplectic_euler_step(forward)
    second = capsys.readouterr().out
    assert "update the velocity first" in second and "x_new =" not in second
    FAILURES.pop(check.symplectic_euler_step.key, None)


NO_CODE = "= x +"      # no hint, at any attempt, writes out the update


@pytest.mark.parametrize("attempt", [0, 1, 2])
def test_no_hint_of_the_step_exercises_prints_the_update(attempt):
    for plant in PLANTS:
        steps = ("symplectic_euler_step", "velocity_verlet_step")
        if plant.exercise in steps and plant.status == "incorrect":
            judge(check, Plant(plant.exercise, plant.kind, plant.label, plant.source, plant.status,
                               "", avoid="f(t + dt, (x_new", attempt=attempt))
            judge(check, Plant(plant.exercise, plant.kind, plant.label, plant.source, plant.status,
                               "", avoid=NO_CODE, attempt=attempt))


def test_checks_report_pending_and_correct_to_results(capsys):
    def stub(*args):
        raise NotImplementedError()

    for name in ("symplectic_euler_step", "velocity_verlet_step", "impact_time", "observed_order"):
        getattr(check, name)(stub)
        assert RESULTS[f"nb05.{name}"]["status"] == "pending"
    check.impact_time(define(IMPACT_RIGHT, "impact_time"))
    assert RESULTS["nb05.impact_time"]["status"] == "correct"
    assert "✓ impact_time: correct" in capsys.readouterr().out
