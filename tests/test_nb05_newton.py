"""Every number quoted in notebook 05 (Newton's second law), and its exercise checks."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import events
from course_lib.check import RESULTS
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


# --- the checks --------------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb05.{name}"]["status"]


def _stub(*args):
    raise NotImplementedError()


def _se(f, t, y, dt):
    v = y[1] + dt * f(t, y)[1]
    return np.stack((y[0] + dt * v, v))


def _vv(f, t, y, dt, old_v=False, t_shift=False):
    x, v = y[0], y[1]
    v_half = v + 0.5 * dt * f(t, y)[1]
    x_new = x + dt * v_half
    a_new = f(t if t_shift else t + dt, np.stack((x_new, v if old_v else v_half)))[1]
    return np.stack((x_new, v_half + 0.5 * dt * a_new))


def _main(func):
    func.__module__ = "__main__"            # as if written in the notebook
    return func


def test_check_symplectic_euler(capsys):
    check.symplectic_euler_step(_se)
    assert _status("symplectic_euler_step") == "correct"
    check.symplectic_euler_step(lambda f, t, y, dt: _se(f, t, y, dt).astype(np.float32))
    assert _status("symplectic_euler_step") == "correct"
    capsys.readouterr()
    check.symplectic_euler_step(lambda f, t, y, dt: cl.forward_euler(f, t, y, dt))
    assert _status("symplectic_euler_step") == "incorrect"
    assert "this is forward Euler" in capsys.readouterr().out

    def late(f, t, y, dt):
        v = y[1] + dt * f(t + dt, y)[1]
        return np.stack((y[0] + dt * v, v))

    check.symplectic_euler_step(late)
    assert "not f(t + dt, y)" in capsys.readouterr().out
    check.symplectic_euler_step(lambda f, t, y, dt: np.full_like(y, np.nan))
    out = capsys.readouterr().out
    assert "returned NaN" in out and "nan" not in out.replace("NaN", "")

    def inplace(f, t, y, dt):
        y[1] += dt * f(t, y)[1]
        y[0] += dt * y[1]
        return y

    check.symplectic_euler_step(inplace)
    assert "changed its input" in capsys.readouterr().out
    check.symplectic_euler_step(_main(lambda f, t, y, dt: cl.symplectic_euler(f, t, y, dt)))
    assert "uses the reference" in capsys.readouterr().out
    check.symplectic_euler_step(_stub)
    assert _status("symplectic_euler_step") == "pending"


def test_check_velocity_verlet(capsys):
    check.velocity_verlet_step(_vv)
    assert _status("velocity_verlet_step") == "correct"
    check.velocity_verlet_step(lambda f, t, y, dt: _vv(f, t, y, dt).astype(np.float32))
    assert _status("velocity_verlet_step") == "correct"
    capsys.readouterr()

    def stale(f, t, y, dt):
        a = f(t, y)[1]
        return np.stack((y[0] + dt * y[1] + 0.5 * dt**2 * a, y[1] + dt * a))

    check.velocity_verlet_step(stale)
    assert _status("velocity_verlet_step") == "incorrect"
    out = capsys.readouterr().out
    assert "acceleration at the NEW position" in out and "OLD velocity" not in out
    check.velocity_verlet_step(lambda f, t, y, dt: _vv(f, t, y, dt, old_v=True))
    out = capsys.readouterr().out
    assert "you passed the OLD velocity v" in out and out.count("\n   ✗") == 2   # the oscillator passes
    check.velocity_verlet_step(lambda f, t, y, dt: _vv(f, t, y, dt, t_shift=True))
    out = capsys.readouterr().out
    assert "END of the step: f(t + dt, ...)" in out and out.count("\n   ✗") == 1  # only the driven case
    check.velocity_verlet_step(_main(lambda f, t, y, dt: cl.velocity_verlet(f, t, y, dt)))
    assert "uses the reference" in capsys.readouterr().out
    check.velocity_verlet_step(_stub)
    assert _status("velocity_verlet_step") == "pending"


def _impact(t, h):
    k = np.flatnonzero(h < 0)[0]
    return t[k - 1] + (t[k] - t[k - 1]) * h[k - 1] / (h[k - 1] - h[k])


def test_check_impact_time(capsys):
    check.impact_time(_impact)
    assert _status("impact_time") == "correct"
    check.impact_time(lambda t, h: np.float32(_impact(t, h)))
    assert _status("impact_time") == "correct"
    capsys.readouterr()
    check.impact_time(lambda t, h: t[np.flatnonzero(h < 0)[0]])
    assert _status("impact_time") == "incorrect"
    assert "first step below ground" in capsys.readouterr().out

    def wrong_numerator(t, h):
        k = np.flatnonzero(h < 0)[0]
        return t[k - 1] + (t[k] - t[k - 1]) * h[k] / (h[k - 1] - h[k])

    check.impact_time(wrong_numerator)
    assert "you used h[k] in the numerator" in capsys.readouterr().out
    check.impact_time(lambda t, h: int(np.flatnonzero(h < 0)[0]))
    assert "you returned an index" in capsys.readouterr().out
    check.impact_time(_main(lambda t, h: cl.events.first_crossing(t, h)))
    assert "uses the reference" in capsys.readouterr().out
    check.impact_time(_stub)
    assert _status("impact_time") == "pending"


def _order(run, dt):
    a, b, c = (np.asarray(run(h), dtype=float) for h in (dt, dt / 2, dt / 4))
    d1, d2 = np.linalg.norm(a - b), np.linalg.norm(b - c)
    p = np.log2(d1 / d2)
    return p, d2 / (2**p - 1)


def test_check_observed_order(capsys):
    check.observed_order(_order)
    assert _status("observed_order") == "correct"
    check.observed_order(lambda run, dt: tuple(np.float32(v) for v in _order(run, dt)))
    assert _status("observed_order") == "correct"
    capsys.readouterr()

    def natural_log(run, dt):
        p, err = _order(run, dt)
        return p * np.log(2), err

    def no_division(run, dt):
        p, err = _order(run, dt)
        return p, err * (2**p - 1)

    def middle_error(run, dt):
        p, err = _order(run, dt)
        return p, err * 2**p

    def inverted(run, dt):
        p, err = _order(run, dt)
        return -p, err

    def coarser_grids(run, dt):
        return _order(lambda h: run(4 * h), dt)

    for answer, hint in [(natural_log, "base-2 logarithm"), (no_division, "divide by 2^p - 1"),
                         (middle_error, "error of the MIDDLE run"), (inverted, "upside down"),
                         (coarser_grids, "run the three grids dt, dt/2 and dt/4")]:
        check.observed_order(answer)
        assert _status("observed_order") == "incorrect"
        assert hint in capsys.readouterr().out, hint
    check.observed_order(lambda run, dt: 2.0)
    assert "never called run" in capsys.readouterr().out
    check.observed_order(lambda run, dt: _order(run, dt)[0])
    assert "return a pair (p, error)" in capsys.readouterr().out
    check.observed_order(_main(lambda run, dt: nb05.three_grid_order(run, dt)))
    assert "uses the reference" in capsys.readouterr().out
    check.observed_order(_stub)
    assert _status("observed_order") == "pending"
