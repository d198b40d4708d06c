"""Every number quoted in solutions/07_springs.ipynb, its widget, and its exercise checks."""

import itertools

import numpy as np
import pytest

import course_lib as cl
from course_lib import springs as S
from course_lib.check import RESULTS
from course_lib.check import nb07 as check
from course_lib.lessons import nb07_springs as nb07
from course_lib.plotting import METHOD_LABELS

K, M, X0 = 10.0, 1.0, 0.1


def test_oscillator_numbers():
    omega = np.sqrt(K / M)
    assert omega == pytest.approx(3.1623, abs=5e-5)
    assert 2 * np.pi / omega == pytest.approx(1.9869, abs=5e-5)
    system, y0, net = S.anchored_spring(K, M, stretch=X0)
    errors, early, periods = {}, {}, {}
    for method in ("symplectic_euler", "velocity_verlet"):
        traj = cl.integrate(system, y0, (0.0, 10.0), 0.05, method=method)
        s = net.lengths(cl.split_state(traj.y)[0])[:, 0] - 1.0
        err = np.abs(s - X0 * np.cos(omega * traj.t))
        errors[method] = err.max()
        early[method] = err[traj.t <= 2.0].max()
        periods[method] = cl.events.measured_period(traj.t, s)
    assert errors["symplectic_euler"] == pytest.approx(1.10e-2, rel=5e-3)
    assert errors["velocity_verlet"] == pytest.approx(3.12e-3, rel=5e-3)
    assert f"{early['symplectic_euler']:.1e}" == "8.4e-03" and f"{early['velocity_verlet']:.1e}" == "5.0e-04"
    # "about x0 omega dt / 2 = 0.008 m": symplectic Euler's first-order tilt
    assert X0 * omega * 0.05 / 2 == pytest.approx(0.008, abs=5e-4)
    assert early["symplectic_euler"] == pytest.approx(X0 * omega * 0.05 / 2, rel=0.1)
    # "over 10 s that lag grows to 0.003 m"
    assert round(errors["velocity_verlet"], 3) == 0.003
    # both oscillate with the discrete frequency cos(w~ dt) = 1 - w^2 dt^2 / 2: 1.9848 s
    w_tilde = np.arccos(1 - (omega * 0.05) ** 2 / 2) / 0.05
    assert 2 * np.pi / w_tilde == pytest.approx(1.9848, abs=5e-5)
    # too fast: w~ = w (1 + w^2 dt^2 / 24 + ...)
    assert w_tilde / omega - 1 == pytest.approx((omega * 0.05) ** 2 / 24, rel=5e-3)
    for method in periods:
        assert round(periods[method], 4) == 1.9848
        assert periods[method] == pytest.approx(2 * np.pi / w_tilde, rel=2e-5)
    # the two step matrices have the same trace 2 - w^2 dt^2
    for method in periods:
        A = nb07.step_matrix(method, K, M, 0.0, 0.05)
        assert np.trace(A) == pytest.approx(2 - (omega * 0.05) ** 2, rel=1e-14)
        assert np.linalg.det(A) == pytest.approx(1.0, rel=1e-14)


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


def test_run_spring_is_integrate_to_round_off():
    """The widget's step-matrix runs equal integrate on the 3D anchored spring."""
    for c in (0.0, 1.3):
        system, y0, net = S.anchored_spring(K, M, c, 1.0, X0)
        for method in cl.METHODS:
            run = nb07.run_spring(K, c, 0.05, method, t_end=5.0)
            traj = cl.integrate(system, y0, (0.0, 5.0), 0.05, method)
            x, v = cl.split_state(traj.y)
            assert run.t.shape == traj.t.shape
            assert np.allclose(run.x, net.lengths(x)[:, 0] - 1.0, rtol=0, atol=1e-13), method
            assert np.allclose(run.v, v[:, 1, 0], rtol=0, atol=1e-13), method


def test_matrix_powers():
    A = np.array([[0.9, 0.3], [-0.2, 1.1]])
    P = nb07.matrix_powers(A, 37)
    for n in (0, 1, 2, 5, 16, 17, 37):
        assert np.allclose(P[n], np.linalg.matrix_power(A, n), rtol=1e-12, atol=0)


