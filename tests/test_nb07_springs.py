"""Every number quoted in solutions/07_springs.ipynb, its widget, and its exercise checks."""

import itertools

import numpy as np
import pytest
from notebook_helpers import drive_kept_figure, printed_holds
from planted import Plant, define, judge

import course_lib as cl
from course_lib import springs as S
from course_lib.check import RESULTS
from course_lib.check import nb07 as check
from course_lib.lessons import nb07_springs as nb07
from course_lib.plotting import METHOD_LABELS

K, M, X0 = 10.0, 1.0, 0.1


def test_oscillator_numbers():
    """Section 1: bounded energy, a phase error that grows linearly, symplectic Euler's tilt."""
    omega, dt = np.sqrt(K / M), 0.05
    assert omega == pytest.approx(3.1623, abs=5e-5)
    assert 2 * np.pi / omega == pytest.approx(1.9869, abs=5e-5)
    w_tilde = np.arccos(1 - (omega * dt) ** 2 / 2) / dt
    assert f"{w_tilde - omega:.4f}" == "0.0033"
    # too fast: w~ = w (1 + w^2 dt^2 / 24 + ...)
    assert w_tilde / omega - 1 == pytest.approx((omega * dt) ** 2 / 24, rel=5e-3)
    assert 2 * np.pi / w_tilde == pytest.approx(1.9848, abs=5e-5)
    system, y0, net = S.anchored_spring(K, M, stretch=X0)
    got = {}
    for method in ("symplectic_euler", "velocity_verlet"):
        traj = cl.integrate(system, y0, (0.0, 10.0), dt, method=method)
        x, v = cl.split_state(traj.y)
        axis = (x[:, 1] - x[:, 0]) / np.linalg.norm(x[:, 1] - x[:, 0], axis=1)[:, None]
        s = net.lengths(x)[:, 0] - 1.0
        speed = np.einsum("nd,nd->n", v[:, 1] - v[:, 0], axis)
        energy = (0.5 * M * speed**2 + 0.5 * K * s**2) / (0.5 * K * X0**2)
        phase = np.unwrap(np.arctan2(-speed / omega, s)) - omega * traj.t
        err = np.abs(s - X0 * np.cos(omega * traj.t))
        period = cl.events.measured_period(traj.t, s)
        got[method] = (err[traj.t <= 2].max(), err[traj.t >= 8].max(), np.abs(energy - 1).max(),
                       period, phase)
        assert round(period, 4) == 1.9848
        assert period == pytest.approx(2 * np.pi / w_tilde, rel=2e-5)
        assert f"{2 * np.pi / period - omega:.4f}" == "0.0033"
    se, vv = got["symplectic_euler"], got["velocity_verlet"]
    # printed: 8.4e-03 / 1.1e-02 m and 5.0e-04 / 3.1e-03 m; the error GROWS for both
    assert (f"{se[0]:.1e}", f"{se[1]:.1e}") == ("8.4e-03", "1.1e-02")
    assert (f"{vv[0]:.1e}", f"{vv[1]:.1e}") == ("5.0e-04", "3.1e-03")
    assert se[1] > 1.25 * se[0] and vv[1] > 5 * vv[0]
    # "about x0 omega dt / 2 = 0.008 m": symplectic Euler's first-order tilt
    assert X0 * omega * dt / 2 == pytest.approx(0.008, abs=5e-4)
    assert se[0] == pytest.approx(X0 * omega * dt / 2, rel=0.1)
    # Verlet's late error is the phase error alone: x0 (w~ - w) t at t = 10 s
    assert vv[1] == pytest.approx(X0 * (w_tilde - omega) * 10.0, rel=0.06)
    # the energy bands of notebook 05: h/2 / (1 - h/2) and h²/4 with h = ω dt = 0.158
    h = omega * dt
    assert se[2] == pytest.approx(1 / (1 - h / 2) - 1, rel=1e-4) and f"{se[2]:.5f}" == "0.08584"
    assert vv[2] == pytest.approx(h * h / 4, rel=1e-4) and f"{vv[2]:.5f}" == "0.00625"
    assert round(100 * se[2], 1) == 8.6 and round(100 * vv[2], 1) == 0.6
    # phase at 10 s: Verlet on the line (w~ - w) t; symplectic Euler above it by its wobble
    assert f"{vv[4][-1]:.3f}" == "0.032" and f"{se[4][-1]:.3f}" == "0.038"
    assert vv[4][-1] == pytest.approx((w_tilde - omega) * 10.0, abs=2e-3)
    wobble = se[4] - (w_tilde - omega) * np.arange(se[4].size) * dt
    assert -1e-3 < wobble.min() and wobble.max() < h / 2 + 1e-3
    # the two step matrices have the same trace 2 - w^2 dt^2 and determinant 1
    for method in got:
        A = nb07.step_matrix(method, K, M, 0.0, dt)
        assert np.trace(A) == pytest.approx(2 - h**2, rel=1e-14)
        assert np.linalg.det(A) == pytest.approx(1.0, rel=1e-14)


