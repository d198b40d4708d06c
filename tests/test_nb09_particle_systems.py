"""Every number quoted in solutions/09_particle_systems.ipynb, and its exercise checks."""

import time

import numpy as np
import pytest

from course_lib import particles as P
from course_lib.check import RESULTS
from course_lib.check import nb09 as check
from course_lib.lessons import nb09_particle_systems as nb09

DT = 1 / 30


def test_frame_cycle_demo():
    ps = P.ParticleSystem(dim=3, capacity=8, attributes={"temperature": ()})
    ps.add(x=np.zeros((5, 3)), v=[0.0, 3.0, 0.0], lifetime=[0.25, 1.0, 0.15, 2.0, 0.35],
           temperature=1500.0)
    removed, heights = [], []
    for _ in range(4):
        ps.step(0.1, [0.0, -9.81, 0.0])
        removed.append(ps.expire())
        heights.append(round(ps["x"][0, 1], 3))
    assert removed == [0, 1, 1, 1]                    # 0.15 s, 0.25 s, 0.35 s die at 0.2, 0.3, 0.4 s
    assert heights == [0.202, 0.306, 0.311, 0.219]          # 0.3 m - 0.0981 m(m+1)/2
    assert ps["lifetime"].tolist() == [1.0, 2.0]


def test_structure_of_arrays_is_two_orders_faster_than_a_list():
    rng = np.random.default_rng(2026)
    n, dt, g = 10_000, 1 / 60, np.array([0.0, -9.81, 0.0])
    age, life = rng.uniform(0.0, 3.0, n), rng.uniform(1.0, 4.0, n)
    plist = [{"x": np.zeros(3), "v": np.zeros(3), "age": a, "lifetime": b}
             for a, b in zip(age, life, strict=True)]
    ps = P.ParticleSystem(3, n)
    ps.add(x=np.zeros((n, 3)), age=age, lifetime=life)
    t0 = time.perf_counter()
    for p in plist:
        p["v"] += dt * g
        p["x"] += dt * p["v"]
        p["age"] += dt
    plist = [p for p in plist if p["age"] < p["lifetime"]]
    t_list = time.perf_counter() - t0
    t_arrays = min(_timed(lambda: (ps.step(dt, g), ps.expire())) for _ in range(1))
    assert len(plist) == len(ps) == 7677                            # "about a quarter" expired
    assert t_list / t_arrays > 30                                   # quoted: two orders of magnitude


def _timed(func):
    t0 = time.perf_counter()
    func()
    return time.perf_counter() - t0


def test_reeves_count_numbers():
    rng = np.random.default_rng(2026)
    counts = np.array([P.reeves_count(40.0, 10.0, rng) for _ in range(20_000)])
    assert f"{counts.mean():.3f}" == "39.994" and f"{counts.var():.2f}" == "33.57"
    assert (counts.min(), counts.max()) == (30, 50)
    assert 100 / 3 + 1 / 6 == pytest.approx(33.5, rel=1e-15)
    se = np.sqrt(33.5 / counts.size)
    assert se == pytest.approx(0.04, abs=0.001) and abs(counts.mean() - 40) < 2 * se


def test_disc_fractions():
    rng = np.random.default_rng(2026)
    for shape in P.SHAPES:
        P.sample_shape(shape, 1500, rng, radius=1.0)              # the notebook draws these first
    r_good = np.linalg.norm(P.sample_shape("disc", 20_000, rng, radius=1.0), axis=1)
    r_naive = rng.random(20_000)
    assert f"{np.mean(r_good < 0.5):.4f}" == "0.2529" and f"{np.mean(r_naive < 0.5):.4f}" == "0.5013"


def test_fountain_lands_half_g_dt_t_below_its_parabola():
    run = nb09.run(nb09.remember_birth(nb09.fountain().emit), lambda ps, t, dt: ps.step(dt, nb09.G),
                   60, attributes={"x0": (3,), "v0": (3,)})
    ps = run.system
    a = ps["age"][:, None]
    parabola = ps["x0"] + ps["v0"] * a + 0.5 * nb09.G * a**2
    drop = parabola[:, 1] - ps["x"][:, 1]
    assert len(ps) == 2356
    assert drop.max() == pytest.approx(0.5 * 9.81 * DT * 2.0, rel=1e-12)
    assert f"{drop.max():.4f}" == "0.3270"
    assert np.abs(drop - nb09.parabola_offset(ps["age"])).max() < 1e-12
    assert np.abs(parabola[:, [0, 2]] - ps["x"][:, [0, 2]]).max() < 1e-13
    assert 0.5 * 9.81 * DT == pytest.approx(0.16, abs=0.005)          # "16 cm per second of flight"
    # with the ground: 2958 drops after 5 s (the picture's title)
    ground = nb09.run(nb09.fountain().emit, nb09.gravity_bounce(0.5), 150, snapshot_frames=[149])
    assert len(ground.snapshots[149]["age"]) == 2958