def test_damped_limit_against_theory():
    w = np.sqrt(K / M)
    for c in (0.0, 0.5, 2.0, 6.0, 30.0):
        gamma = c / M
        closed = 4 / (gamma + np.sqrt(gamma**2 + 4 * w**2))
        assert nb07.damped_dt_limit("symplectic_euler", K, M, c) == pytest.approx(closed, rel=1e-12)
        assert nb07.symplectic_euler_limit(K, M, c) == pytest.approx(closed, rel=1e-15)
        # the condition w^2 dt^2 + 2 gamma dt < 4 holds just below, fails just above
        assert (w * closed) ** 2 + 2 * gamma * closed == pytest.approx(4.0, rel=1e-12)
        zeta = c / (2 * np.sqrt(K * M))
        assert closed == pytest.approx(2 / w * (np.sqrt(1 + zeta**2) - zeta), rel=1e-12)
    assert nb07.damped_dt_limit("symplectic_euler", K, M, 0.0) == pytest.approx(2 / w, rel=1e-12)
    assert nb07.damped_dt_limit("rk4", K, M, 0.0) == pytest.approx(2 * np.sqrt(2) / w, rel=1e-12)
    assert nb07.damped_dt_limit("forward_euler", K, M, 0.0) == 0.0
    assert nb07.damped_dt_limit("forward_euler", K, M, 0.7) == pytest.approx(0.7 / w**2, rel=1e-12)
    for method in ("backward_euler", "trapezoidal"):
        assert nb07.damped_dt_limit(method, K, M, 3.0) == np.inf
        assert nb07.limit_text(np.inf) == "no step limit (A-stable)"
    assert nb07.limit_text(0.0) == "unstable at every dt"
    assert nb07.limit_text(2 / w) == "stable for dt < 0.632 s"


def test_damped_limit_table():
    c_crit = S.critical_damping(K, M)
    w = np.sqrt(K / M)
    printed = {0.0: (0.632456, 1.0), 0.25: (0.493806, 0.78078), 0.5: (0.390879, 0.61803),
               1.0: (0.261972, 0.41421), 2.0: (0.149302, 0.23607), 4.0: (0.077859, 0.12311)}
    for zeta, (limit, ratio) in printed.items():
        lim = nb07.damped_dt_limit("symplectic_euler", K, M, zeta * c_crit)
        assert lim == pytest.approx(limit, abs=5e-7) and lim * w / 2 == pytest.approx(ratio, abs=5e-6)
        assert lim * w / 2 == pytest.approx(np.sqrt(1 + zeta**2) - zeta, rel=1e-12)
        if zeta:
            assert round(2 * M / (zeta * c_crit), 4) == {0.25: 1.2649, 0.5: 0.6325, 1.0: 0.3162,
                                                         2.0: 0.1581, 4.0: 0.0791}[zeta]
    # "critical damping cuts the step to 0.41 of the undamped limit, and twice critical to 0.24"
    assert round(np.sqrt(2) - 1, 2) == 0.41 and round(np.sqrt(5) - 2, 2) == 0.24
    # "for strong damping the limit approaches 2/gamma"
    big = 1e4 * c_crit
    assert nb07.damped_dt_limit("symplectic_euler", K, M, big) == pytest.approx(2 * M / big, rel=1e-6)
    # one row checked by simulation of the 3D spring
    lim = nb07.damped_dt_limit("symplectic_euler", K, M, c_crit)
    system, y0, _ = S.anchored_spring(K, M, c_crit, 1.0, 1e-3)
    below = cl.integrate(system, y0, (0.0, 3000 * 0.99 * lim), 0.99 * lim, "symplectic_euler",
                         blowup_bound=1.5)
    above = cl.integrate(system, y0, (0.0, 3000 * 1.01 * lim), 1.01 * lim, "symplectic_euler",
                         blowup_bound=1.5)
    assert below.stable and not above.stable
    assert above.message == "unstable at step 246, t = 65.0895 (|y| > 1.5)"