@pytest.mark.roundoff
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
    # "below 1e-15 of the largest force": exact arithmetic gives 0; each of the 2M = 56 spring
    # ends adds a rounding of about eps times a spring force (at most 115 N here), and the
    # errors add like a random walk: sqrt(56) eps 115 N / 410 N = 2e-16, so 1e-15 has room
    scale = np.abs(F).max()
    assert np.abs(net.spring_forces(x)).max() < 120.0
    assert np.linalg.norm(F.sum(axis=0)) < 1e-15 * scale
    assert np.linalg.norm(np.cross(x, F).sum(axis=0)) < 1e-15 * scale * np.abs(x).max()
    # "max |F + dE/dx| < 1e-6 N": forces are minus the energy gradient (central differences,
    # whose round-off is about eps × E / h = 2e-16 × 1e3 J / 1e-6 m = 2e-7 N)
    h = 1e-6
    grad = np.zeros_like(x)
    for a in range(n):
        for p in range(3):
            e = np.zeros_like(x)
            e[a, p] = h
            grad[a, p] = (net.energy(x + e) - net.energy(x - e)) / (2 * h)
    assert np.abs(F + grad).max() < 1e-6
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


def test_the_cliff_at_two_over_omega():
    """Section 4's right panel and prose: bounded just below 2/ω, astronomical just above."""
    unit = 2 / np.sqrt(16.0 / M)
    below, above = nb07.growth("symplectic_euler", 16.0, M, 0.0, [0.99 * unit, 1.01 * unit],
                               cap=1e300)
    ellipse = 1 / np.sqrt(1 - 0.99**2)            # the modified energy's ellipse: max |x| / x0
    assert below <= ellipse * (1 + 1e-12) and below == pytest.approx(ellipse, rel=1e-3)
    # 1000 steps of a 2x2 product: relative round-off far below 1e-10
    printed_holds(below, ".2f", "7.09", 1e-10 * below)
    printed_holds(ellipse, ".2f", "7.09", 1e-12)
    rho = nb07.spectral_radius(nb07.step_matrix("symplectic_euler", 16.0, M, 0.0, 1.01 * unit))
    assert np.log10(above) == pytest.approx(1000 * np.log10(rho), abs=1.0)
    printed_holds(above, ".0e", "2e+123", 1e-10 * above)
    # the bisection's bound (a growth of 3.75e8 here, see below) is passed in 1000 steps by
    # a step 1e-4 above the limit already (so it resolves the limit)
    assert nb07.growth("symplectic_euler", 16.0, M, 0.0, [1.0001 * unit])[0] > 1.5e9


def test_the_verdict_line_is_the_growth_at_which_integrate_says_unstable():
    """Section 4's prose and the cliff panel's dotted line: from a 1 nm stretch the state
    passes 1.5 when the speed ω|x| passes 1.5 m/s (ω > 3 rad/s) or the stretch 0.5 m:
    5e8 at k = 1 and 4 N/m, 3.75e8 at 16 N/m (the panel), 0.94e8 at 256 N/m."""
    expected = {1.0: 5e8, 4.0: 5e8, 16.0: 3.75e8, 64.0: 1.875e8, 256.0: 9.375e7}
    for k, value in expected.items():
        assert nb07.verdict_growth(k, M) == pytest.approx(value, rel=1e-12), k
        # integrate's own verdict just past the limit: the largest stretch before the step
        # that is declared unstable, and at it, bracket the growth within one step's factor
        for ratio in (1.0001, 1.001):
            dt = ratio * 2 / np.sqrt(k / M)
            rho = nb07.spectral_radius(nb07.step_matrix("symplectic_euler", k, M, 0.0, dt))
            system, y0, _ = S.anchored_spring(k, M, stretch=1e-9)
            run = cl.integrate(system, y0, (0.0, 1000 * dt), dt, "symplectic_euler",
                               blowup_bound=1.5)
            stretch = np.abs(cl.split_state(run.y)[0][:, 1, 0] - 1.0) / 1e-9
            before, at = stretch[:run.blowup_step].max(), stretch[run.blowup_step]
            assert before < value * rho and at > value / rho, (k, ratio, before, at)
    printed_holds(nb07.verdict_growth(16.0, M), ".3g", "3.75e+08", 1e-12 * 3.75e8)
    printed_holds(nb07.verdict_growth(256.0, M) / 1e8, ".2f", "0.94", 1e-12)


def _jury_vv(zeta, w):
    """Velocity Verlet on the damped spring: both Jury conditions, in w = ω dt."""
    q = 1 - zeta * w
    return abs(q) < 1 and w * w * (1 + q) < 4 * (1 + q * q)