def test_steady_state_numbers():
    assert 40 * 2.5 / DT == pytest.approx(3000.0, rel=1e-12)
    assert P.steady_population(40.0, DT, 2.5, 0.5) == pytest.approx(2980.0, rel=1e-12)
    run = nb09.run(nb09.fountain(count=40.0, lifetime=2.5).emit, nb09.gravity_bounce(0.5), 3000)
    measured = run.population[120:].mean()
    given = P.expected_population(run.emitted, DT, 2.5, 0.5)[120:].mean()
    assert f"{measured:.1f}" == "2960.8" and f"{run.emitted.mean():.3f}" == "39.749"
    assert f"{given:.1f}" == "2961.8"
    assert 1 - run.emitted.mean() / 40 == pytest.approx(0.006, abs=0.0005)       # 0.6 % short
    assert 1 - measured / 2980 == pytest.approx(0.006, abs=0.001)                 # by the same 0.6 %
    assert abs(given / measured - 1) < 0.0004                                      # 0.03 %
    shortfall_in_se = (40 - run.emitted.mean()) / np.sqrt(33.5 / run.emitted.size)
    assert 1.8 < shortfall_in_se < 2.6                                             # "about two"


def test_fire_numbers():
    run = nb09.run(nb09.fire().emit, nb09.fire_update(), 120, attributes={"temperature": ()},
                   snapshot_frames=[119])
    s = run.snapshots[119]
    assert len(s["age"]) == 4274
    assert np.sum(s["temperature"] > 800) == 663 and np.sum(s["temperature"] < 400) == 2468
    assert np.abs(s["temperature"] - nb09.cooled(s["age"])).max() < 1e-12
    # smoke within 100 K of the air after tau ln 13 = 1.0 s
    assert 0.4 * np.log(1300 / 100) == pytest.approx(1.0, abs=0.05)
    assert nb09.cooled(0.4 * np.log(13.0)) == pytest.approx(400.0, rel=1e-12)


def test_genesis_numbers():
    emit = nb09.genesis()
    run = nb09.run(emit, nb09.gravity_bounce(0.3), 60)
    t = DT * np.arange(60)
    expected = P.expected_population(emit.mean_count(t), DT, 1.2, 0.4)
    given = P.expected_population(run.emitted, DT, 1.2, 0.4)
    assert f"{emit.mean_count(0.0):.1f}" == "7.5" and f"{emit.mean_count(t[-1]):.1f}" == "118.8"
    assert run.emitted.sum() == 3892
    ratio = run.emitted.sum() / emit.mean_count(t).sum()
    assert f"{ratio:.4f}" == "1.0272"                                   # "2.7 % more"
    assert run.population[-1] == 3110
    assert f"{expected[-1]:.1f}" == "3016.2" and f"{given[-1]:.1f}" == "3090.3"
    assert run.population[-1] / expected[-1] - 1 == pytest.approx(0.031, abs=0.0005)
    assert run.population[-1] / given[-1] - 1 == pytest.approx(0.0065, abs=0.0015)   # "within 0.7 %"
    # lifetimes 1.2 ± 0.4 s: "the last 0.8 to 1.6 s of emission remains alive"
    assert P.survival([0.8, 1.6], 1.2, 0.4).tolist() == [1.0, 0.0]


def test_whirlpool_is_second_order():
    errors = [nb09.whirlpool_error(h) for h in (0.04, 0.02, 0.01)]
    assert [f"{e:.3e}" for e in errors] == ["7.977e-04", "1.990e-04", "4.968e-05"]
    assert errors[0] / errors[1] == pytest.approx(4.0, abs=0.02)
    assert errors[1] / errors[2] == pytest.approx(4.0, abs=0.02)


def test_ten_thousand_particles_in_under_five_ms():
    cost, live = nb09.frame_cost(10_000)
    assert live == 9913
    assert cost < 5e-3


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb09.{name}"]["status"]