def test_widget_static_states():
    assert 2 / np.sqrt(10.0) == pytest.approx(0.632, abs=5e-4)
    stable = nb07.run_spring(k=10.0, c=0.0, dt=0.6, method="symplectic_euler", t_end=30.0)
    assert stable.stable and stable.dt_limit == pytest.approx(2 / np.sqrt(10.0), rel=1e-12)
    assert stable.message == "stable" and stable.limit_text == "stable for dt < 0.632 s"
    assert np.max(np.abs(stable.x[:20])) / X0 == pytest.approx(3.16, abs=1e-9)  # "about three times"
    assert np.all(np.isfinite(stable.x)) and np.abs(stable.x).max() < 4 * X0      # bounded for ever
    blown = nb07.run_spring(k=10.0, c=0.0, dt=0.65, method="symplectic_euler", t_end=30.0)
    assert not blown.stable and blown.message == "blew up: |x| or |v| passed 1000 at step 16, t = 10.4 s"
    assert round(np.nanmax(np.abs(blown.x[:20])) / X0, 1) == 3074.5
    damped = nb07.run_spring(k=10.0, c=2.0, dt=0.5, method="symplectic_euler", t_end=30.0)
    assert damped.dt_limit == pytest.approx(0.463325, abs=5e-7) and damped.limit_text.endswith("0.463 s")
    assert damped.message == "blew up: |x| or |v| passed 1000 at step 20, t = 10 s"
    assert round(np.nanmax(np.abs(damped.x[:20])) / X0, 1) == 2216.8
    assert nb07.run_spring(k=10.0, c=0.0, dt=0.5, method="symplectic_euler").stable   # undamped: fine
    # forward Euler without damping grows slowly: unstable although far from the bound
    fe = nb07.run_spring(k=10.0, c=0.0, dt=0.05, method="forward_euler")
    assert fe.blowup_step is None and not fe.stable and "grows by a factor 1.01242" in fe.message
    assert 1.01242 == round(np.sqrt(1 + 10 * 0.05**2), 5)


def test_spring_explorer_view():
    view = nb07.spring_explorer(k=10.0, c=0.0, dt=0.05)
    assert view.result.stable and view.result.dt_limit == pytest.approx(2 / np.sqrt(10.0), rel=1e-9)
    labels = [label for label, _ in view.controls["method"].options]
    assert labels == [METHOD_LABELS[m] for m in cl.METHODS]          # readable names
    assert "updated in" in view.status.value                          # says it is done
    view.controls["dt"].value = 0.7                       # past the limit 0.632 s
    assert not view.result.stable and view.result.params["dt"] == pytest.approx(0.7, rel=1e-2)
    view.controls["k"].value = 1.0                        # softer spring: limit 2 s
    r = view.result
    assert r.stable and r.dt_limit == pytest.approx(2.0, rel=1e-9)
    assert {key: r.params[key] for key in ("k", "c", "method", "m")} == {
        "k": 1.0, "c": 0.0, "method": "symplectic_euler", "m": 1.0}
    view.controls["c"].value = 2.0                        # damped limit 4/(2 + sqrt(8)) = 0.828 s
    assert view.result.dt_limit == pytest.approx(4 / (2 + np.sqrt(8)), rel=1e-12)
    view.controls["method"].value = "backward_euler"
    assert view.result.dt_limit == np.inf and "no step limit" in view.result.limit_text
    # a long run at the smallest step: every step computed, drawn thinned
    view.controls["method"].value = "rk4"
    view.controls["dt"].value = 1e-3
    assert view.result.t.size == 20001 and view.result.stable
    assert "every 14th step drawn" in view.figure.axes[0].get_legend().texts[1].get_text()


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


def test_check_spring_force_float32_and_reference(capsys):
    check.spring_force(lambda x1, x2, k, L: S.spring_force_pair(x1, x2, k, L).astype(np.float32))
    assert _status("spring_force") == "correct"

    def borrowed(x1, x2, k, L):
        return cl.springs.spring_force_pair(x1, x2, k, L)

    borrowed.__module__ = "__main__"             # as if written in the notebook
    capsys.readouterr()
    check.spring_force(borrowed)
    assert _status("spring_force") == "incorrect" and "uses the reference" in capsys.readouterr().out

    def nan_force(x1, x2, k, L):
        return np.full(3, np.nan)

    check.spring_force(nan_force)
    assert "returned NaN" in capsys.readouterr().out


def _damped(k, m, c):
    gamma = c / m
    return 4.0 / (gamma + np.sqrt(gamma**2 + 4.0 * k / m))