def test_velocity_verlet_windows_from_the_jury_conditions():
    # det S = q², tr S = 1 + q² - w²(1 + q)/2, and P = 2 (1 + det + tr)
    for zeta, w in [(0.3, 1.7), (0.7, 3.1), (0.5, 2.9), (1.5, 0.4)]:
        S = nb07.step_matrix("velocity_verlet", 1.0, 1.0, 2 * zeta, w)
        q = 1 - zeta * w
        assert np.trace(S) == pytest.approx(1 + q * q - 0.5 * w * w * (1 + q), rel=1e-12)
        assert np.linalg.det(S) == pytest.approx(q * q, rel=1e-12, abs=1e-14)
        P = zeta * w**3 + (4 * zeta**2 - 2) * w**2 - 8 * zeta * w + 8
        assert P == pytest.approx(2 * (1 + np.linalg.det(S) + np.trace(S)), rel=1e-10)
    for zeta in (0.1, 0.3, 0.6, 2.0):            # P(0) = P(2/ζ) = 8
        assert zeta * (2 / zeta) ** 3 + (4 * zeta**2 - 2) * (2 / zeta) ** 2 - 16 + 8 == \
            pytest.approx(8.0, rel=1e-12)
    # at ζ = 0.5: P = (w - 2)(w² - 8)/2, windows ω dt < 2 and 2√2 < ω dt < 4
    windows = nb07.velocity_verlet_windows(1.0, 1.0, 1.0)
    assert np.allclose(windows, [(0.0, 2.0), (2 * np.sqrt(2), 4.0)], rtol=1e-12)
    # the windows are exactly where the Jury conditions hold, on a fine grid of w
    for zeta in (0.05, 0.25, 0.4, 0.5, 0.52, 0.53, 0.75, 1.0, 3.0):
        windows = nb07.velocity_verlet_windows(1.0, 1.0, 2 * zeta)
        for w in np.linspace(1e-3, 2 / zeta + 0.5, 4001):
            inside = any(lo < w < hi for lo, hi in windows)
            edge = any(min(abs(w - lo), abs(w - hi)) < 1e-9 for lo, hi in windows)
            assert edge or inside == _jury_vv(zeta, w), (zeta, w)
        assert len(windows) == (2 if zeta < 0.5263 else 1)
    # ζ* from the discriminant, 16 u³ + 8 u² + 11 u = 4 with u = ζ²; the gap closes there
    zeta_star, w_star = nb07.velocity_verlet_gap_end()
    u = zeta_star**2
    assert 16 * u**3 + 8 * u**2 + 11 * u == pytest.approx(4.0, rel=1e-14)
    assert len(nb07.velocity_verlet_windows(1.0, 1.0, 2 * (zeta_star - 1e-4))) == 2
    assert len(nb07.velocity_verlet_windows(1.0, 1.0, 2 * (zeta_star + 1e-6))) == 1
    P = zeta_star * w_star**3 + (4 * zeta_star**2 - 2) * w_star**2 - 8 * zeta_star * w_star + 8
    assert abs(P) < 1e-12                       # a double root: P and P' vanish together
    # printed: "zeta* = 0.5263 ... jumps from 1.147 to 1.900 x 2/ω"; prose 0.526, 1.15, 1.90
    printed_holds(zeta_star, ".4f", "0.5263", 1e-12)
    printed_holds(w_star / 2, ".3f", "1.147", 1e-10)
    printed_holds(1 / zeta_star, ".3f", "1.900", 1e-12)
    assert (round(zeta_star, 3), round(w_star / 2, 2), round(1 / zeta_star, 2)) == (0.526, 1.15, 1.9)


@pytest.mark.parametrize("method", ["forward_euler", "midpoint", "heun", "rk4", "symplectic_euler",
                                    "velocity_verlet", "backward_euler", "trapezoidal"])
def test_stable_windows_against_a_dense_scan(method):
    """stable_windows (what the widget says) is every step the step matrix keeps bounded,
    for damping ratios 0 to 10: the Runge-Kutta methods' set is one interval. The grid:
    2000 even steps (the narrowest window or gap, 0.0023 of the range, holds 4 of them)
    and 60 more within 1 % of the range either side of each edge the formula gives."""
    for zeta in (0.0, 0.05, 0.2, 0.35, 0.5, 0.51, 0.6, 1.0, 2.5, 10.0):
        c = 2 * zeta * np.sqrt(K * M)
        windows = nb07.stable_windows(method, K, M, c)
        top = 2.2 / (zeta * np.sqrt(K / M)) if zeta else 3.0 / np.sqrt(K / M)
        edges = [e for lo, hi in windows for e in (lo, hi) if 0 < e < top]
        grid = np.concatenate([np.linspace(1e-4, top, 2000)]
                              + [e + np.linspace(-0.01, 0.01, 60) * top for e in edges])
        grid = grid[(grid > 0) & (grid <= top)]
        for dt in grid[::7] if method in ("backward_euler", "trapezoidal") else grid:
            rho = nb07.spectral_radius(nb07.step_matrix(method, K, M, c, dt))
            inside = any(lo < dt < hi for lo, hi in windows)
            if any(min(abs(dt - lo), abs(dt - hi)) < 1e-9 * top for lo, hi in windows):
                continue
            if abs(rho - 1) < 1e-12:          # marginal within round-off: either verdict
                continue
            assert inside == (rho <= 1 + 1e-13), (method, zeta, dt, rho, windows)