def _emit_right(mean, variance, radius, rng):
    k = max(0, int(np.floor(mean + variance * rng.uniform(-1, 1) + rng.random())))
    r = radius * np.sqrt(rng.random(k))
    phi = rng.uniform(0, 2 * np.pi, k)
    return np.column_stack((r * np.cos(phi), r * np.sin(phi)))


def _emit_variant(count_rule, radius_rule=np.sqrt, full_turn=True):
    def emit(mean, variance, radius, rng):
        k = count_rule(mean, variance, rng)
        r = radius * radius_rule(rng.random(k))
        phi = rng.uniform(0, 2 * np.pi if full_turn else np.pi, k)
        return np.column_stack((r * np.cos(phi), r * np.sin(phi)))
    return emit


def test_check_emit(capsys):
    check.emit(_emit_right)
    assert _status("emit") == "correct"
    check.emit(_emit_variant(lambda m, v, rng: round(m + v * rng.uniform(-1, 1))))
    assert _status("emit") == "correct"                                # plain rounding is fine
    capsys.readouterr()
    wrong = [
        (_emit_variant(lambda m, v, rng: int(m + v * rng.uniform(-1, 1))), "int() truncates"),
        (_emit_variant(lambda m, v, rng: round(m + v * rng.random())), "uniform on [0, 1)"),
        (_emit_variant(lambda m, v, rng: round(m)), "draw a new count every frame"),
        (_emit_variant(lambda m, v, rng: max(0, round(m + v * rng.normal()))), "not a normal draw"),
        (_emit_variant(lambda m, v, rng: round(m + v * rng.uniform(-1, 1)), radius_rule=lambda u: u),
         "r = R u crowds the centre"),
        (_emit_variant(lambda m, v, rng: round(m + v * rng.uniform(-1, 1)), radius_rule=np.ones_like),
         "that is a ring"),
        (_emit_variant(lambda m, v, rng: round(m + v * rng.uniform(-1, 1)), full_turn=False),
         "full turn"),
        (lambda m, v, radius, rng: rng.uniform(-radius, radius, (round(m), 2)), "fill a square"),
        (lambda m, v, radius, rng: _emit_right(m, v, radius, np.random.default_rng()),
         "from the generator `rng` you are given"),
    ]
    for func, hint in wrong:
        check.emit(func)
        assert _status("emit") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(mean, variance, radius, rng):
        raise NotImplementedError()

    check.emit(pending)
    assert _status("emit") == "pending"


def _expire_right(data, n):
    alive = data["age"][:n] < data["lifetime"][:n]
    m = int(alive.sum())
    for a in data.values():
        a[:m] = a[:n][alive]
    return m


def test_check_expire(capsys):
    check.expire(_expire_right)
    assert _status("expire") == "correct"
    capsys.readouterr()

    def le(data, n):
        alive = data["age"][:n] <= data["lifetime"][:n]
        m = int(alive.sum())
        for a in data.values():
            a[:m] = a[:n][alive]
        return m

    def some_keys(data, n):
        alive = data["age"][:n] < data["lifetime"][:n]
        m = int(alive.sum())
        for k in ("x", "age", "lifetime"):
            data[k][:m] = data[k][:n][alive]
        return m

    def no_move(data, n):
        return int(np.sum(data["age"][:n] < data["lifetime"][:n]))

    def swap_remove(data, n):
        i = 0
        while i < n:
            if data["age"][i] >= data["lifetime"][i]:
                n -= 1
                for a in data.values():
                    a[i] = a[n]
            else:
                i += 1
        return n

    def rebind(data, n):
        alive = data["age"][:n] < data["lifetime"][:n]
        for k in list(data):
            data[k] = data[k][:n][alive]
        return int(alive.sum())

    def inverted(data, n):
        alive = data["age"][:n] >= data["lifetime"][:n]
        m = int(alive.sum())
        for a in data.values():
            a[:m] = a[:n][alive]
        return m

    for func, hint in [(le, "not age <= lifetime"), (some_keys, "wrong in ['colour']"),
                       (no_move, "move the survivors to the front"),
                       (swap_remove, "original order"), (rebind, "do not rebind"),
                       (inverted, "deleted the living ones")]:
        check.expire(func)
        assert _status("expire") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(data, n):
        raise NotImplementedError()

    check.expire(pending)
    assert _status("expire") == "pending"
