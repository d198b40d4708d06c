"""Every number quoted in solutions/07_springs.ipynb, its widget, and its exercise checks."""

import itertools

import numpy as np
import pytest

import course_lib as cl
from course_lib import springs as S
from course_lib.check import RESULTS
from course_lib.check import nb07 as check
from course_lib.lessons import nb07_springs as nb07

K, M, X0 = 10.0, 1.0, 0.1


def test_oscillator_numbers():
    omega = np.sqrt(K / M)
    assert omega == pytest.approx(3.1623, abs=5e-5)
    assert 2 * np.pi / omega == pytest.approx(1.9869, abs=5e-5)
    system, y0, net = S.anchored_spring(K, M, stretch=X0)
    errors = {}
    for method in ("symplectic_euler", "velocity_verlet"):
        traj = cl.integrate(system, y0, (0.0, 10.0), 0.05, method=method)
        s = net.lengths(cl.split_state(traj.y)[0])[:, 0] - 1.0
        errors[method] = np.max(np.abs(s - X0 * np.cos(omega * traj.t)))
    assert errors["symplectic_euler"] == pytest.approx(1.10e-2, rel=5e-3)
    assert errors["velocity_verlet"] == pytest.approx(3.12e-3, rel=5e-3)


def test_internal_forces_sum_to_zero_and_no_torque():
    rng = np.random.default_rng(2026)
    n = 8
    pairs = np.array([(a, b) for a in range(n) for b in range(a + 1, n)])
    x = rng.normal(size=(n, 3))
    net = S.SpringNetwork(pairs[:, 0], pairs[:, 1], rng.uniform(0.5, 1.5, len(pairs)),
                          rng.uniform(10.0, 100.0, len(pairs)), 0.0, n)
    F = net.forces(x)
    assert net.n_springs == 28
    assert np.abs(F).max() == pytest.approx(409.8, abs=0.05)
    # "about 10^-14 of the forces"
    assert np.linalg.norm(F.sum(axis=0)) < 1e-12 * np.abs(F).max()
    assert np.linalg.norm(np.cross(x, F).sum(axis=0)) < 1e-12 * np.abs(F).max()
    # "max |F + dE/dx| = 1.5e-07 N": forces are minus the energy gradient (central differences)
    h = 1e-6
    grad = np.zeros_like(x)
    for a in range(n):
        for p in range(3):
            e = np.zeros_like(x)
            e[a, p] = h
            grad[a, p] = (net.energy(x + e) - net.energy(x - e)) / (2 * h)
    assert np.abs(F + grad).max() == pytest.approx(1.5e-7, abs=5e-9)
    # a translating pair at rest length feels no force, even with critical damping
    pair = S.SpringNetwork([0], [1], [1.0], [K], [S.critical_damping(K, M)], 2)
    xs = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert np.array_equal(pair.forces(xs, np.ones((2, 3))), np.zeros((2, 3)))


def test_critical_damping_and_settling_times():
    c = S.critical_damping(K, M)
    assert c == pytest.approx(2 * np.sqrt(10.0), rel=1e-15)
    assert round(c, 4) == 6.3246
    quoted = {0.25: 5.46, 1.0: 2.10, 4.0: 11.51}          # exact, on the notebook's 0.1 ms grid
    numerical = {0.25: 5.45, 1.0: 2.12, 4.0: 11.52}       # velocity Verlet, dt = 0.01 s
    t_grid = np.linspace(0.0, 15.0, 150_001)
    t_finer = np.linspace(0.0, 15.0, 1_500_001)
    for factor, settle in quoted.items():
        run = nb07.run_spring(K, factor * c, 0.01, "velocity_verlet", m=M, t_end=15.0, stretch=X0)
        assert nb07.settling_time(run.t, run.x) == pytest.approx(numerical[factor], abs=0.005)
        exact = S.damped_oscillator(t_grid, K, M, factor * c, X0)
        assert nb07.settling_time(t_grid, exact) == pytest.approx(settle, abs=0.005)
        # a ten times finer grid does not change the quoted value
        exact = S.damped_oscillator(t_finer, K, M, factor * c, X0)
        assert nb07.settling_time(t_finer, exact) == pytest.approx(settle, abs=0.005)
    # critical damping in closed form: (1 + ωt) e^{-ωt} = 0.01
    from scipy.optimize import brentq
    omega = np.sqrt(K / M)
    u = brentq(lambda u: (1 + u) * np.exp(-u) - 0.01, 1.0, 20.0)
    assert u / omega == pytest.approx(2.10, abs=0.005)
    # critical is the fastest of the three, and never crosses zero
    run = nb07.run_spring(K, c, 0.01, "velocity_verlet", t_end=15.0)
    assert np.all(run.x > -1e-9)
    assert np.all(nb07.run_spring(K, 4 * c, 0.01, "velocity_verlet", t_end=15.0).x > 0)


def test_dt_max_measured_against_two_over_omega():
    ks = [1.0, 4.0, 16.0, 64.0, 256.0]
    printed = [1.999939, 0.999969, 0.499985, 0.249992, 0.124996]
    measured = [nb07.spring_dt_max(k, M) for k in ks]
    for k, d, shown in zip(ks, measured, printed, strict=True):
        theory = 2.0 / np.sqrt(k / M)
        assert d / theory == pytest.approx(0.99997, abs=5e-6)      # quoted: within 0.003%
        assert d == pytest.approx(shown, abs=5e-7)
    for a, b in itertools.pairwise(measured):
        assert b / a == pytest.approx(0.5, abs=5e-5)               # 4x stiffer: half the step
    assert measured[-1] == pytest.approx(0.125, rel=1e-4)
    # the exercise check quotes the k = 16 N/m measurement as 0.49998 s
    assert f"{measured[2]:.5f}" == "0.49998"