def test_damped_stable_sets_table_and_simulations():
    """Section 5's table, the scan against the formulas, and the four 3D runs."""
    c_crit = S.critical_damping(K, M)
    w = np.sqrt(K / M)
    unit = 2 / w
    grid = np.linspace(0.001, 4.1, 821) * unit
    printed = {"symplectic_euler": {0.0: "< 1.00000", 0.25: "< 0.78078", 0.5: "< 0.61803",
                                    1.0: "< 0.41421", 2.0: "< 0.23607"},
               "velocity_verlet": {0.0: "< 1.00000", 0.25: "< 0.91598 and 3.74888 to 4.00000",
                                   0.5: "< 1.00000 and 1.41421 to 2.00000", 1.0: "< 1.00000",
                                   2.0: "< 0.50000"}}
    for method, rows in printed.items():
        for zeta, text in rows.items():
            found = nb07.scan_windows(method, K, M, zeta * c_crit, grid)
            formula = nb07.stable_windows(method, K, M, zeta * c_crit)
            assert np.max(formula) < grid[-1]      # the scan reaches every edge
            assert len(found) == len(formula)
            assert np.allclose(found, formula, rtol=1e-9)
            parts = []
            for lo, hi in found:           # bisected to 1e-14: 1e-10 of spread is generous
                if lo:
                    printed_holds(lo / unit, ".5f", f"{lo / unit:.5f}", 1e-10)
                printed_holds(hi / unit, ".5f", f"{hi / unit:.5f}", 1e-10)
                parts.append(f"< {hi / unit:.5f}" if lo == 0 else f"{lo / unit:.5f} to {hi / unit:.5f}")
            assert " and ".join(parts) == text, (method, zeta)
        for zeta in rows:                  # symplectic Euler: (2/ω)(√(1 + ζ²) - ζ)
            if method == "symplectic_euler":
                lim = nb07.symplectic_euler_limit(K, M, zeta * c_crit)
                assert lim / unit == pytest.approx(np.sqrt(1 + zeta**2) - zeta, rel=1e-12)
    # prose: 0.41 and 0.24 of the undamped limit; Verlet's first window 0.92 at ζ = 0.25;
    # past ζ* the limit is 4/γ, twice symplectic Euler's 2/γ for strong damping
    assert round(np.sqrt(2) - 1, 2) == 0.41 and round(np.sqrt(5) - 2, 2) == 0.24
    assert round(nb07.velocity_verlet_windows(K, M, 0.25 * c_crit)[0][1] / unit, 2) == 0.92
    # ζ = 0.25: P(w) = w³/4 - 7w²/4 - 2w + 8 has roots r1 < r2 in (0, 2/ζ = 8); Verlet is
    # stable for w < r1 and r2 < w < 8, "< 0.91598 and 3.74888 to 4.00000" in units of 2/ω
    r1, r2 = sorted(r.real for r in np.roots([0.25, 4 * 0.25**2 - 2, -2.0, 8.0]) if r.real > 0)
    (a0, a1), (b0, b1) = (np.array(w) / unit for w in nb07.velocity_verlet_windows(K, M, 0.25 * c_crit))
    assert (a0, b1) == (0.0, pytest.approx(4.0, rel=1e-12))
    assert (a1, b0) == (pytest.approx(r1 / 2, rel=1e-9), pytest.approx(r2 / 2, rel=1e-9))
    assert f"{r1 / 2:.5f} {r2 / 2:.5f}" == "0.91598 3.74888"
    assert (round(r2 / 2, 2), round(b1, 2)) == (3.75, 4.0)      # prose: "from 3.75 to 4"
    for zeta in (0.6, 1.0, 2.0, 10.0):
        (lo, hi), = nb07.stable_windows("velocity_verlet", K, M, zeta * c_crit)
        assert hi == pytest.approx(4 * M / (zeta * c_crit), rel=1e-12)
    big = 1e4 * c_crit
    assert nb07.symplectic_euler_limit(K, M, big) == pytest.approx(2 * M / big, rel=1e-4)
    # the four 3D runs of 3000 steps
    lim = nb07.symplectic_euler_limit(K, M, c_crit)
    crit, y_crit, _ = S.anchored_spring(K, M, c_crit, 1.0, 1e-3)
    half, y_half, _ = S.anchored_spring(K, M, 0.5 * c_crit, 1.0, 1e-3)
    runs = [cl.integrate(system, y, (0.0, 3000 * dt), dt, method, blowup_bound=1.5)
            for method, system, y, dt in [
                ("symplectic_euler", crit, y_crit, 0.99 * lim),
                ("symplectic_euler", crit, y_crit, 1.01 * lim),
                ("velocity_verlet", half, y_half, 1.2 * unit),
                ("velocity_verlet", half, y_half, 1.5 * unit)]]
    assert runs[0].stable and runs[3].stable
    assert runs[1].message == "unstable at step 246, t = 65.0895 (|y| > 1.5)"
    assert runs[2].message == "unstable at step 27, t = 20.4916 (|y| > 1.5)"
    # the step numbers are robust: the size passes 1.5 far (1e-9) from a step edge, where
    # the round-off of a few hundred steps (1e-13) cannot move it
    for run_dt, method, system, y, step in ((1.01 * lim, "symplectic_euler", crit, y_crit, 246),
                                            (1.2 * unit, "velocity_verlet", half, y_half, 27)):
        free = cl.integrate(system, y, (0.0, step * run_dt), run_dt, method)
        sizes = np.abs(free.y.reshape(len(free.y), -1)).max(axis=1)
        assert sizes[step - 1] < 1.5 * (1 - 1e-9) and sizes[step] > 1.5 * (1 + 1e-9)
    assert 27 * 1.2 * unit == pytest.approx(20.4916, abs=5e-5)


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
    # the fourth key state: velocity Verlet, c = 3.2 N s/m (ζ = 0.51), dt = 1 s, in its
    # second window; the subtitle names both windows; the first step throws it to -4 x0
    vv = nb07.run_spring(k=10.0, c=3.2, dt=1.0, method="velocity_verlet", t_end=30.0)
    assert vv.stable and vv.message == "stable"
    assert round(3.2 / S.critical_damping(10.0, 1.0), 2) == 0.51
    (a, b), (c, d) = vv.windows
    assert a == 0.0 and c < 1.0 < d
    assert vv.limit_text == f"stable for dt < {b:.3g} s and for {c:.3g} s < dt < {d:.3g} s"
    assert vv.limit_text == "stable for dt < 0.641 s and for 0.868 s < dt < 1.25 s"
    for value in (b, c, d):                 # from np.roots: good to 1e-12, far from a 3rd digit
        printed_holds(value, ".3g", f"{value:.3g}", 1e-9)
    assert vv.x[1] == pytest.approx(-4 * X0, rel=1e-12)       # 1 - (ω dt)²/2 = -4
    assert f"{np.nanmax(np.abs(vv.x[:20])) / X0:.1f}" == "4.0"