def test_check_damped_dt_max(capsys):
    check.damped_dt_max(_damped)
    assert _status("damped_dt_max") == "correct"
    check.damped_dt_max(lambda k, m, c: np.float32(_damped(k, m, c)))
    assert _status("damped_dt_max") == "correct"
    capsys.readouterr()
    wrong = {
        "undamped limit 2/ω": lambda k, m, c: 2 * np.sqrt(m / k),
        "forgot to divide c by m": lambda k, m, c: 4 / (c + np.sqrt(c**2 + 4 * k / m)),
        "wrong root": lambda k, m, c: (c / m + np.sqrt((c / m) ** 2 + 4 * k / m)) / (k / m),
        "the discriminant": lambda k, m, c: (-c / m + np.sqrt((c / m) ** 2 + 16 * k / m)) / (k / m),
    }
    for hint, answer in wrong.items():
        check.damped_dt_max(answer)
        assert _status("damped_dt_max") == "incorrect"
        assert hint in capsys.readouterr().out, hint

    def borrowed(k, m, c):
        return nb07.symplectic_euler_limit(k, m, c)

    borrowed.__module__ = "__main__"
    check.damped_dt_max(borrowed)
    assert _status("damped_dt_max") == "incorrect" and "uses the reference" in capsys.readouterr().out

    def pending(k, m, c):
        raise NotImplementedError()

    check.damped_dt_max(pending)
    assert _status("damped_dt_max") == "pending"


def _network(x, v, i, j, rest, k, c):
    d = x[i] - x[j]
    length = np.linalg.norm(d, axis=1)
    u = d / length[:, None]
    f = -(k * (length - rest) + c * np.einsum("md,md->m", v[i] - v[j], u))[:, None] * u
    F = np.zeros_like(x)
    np.add.at(F, i, f)
    np.add.at(F, j, -f)
    return F


def test_check_network_forces(capsys):
    check.network_forces(_network)
    assert _status("network_forces") == "correct"
    check.network_forces(lambda *a: _network(*a).astype(np.float32))
    assert _status("network_forces") == "correct"
    capsys.readouterr()

    def buffered(x, v, i, j, rest, k, c):
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        f = -(k * (length - rest) + c * np.einsum("md,md->m", v[i] - v[j], u))[:, None] * u
        F = np.zeros_like(x)
        F[i] += f
        F[j] -= f
        return F

    def looped(x, v, i, j, rest, k, c):
        F = np.zeros_like(x)
        for s in range(len(i)):
            a, b = i[s], j[s]
            d = x[a] - x[b]
            u = d / np.linalg.norm(d)
            f = -(k[s] * (np.linalg.norm(d) - rest[s]) + c[s] * (v[a] - v[b]) @ u) * u
            F[a] += f
            F[b] -= f
        return F

    def unprojected(x, v, i, j, rest, k, c):
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1)
        f = -(k * (length - rest))[:, None] * d / length[:, None] - c[:, None] * (v[i] - v[j])
        F = np.zeros_like(x)
        np.add.at(F, i, f)
        np.add.at(F, j, -f)
        return F

    def undamped(x, v, i, j, rest, k, c):
        return _network(x, v, i, j, rest, k, 0.0 * c)

    def one_end(x, v, i, j, rest, k, c):
        F = _network(x, v, i, j, rest, k, c)
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        f = -(k * (length - rest) + c * np.einsum("md,md->m", v[i] - v[j], u))[:, None] * u
        G = np.zeros_like(x)
        np.add.at(G, i, f)
        return G + 0 * F

    for answer, hint in [(buffered, "np.add.at"), (looped, "loops over the springs"),
                         (unprojected, "damp only the stretching rate"),
                         (undamped, "left out the damping"), (one_end, "add f at i AND -f at j"),
                         (lambda *a: -_network(*a), "sign error")]:
        check.network_forces(answer)
        assert _status("network_forces") == "incorrect"
        assert hint in capsys.readouterr().out, hint

    def borrowed(x, v, i, j, rest, k, c):
        return cl.springs.SpringNetwork(i, j, rest, k, c, len(x)).forces(x, v)

    borrowed.__module__ = "__main__"
    check.network_forces(borrowed)
    assert "uses the reference" in capsys.readouterr().out

    def pending(*args):
        raise NotImplementedError()

    check.network_forces(pending)
    assert _status("network_forces") == "pending"