def test_symplectic_euler_limit_from_the_amplification_matrix():
    # one step multiplies (x, v) by A = [[1 - w^2 dt^2, dt], [-w^2 dt, 1]]: det 1, trace 2 - w^2 dt^2
    w = np.sqrt(K / M)
    for wdt, bounded in [(1.0, True), (1.99, True), (2.01, False), (3.0, False)]:
        dt = wdt / w
        A = np.array([[1 - (w * dt) ** 2, dt], [-w**2 * dt, 1.0]])
        assert np.linalg.det(A) == pytest.approx(1.0, rel=1e-12)
        assert np.trace(A) == pytest.approx(2 - wdt**2, rel=1e-12)
        assert bool(np.abs(np.linalg.eigvals(A)).max() <= 1 + 1e-9) is bounded
    # and it is what course_lib's symplectic Euler does
    system, y0, _ = S.anchored_spring(K, M, stretch=X0)
    dt = 0.3
    y1 = cl.integrate(system, y0, (0.0, dt), dt, method="symplectic_euler").y[-1]   # (x, v) after one step
    A = np.array([[1 - (w * dt) ** 2, dt], [-w**2 * dt, 1.0]])
    assert np.allclose([y1[0, 1, 0] - 1.0, y1[1, 1, 0]], A @ [X0, 0.0], rtol=1e-12, atol=1e-15)


def test_widget_static_states():
    assert 2 / np.sqrt(10.0) == pytest.approx(0.632, abs=5e-4)
    stable = nb07.run_spring(k=10.0, c=0.0, dt=0.6, method="symplectic_euler", t_end=30.0)
    assert stable.stable and stable.dt_limit == pytest.approx(2 / np.sqrt(10.0), rel=1e-9)
    assert np.max(np.abs(stable.x[:20])) / X0 == pytest.approx(3.2, abs=0.05)
    blown = nb07.run_spring(k=10.0, c=0.0, dt=0.65, method="symplectic_euler", t_end=30.0)
    assert not blown.stable and "step 26" in blown.message and "t = 16.9" in blown.message
    assert np.nanmax(np.abs(blown.x[:20])) / X0 == pytest.approx(360.0, abs=0.05)
    assert 3.2 == round(np.max(np.abs(stable.x[:20])) / X0, 1)     # "about three times"


def test_spring_explorer_view():
    view = nb07.spring_explorer(k=10.0, c=0.0, dt=0.05)
    assert view.result.stable and view.result.dt_limit == pytest.approx(2 / np.sqrt(10.0), rel=1e-9)
    view.controls["dt"].value = 0.7                       # past the limit 0.632 s
    assert not view.result.stable and view.result.params["dt"] == pytest.approx(0.7, rel=1e-2)
    view.controls["k"].value = 1.0                        # softer spring: limit 2 s
    r = view.result
    assert r.stable and r.dt_limit == pytest.approx(2.0, rel=1e-6)
    assert r.params == {"k": 1.0, "c": 0.0, "dt": view.controls["dt"].value,
                        "method": "symplectic_euler", "m": 1.0}


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb07.{name}"]["status"]


def test_check_spring_force(capsys):
    check.spring_force(lambda x1, x2, k, L: S.spring_force_pair(x1, x2, k, L))
    assert _status("spring_force") == "correct"

    def sign_error(x1, x2, k, L):
        return -S.spring_force_pair(x1, x2, k, L)

    def not_normalised(x1, x2, k, L):
        d = x1 - x2
        return -k * (np.linalg.norm(d) - L) * d

    def rest_not_stretch(x1, x2, k, L):
        d = x1 - x2
        return -k * L * d / np.linalg.norm(d)

    capsys.readouterr()
    for wrong, hint in [(sign_error, "sign error"), (not_normalised, "forgot to normalise"),
                        (rest_not_stretch, "used the rest length L instead of the stretch")]:
        check.spring_force(wrong)
        assert _status("spring_force") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(x1, x2, k, L):
        raise NotImplementedError()

    check.spring_force(pending)
    assert _status("spring_force") == "pending"


def test_check_predict_dt_max(capsys):
    check.predict_dt_max(lambda k, m: 2 * np.sqrt(m / k))
    assert _status("predict_dt_max") == "correct"
    capsys.readouterr()
    check.predict_dt_max(lambda k, m: np.sqrt(m / k))
    assert _status("predict_dt_max") == "incorrect"
    assert "missing factor 2" in capsys.readouterr().out
    check.predict_dt_max(lambda k, m: 2 * np.sqrt(k / m))
    assert "inverted" in capsys.readouterr().out

    def pending(k, m):
        raise NotImplementedError()

    check.predict_dt_max(pending)
    assert _status("predict_dt_max") == "pending"


def test_check_critical_damping(capsys):
    check.critical_damping(lambda k, m: 2 * np.sqrt(k * m))
    assert _status("critical_damping") == "correct"
    capsys.readouterr()
    check.critical_damping(lambda k, m: np.sqrt(k * m))
    assert _status("critical_damping") == "incorrect"
    assert "missing factor 2" in capsys.readouterr().out

    def pending(k, m):
        raise NotImplementedError()

    check.critical_damping(pending)
    assert _status("critical_damping") == "pending"