def test_widget_says_when_verlet_is_stable_again():
    """The review's case: ζ = 0.5, stable at 1.0 and 1.2 s, unstable at 0.75 s, and the
    subtitle says so (it used to read "stable for dt < 0.632 s")."""
    c = S.critical_damping(K, M) / 2
    text = "stable for dt < 0.632 s and for 0.894 s < dt < 1.26 s"
    for dt, stable in ((0.5, True), (0.75, False), (1.0, True), (1.2, True), (1.3, False)):
        run = nb07.run_spring(K, c, dt, "velocity_verlet", t_end=200.0)
        assert run.stable is stable and run.limit_text == text, dt
        assert any(lo < dt < hi for lo, hi in run.windows) is stable
    assert nb07.limit_text(nb07.stable_windows("backward_euler", K, M, c)) == "no step limit (A-stable)"
    assert nb07.limit_text(nb07.stable_windows("forward_euler", K, M, 0.0)) == "unstable at every dt"
    assert nb07.limit_text(((0.0, 0.5), (0.9, 1.3))) == "stable for dt < 0.5 s and for 0.9 s < dt < 1.3 s"


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
    view.controls["method"].value = "velocity_verlet"      # ζ = 1: one window, 4/γ
    assert np.allclose(view.result.windows, [(0.0, 4 / 2.0)], rtol=1e-12)
    view.controls["method"].value = "backward_euler"
    assert view.result.dt_limit == np.inf and "no step limit" in view.result.limit_text
    # a long run at the smallest step: every step computed, drawn thinned
    view.controls["method"].value = "rk4"
    view.controls["dt"].value = 1e-3
    assert view.result.t.size == 20001 and view.result.stable
    assert "every 14th step drawn" in view.figure.axes[0].get_legend().texts[1].get_text()
    view.controls["dt"].value = 6.7e-3                    # 2986 steps: every 2nd drawn
    assert "every 2nd step drawn" in view.figure.axes[0].get_legend().texts[1].get_text()
    view.controls["method"].value = "backward_euler"
    subtitle = view.figure.texts[1].get_text()
    assert subtitle.startswith("backward Euler with this damping: no step limit (A-stable)")


