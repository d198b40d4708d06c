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
    return {m: cl.integrate(f, [1.0, 0.0], (0.0, 40 * np.pi), 0.1, m)
            for m in ("forward_euler", "symplectic_euler", "velocity_verlet")}


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


# --- the checks --------------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb05.{name}"]["status"]


def _stub(*args):
    raise NotImplementedError()


def test_check_symplectic_euler(capsys):
    check.symplectic_euler_step(lambda f, t, y, dt: cl.symplectic_euler(f, t, y, dt))
    assert _status("symplectic_euler_step") == "correct"
    check.symplectic_euler_step(lambda f, t, y, dt: cl.forward_euler(f, t, y, dt))
    assert _status("symplectic_euler_step") == "incorrect"
    assert "this is forward Euler" in capsys.readouterr().out
    check.symplectic_euler_step(_stub)
    assert _status("symplectic_euler_step") == "pending"


def test_check_velocity_verlet(capsys):
    check.velocity_verlet_step(lambda f, t, y, dt: cl.velocity_verlet(f, t, y, dt))
    assert _status("velocity_verlet_step") == "correct"

    def stale(f, t, y, dt):
        a = f(t, y)[1]
        return np.stack((y[0] + dt * y[1] + 0.5 * dt**2 * a, y[1] + dt * a))

    check.velocity_verlet_step(stale)
    assert _status("velocity_verlet_step") == "incorrect"
    assert "acceleration at the NEW position" in capsys.readouterr().out
    check.velocity_verlet_step(_stub)
    assert _status("velocity_verlet_step") == "pending"


def test_check_impact_time(capsys):
    check.impact_time(lambda t, h: events.first_crossing(t, h))
    assert _status("impact_time") == "correct"
    check.impact_time(lambda t, h: t[np.flatnonzero(h < 0)[0]])
    assert _status("impact_time") == "incorrect"
    assert "first step below ground" in capsys.readouterr().out
    check.impact_time(_stub)
    assert _status("impact_time") == "pending"


def test_check_euler_apple_height(capsys):
    check.euler_apple_height(lambda n, dt, h0, g: h0 - g * dt**2 * n * (n - 1) / 2)
    assert _status("euler_apple_height") == "correct"
    check.euler_apple_height(lambda n, dt, h0, g: h0 - g * dt**2 * n * (n + 1) / 2)
    assert _status("euler_apple_height") == "incorrect"
    assert "symplectic Euler's height" in capsys.readouterr().out
    check.euler_apple_height(_stub)
    assert _status("euler_apple_height") == "pending"
