"""Every number quoted by notebook 01 (particles in vector fields), and its checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

import course_lib as cl
from course_lib import check
from course_lib.check import nb01
from course_lib.fields import compose, constant_wind, grid, radial, sample, scaled, vortex

WIND = constant_wind((7.0, 2.0))
CLOUD = np.random.default_rng(2026).uniform(-2.0, 2.0, size=(300, 2))


# --- Section 3: the three fields ---------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "expected"),
    [(radial, (1.0, 2.0)), (vortex, (-2.0, 1.0)), (WIND, (7.0, 2.0))],
    ids=["radial", "vortex", "wind"],
)
def test_field_values_at_1_2(field, expected):
    np.testing.assert_array_equal(field(0.0, np.array([1.0, 2.0])), expected)


@pytest.mark.parametrize("field", [radial, vortex, WIND], ids=["radial", "vortex", "wind"])
@pytest.mark.parametrize("shape", [(2,), (300, 2), (13, 13, 2)])
def test_fields_return_one_velocity_per_position(field, shape):
    X = np.ones(shape)
    assert field(0.0, X).shape == shape


def test_field_formulas_on_a_cloud():
    x, y = CLOUD[:, 0], CLOUD[:, 1]
    np.testing.assert_array_equal(radial(0.0, CLOUD), CLOUD)
    np.testing.assert_array_equal(vortex(0.0, CLOUD), np.stack((-y, x), axis=-1))
    np.testing.assert_array_equal(WIND(1.5, CLOUD), np.broadcast_to([7.0, 2.0], CLOUD.shape))


def test_vortex_is_perpendicular_and_as_fast_as_the_radius():
    V = vortex(0.0, CLOUD)
    # The notebook prints both maxima as exactly 0.0.
    assert np.max(np.abs(np.sum(V * CLOUD, axis=1))) == 0.0
    assert np.max(np.abs(np.linalg.norm(V, axis=1) - np.linalg.norm(CLOUD, axis=1))) == 0.0


def test_vortex_period_and_wind_speed():
    assert f"{2 * np.pi:.2f}" == "6.28"  # one turn of the vortex, in s
    assert f"{math.hypot(7.0, 2.0):.2f}" == "7.28"  # wind speed, in m/s


def test_exact_paths_of_the_table_solve_the_odes():
    X0 = np.array([0.3, -1.2])
    t, h = 0.7, 1e-6

    def paths(t):
        c, s = np.cos(t), np.sin(t)
        return {
            radial: np.exp(t) * X0,
            vortex: np.array([c * X0[0] - s * X0[1], s * X0[0] + c * X0[1]]),
            WIND: X0 + t * np.array([7.0, 2.0]),
        }

    for field, X in paths(t).items():
        dXdt = (paths(t + h)[field] - paths(t - h)[field]) / (2 * h)
        np.testing.assert_allclose(dXdt, field(t, X), rtol=1e-8, atol=1e-8)


def test_grid_and_sample_shapes():
    Xg, Yg = grid(extent=2.0, n=11)
    assert Xg.shape == Yg.shape == (11, 11)
    assert Xg.min() == -2.0 and Xg.max() == 2.0
    U, W = sample(vortex, Xg, Yg)
    np.testing.assert_array_equal(U, -Yg)
    np.testing.assert_array_equal(W, Xg)


def test_compose_adds_velocities():
    both = compose(vortex, WIND)
    np.testing.assert_array_equal(both(0.0, CLOUD), vortex(0.0, CLOUD) + WIND(0.0, CLOUD))
    np.testing.assert_array_equal(compose(radial)(0.0, CLOUD), CLOUD)
    np.testing.assert_allclose(scaled(radial, -0.25)(0.0, CLOUD), -0.25 * CLOUD)


def test_vortex_in_wind_turns_about_minus2_7():
    both = compose(vortex, WIND)
    np.testing.assert_array_equal(both(0.0, np.array([-2.0, 7.0])), [0.0, 0.0])
    # ... and it is the vortex about that point: V = (-(y - 7), x + 2).
    c = np.array([-2.0, 7.0])
    np.testing.assert_allclose(both(0.0, CLOUD), vortex(0.0, CLOUD - c), atol=1e-14)


# --- Section 4: the worked step ----------------------------------------------------------


def test_worked_step_is_exact():
    traj = cl.integrate(constant_wind((-1.0, -1.0)), [1.0, 2.0], (0.0, 0.5), 0.5)
    np.testing.assert_array_equal(traj.y[-1], [0.5, 1.5])
    np.testing.assert_array_equal(np.array([1.0, 2.0]) + 0.5 * np.array([-1.0, -1.0]), [0.5, 1.5])


def test_four_constant_steps_stay_on_the_exact_line():
    traj = cl.integrate(constant_wind((-1.0, -1.0)), [1.0, 2.0], (0.0, 2.0), 0.5)
    exact = np.array([1.0, 2.0]) + traj.t[:, None] * np.array([-1.0, -1.0])
    assert np.max(np.linalg.norm(traj.y - exact, axis=1)) == 0.0
    np.testing.assert_array_equal(traj.y[-1], [-1.0, 0.0])


# --- Section 5: the whirlpool cloud ------------------------------------------------------

K, DT = 0.25, 0.01


def _whirl_run():
    whirl = compose(vortex, scaled(radial, -K))
    X0 = np.random.default_rng(2026).uniform(-2.0, 2.0, size=(300, 2))
    traj = cl.integrate(whirl, X0, (0.0, 628 * DT), DT)
    T = traj.t[-1]
    c, s, d = np.cos(T), np.sin(T), np.exp(-K * T)
    exact = d * np.stack((c * X0[:, 0] - s * X0[:, 1], s * X0[:, 0] + c * X0[:, 1]), axis=-1)
    return traj, exact


def test_whirlpool_exact_solution_solves_the_ode():
    whirl = compose(vortex, scaled(radial, -K))
    X0, t, h = np.array([1.3, -0.4]), 0.9, 1e-6

    def X(t):
        c, s = np.cos(t), np.sin(t)
        return np.exp(-K * t) * np.array([c * X0[0] - s * X0[1], s * X0[0] + c * X0[1]])

    np.testing.assert_allclose((X(t + h) - X(t - h)) / (2 * h), whirl(t, X(t)), rtol=1e-8)


def test_whirlpool_run_numbers():
    traj, exact = _whirl_run()
    assert traj.n_steps == 628 and traj.stable
    assert f"{traj.t[-1]:.2f}" == "6.28"
    assert f"{math.exp(-2 * math.pi * K):.2f}" == "0.21"  # radius factor after one turn
    ratio = np.linalg.norm(traj.y[-1], axis=1) / np.linalg.norm(exact, axis=1)
    theory = math.hypot(1 - K * DT, DT) ** traj.n_steps * math.exp(K * traj.t[-1])
    # Linear field: every particle has the same ratio, the per-step analysis, "about 3 %".
    np.testing.assert_allclose(ratio, theory, rtol=1e-10)
    assert f"{theory:.4f}" == "1.0300"
    error = np.linalg.norm(traj.y[-1] - exact, axis=1)
    assert f"{error.max():.3f}" == "0.019"


def test_animation_frames_every_22nd_step():
    # "30 frames, about every 22nd step" of the 628-step run.
    frames = np.linspace(0, 628, 30).round().astype(int)
    assert len(frames) == 30 and frames[0] == 0 and frames[-1] == 628
    assert set(np.diff(frames)) <= {21, 22}
    assert round(628 / 29) == 22


def test_whirlpool_ratio_matches_second_order_expansion():
    # Per step, log of (Euler factor / exact factor) = (1 - k^2) dt^2 / 2 + O(dt^3), so over
    # T = 6.28 s the ratio is about exp((1 - k^2) T dt / 2): "about 3 %".
    traj, exact = _whirl_run()
    ratio = np.linalg.norm(traj.y[-1, 0]) / np.linalg.norm(exact[0])
    approx = math.exp((1 - K**2) * traj.t[-1] * DT / 2)
    assert ratio == pytest.approx(approx, rel=3e-4)
    assert round(100 * (ratio - 1)) == 3


# --- Section 6 and exercise 5: drift of forward Euler on the vortex -----------------------


def test_euler_on_vortex_worked_points():
    traj = cl.integrate(vortex, [0.0, 1.0], (0.0, 1.5), 0.5)
    np.testing.assert_array_equal(traj.y, [[0.0, 1.0], [-0.5, 1.0], [-1.0, 0.75], [-1.375, 0.25]])
    assert f"{np.linalg.norm(traj.y[3]):.2f}" == "1.40"


def test_euler_on_vortex_radius_grows_by_sqrt_1_plus_dt2():
    traj = cl.integrate(vortex, [0.0, 1.0], (0.0, 6.0), 0.5)
    r = np.linalg.norm(traj.y, axis=1)
    np.testing.assert_allclose(r[1:] / r[:-1], math.sqrt(1.25), rtol=1e-14)
    assert f"{math.sqrt(1.25):.6f}" == "1.118034"
    np.testing.assert_allclose(r[-1], 1.25**6, rtol=1e-14)  # 12 steps: 3.8 m, not 1 m
    assert f"{r[-1]:.1f}" == "3.8"
    assert f"{1.25**1.5:.2f}" == "1.40"


def test_exact_vortex_stays_on_unit_circle():
    t = np.linspace(0.0, 6.0, 13)
    exact = np.stack((-np.sin(t), np.cos(t)), axis=-1)
    np.testing.assert_allclose(np.linalg.norm(exact, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(
        cl.integrate(vortex, [0.0, 1.0], (0.0, 6.0), 1e-3, method="rk4").y[-1], exact[-1],
        atol=1e-10)


# --- the checks of course_lib.check.nb01 -------------------------------------------------


def _run(check_fn, answer, capsys):
    check_fn(answer)
    out = capsys.readouterr().out
    return nb01_result(check_fn), out


def nb01_result(check_fn):
    return check.RESULTS[f"nb01.{check_fn.__name__}"]["status"]


def _pending(*args, **kwargs):
    raise NotImplementedError()


@pytest.mark.parametrize("name", ["vortex_field", "whirlpool", "advect_step", "particle_frame",
                                  "cohesion"])
def test_checks_report_pending(name, capsys):
    status, out = _run(getattr(nb01, name), _pending, capsys)
    assert status == "pending"
    assert "pending" in out


def test_every_check_is_registered():
    names = {k for k in check.REGISTRY if k.startswith("nb01.")}
    assert names == {"nb01.vortex_field", "nb01.whirlpool", "nb01.advect_step",
                     "nb01.particle_frame", "nb01.cohesion"}


# vortex_field


def _vortex_ok(t, X):
    X = np.asarray(X, dtype=float)
    return np.stack((-X[..., 1], X[..., 0]), axis=-1)


def _vortex_in_place(t, X):
    V = _vortex_ok(t, X)
    X[...] = 0.0
    return V


@pytest.mark.parametrize(
    ("answer", "hint"),
    [
        (lambda t, X: np.stack((X[..., 1], -X[..., 0]), axis=-1), "clockwise"),
        (lambda t, X: np.stack((X[..., 1], X[..., 0]), axis=-1), "a minus sign is missing"),
        (lambda t, X: np.stack((-X[..., 0], X[..., 1]), axis=-1), "not swapped"),
        (lambda t, X: np.array(X, dtype=float), "that is the radial field"),
        (lambda t, X: np.array([-X[..., 1], X[..., 0]]), "np.stack((vx, vy), axis=-1)"),
        (lambda t, X: np.array([-X[1], X[0]]), "not X[0] and X[1]"),
        (_vortex_in_place, "do not assign into X"),
        (lambda t, X: (1 + t) * _vortex_ok(t, X), "does not depend on t"),
    ],
    ids=["clockwise", "no-minus", "not-swapped", "radial", "shape-2N", "rows", "in-place",
         "uses-t"],
)
def test_vortex_field_mistakes(answer, hint, capsys):
    status, out = _run(nb01.vortex_field, answer, capsys)
    assert status == "incorrect"
    assert hint in out


def test_vortex_field_correct(capsys):
    status, out = _run(nb01.vortex_field, _vortex_ok, capsys)
    assert status == "correct", out
    assert check.RESULTS["nb01.vortex_field"]["passed"] == 7


# whirlpool


def _whirl_ok(t, X, k=0.5):
    X = np.asarray(X, dtype=float)
    return vortex(t, X) - k * X


@pytest.mark.parametrize(
    ("answer", "hint"),
    [
        (lambda t, X, k=0.5: vortex(t, X) + k * np.asarray(X), "the pull points outwards"),
        (lambda t, X, k=0.5: -k * np.asarray(X), "the vortex part (-y, x) is missing"),
        (lambda t, X, k=0.5: vortex(t, X), "the inward pull -k (x, y) is missing"),
        (lambda t, X, k=0.5: vortex(t, X) - 0.5 * np.asarray(X), "use the argument k"),
    ],
    ids=["outward", "no-vortex", "no-pull", "ignores-k"],
)
def test_whirlpool_mistakes(answer, hint, capsys):
    status, out = _run(nb01.whirlpool, answer, capsys)
    assert status == "incorrect"
    assert hint in out


def test_whirlpool_correct_and_reference(capsys):
    status, out = _run(nb01.whirlpool, _whirl_ok, capsys)
    assert status == "correct", out
    np.testing.assert_array_equal(nb01.whirlpool_reference(0.0, [1.0, 2.0], 0.5), [-2.5, 0.0])


# advect_step


def _advect_in_place(X, V, dt):
    X += dt * V
    return X


@pytest.mark.parametrize(
    ("answer", "hint"),
    [
        (lambda X, V, dt: X - dt * V, "you moved against the velocity"),
        (lambda X, V, dt: X + V, "dt is missing (or taken as 1)"),
        (lambda X, V, dt: dt * V, "you returned the displacement"),
        (lambda X, V, dt: X + 0.5 * dt * V, "you used dt / 2"),
        (_advect_in_place, "instead of updating X in place"),
    ],
    ids=["subtract", "no-dt", "displacement", "half-dt", "in-place"],
)
def test_advect_step_mistakes(answer, hint, capsys):
    status, out = _run(nb01.advect_step, answer, capsys)
    assert status == "incorrect"
    assert hint in out


def test_advect_step_correct(capsys):
    status, out = _run(nb01.advect_step, lambda X, V, dt: X + dt * V, capsys)
    assert status == "correct", out
    assert "worked example X = (1, 2), V = (-1, -1), dt = 0.5" in out


def test_advect_step_worked_example_wrong_value_is_reported(capsys):
    # A subtracting answer gives (1.5, 2.5) on the worked example; the check names both.
    _, out = _run(nb01.advect_step, lambda X, V, dt: X - dt * V, capsys)
    assert "expected [0.5, 1.5], got [1.5, 2.5]" in out


# particle_frame


def _frame(particles, V, dt, newborn, *, keep=lambda age, life: age < life, age_it=True,
           move=True, keys=None):
    X = particles["X"] + dt * V if move else particles["X"]
    age = particles["age"] + dt if age_it else particles["age"]
    alive = keep(age, particles["lifetime"])
    new = dict(particles, X=X, age=age)
    keys = list(particles) if keys is None else keys
    return {k: np.concatenate([new[k][alive], newborn[k]]) for k in keys}


def _frame_in_place(particles, V, dt, newborn):
    out = _frame(particles, V, dt, newborn)
    particles["age"] += dt
    return out


@pytest.mark.parametrize(
    ("answer", "hint"),
    [
        (lambda p, V, dt, nb: _frame(p, V, dt, nb, keep=lambda a, life: a <= life),
         "keep age < lifetime"),
        (lambda p, V, dt, nb: _frame(p, V, dt, nb, keep=lambda a, life: a == a),
         "no particle was deleted"),
        (lambda p, V, dt, nb: _frame(p, V, dt, nb, age_it=False),
         "age every particle by dt"),
        (lambda p, V, dt, nb: _frame(p, V, dt, nb, move=False),
         "move every surviving particle by dt * V"),
        (lambda p, V, dt, nb: _frame(p, V, dt, nb, keys=["X", "age", "lifetime"]),
         "build the result from every key of particles"),
        (lambda p, V, dt, nb: list(p), "return a dict with the same keys"),
        (_frame_in_place, "build and return a new dict"),
    ],
    ids=["le", "no-delete", "no-age", "no-move", "drops-colour", "not-dict", "in-place"],
)
def test_particle_frame_mistakes(answer, hint, capsys):
    status, out = _run(nb01.particle_frame, answer, capsys)
    assert status == "incorrect"
    assert hint in out


def test_particle_frame_correct_and_reference(capsys):
    status, out = _run(nb01.particle_frame, _frame, capsys)
    assert status == "correct", out
    particles, V, dt, newborn = nb01._particle_case()
    got = nb01.particle_frame_reference(particles, V, dt, newborn)
    # Ages 0, 0.5, 1.5, 3 plus 0.5 against lifetimes 2, 1, 1.75, 4: particles 0 and 3 live
    # (particle 1 reaches its lifetime exactly), then the two newborns follow.
    np.testing.assert_array_equal(got["age"], [0.5, 3.5, 0.0, 0.0])
    np.testing.assert_array_equal(got["X"], [[0.5, 0.0], [-0.75, 0.75], [5.0, 5.0], [6.0, 6.0]])
    np.testing.assert_array_equal(got["lifetime"], [2.0, 4.0, 3.0, 2.5])
    assert got["colour"].shape == (4, 3)


def test_checks_survive_a_crashing_answer(capsys):
    def boom(*args, **kwargs):
        raise ZeroDivisionError("oops")

    for name in ("vortex_field", "whirlpool", "advect_step", "particle_frame", "cohesion"):
        status, out = _run(getattr(nb01, name), boom, capsys)
        assert status == "incorrect"
        assert "ZeroDivisionError: oops" in out


# --- the field speeds quoted under the quiver plot ----------------------------------------


def test_quiver_speeds_quoted():
    Xg, Yg = grid(extent=2.0, n=11)
    for field in (radial, vortex):
        U, W = sample(field, Xg, Yg)
        assert np.hypot(U, W).min() == 0.0
        assert np.hypot(U, W).max() == pytest.approx(2 * math.sqrt(2), rel=1e-15)
    assert f"{2 * math.sqrt(2):.2f}" == "2.83"


def test_whirlpool_gap_grows_as_the_per_step_analysis_says():
    traj, _ = _whirl_run()
    n = np.arange(629)
    r = np.linalg.norm(traj.y[:, 0], axis=1)
    X0 = traj.y[0, 0]
    r_exact = np.linalg.norm(X0) * np.exp(-K * traj.t)
    predicted = math.hypot(1 - K * DT, DT) ** n * np.exp(K * traj.t)
    np.testing.assert_allclose(r / r_exact, predicted, rtol=1e-12)
    assert np.all(np.diff(predicted) > 0)  # grows steadily, step after step
    assert traj.t[-1] == pytest.approx(6.28, abs=1e-12)


# --- Section 7: the flock ----------------------------------------------------------------


def test_flock_numbers_quoted():
    from course_lib.lessons import nb01_vector_fields as lesson

    flock = lesson.run_flock(n=80, steps=600, dt=0.05)
    alone = lesson.run_flock(n=80, steps=600, dt=0.05, weights=(1.0, 0.0, 0.6))
    assert flock.t[-1] == pytest.approx(30.0)
    assert f"{flock.polarisation[0]:.2f}" == "0.08"
    assert f"{flock.polarisation[-1]:.2f}" == "0.86"
    assert f"{alone.polarisation[-1]:.2f}" == "0.23"
    assert 1 / math.sqrt(80) == pytest.approx(0.11, abs=0.005)  # "about 0.1"
    speeds = np.linalg.norm(flock.V[1:], axis=-1)
    assert speeds.min() >= 0.6 - 1e-12 and speeds.max() <= 1.5 + 1e-12
    assert np.all((flock.X >= 0) & (flock.X < 10.0))


def test_flock_rules_against_a_loop():
    from course_lib.lessons import nb01_vector_fields as lesson

    rng = np.random.default_rng(7)
    X = rng.uniform(0, 10, (25, 2))
    V = rng.normal(size=(25, 2))
    got = lesson.flock_acceleration(X, V, box=10.0, radius=1.5, r_sep=0.5, weights=(1.0, 1.0, 0.6))
    want = np.zeros_like(X)
    for i in range(25):
        sep, ali, coh, count = np.zeros(2), np.zeros(2), np.zeros(2), 0
        for j in range(25):
            d = X[j] - X[i]
            d -= 10.0 * np.round(d / 10.0)
            dist = np.linalg.norm(d)
            if i == j or dist >= 1.5:
                continue
            count += 1
            coh += d
            ali += V[j]
            if dist < 0.5:
                sep -= d / dist**2
        if count:
            want[i] = sep + (ali / count - V[i]) + 0.6 * coh / count
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert lesson.polarisation(np.ones((3, 2))) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="n >= 2"):
        lesson.run_flock(n=1)


# cohesion


def _cohesion_ok(X, radius):
    X = np.asarray(X, dtype=float)
    D = X[None, :, :] - X[:, None, :]
    near = np.sum(D**2, axis=-1) < radius**2
    np.fill_diagonal(near, False)
    count = near.sum(axis=1, keepdims=True)
    return (near[:, :, None] * D).sum(axis=1) / np.maximum(count, 1)


def _cohesion_loop(X, radius):
    out = np.zeros((len(X), 2))
    for i in range(len(X)):
        nbrs = [X[j] - X[i] for j in range(len(X)) if j != i and np.linalg.norm(X[j] - X[i]) < radius]
        if nbrs:
            out[i] = np.mean(nbrs, axis=0)
    return out


def test_cohesion_reference_against_a_loop_and_by_hand():
    for _, X, radius in nb01._cohesion_cases():
        np.testing.assert_allclose(nb01.cohesion_reference(X, radius), _cohesion_loop(X, radius),
                                   rtol=1e-12, atol=1e-14)
    X = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0], [5.5, 5.0]])
    np.testing.assert_allclose(nb01.cohesion_reference(X, 1.2),
                               [[0.5, 0.5], [-1, 0], [0, -1], [0.5, 0], [-0.5, 0]])


def test_cohesion_accepts_right_answers(capsys):
    for answer in (_cohesion_ok, _cohesion_loop,
                   lambda X, r: _cohesion_ok(X, r).astype(np.float32),
                   lambda X, r: _cohesion_ok(np.asarray(X, np.float32), np.float32(r)),
                   lambda X, r: _cohesion_ok(X, r).tolist()):
        status, out = _run(nb01.cohesion, answer, capsys)
        assert status == "correct", out


def _cohesion_self(X, radius):
    D = X[None] - X[:, None]
    near = np.sum(D**2, axis=-1) < radius**2
    return (near[:, :, None] * D).sum(1) / near.sum(1, keepdims=True)


def _cohesion_nan(X, radius):
    D = X[None] - X[:, None]
    near = np.sum(D**2, axis=-1) < radius**2
    np.fill_diagonal(near, False)
    with np.errstate(all="ignore"):
        return (near[:, :, None] * D).sum(1) / near.sum(1, keepdims=True)


def _cohesion_in_place(X, radius):
    out = _cohesion_ok(X, radius)
    X -= X.mean(axis=0)
    return out


@pytest.mark.parametrize(
    ("answer", "hint"),
    [
        (_cohesion_self, "a boid is not its own neighbour"),
        (_cohesion_nan, "return 0 for it"),
        (lambda X, r: -_cohesion_ok(X, r), "points away from the neighbours"),
        (lambda X, r: _cohesion_ok(X, r) + np.where(
            np.abs(_cohesion_ok(X, r)).sum(1, keepdims=True) > 0, X, 0.0), "not the centre itself"),
        (_cohesion_in_place, "do not assign into X"),
        (lambda X, r: _cohesion_ok(X, r)[:, 0], "expected shape"),
    ],
    ids=["self", "nan", "sign", "centre", "in-place", "shape"],
)
def test_cohesion_mistakes(answer, hint, capsys):
    status, out = _run(nb01.cohesion, answer, capsys)
    assert status == "incorrect"
    assert hint in out
    assert len(out) < 4000  # a wrong 200-boid answer is summarised, not printed whole


# the reference is computed before the student's function runs


def test_scribbling_answer_is_compared_with_the_true_reference(capsys):
    def scribbler(t, X):
        V = _vortex_ok(t, X)
        X *= 100.0                      # corrupts its input after computing the answer
        return V

    status, out = _run(nb01.vortex_field, scribbler, capsys)
    assert status == "incorrect"
    assert "do not assign into X" in out
    # every value case passes: the expected values came from pristine copies
    assert check.RESULTS["nb01.vortex_field"]["passed"] == 6

    def scribbling_frame(particles, V, dt, newborn):
        out = _frame(particles, V, dt, newborn)
        particles["X"] *= 0.0
        return out

    status, out = _run(nb01.particle_frame, scribbling_frame, capsys)
    assert "the positions after one frame (dt = 0.5 s): expected" not in out
    assert "build and return a new dict" in out


@pytest.mark.parametrize("name", ["vortex_field", "whirlpool"])
def test_field_checks_accept_float32(name, capsys):
    answer = {"vortex_field": lambda t, X: _vortex_ok(t, X).astype(np.float32),
              "whirlpool": lambda t, X, k=0.5: _whirl_ok(t, X, k).astype(np.float32)}[name]
    status, out = _run(getattr(nb01, name), answer, capsys)
    assert status == "correct", out


def test_advect_and_frame_accept_float32_and_lists(capsys):
    status, out = _run(nb01.advect_step, lambda X, V, dt: (X + dt * V).astype(np.float32), capsys)
    assert status == "correct", out
    status, out = _run(nb01.advect_step, lambda X, V, dt: (X + dt * V).tolist(), capsys)
    assert status == "correct", out