def test_spring_widget_redraws_only_the_curves_and_its_picture_is_right():
    """Driven through its sliders: small changes of dt reuse the kept background (axes,
    ticks, legend), a change of limits, scale or legend redraws it, and each picture equals
    a full redraw of the figure; every panel's limits hold what it draws."""
    view = nb07.spring_explorer(k=10.0, c=0.0, dt=0.05)
    moves = [("dt", 0.0505), ("dt", 0.051), ("dt", 0.0515), ("dt", 0.7), ("method", "rk4"),
             ("dt", 1e-3), ("c", 2.0), ("method", "backward_euler"), ("dt", 0.5)]
    redrawn = []
    for name, value, run, fresh in drive_kept_figure(view, moves):
        redrawn.append(fresh)
        ax_x, ax_e, ax_E = view.figure.axes
        last = run.blowup_step - 1 if run.blowup_step is not None else run.t.size - 1
        floor = 1e-8 * run.exact_energy[0]        # the energy panel's lowest decade
        for ax, y, least in ((ax_x, run.x, -np.inf), (ax_E, run.energy, floor)):
            lo, hi = ax.get_ylim()
            assert ax.get_xlim()[1] >= run.t[last] and lo <= max(np.min(y[: last + 1]), least)
            assert np.max(y[: last + 1]) <= hi, (name, value)
        assert ax_e.get_ylim()[1] >= np.max(run.error[: last + 1])
    # the 1% steps reuse it (one may lower the error panel by a decade); dt = 0.7 does not
    assert sum(redrawn[:3]) <= 1 and redrawn[3]


def test_ordinal():
    from course_lib.lessons.nb07_spring_view import ordinal

    assert [ordinal(n) for n in (1, 2, 3, 4, 11, 12, 13, 21, 22, 23, 111, 112)] == [
        "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "23rd", "111th",
        "112th"]


# --- the exercise checks -------------------------------------------------------------------


SPRING_RIGHT = """def spring_force(x1, x2, k, rest):
    d = np.asarray(x1, dtype=float) - np.asarray(x2, dtype=float)
    length = np.linalg.norm(d)
    return -k * (length - rest) * d / length"""
DAMPED_RIGHT = """def damped_dt_max(k, m, c):
    gamma = c / m
    return 4.0 / (gamma + np.sqrt(gamma**2 + 4.0 * k / m))"""
NETWORK_RIGHT = """def network_forces(x, v, i, j, rest, k, c):
    d = x[i] - x[j]
    length = np.linalg.norm(d, axis=1)
    u = d / length[:, None]
    f = -(k * (length - rest) + c * np.einsum("md,md->m", v[i] - v[j], u))[:, None] * u
    F = np.zeros_like(x, dtype=float)
    np.add.at(F, i, f)
    np.add.at(F, j, -f)
    return F"""
SEARCH = """def damped_dt_max(k, m, c):
    S = lambda dt: np.array([[1 - k / m * dt**2, dt * (1 - c / m * dt)], [-k / m * dt, 1 - c / m * dt]])
    lo, hi = 1e-6, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if np.abs(np.linalg.eigvals(S(mid))).max() <= 1:
            lo = mid
        else:
            hi = mid
    return lo"""

