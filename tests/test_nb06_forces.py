"""Every number quoted in notebook 06 (forces), and its exercise checks."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import events, forces
from course_lib.check import RESULTS
from course_lib.check import nb06 as check
from course_lib.lessons import nb06_forces as nb06

G = 9.81


def test_net_force_is_the_sum():
    rng = np.random.default_rng(2026)
    x, v = rng.uniform(-1, 1, size=(5, 2)), rng.normal(size=(5, 2))
    mass = np.array([1.0, 2.0, 1.0, 0.5, 1.5])
    net = cl.systems.sum_forces(cl.forces.constant_gravity(mass, g=[0.0, -G]),
                                cl.forces.drag(b=0.4, wind=[2.0, 0.0]))
    F = net(0.0, x, v)
    assert F.shape == (5, 2)
    assert np.allclose(F, mass[:, None] * [0.0, -G] - 0.4 * (v - [2.0, 0.0]))
    assert np.allclose(np.round(F[0], 4), [0.512, -10.0159])            # printed


def test_two_body_period():
    masses, y0, T = nb06.two_body_circular(M=1.0, m=0.01, r=1.0, G=1.0)
    assert T == pytest.approx(2 * np.pi * np.sqrt(1 / 1.01), rel=1e-15)
    system = cl.newtonian(cl.forces.nbody_gravity(masses, G=1.0), masses)
    orbit = cl.integrate(system, y0, (0.0, 5 * T), T / 2000, "velocity_verlet")
    sep = orbit.y[:, 0, 1] - orbit.y[:, 0, 0]
    T_meas = events.measured_period(orbit.t, sep[:, 1])
    assert T_meas == pytest.approx(T, rel=1e-5)                 # "a few parts per million"
    assert 1e-6 < abs(T_meas / T - 1) < 1e-5
    assert np.allclose(np.linalg.norm(sep, axis=1), 1.0, atol=1e-5)   # circular
    # total momentum stays zero, centre of mass at rest at the origin
    com = np.einsum("k,nkd->nd", masses, orbit.y[:, 0]) / masses.sum()
    assert np.abs(com).max() < 1e-12
    assert round(T, 6) == 6.252003 and round(T_meas, 6) == 6.252024    # printed
    assert f"{abs(T_meas / T - 1):.1e}" == "3.3e-06"


def test_two_body_period_error_is_second_order():
    masses, y0, T = nb06.two_body_circular(M=1.0, m=0.01, r=1.0, G=1.0)
    system = cl.newtonian(cl.forces.nbody_gravity(masses, G=1.0), masses)
    errs = []
    for steps in (1000, 2000):
        orbit = cl.integrate(system, y0, (0.0, 5 * T), T / steps, "velocity_verlet")
        sep = orbit.y[:, 0, 1] - orbit.y[:, 0, 0]
        errs.append(abs(events.measured_period(orbit.t, sep[:, 1]) / T - 1))
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.01)           # shrinks like dt²


def test_cluster_conservation():
    m, y0 = nb06.cluster(n=8, seed=2026)
    assert m.sum() == pytest.approx(1.0)
    assert np.allclose(m @ y0[0], 0.0) and np.allclose(m @ y0[1], 0.0)
    stars = cl.newtonian(cl.forces.nbody_gravity(m, softening=0.1), m)
    out = {}
    for meth in ("forward_euler", "symplectic_euler", "velocity_verlet", "rk4"):
        tr = cl.integrate(stars, y0, (0.0, 20.0), 0.01, meth)
        E = forces.nbody_energy(tr.y, m, softening=0.1)
        L = forces.angular_momentum(tr.y, m)
        out[meth] = (np.abs(E / E[0] - 1).max(), np.abs(L - L[0]).max())
    assert out["forward_euler"][0] > 0.5 and out["forward_euler"][1] > 1e-2
    assert out["symplectic_euler"][1] < 1e-13 and out["velocity_verlet"][1] < 1e-13
    assert 1e-9 < out["rk4"][1] < 1e-5
    assert out["rk4"][0] < out["velocity_verlet"][0] < out["symplectic_euler"][0] < 0.1
    assert out["symplectic_euler"][0] < out["forward_euler"][0]
    printed = {m: (f"{dE:.0e}", f"{dL:.0e}") for m, (dE, dL) in out.items()}
    assert printed["forward_euler"] == ("1e+00", "3e-02")
    assert printed["symplectic_euler"][0] == "4e-02"
    assert printed["velocity_verlet"][0] == "5e-03"
    assert printed["rk4"] == ("2e-04", "2e-07")


def test_terminal_velocity_and_euler_closed_form():
    m, b, dt = 1.0, 0.5, 0.25
    assert m * G / b == pytest.approx(19.62) and m / b == 2.0
    faller = cl.newtonian(cl.systems.sum_forces(cl.forces.constant_gravity(m, g=[0.0, -G]),
                                                cl.forces.drag(b=b)), m)
    start = cl.stack_state([[0.0, 0.0]], [[0.0, 0.0]])
    fe = cl.integrate(faller, start, (0.0, 12.0), dt, "forward_euler")
    n = np.arange(fe.t.size)
    assert np.allclose(fe.y[:, 1, 0, 1], -19.62 * (1 - (1 - b * dt / m) ** n), atol=1e-12)
    rk = cl.integrate(faller, start, (0.0, 60.0), dt, "rk4")
    assert rk.y[-1, 1, 0, 1] == pytest.approx(-19.62, rel=1e-10)    # reaches mg/b
    exact = -19.62 * (1 - np.exp(-b * rk.t / m))
    assert np.abs(rk.y[:, 1, 0, 1] - exact).max() < 2e-5
    assert round(-19.62 * (1 - np.exp(-6)), 4) == -19.5714
    # forward Euler's factor (1 - b dt/m) must have modulus < 1: b dt / m < 2
    assert abs(1 - b * 3.9 / m) < 1 < abs(1 - b * 4.1 / m)
    assert b * dt / m == 0.125


def test_drag_printed_errors_and_verlet_order():
    m, b, dt = 1.0, 0.5, 0.25
    faller = cl.newtonian(cl.systems.sum_forces(cl.forces.constant_gravity(m, g=[0.0, -G]),
                                                cl.forces.drag(b=b)), m)
    start = cl.stack_state([[0.0, 0.0]], [[0.0, 0.0]])

    def run(meth, step):
        tr = cl.integrate(faller, start, (0.0, 12.0), step, meth)
        v = tr.y[:, 1, 0, 1]
        return tr, v[-1], np.abs(v + 19.62 * (1 - np.exp(-b * tr.t / m))).max()

    printed = {}
    for meth in ("forward_euler", "velocity_verlet", "rk4"):
        _, v_end, err = run(meth, dt)
        printed[meth] = (round(v_end, 4), f"{err:.1e}")
    assert printed == {"forward_euler": (-19.5877, "4.8e-01"),
                       "velocity_verlet": (-19.58, "2.3e-01"),
                       "rk4": (-19.5714, "1.6e-05")}
    # Verlet's two half kicks are two forward Euler steps of dt/2 when F depends on v only
    vv, _, err_vv = run("velocity_verlet", dt)
    fe_half, _, err_fe_half = run("forward_euler", dt / 2)
    assert np.allclose(vv.y[:, 1], fe_half.y[::2, 1], rtol=0, atol=1e-12)
    # so both are first order: halving dt halves the error; Verlet is "twice as good"
    _, _, err_fe = run("forward_euler", dt)
    assert err_fe / err_fe_half == pytest.approx(2.0, rel=0.05)
    assert err_fe / err_vv == pytest.approx(2.0, rel=0.05)
    _, _, err_vv_half = run("velocity_verlet", dt / 2)
    assert err_vv / err_vv_half == pytest.approx(2.0, rel=0.05)


def test_wind_exact_solution():
    t = np.linspace(0, 2.0, 41)
    for w in (0.0, -4.0):
        system = cl.newtonian(cl.systems.sum_forces(cl.forces.constant_gravity(1.0, g=[0.0, -G]),
                                                    cl.forces.drag(b=0.5, wind=[w, 0.0])), 1.0)
        tr = cl.integrate(system, cl.stack_state([[0.0, 0.0]], [[5.0, 5.0]]), (0.0, 2.0), 0.05,
                          "rk4")
        x, v = nb06.linear_drag_exact(t, [0, 0], [5, 5], 1.0, 0.5, wind=[w, 0.0])
        assert np.allclose(tr.y[:, 0, 0], x, atol=1e-6)
        assert np.allclose(tr.y[:, 1, 0], v, atol=1e-6)
    # head wind -4 m/s: horizontal velocity -4 + 9 e^{-t/2} changes sign at 2 ln(9/4) s
    t_turn = 2 * np.log(9 / 4)
    assert round(t_turn, 2) == 1.62
    _, v_turn = nb06.linear_drag_exact([t_turn], [0, 0], [5, 5], 1.0, 0.5, wind=[-4.0, 0.0])
    assert v_turn[0, 0] == pytest.approx(0.0, abs=1e-12)


def test_damping_glide_distance():
    glider = cl.newtonian(cl.forces.viscous_damping(0.5), 1.0)
    glide = cl.integrate(glider, cl.stack_state([[0.0, 0.0]], [[2.0, 0.0]]), (0.0, 40.0), 0.01,
                         "rk4")
    assert glide.y[-1, 0, 0, 0] == pytest.approx(4 * (1 - np.exp(-20)), rel=1e-9)
    assert 2.0 * 1.0 / 0.5 == 4.0


def test_friction_stopping():
    mu, v0, dt = 0.5, 5.0, 0.001
    assert round(v0 / (mu * G), 3) == 1.019 and round(v0**2 / (2 * mu * G), 3) == 2.548
    puck = cl.newtonian(cl.forces.constant_gravity(1.0, g=[0.0, -G]), 1.0)
    ground = cl.collisions.plane(normal=(0.0, 1.0), restitution=0.0, friction=mu)
    slide = cl.integrate(puck, cl.stack_state([[0.0, 0.0]], [[v0, 0.0]]), (0.0, 1.5), dt,
                         "symplectic_euler", post_step=ground)
    vx = slide.y[:, 1, 0, 0]
    t_stop = slide.t[np.flatnonzero(vx <= 0)[0]]
    assert abs(t_stop - v0 / (mu * G)) <= dt
    assert abs(slide.y[-1, 0, 0, 0] - v0**2 / (2 * mu * G)) <= v0 * dt
    assert round(t_stop, 3) == 1.020 and round(slide.y[-1, 0, 0, 0], 3) == 2.551
    # deceleration mu g while sliding, the puck never leaves the ground
    assert np.allclose(np.diff(vx[:1000]), -mu * G * dt, atol=1e-12)
    assert np.all(slide.y[:, 0, 0, 1] == 0.0)


def test_bouncing_ball_ratios():
    e = 0.8
    t, h, _ = nb06.bouncing_ball(h0=1.0, restitution=e, dt=0.01, t_end=3.0, locate=True)
    _, peaks = events.local_maxima(t, h)
    assert np.allclose(peaks[:4], e ** (2 * np.arange(1, 5)), rtol=1e-10)
    assert np.allclose(np.round(peaks[:4], 4), [0.64, 0.4096, 0.2621, 0.1678])
    t, h, _ = nb06.bouncing_ball(h0=1.0, restitution=e, dt=0.01, t_end=3.0, locate=False)
    _, peaks = events.local_maxima(t, h)
    ratios = peaks[:4] / np.r_[1.0, peaks[:3]]
    assert np.all((ratios > 0.65) & (ratios < 0.68))       # "between 0.65 and 0.68"
    assert np.allclose(np.round(peaks[:4], 4), [0.6643, 0.4344, 0.2871, 0.1932])   # printed
    assert np.allclose(np.round(ratios, 4), [0.6643, 0.654, 0.6608, 0.673])
    assert np.ptp(ratios) > 0.01                            # scatters bounce to bounce


def test_bounce_post_step_error_shrinks_with_dt():
    errs = []
    for dt in (0.01, 0.001):
        t, h, _ = nb06.bouncing_ball(dt=dt, t_end=1.0, locate=False)
        errs.append(abs(events.local_maxima(t, h)[1][0] - 0.64))
    assert errs[1] < errs[0] / 5


def test_helix():
    tr = nb06.charged_particle(1.0, 1.0, (0.0, 0.0, 2.0), (1.0, 0.0, 0.3), dt=0.01, t_end=10.0)
    center, r = events.fit_circle(tr.y[:, 0, 0, :2])
    assert r == pytest.approx(0.5, rel=1e-6)
    assert np.allclose(center, [0.0, -0.5], atol=1e-6)
    T = events.measured_period(tr.t, tr.y[:, 1, 0, 1])
    assert T == pytest.approx(np.pi, rel=1e-7)
    assert np.interp(T, tr.t, tr.y[:, 0, 0, 2]) == pytest.approx(0.3 * np.pi, rel=1e-6)
    assert round(0.3 * np.pi, 3) == 0.942
    assert round(np.pi / 0.01) == 314                                    # steps per turn
    assert 1.0 * 2.0 / 1.0 == 2.0 and 2 * np.pi / 2.0 == np.pi           # omega_c, period
    assert 3 < 10.0 / np.pi < 3.5                                        # "three turns"
    speed = np.linalg.norm(tr.y[:, 1, 0], axis=1)
    assert np.allclose(speed, np.hypot(1.0, 0.3), rtol=1e-8)
    fe = nb06.charged_particle(1.0, 1.0, (0.0, 0.0, 2.0), (1.0, 0.0, 0.3), dt=0.01, t_end=1.0,
                                method="forward_euler")
    vperp = np.linalg.norm(fe.y[:, 1, 0, :2], axis=1)
    assert np.allclose(vperp[1:] / vperp[:-1], np.sqrt(1 + 0.02**2), rtol=1e-13)


def test_steering_widget_and_pure_function():
    still = nb06.steer_swarm(cx=1.0, cy=0.5, strength=2.0, wind=0.0)
    assert np.allclose(np.round(still.centroid, 2), [0.99, 0.50])
    windy = nb06.steer_swarm(cx=1.0, cy=0.5, strength=2.0, wind=-1.0)
    assert np.allclose(np.round(windy.centroid, 2), [-0.05, 0.45])
    again = nb06.steer_swarm(cx=1.0, cy=0.5, strength=2.0, wind=-1.0)
    assert np.array_equal(again.x, windy.x)                        # pure and seeded
    view = nb06.steering_view(cx=1.0, cy=0.5)
    assert np.allclose(view.result.center, [1.0, 0.5])
    view.controls["cx"].value = -1.5
    assert np.allclose(view.result.center, [-1.5, 0.5])
    assert view.result.centroid[0] < -1.0                           # the swarm followed
    view.controls["wind"].value = 2.0
    assert view.result.wind[0] == 2.0
    assert view.result.centroid[0] > -1.5                           # blown downstream (+x)


# --- the checks --------------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb06.{name}"]["status"]


def _stub(*args):
    raise NotImplementedError()


def test_check_drag_force(capsys):
    check.drag_force(lambda v, b, w: -b * (v - w))
    assert _status("drag_force") == "correct"
    check.drag_force(lambda v, b, w: b * (v - w))
    assert _status("drag_force") == "incorrect"
    assert "sign error" in capsys.readouterr().out
    check.drag_force(lambda v, b, w: -b * v)
    assert _status("drag_force") == "incorrect"
    assert "forgot the wind" in capsys.readouterr().out
    check.drag_force(_stub)
    assert _status("drag_force") == "pending"


def test_check_terminal_velocity(capsys):
    check.terminal_velocity(lambda m, g, b: m * g / b)
    assert _status("terminal_velocity") == "correct"
    check.terminal_velocity(lambda m, g, b: g / b)
    assert _status("terminal_velocity") == "incorrect"
    assert "forgot the mass" in capsys.readouterr().out
    check.terminal_velocity(_stub)
    assert _status("terminal_velocity") == "pending"


def test_check_circular_speed(capsys):
    check.circular_speed(lambda G_, M, r: np.sqrt(G_ * M / r))
    assert _status("circular_speed") == "correct"
    check.circular_speed(lambda G_, M, r: np.sqrt(2 * G_ * M / r))
    assert _status("circular_speed") == "incorrect"
    out = capsys.readouterr().out
    assert "escape speed" in out and "misses its start" in out
    check.circular_speed(_stub)
    assert _status("circular_speed") == "pending"
