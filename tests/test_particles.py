"""course_lib.particles: the structure-of-arrays system, Reeves emitters, expected populations."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import fields
from course_lib import particles as P


def test_add_step_expire_keep_the_survivors_in_order():
    ps = P.ParticleSystem(3, capacity=4, attributes={"temperature": (), "colour": (3,)})
    ps.add(x=np.arange(15.0).reshape(5, 3), v=[0.0, 1.0, 0.0], lifetime=[0.3, 1.0, 0.1, 2.0, 0.2],
           temperature=[1.0, 2.0, 3.0, 4.0, 5.0], colour=[0.5, 0.5, 0.5])
    assert len(ps) == 5 and ps.capacity >= 5                      # grew past its capacity
    assert ps["colour"].shape == (5, 3) and np.all(ps["age"] == 0.0)
    ps.step(0.25)                                                 # no force: x += dt v
    assert np.array_equal(ps["x"][:, 1], np.arange(1.0, 15.0, 3.0) + 0.25)
    assert ps.expire() == 2                                       # lifetimes 0.1 and 0.2 < 0.25
    assert np.array_equal(ps["temperature"], [1.0, 2.0, 4.0])     # order kept
    assert np.array_equal(ps["lifetime"], [0.3, 1.0, 2.0])
    assert np.array_equal(ps["x"][:, 0], [0.0, 3.0, 9.0])
    ps["x"][:, 0] = -1.0                                          # a view: writes stick
    assert np.all(ps["x"][:, 0] == -1.0)
    ps.step(0.05)
    assert ps.expire() == 1                                       # age 0.3 reached lifetime 0.3
    assert np.array_equal(ps["temperature"], [2.0, 4.0])


def test_step_is_symplectic_euler_and_lands_half_g_dt_t_low():
    ps = P.ParticleSystem(3)
    ps.add(x=np.zeros((1, 3)), v=[[1.0, 5.0, 0.0]], lifetime=10.0)
    g, dt = np.array([0.0, -9.81, 0.0]), 0.05
    y = np.stack((np.zeros((1, 3)), [[1.0, 5.0, 0.0]]))
    system = cl.NewtonianSystem(lambda t, x, v: np.broadcast_to(g, x.shape), 1.0)
    for _ in range(40):
        ps.step(dt, g)
        y = cl.symplectic_euler(system, 0.0, y, dt)
    assert np.allclose(ps["x"], y[0], rtol=0, atol=1e-13)
    t = 40 * dt
    exact = np.array([t, 5.0 * t - 0.5 * 9.81 * t**2, 0.0])
    assert ps["x"][0] - exact == pytest.approx([0.0, -0.5 * 9.81 * dt * t, 0.0], abs=1e-12)


def test_advect_is_one_midpoint_step():
    ps = P.ParticleSystem(2)
    x0 = np.array([[1.0, 0.5], [-0.3, 2.0]])
    ps.add(x=x0, lifetime=5.0)
    ps.advect(0.0, 0.1, fields.vortex)
    ref = cl.integrate(fields.vortex, x0, (0.0, 0.1), 0.1, method="midpoint").y[-1]
    assert np.allclose(ps["x"], ref, rtol=0, atol=1e-15)
    assert np.allclose(ps["v"], fields.vortex(0.05, x0 + 0.05 * fields.vortex(0.0, x0)))
    assert np.all(ps["age"] == 0.1)


def test_compaction_of_a_large_system_matches_boolean_indexing():
    rng = np.random.default_rng(1)
    ps = P.ParticleSystem(3, 100)
    x = rng.normal(size=(10_000, 3))
    ps.add(x=x, age=rng.uniform(0, 2, 10_000), lifetime=rng.uniform(0, 2, 10_000))
    keep = ps["age"] < ps["lifetime"]
    expected = x[keep]
    assert ps.expire() == 10_000 - keep.sum()
    assert np.array_equal(ps["x"], expected)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="dim"):
        P.ParticleSystem(4)
    with pytest.raises(ValueError, match="capacity"):
        P.ParticleSystem(3, 0)
    with pytest.raises(ValueError, match="built in"):
        P.ParticleSystem(3, attributes={"age": ()})
    ps = P.ParticleSystem(3)
    with pytest.raises(KeyError, match="unknown attributes"):
        ps.add(x=np.zeros((1, 3)), colour=1.0)
    with pytest.raises(ValueError, match=r"x must have shape \(k, 3\)"):
        ps.add(x=np.zeros((2, 2)))
    with pytest.raises(KeyError, match="no attribute"):
        ps["temperature"]
    with pytest.raises(ValueError, match="keep must have shape"):
        ps.compact([True])
    with pytest.raises(ValueError, match="unknown shape 'cube'"):
        P.Emitter(shape="cube")
    with pytest.raises(ValueError, match="lifetime_variance"):
        P.Emitter(lifetime=1.0, lifetime_variance=2.0)
    with pytest.raises(ValueError, match="direction must have 2"):
        P.Emitter(center=(0.0, 0.0), direction=(0.0, 1.0, 0.0))
    with pytest.raises(ValueError, match="sphere"):
        P.sample_shape("sphere", 3, np.random.default_rng(0), center=(0.0, 0.0))
    with pytest.raises(ValueError, match="dt"):
        ps.step(0.0)


def test_reeves_count_has_mean_exactly_mean_and_variance_v2_over_3_plus_one_sixth():
    rng = np.random.default_rng(7)
    for mean, var in [(40.0, 10.0), (7.3, 2.5)]:
        counts = np.array([P.reeves_count(mean, var, rng) for _ in range(40_000)])
        theory_var = var**2 / 3 + 1 / 6              # exact when 2 var is a whole number
        se = np.sqrt(theory_var / counts.size)
        assert abs(counts.mean() - mean) < 4 * se
        assert counts.min() >= np.floor(mean - var) and counts.max() <= np.ceil(mean + var)
        if var == 10.0:
            assert counts.var() == pytest.approx(theory_var, rel=0.03)
    assert P.reeves_count(5.0, 0.0, rng) == 5                  # no variance: exactly the mean
    assert P.reeves_count(-3.0, 1.0, rng) == 0                 # never negative


def test_shapes_are_uniform_and_lie_where_they_should():
    rng = np.random.default_rng(3)
    n = 40_000
    disc = P.sample_shape("disc", n, rng, center=(1.0, 2.0, 3.0), radius=2.0, normal=(1.0, 1.0, 0.0))
    off = disc - [1.0, 2.0, 3.0]
    assert np.allclose(off @ np.array([1.0, 1.0, 0.0]), 0.0, atol=1e-12)     # in the plane
    r = np.linalg.norm(off, axis=1)
    assert r.max() <= 2.0
    assert np.mean(r < 1.0) == pytest.approx(0.25, abs=4 * np.sqrt(0.25 * 0.75 / n))
    ring = P.sample_shape("ring", 100, rng, center=(0.0, 0.0), radius=3.0)
    assert np.allclose(np.linalg.norm(ring, axis=1), 3.0, rtol=1e-14)
    sphere = P.sample_shape("sphere", n, rng, radius=0.5)
    assert np.allclose(np.linalg.norm(sphere, axis=1), 0.5, rtol=1e-14)
    assert np.abs(sphere.mean(axis=0)).max() < 4 * 0.5 / np.sqrt(3 * n)
    assert np.mean(sphere[:, 2] > 0.25) == pytest.approx(0.25, abs=0.01)      # Archimedes: z uniform
    assert np.array_equal(P.sample_shape("point", 4, rng, center=(1.0, 2.0)), np.tile([1.0, 2.0], (4, 1)))


def test_directions_fill_the_cone_uniformly():
    rng = np.random.default_rng(4)
    spread = np.radians(30.0)
    d = P.sample_directions(50_000, rng, (0.0, 0.0, 2.0), spread)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert d[:, 2].min() >= np.cos(spread) - 1e-12
    assert d[:, 2].mean() == pytest.approx((1 + np.cos(spread)) / 2, abs=1e-3)   # cos θ uniform
    d2 = P.sample_directions(1000, rng, (1.0, 0.0), spread)
    assert np.abs(np.arctan2(d2[:, 1], d2[:, 0])).max() <= spread


def test_emitter_draws_around_its_means():
    em = P.Emitter(count=lambda t: 10.0 + 100.0 * t, count_variance=0.0, shape="ring", radius=2.0,
                   speed=3.0, speed_variance=1.0, radial=0.5, lifetime=2.0, lifetime_variance=0.5,
                   attributes={"temperature": (1000.0, 100.0)})
    ps = P.ParticleSystem(3, attributes={"temperature": ()})
    rng = np.random.default_rng(5)
    assert em.emit(ps, 0.0, rng) == 10 and em.emit(ps, 0.5, rng) == 60      # the mean changes
    assert em.mean_count(0.25) == 35.0
    assert np.all(np.abs(ps["lifetime"] - 2.0) <= 0.5)
    assert np.all(np.abs(ps["temperature"] - 1000.0) <= 100.0)
    outward = ps["x"] / np.linalg.norm(ps["x"], axis=1, keepdims=True)
    up_speed = ps["v"] - 0.5 * outward                            # remove the radial part
    assert np.allclose(up_speed[:, [0, 2]], 0.0, atol=1e-12)       # spread 0: straight up
    assert np.all((up_speed[:, 1] >= 2.0) & (up_speed[:, 1] <= 4.0))


def test_expected_population_matches_a_deterministic_run_exactly():
    # integer count, no count variance and fixed lifetimes: the run is deterministic
    dt, life, mu = 0.125, 0.5, 7.0
    em = P.Emitter(count=mu, lifetime=life, center=(0.0, 0.0), speed=0.0)
    ps = P.ParticleSystem(2)
    rng = np.random.default_rng(0)
    pops = []
    for f in range(12):
        em.emit(ps, f * dt, rng)
        ps.step(dt)
        ps.expire()
        pops.append(len(ps))
    expected = P.expected_population(np.full(12, mu), dt, life)
    assert np.array_equal(pops, expected)
    assert pops[-1] == mu * (life / dt - 1)                        # alive at ages dt, 2dt, 3dt


def test_steady_population_is_little_less_half_a_frame():
    dt = 1 / 30
    assert P.steady_population(40.0, dt, 2.5, 0.5) == pytest.approx(40 * (2.5 / dt - 0.5), rel=1e-12)
    assert P.steady_population(10.0, 0.1, 1.0, 0.3) == pytest.approx(10 * (1.0 / 0.1 - 0.5), rel=1e-12)
    ramp = P.expected_population(np.full(400, 40.0), dt, 2.5, 0.5)
    assert ramp[-1] == pytest.approx(2980.0, rel=1e-12)
    assert ramp[58] == pytest.approx(40 * 59, rel=1e-12)          # nobody dies before 2 s
    assert P.survival([0.5, 1.0, 1.5], 1.0, 0.5).tolist() == [1.0, 0.5, 0.0]


# --- ages are counted, not summed (issue 20) ----------------------------------------------


def test_a_lifetime_of_m_frames_dies_after_exactly_m_frames():
    """Lifetimes m/n s at dt = 1/n s, and the same lifetimes typed as m × dt: every
    particle dies at the end of its m-th step. A running sum age += dt kept thousands of
    them alive a step too long (0.1 + ... + 0.1, eight times, is below 0.8)."""
    for n in (10, 24, 30, 60, 100):
        dt = 1.0 / n
        m = np.arange(1, 3 * n + 1)
        for lifetimes in (m / n, m * dt):
            ps = P.ParticleSystem(2, capacity=m.size)
            ps.add(x=np.zeros((m.size, 2)), lifetime=lifetimes)
            died_at = np.zeros(m.size, dtype=int)
            alive = np.arange(m.size)
            for step in range(1, 3 * n + 2):
                ps.step(dt)
                gone = P.reached(ps["age"], ps["lifetime"])
                died_at[alive[gone]] = step
                alive = alive[~gone]
                ps.expire()
            assert np.array_equal(died_at, m), (n, np.flatnonzero(died_at != m)[:5])
    ps = P.ParticleSystem(2)
    ps.add(x=np.zeros((1, 2)), lifetime=0.8)
    for _ in range(8):
        ps.step(0.1)
    assert ps.expire() == 1


def test_ages_restart_their_count_when_the_step_changes():
    ps = P.ParticleSystem(2)
    ps.add(x=np.zeros((2, 2)), age=[0.0, 0.5], lifetime=10.0)
    for _ in range(3):
        ps.step(0.1)
    ps.add(x=np.zeros((1, 2)), lifetime=10.0)
    for _ in range(4):
        ps.step(0.25)
    assert np.allclose(ps["age"], [1.3, 1.8, 1.0], rtol=0, atol=1e-15)
    assert ps["age"][2] == 4 * 0.25                               # counted: one rounding


@pytest.mark.parametrize("dt,life", [(0.1, 0.8), (1 / 30, 2.5), (1 / 60, 0.7), (0.05, 0.35),
                                     (1 / 24, 1.0), (0.1, 0.3)])
def test_expected_population_matches_deterministic_runs_frame_by_frame(dt, life):
    mu, frames = 3.0, round(life / dt) + 6
    em = P.Emitter(count=mu, lifetime=life, center=(0.0, 0.0), speed=0.0)
    ps, rng, pops = P.ParticleSystem(2), np.random.default_rng(0), []
    for f in range(frames):
        em.emit(ps, f * dt, rng)
        ps.step(dt)
        ps.expire()
        pops.append(len(ps))
    expected = P.expected_population(np.full(frames, mu), dt, life)
    assert np.array_equal(pops, expected)
    steady = mu * (round(life / dt) - 1)                          # V = 0: L/dt - 1 per count
    assert pops[-1] == steady == P.steady_population(mu, dt, life)


def test_expected_population_matches_random_lifetimes_frame_by_frame():
    """Random lifetimes, a growing count: each frame's population is a sum of independent
    survivals, so the measurement lies within 4 standard deviations of the expectation
    at every frame (a binomial-like variance, bounded by the expectation itself)."""
    dt, life, var, frames = 1 / 30, 0.5, 0.2, 40
    mean_counts = np.round(200 + 20 * np.arange(frames)).astype(float)
    ps, rng, pops = P.ParticleSystem(2, 4096), np.random.default_rng(12), []
    for f in range(frames):
        ps.add(x=np.zeros((int(mean_counts[f]), 2)),
               lifetime=P.around(life, var, int(mean_counts[f]), rng))
        ps.step(dt)
        ps.expire()
        pops.append(len(ps))
    expected = P.expected_population(mean_counts, dt, life, var)
    assert np.all(np.abs(np.array(pops) - expected) <= 4 * np.sqrt(expected) + 1e-12)
    assert np.array_equal(np.array(pops)[:9], np.cumsum(mean_counts)[:9])   # nobody dies < 0.3 s


@pytest.mark.parametrize("dt", [1 / 30, 0.1, 1 / 60])
def test_steady_population_says_what_it_computes(dt):
    for life, var in [(2.5, 0.5), (1.0, 0.3), (0.6, 0.2)]:
        whole = round((life - var) / dt), round((life + var) / dt)
        if not np.allclose(whole, [(life - var) / dt, (life + var) / dt], rtol=1e-12):
            continue
        assert P.steady_population(10.0, dt, life, var) == pytest.approx(10 * (life / dt - 0.5), rel=1e-12)
        ramp = P.expected_population(np.full(400, 10.0), dt, life, var)
        assert ramp[-1] == pytest.approx(P.steady_population(10.0, dt, life, var), rel=1e-12)
    assert P.steady_population(10.0, dt, 1.0) == pytest.approx(10 * (1.0 / dt - 1), rel=1e-12)