PLANTS = [
    Plant("spring_force", "other", "right", SPRING_RIGHT, "correct", ""),
    Plant("spring_force", "other", "right, float32", SPRING_RIGHT.replace(
        "return -k * (length - rest) * d / length",
        "return (-k * (length - rest) * d / length).astype(np.float32)"), "correct", ""),
    Plant("spring_force", "delegating", "cl.springs.spring_force_pair",
          "def spring_force(x1, x2, k, rest):\n    return cl.springs.spring_force_pair(x1, x2, k, rest)",
          "incorrect", "spring_force_pair"),
    Plant("spring_force", "delegating", "a one-spring SpringNetwork",
          "def spring_force(x1, x2, k, rest):\n"
          "    net = cl.springs.SpringNetwork([0], [1], [rest], [k], [0.0], 2)\n"
          "    return net.forces(np.stack((x1, x2)))[0]", "incorrect", "uses the reference"),
    Plant("spring_force", "shortcut", "divides d by the rest length (right only near rest)",
          SPRING_RIGHT.replace("d / length", "d / rest"), "incorrect",
          "you divided d by the rest length L"),
    Plant("spring_force", "misconception", "subtracts L from the vector d",
          "def spring_force(x1, x2, k, rest):\n    return -k * (x1 - x2 - rest)", "incorrect",
          "subtracted L from the vector d"),
    Plant("spring_force", "other", "sign error (d = x2 - x1): a nudge, no formula",
          SPRING_RIGHT.replace("return -k", "return k"), "incorrect", "sign error",
          avoid="-k ("),
    Plant("spring_force", "other", "sign error, second try: still no formula",
          SPRING_RIGHT.replace("return -k", "return k"), "incorrect",
          "points from particle 2 to particle 1", avoid="-k (", attempt=1),
    Plant("spring_force", "other", "force on the length: no sign-error hint on the compressed case",
          "def spring_force(x1, x2, k, rest):\n    return -k * (x1 - x2)", "incorrect",
          "acts on the stretch, not on the length", avoid="sign error"),
    Plant("spring_force", "other", "Hooke on the strain (divided by L)",
          SPRING_RIGHT.replace("(length - rest)", "(length - rest) / rest"), "incorrect",
          "divided the stretch by the rest length"),
    Plant("spring_force", "other", "|ℓ - L|: pulls when compressed",
          SPRING_RIGHT.replace("(length - rest)", "abs(length - rest)"), "incorrect",
          "pulls even when it is compressed", avoid="sign error"),
    Plant("spring_force", "other", "not normalised",
          SPRING_RIGHT.replace("* d / length", "* d"), "incorrect", "must be a unit vector"),
    Plant("spring_force", "other", "rest length for the stretch",
          SPRING_RIGHT.replace("(length - rest)", "rest"), "incorrect",
          "you used the rest length L where the stretch belongs"),
    Plant("spring_force", "other", "returns NaN",
          "def spring_force(x1, x2, k, rest):\n    return np.full(3, np.nan)", "incorrect",
          "returned NaN"),
    Plant("damped_dt_max", "other", "right", DAMPED_RIGHT, "correct", ""),
    Plant("damped_dt_max", "delegating", "lesson.damped_dt_limit",
          "def damped_dt_max(k, m, c):\n    return lesson07.damped_dt_limit('symplectic_euler', k, m, c)",
          "incorrect", "uses the reference"),
    Plant("damped_dt_max", "delegating", "bisection on cl.integrate's verdict",
          "def damped_dt_max(k, m, c):\n"
          "    f = cl.systems.oscillator(np.sqrt(k / m), c / m)\n"
          "    ok = lambda dt: cl.integrate(f, [1.0, 0.0], (0, 300 * dt), dt, 'symplectic_euler',"
          " blowup_bound=1e3).stable\n"
          "    return cl.stability.bisect_stable_dt(ok, 0.01, 5.0, 1e-9)", "incorrect",
          "uses the reference"),
    Plant("damped_dt_max", "shortcut", "bisection on its own step matrix (a search, not a formula)",
          SEARCH, "incorrect", "(a simulation or a bisection)"),
    Plant("damped_dt_max", "other", "a factor 2 lost: w² dt² + g dt < 4",
          "def damped_dt_max(k, m, c):\n    g, w2 = c / m, k / m\n"
          "    return (-g + np.sqrt(g**2 + 16 * w2)) / (2 * w2)", "incorrect",
          "a factor 2 went missing"),
    Plant("damped_dt_max", "shortcut", "small-damping approximation (2/ω)(1 - ζ)",
          "def damped_dt_max(k, m, c):\n    w = np.sqrt(k / m)\n"
          "    return 2 / w * (1 - c / m / (2 * w))", "incorrect", "small-damping approximation"),
    Plant("damped_dt_max", "misconception", "the undamped limit 2/ω",
          "def damped_dt_max(k, m, c):\n    return 2 * np.sqrt(m / k)", "incorrect",
          "undamped limit 2/ω"),
    Plant("damped_dt_max", "other", "c not divided by m",
          "def damped_dt_max(k, m, c):\n    return 4 / (c + np.sqrt(c**2 + 4 * k / m))",
          "incorrect", "damping rate γ = c/m"),
    Plant("damped_dt_max", "other", "the wrong root",
          "def damped_dt_max(k, m, c):\n    g = c / m\n    return (g + np.sqrt(g**2 + 4 * k / m)) / (k / m)",
          "incorrect", "wrong root"),
    Plant("damped_dt_max", "misconception", "velocity Verlet's min(2/ω, 4/γ): named on every row",
          "def damped_dt_max(k, m, c):\n"
          "    return min(2 * np.sqrt(m / k), 4 * m / c if c else np.inf)", "incorrect",
          "velocity Verlet's limit away from light damping", avoid="undamped limit"),
    Plant("damped_dt_max", "other", "4/γ alone (two half kicks of damping)",
          "def damped_dt_max(k, m, c):\n    return 4 * m / c if c else 2 * np.sqrt(m / k)",
          "incorrect", "two half kicks"),
    Plant("damped_dt_max", "other", "velocity Verlet's first instability, from its cubic",
          """def damped_dt_max(k, m, c):
    w, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    if z == 0:
        return 2 / w
    r = np.roots([z, 4 * z * z - 2, -8 * z, 8])
    r = np.sort(r[(abs(r.imag) < 1e-9) & (r.real > 0)].real)
    return (r[0] if r.size else 2 / z) / w""", "incorrect", "velocity Verlet's first instability"),
    Plant("damped_dt_max", "other", "4/γ alone, second try: the fix added",
          "def damped_dt_max(k, m, c):\n    return 4 * m / c if c else 2 * np.sqrt(m / k)",
          "incorrect", "keep both terms", attempt=1),
    Plant("network_forces", "other", "right", NETWORK_RIGHT, "correct", ""),
    Plant("network_forces", "misconception", "+f on both ends (no reaction)",
          NETWORK_RIGHT.replace("np.add.at(F, j, -f)", "np.add.at(F, j, f)"), "incorrect",
          "opposite directions (Newton's third law"),
    Plant("network_forces", "other", "damping sign flipped",
          NETWORK_RIGHT.replace("+ c * np.einsum", "- c * np.einsum"), "incorrect",
          "the damping force opposes the stretching rate"),
    Plant("network_forces", "other", "a failure shows the worst row, not the whole array",
          NETWORK_RIGHT.replace("np.add.at(F, j, -f)", "np.add.at(F, j, f)"), "incorrect",
          "values differ; the worst, row"),
    Plant("network_forces", "delegating", "cl.springs.SpringNetwork",
          "def network_forces(x, v, i, j, rest, k, c):\n"
          "    return cl.springs.SpringNetwork(i, j, rest, k, c, len(x)).forces(x, v)",
          "incorrect", "uses the reference"),
    Plant("network_forces", "shortcut", "F[i] += f (breaks on repeated indices): no np.add.at yet",
          NETWORK_RIGHT.replace("np.add.at(F, i, f)", "F[i] += f")
          .replace("np.add.at(F, j, -f)", "F[j] -= f"),
          "incorrect", "does not add up repeated indices", avoid="np.add.at"),
    Plant("network_forces", "other", "F[i] += f, second try: the unbuffered add named",
          NETWORK_RIGHT.replace("np.add.at(F, i, f)", "F[i] += f")
          .replace("np.add.at(F, j, -f)", "F[j] -= f"),
          "incorrect", "np.add.at", attempt=1),
    Plant("network_forces", "shortcut", "a loop over the springs",
          """def network_forces(x, v, i, j, rest, k, c):
    F = np.zeros_like(x)
    for s in range(len(i)):
        a, b = i[s], j[s]
        d = x[a] - x[b]
        u = d / np.linalg.norm(d)
        f = -(k[s] * (np.linalg.norm(d) - rest[s]) + c[s] * (v[a] - v[b]) @ u) * u
        F[a] += f
        F[b] -= f
    return F""", "incorrect", "loops over the springs"),
    Plant("network_forces", "misconception", "damps the whole relative velocity",
          NETWORK_RIGHT.replace(
              "f = -(k * (length - rest) + c * np.einsum(\"md,md->m\", v[i] - v[j], u))[:, None] * u",
              "f = -(k * (length - rest))[:, None] * u - c[:, None] * (v[i] - v[j])"),
          "incorrect", "act along the spring only"),
    Plant("network_forces", "other", "leaves out the damping",
          NETWORK_RIGHT.replace(" + c * np.einsum(\"md,md->m\", v[i] - v[j], u)", ""),
          "incorrect", "you left out the damping"),
    Plant("network_forces", "other", "one end only",
          NETWORK_RIGHT.replace("    np.add.at(F, j, -f)\n", ""), "incorrect",
          "pushes both of its ends"),
    Plant("network_forces", "other", "sign error",
          NETWORK_RIGHT.replace("f = -(k", "f = (k"), "incorrect", "sign error"),
]


@pytest.mark.parametrize("plant", PLANTS, ids=lambda p: f"{p.exercise}: {p.label}")
def test_planted_answer(plant):
    judge(check, plant)


def test_every_exercise_has_the_three_kinds_of_plants():
    for exercise in ("spring_force", "damped_dt_max", "network_forces"):
        kinds = {p.kind for p in PLANTS if p.exercise == exercise}
        assert {"delegating", "shortcut", "misconception"} <= kinds, exercise


def test_checks_report_pending_and_correct(capsys):
    def stub(*args):
        raise NotImplementedError()

    for name in ("spring_force", "damped_dt_max", "network_forces"):
        getattr(check, name)(stub)
        assert RESULTS[f"nb07.{name}"]["status"] == "pending"
    check.spring_force(define(SPRING_RIGHT, "spring_force"))
    assert RESULTS["nb07.spring_force"]["status"] == "correct"
    out = capsys.readouterr().out
    assert "momentum: F1 + F2 = 0" in out and "compressed to half its rest length" in out
