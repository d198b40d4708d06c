"""Every number quoted in solutions/10_flocking.ipynb, its widget, and its exercise checks."""

import time

import numpy as np
import pytest
from notebook_helpers import drive_kept_figure, printed_holds

import course_lib as cl
from course_lib import boids as B
from course_lib.check import FAILURES, evaluate
from course_lib.check import nb10 as check
from course_lib.lessons import nb10_flocking as nb10
from course_lib.lessons import nb10_studies as studies


def test_three_boids_numbers():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [-0.5, 1.0]])
    v = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, -1.0]])
    sep, ali, coh = B.steering(x, v, B.Rules(radius=2.0, view_angle=np.pi))
    assert np.round(sep[2], 4).tolist() == [-0.8615, 1.1077]
    assert ali[2].tolist() == [1.0, 1.0] and coh[2].tolist() == [1.0, -1.0]


def test_one_step_written_out():
    """Section 1's step of three boids: the rules' sum, the limits, the move, as boids.step."""
    x = np.array([[0.0, 0.0], [1.0, 0.0], [-0.5, 1.0]])
    v = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, -1.0]])
    rules = B.Rules(radius=2.0, view_angle=np.pi)
    sep, ali, coh = B.steering(x, v, rules)
    a = rules.separation * sep + rules.alignment * ali + rules.cohesion * coh
    free = v + nb10.DT * a
    new = B.clamp_speed(free, rules.min_speed, rules.max_speed)
    xs, vs = B.step(x, v, nb10.DT, rules)
    assert np.allclose(vs, new) and np.allclose(xs, x + nb10.DT * new)
    before, after = np.linalg.norm(free, axis=1), np.linalg.norm(new, axis=1)
    assert np.round(before, 3).tolist() == [1.14, 1.0, 0.916]
    assert np.round(after, 3).tolist() == [1.14, 1.0, 1.0]
    # "cohesion pulls boid 0 towards boid 1 harder than separation pushes it back": 1 m/s² > 0.3
    assert rules.cohesion * coh[0, 0] > -rules.separation * sep[0, 0] > 0
    assert before[2] < rules.min_speed == after[2]          # boid 2 lifted back to the floor


def test_all_pairs_numbers_and_agreement():
    rng = np.random.default_rng(2026)
    rules = B.Rules(box=20.0)
    x, v = B.random_flock(300, 20.0, 1.5, rng)
    i, _j, _ = B.all_pairs(x, v, rules)
    count = np.bincount(i, minlength=300)
    assert len(i) == 1991 and f"{count.mean():.2f}" == "6.64" and np.sum(count == 0) == 0
    t = B.tree_pairs(x, v, rules)
    assert all(np.array_equal(a, b) for a, b in zip(B.all_pairs(x, v, rules), t, strict=True))
    for a, b in zip(B.steering(x, v, rules, "all_pairs"), B.steering(x, v, rules, "tree"),
                    strict=True):
        assert np.abs(a - b).max() <= 1e-13 * np.abs(a).max()        # "agree to 1e-13"


def test_random_references():
    rng = np.random.default_rng(2026)
    n, box = 300, 28.0
    theta = rng.uniform(0.0, 2 * np.pi, (4000, n))
    pol = np.hypot(np.cos(theta).mean(axis=1), np.sin(theta).mean(axis=1))
    nn = np.array([B.nearest_distances(rng.uniform(0, box, (n, 2)), box).mean() for _ in range(400)])
    assert f"{pol.mean():.4f}" == "0.0510" and f"{B.random_polarization(n):.4f}" == "0.0512"
    assert f"{nn.mean():.4f}" == "0.8096"
    assert f"{B.random_nearest_distance(n, box):.4f}" == "0.8086"
    assert f"{0.5 / np.sqrt(n / box**2):.4f}" == "0.8083"
    se_pol, se_nn = pol.std() / np.sqrt(4000), nn.std() / np.sqrt(400)
    assert se_pol == pytest.approx(0.0004, abs=0.00005) and se_nn == pytest.approx(0.0013, abs=0.00005)
    assert abs(pol.mean() - B.random_polarization(n)) < 2 * se_pol + 1 / n      # O(1/n) formula
    assert abs(nn.mean() - B.random_nearest_distance(n, box)) < 2 * se_nn


def test_timing_cells_run_and_agree():
    # the times are the machine's (make bench judges the 20 ms target); the cell's own
    # check that both methods give the same step is what is tested here
    t = nb10.neighbour_timings([20, 80], repeats=1)
    assert np.all(np.isfinite(t["all_pairs"])) and np.all(t["tree"] > 0)
    assert np.isnan(nb10.neighbour_timings([720], repeats=1)["all_pairs"][0])
    assert 16 * 320**2 / 1e6 == pytest.approx(1.6, abs=0.05)                 # "1.6 MB at N = 320"


# --- chaotic runs: quoted and asserted over the eight seeds ----------------------------


@pytest.fixture(scope="module")
def flock60():
    return studies.ensemble(steps=300, snapshot_at=100)


def clear(values, threshold, margin) -> bool:
    """Does every run clear ``threshold`` by more than ``margin``? A count of runs above a
    threshold holds on another machine when no run lies within what a second rounding
    moves it (the twins of Section 4: polarizations within 0.01 up to 60 s)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return bool(np.all(np.abs(values - threshold) > margin))


def first_crossing_clear(ens, within: float, margin: float) -> bool:
    """Does "first above 0.5 within ``within`` s" give the same answer under a second
    rounding? A run has crossed 0.5 by ``within`` exactly when its largest polarization up
    to then exceeds 0.5, so that largest value must clear 0.5 by ``margin`` in every run."""
    return clear([pol[ens.t <= within + 1e-9].max() for pol in ens.polarization], 0.5, margin)


#: The yardstick of Section 4: the twins' polarizations differ by less than 0.01 up to 60 s
#: (and by less than 1e-10 up to 15 s); every count clears its threshold by more.
MARGIN = 0.01


def reversed_twin(seed: int, steps: int = 75, **weights):
    """The flock of ``seed`` run with its boids numbered in reverse: a second rounding of
    the same run (Section 4). Returns its final polarization and mean spacing."""
    rules = B.Rules(box=nb10.BOX, **weights)
    x, v = B.random_flock(nb10.N_BOIDS, nb10.BOX, 1.0, np.random.default_rng(seed))
    x, v = x[::-1].copy(), v[::-1].copy()
    for _ in range(steps):
        x, v = B.step(x, v, nb10.DT, rules)
    return B.polarization(v), B.nearest_distances(x, nb10.BOX).mean()


def rounding_spread(ens, steps: int = 75, **weights) -> tuple[float, float]:
    """How far a second rounding moves the final polarization and spacing of ``ens``
    (measured on every seed with the boids numbered in reverse), times e² for two
    e-foldings of margin: the spread :func:`printed_holds` must respect."""
    twins = np.array([reversed_twin(s, steps, **weights) for s in studies.SEEDS])
    return (float(np.abs(twins[:, 0] - ens.final).max()) * np.e**2 + 1e-12,
            float(np.abs(twins[:, 1] - ens.spacing).max()) * np.e**2 + 1e-12)


@pytest.mark.roundoff
def test_the_flock_forms_in_seven_runs_of_eight(flock60):
    assert clear(flock60.final, 0.9, MARGIN) and first_crossing_clear(flock60, 12.0, MARGIN)
    assert clear(flock60.spacing, flock60.random_nn, 0.02) and clear(flock60.spacing, 0.5, 0.02)
    assert len(flock60.final) == 8
    assert np.sum(flock60.final > 0.9) == 7 and np.sum(flock60.t_order < 12) == 7
    assert np.all(flock60.spacing < flock60.random_nn) and np.all(flock60.spacing > 0.5)
    assert f"{flock60.random_polarization:.3f}" == "0.072" and f"{flock60.random_nn:.3f}" == "0.817"
    low = np.argmin(flock60.final)                                  # "the eighth ... not merged"
    assert flock60.final[low] < 0.5
    # the nearest-neighbour distance drops below random "within a few seconds" in every run
    first = np.argmax(flock60.nn < flock60.random_nn, axis=1)
    assert np.all(flock60.t_nn[first] <= 5.0)


def dpol_15(pol, t) -> float:
    return float(np.abs(pol[0] - pol[1])[t <= 15.0 + 1e-9].max())


@pytest.mark.roundoff
def test_the_same_flock_under_two_roundings():
    """Each quoted bound holds with a margin of an e-folding (a factor e = 2.7, the growth
    of two to three seconds), so that another machine's rounding does not cross it; the
    twins share the flock itself."""
    e = np.e
    both = studies.twins(0, 600)
    # one twin alone is the same run, step for step (compared over its first 10 s)
    assert np.array_equal(both["ulp"][1][:50], studies.divergence(0, 50, "ulp")[1])
    for t, d, pol in both.values():
        at = {s: np.flatnonzero(np.isclose(t, s))[0] for s in (1, 5, 15, 60)}
        at[35] = np.flatnonzero(np.isclose(t, 35))[0]
        assert d[at[1]] < 1e-14 / e and d[at[15]] < 1e-8 / e and d[at[60]] < 1.0 / e
        assert d[at[35]] < 1e-4 / e**2         # "within 0.1 mm after 35 s": see test_nb10_hints
        assert dpol_15(pol, t) < 1e-10                        # "less than 1e-10 up to 15 s"
        assert d[t > 100].max() > 0.1 * e
        dpol = np.abs(pol[0] - pol[1])
        assert dpol[: at[60] + 1].max() < 0.01 / e and dpol.max() < 0.05 / e
        assert 2.0 <= 1 / studies.growth_rate(t, d) <= 3.0             # "× e every 2 to 3 s"
    t, d, _ = both["order"]
    at = {s: np.flatnonzero(np.isclose(t, s))[0] for s in (1, 5)}
    assert d[at[5]] > e * 1e3 * d[at[1]]                       # "more than three decades"
    x, _ = B.random_flock(150, 20.0, 1.0, np.random.default_rng(0))
    assert np.spacing(x[0, 0]) == pytest.approx(1.8e-15, rel=0.02)     # the one-ulp nudge
    with pytest.raises(ValueError, match="how"):
        studies.divergence(0, 2, "shuffle")


@pytest.mark.roundoff
def test_alignment_relaxation_follows_the_factor_within_its_round_off_bound():
    """The bound is derived (n + 8 roundings of the largest speed per step, carried by the
    factor), not copied from a run: 1.13e-10 on AVX-512, 5.6e-11 on AVX2, both inside it."""
    for w, factor, worst in [(2.5, 0.737, 1e-10), (12.5, -0.316, 2e-7), (22.5, -1.368, 1e-12)]:
        assert 1 - w * 0.1 * 20 / 19 == pytest.approx(factor, abs=5e-4)
        rms, exact, drift, bound = studies.relaxation(w)
        compared = exact > 1e-8 * rms[0]
        assert compared.sum() >= 4
        assert np.all(np.abs(rms - exact)[compared] <= bound[compared])
        assert (bound / exact)[compared].max() <= worst
        assert drift <= bound.max()
    # the bound is not vacuous: a wrong factor (one boid too few) breaks it at once
    rms, exact, _, bound = studies.relaxation(12.5)
    wrong = rms[0] * abs(1 - 12.5 * 0.1 * 19 / 18) ** np.arange(rms.size)
    assert np.any(np.abs(rms - wrong)[1:5] > bound[1:5])
    assert 1 / nb10.DT == pytest.approx(5.0) and 2 / nb10.DT == pytest.approx(10.0)


@pytest.mark.roundoff
def test_alignment_sweep_over_eight_seeds(flock60):
    sweep = {2.0: flock60.until(15.0)}
    sweep.update({w: studies.ensemble(alignment=w) for w in (4.0, 6.0, 8.0)})
    counts = {w: (int(np.sum(e.final > 0.9)), int(np.sum(e.t_order <= 8.0)), int(np.sum(e.reversal < 0)))
              for w, e in sweep.items()}
    assert counts == {2.0: (4, 6, 0), 4.0: (8, 8, 0), 6.0: (8, 8, 0), 8.0: (0, 0, 8)}
    default = sweep[2.0]
    assert np.sum(default.t_order > 8.0) == 2 and np.sum(np.isinf(default.t_order)) == 1
    assert np.all(sweep[8.0].final < sweep[8.0].random_polarization)              # "below random"
    rev8, final8 = sweep[8.0].reversal, sweep[8.0].final            # the printed ranges
    assert final8.max() < sweep[8.0].random_polarization                  # "at most 0.06, against 0.072"
    assert final8.max() <= 0.065 and final8.max() < sweep[8.0].random_polarization - 0.005
    assert f"{sweep[8.0].random_polarization:.3f}" == "0.072"
    for e in sweep.values():                   # every count clears its threshold by 0.01
        assert clear(e.final, 0.9, MARGIN) and first_crossing_clear(e, 8.0, MARGIN)
        assert clear(e.reversal, 0.0, 0.5)
    # the old "within 7 s" did not: one run at 4 /s crossed at 7.0 s by 0.003
    assert not first_crossing_clear(sweep[4.0], 7.0, MARGIN)
    spread_pol = rounding_spread(sweep[8.0], alignment=8.0)[0]
    printed_holds(rev8.min(), ".2f", "-0.92", 1e-6)
    printed_holds(rev8.max(), ".2f", "-0.83", 1e-6)
    printed_holds(final8.min(), ".2f", "0.01", spread_pol)
    printed_holds(final8.max(), ".2f", "0.06", spread_pol)
    assert 0.5 <= (2 - 1) / 2 and (20 - 1) / 20 < 1                       # (n − 1)/n in [1/2, 1)


@pytest.mark.roundoff
def test_predator_over_eight_seeds(flock60):
    chases = [studies.chase(seed, formed=flock60.snapshots[seed]) for seed in studies.SEEDS]
    assert all(5.0 <= c.start <= 8.5 for c in chases)
    assert all(c.closest[3.0].min() > 0.5 for c in chases)
    assert clear([c.closest[3.0].min() for c in chases], 0.5, 0.01)
    assert clear([np.mean(c.closest[0.0] < 0.5) for c in chases], 0.45, 0.02)
    # the formed flocks cruise at the 1 m/s floor: "median speed 1.00 m/s in 8 of 8 runs,
    # with 78 % to 91 % of the boids exactly at the floor"
    speeds = [np.linalg.norm(v, axis=1) for _, v in flock60.snapshots]
    at_floor = np.array([np.mean(sp <= 1.0 + 1e-12) for sp in speeds])
    assert all(np.median(sp) <= 1.0 + 1e-12 for sp in speeds)
    assert all(sp.min() >= 1.0 - 1e-12 for sp in speeds)
    # "more than three quarters ... in 8 of 8": the fewest at the floor, 117 of 150, is 4 boids
    # clear of 112.5 (a boid is at the floor or not; a second rounding would have to move a
    # speed across 1 m/s, within 1e-8 m/s of it after 20 s, to change a count)
    assert np.all(at_floor > 0.75 + 3 / nb10.N_BOIDS)
    # why: alignment alone is a weighted average of v and the neighbours' mean velocity
    # (weights 1 - w_a dt = 0.6 and 0.4), never longer than the floor when all sit on it
    assert 1 - 2.0 * nb10.DT == pytest.approx(0.6)
    x, v = flock60.snapshots[0]
    unit = v / np.linalg.norm(v, axis=1, keepdims=True)                  # everyone at 1 m/s
    _, ali, _ = B.steering(x, unit, B.Rules(box=nb10.BOX))
    assert np.all(np.linalg.norm(unit + nb10.DT * 2.0 * ali, axis=1) <= 1.0 + 1e-12)
    assert all(np.mean(c.closest[0.0] < 0.5) >= 0.45 for c in chases)
    assert all(np.median(c.closest[3.0]) > 3 * np.median(c.closest[0.0]) for c in chases)
    # the shared start is the same seed's run after 100 steps
    alone = studies.chase(0)
    assert np.array_equal(alone.closest[0.0], chases[0].closest[0.0])


@pytest.mark.roundoff
def test_pillars_over_eight_seeds():
    avoiding = [studies.pillars(seed) for seed in studies.SEEDS]
    ignoring = [studies.pillars(seed, strength=0.0) for seed in studies.SEEDS]
    assert all(r[0] == 0 and r[1] > 0.3 for r in avoiding)
    inside = np.array([r[0] for r in ignoring])
    # printed "1% to 8%": a second rounding may move a boid-step or two in or out
    steps = nb10.STEPS * nb10.N_BOIDS
    printed_holds(inside.min(), ".0%", "1%", 3 / steps)
    printed_holds(inside.max(), ".0%", "8%", 3 / steps)
    _centers, radii = studies.PILLARS
    assert sorted(radii.tolist()) == [1.0, 1.5, 2.0]
    covered = np.pi * np.sum(radii**2) / nb10.BOX**2
    printed_holds(covered, ".1%", "5.7%", 1e-12)              # "the pillars cover 5.7 % of the box"
    assert inside.min() < covered < inside.max()                # "about the 5.7 %"


@pytest.fixture(scope="module")
def no_alignment():
    """The eight runs without alignment (cell 35), shared by the two tests that quote them."""
    return studies.ensemble(alignment=0.0)


@pytest.mark.roundoff
def test_key_states_over_eight_seeds(flock60, no_alignment):
    random_nn = flock60.random_nn
    weights = {"default": {}, "separation 0": {"separation": 0.0}, "alignment 0": {"alignment": 0.0},
               "cohesion 0": {"cohesion": 0.0}}
    ens = {k: (flock60.until(15.0) if not kw else studies.ensemble(**kw)) for k, kw in weights.items()
           if k != "alignment 0"}
    ens["alignment 0"] = no_alignment
    printed = {"default": ("0.67", "0.73", "0.32", "0.99", 7),
               "separation 0": ("0.00", "0.06", "0.30", "0.97", 6),
               "alignment 0": ("0.74", "0.86", "0.05", "0.11", 0),
               "cohesion 0": ("1.08", "1.20", "0.23", "0.96", 6)}
    for label, e in ens.items():
        spread_pol, spread_nn = rounding_spread(e, **weights[label])
        assert spread_pol < 1e-6 and spread_nn < 1e-6                # 15 s: far below the digits
        lo, hi, plo, phi, above = printed[label]
        printed_holds(e.spacing.min(), ".2f", lo, spread_nn)
        printed_holds(e.spacing.max(), ".2f", hi, spread_nn)
        printed_holds(e.final.min(), ".2f", plo, spread_pol)
        printed_holds(e.final.max(), ".2f", phi, spread_pol)
        assert np.sum(e.final > 0.7) == above and clear(e.final, 0.7, MARGIN)
    # the prose: alignment 0 around random headings; cohesion 0 wider than random in every run;
    # separation 0 below 6 cm in every run, yet ordered
    assert ens["alignment 0"].final.min() < flock60.random_polarization < ens["alignment 0"].final.max()
    assert clear(ens["cohesion 0"].spacing, random_nn, 0.2) and np.all(ens["cohesion 0"].spacing > random_nn)
    assert np.all(ens["separation 0"].spacing < 0.06) and clear(ens["separation 0"].spacing, 0.06, 0.004)
    assert np.all(ens["default"].spacing < random_nn)
    assert f"{random_nn:.2f}" == "0.82" and f"{flock60.random_polarization:.2f}" == "0.07"


def test_ring_balance_numbers(flock60):
    """Exercise 2's ring: the model's accelerations vanish on it, and the prose's numbers."""
    for n in range(2, 13):
        r = nb10.ring_radius(n, 0.3, 1.0)
        angle = 2 * np.pi * np.arange(n) / n
        x = 10.0 + r * np.column_stack((np.cos(angle), np.sin(angle)))
        v = np.tile([1.2, 0.4], (n, 1))
        rules = B.Rules(radius=2.5 * r, view_angle=2 * np.pi, box=nb10.BOX)
        sep, ali, coh = B.steering(x, v, rules)
        a = rules.separation * sep + rules.alignment * ali + rules.cohesion * coh
        assert np.abs(a).max() < 1e-13 * np.abs(rules.cohesion * coh).max()
        if n <= 8:                                   # "all within the 2 m neighbour radius"
            assert 2 * r < 2.0
    assert 2 * nb10.ring_radius(9, 0.3, 1.0) > 2.0
    assert f"{2 * nb10.ring_radius(2, 0.3, 1.0):.2f}" == f"{np.sqrt(0.3):.2f}" == "0.55"
    spacing = [2 * nb10.ring_radius(n, 0.3, 1.0) * np.sin(np.pi / n) for n in range(3, 9)]
    assert (f"{min(spacing):.2f}", f"{max(spacing):.2f}") == ("0.73", "0.82")
    # "after 15 s ... 0.67 to 0.73 m": the key states' range (printed_holds there), between
    # the pair's 0.55 m and the rings' 0.82 m
    default = flock60.until(15.0)
    assert 0.55 < default.spacing.min() and default.spacing.max() < max(spacing)
    with pytest.raises(ValueError, match="n must"):
        nb10.ring_radius(1, 0.3, 1.0)


def test_flock_explorer_view():
    view = nb10.flock_explorer()
    assert view.result.rules.alignment == 2.0 and len(view.result.x) == 150
    view.controls["separation"].value = 0.0
    assert view.result.rules.separation == 0.0 and view.result.nn[-1] < 0.05
    t0 = time.process_time()                   # CPU time: wall time failed under load (1.7 s)
    view.controls["alignment"].value = 3.0
    elapsed = time.process_time() - t0
    assert view.result.rules.alignment == 3.0
    assert elapsed < 1.0                       # 100 ms target in benchmarks/bench_boids.py


def test_flock_widget_redraws_only_the_flock_and_curves_and_its_picture_is_right():
    """Every slider move keeps the background (the limits never change) and gives the
    picture a full redraw gives; the widget's title names no weight, a still picture's
    names all three."""
    from course_lib.lessons.nb10_drawings import draw_flock

    view = nb10.flock_explorer()
    moves = [("alignment", 3.0), ("separation", 0.5), ("cohesion", 2.5), ("alignment", 0.0)]
    assert not any(redrawn for *_, redrawn in drive_kept_figure(view, moves))
    assert "weights set above" in view.draw.title.get_text()
    still = draw_flock(view.result)
    assert "alignment 0 1/s" in still.texts[0].get_text() and "cohesion 2.5" in still.texts[0].get_text()


def test_flock_plot_keeps_its_limits_ticks_and_label_places():
    # the widget's figure fixes its ticks and axis-label places once; the limits must
    # stay those asked for, and the labels where matplotlib's automatic placement puts them
    import matplotlib.pyplot as plt

    from course_lib.lessons.nb10_drawings import FlockPlot

    run = nb10.run_flock(steps=10)
    fig = FlockPlot(150, nb10.BOX, 2.0)(run)
    ax, ax1, ax2 = fig.axes
    assert ax.get_xlim() == ax.get_ylim() == (0.0, nb10.BOX)
    assert ax1.get_ylim() == (0.0, 1.02) and ax2.get_ylim() == (0.0, 1.5)
    assert ax1.get_xlim() == ax2.get_xlim() == (0.0, 2.0)
    assert ax.get_xticks().tolist() == [0.0, 10.0, 20.0]
    assert ax2.get_yticks().tolist() == [0.0, 0.5, 1.0, 1.5]
    fig.canvas.draw()
    frozen = [a.get_window_extent() for a in (ax.xaxis.label, ax.yaxis.label,
                                               ax2.xaxis.label, ax2.yaxis.label)]
    auto, (a0, a1, a2) = plt.figure(figsize=fig.get_size_inches()), (ax, ax1, ax2)
    for a in (a0, a1, a2):                                    # the same axes, left automatic
        b = auto.add_axes(a.get_position())
        b.set(xlim=a.get_xlim(), ylim=a.get_ylim(), xticks=a.get_xticks(),
              yticks=a.get_yticks(), xlabel=a.get_xlabel(), ylabel=a.get_ylabel())
        b.set_xlim(a.get_xlim()), b.set_ylim(a.get_ylim())
        b.tick_params(labelbottom=a.xaxis.get_tick_params()["labelbottom"])
    auto.canvas.draw()
    b0, _, b2 = auto.axes
    for f, g in zip(frozen, [b0.xaxis.label, b0.yaxis.label, b2.xaxis.label, b2.yaxis.label],
                    strict=True):
        assert np.allclose(f.get_points(), g.get_window_extent().get_points(), atol=1e-6)
    plt.close(auto)


# --- the exercise checks: planted answers ----------------------------------------------


def notebook_answer(source: str, name: str):
    """A function defined the way a notebook cell defines it (module ``__main__``)."""
    namespace = {"__name__": "__main__", "np": np, "cl": cl, "boids": B}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


def judged(check_fn, answer, attempt: int = 0) -> tuple[str, str]:
    """(status, every failure message) of ``answer``, as after ``attempt`` wrong tries."""
    FAILURES.pop(check_fn.key, None)
    if attempt:
        FAILURES[check_fn.key] = attempt
    verdict = evaluate(check_fn, answer)
    FAILURES.pop(check_fn.key, None)
    return verdict["status"], "\n".join(verdict["failed_cases"])


def _right(i, j, d, n):
    push = d / np.einsum("pk,pk->p", d, d)[:, None]
    S = np.zeros((n, 2))
    np.add.at(S, i, -push)
    return S


def _buffered(i, j, d, n):
    S = np.zeros((n, 2))
    S[i] -= d / np.einsum("pk,pk->p", d, d)[:, None]
    return S


def _unit(i, j, d, n):
    S = np.zeros((n, 2))
    np.add.at(S, i, -d / np.linalg.norm(d, axis=1)[:, None])
    return S


def _at_j(i, j, d, n):
    S = np.zeros((n, 2))
    np.add.at(S, j, -d / np.einsum("pk,pk->p", d, d)[:, None])
    return S


def _in_place(i, j, d, n):
    d /= np.einsum("pk,pk->p", d, d)[:, None]
    S = np.zeros((n, 2))
    np.add.at(S, i, -d)
    return S


def _guarded(i, j, d, n):
    S = np.zeros((n, 2))
    np.add.at(S, i, -d / (np.einsum("pk,pk->p", d, d) + 1e-12)[:, None])
    return S


def _floored(i, j, d, n):
    S = np.zeros((n, 2))
    np.add.at(S, i, -d / np.maximum(np.einsum("pk,pk->p", d, d), 1e-300)[:, None])
    return S


def _float32(i, j, d, n):
    d32 = d.astype(np.float32)
    S = np.zeros((n, 2), dtype=np.float32)
    np.add.at(S, i, -d32 / (d32 * d32).sum(axis=1)[:, None])
    return S


def _pair_loop(i, j, d, n):
    S = np.zeros((n, 2))
    for p in range(len(i)):
        S[i[p]] -= d[p] / (d[p] @ d[p])
    return S


def _reordered(i, j, d, n):
    order = np.argsort(-j, kind="stable")              # each boid's terms in another order
    S = np.zeros((n, 2))
    np.add.at(S, i[order], -(d / np.einsum("pk,pk->p", d, d)[:, None])[order])
    return S


SEPARATION_PLANTED = {
    "right": (_right, "correct", None),
    "by bincount": (lambda i, j, d, n: -np.stack([np.bincount(i, d[:, k] / (d**2).sum(1), minlength=n)
                                                  for k in range(2)], axis=1), "correct", None),
    "delegates to the library": (notebook_answer(
        "def separation(i, j, d, n):\n"
        "    x = np.zeros((n, 2))\n"
        "    return boids.steering(x, np.ones((n, 2)), boids.Rules())[0]", "separation"),
        "incorrect", "uses the reference: your function calls course_lib.boids"),
    "sign": (lambda i, j, d, n: -_right(i, j, d, n), "incorrect", "sign: separation pushes boid i away"),
    "S[i] -= w (buffered)": (_buffered, "incorrect", "applies each index only once"),
    "unit push": (_unit, "incorrect", "what is its size at distance"),
    "averaged": (lambda i, j, d, n: _right(i, j, d, n) / np.maximum(np.bincount(i, minlength=n), 1)[:, None],
                 "incorrect", "do not average"),
    "at j": (_at_j, "incorrect", "accumulate at i"),
    "changes its input": (_in_place, "incorrect", "changed its input"),
    "one row per pair": (lambda i, j, d, n: -d / np.einsum("pk,pk->p", d, d)[:, None], "incorrect",
                         "one row per boid"),
    "sized by i.max() + 1 (broken by the last boid, without neighbours)":
        (lambda i, j, d, n: _right(i, j, d, i.max() + 1), "incorrect", "size S by n, not by i"),
    # a guard against d = 0 changes every push by about 1e-12/|d|² (2e-9 relative here): more
    # than round-off, and the message says so in the same terms as the verdict
    "a guard |d|² + 1e-12": (_guarded, "incorrect", "such as a guard ε"),
    "a guard that changes no real pair": (_floored, "correct", None),
    "computed in float32 (judged at its own precision)": (_float32, "correct", None),
    "a loop over the pairs (the prompt says vectorize)": (_pair_loop, "incorrect", "np.add.at or"),
    "the sum in another order (round-off only)": (_reordered, "correct", None),
}


@pytest.mark.parametrize("planted", sorted(SEPARATION_PLANTED))
def test_check_separation_planted(planted):
    answer, status, nudge = SEPARATION_PLANTED[planted]
    got, messages = judged(check.separation, answer)
    assert got == status, (planted, messages)
    if nudge:
        assert nudge in messages, (planted, messages)


def test_check_separation_message_agrees_with_its_verdict():
    """The guard fails on some boids: the message counts the boids beyond the same round-off
    bound the verdict uses (it said "0 of 30 boids wrong" while failing), and shows the size
    of the difference, since six printed digits agree."""
    import re
    _, messages = judged(check.separation, _guarded)
    for line in messages.splitlines():
        m = re.search(r"off by ([0-9.e+-]+) where round-off allows ([0-9.e+-]+) \((\d+) of (\d+) boids", line)
        if m:
            assert float(m.group(1)) > float(m.group(2)) and int(m.group(3)) >= 1
    assert "off by" in messages and "(0 of" not in messages
    # the bound is the answer's precision: a float32 answer gets float32's, float64 float64's
    rng = np.random.default_rng(3)
    d = rng.normal(size=(40, 2))
    i = rng.integers(0, 5, 40)
    b64, b32 = (check.roundoff_bound(i, d, 5, np.finfo(t).eps) for t in (np.float64, np.float32))
    assert np.allclose(b32 / b64, np.finfo(np.float32).eps / np.finfo(np.float64).eps)
    exact = _right(i, None, d, 5)
    assert np.all(np.abs(_reordered(i, i, d, 5) - exact) <= b64)


def test_check_separation_escalates_and_is_pending_when_blank():
    assert "np.add.at" not in judged(check.separation, _buffered)[1]
    assert "np.add.at" in judged(check.separation, _buffered, attempt=1)[1]

    def pending(i, j, d, n):
        raise NotImplementedError()

    assert judged(check.separation, pending)[0] == "pending"


RING_PLANTED = {
    "right": ("def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * (n - 1) ** 2 / (2 * n * w_c))",
              "correct", None),
    "a root found numerically (brentq on the radial balance)": (
        "import scipy.optimize\n"
        "def ring_radius(n, w_s, w_c):\n"
        "    def radial(r):\n"
        "        a = 2 * np.pi * np.arange(1, n) / n\n"
        "        d = r * np.column_stack((np.cos(a) - 1, np.sin(a)))\n"
        "        push = -w_s * (d / (d ** 2).sum(1)[:, None]).sum(0)[0]\n"
        "        return push + w_c * d.mean(0)[0]\n"
        "    return scipy.optimize.brentq(radial, 1e-3, 100.0, xtol=1e-14, rtol=1e-14)",
        "correct", None),
    "hard-codes the notebook's weights (ignores w_s and w_c)": (
        "def ring_radius(n, w_s, w_c):\n    return np.sqrt(0.3 * (n - 1) ** 2 / (2 * n * 1.0))",
        "incorrect", "5 boids, w_s = 2"),
    "the pair's radius for every n": ("def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s / w_c) / 2",
                                      "incorrect", "that is the pair's radius for every n"),
    "the pair's distance, not its radius": ("def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s / w_c)",
                                            "incorrect", "that is a distance between two boids"),
    "cohesion towards the centre of all n": (
        "def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * (n - 1) / (2 * w_c))",
        "incorrect", "the centre of the *other* n - 1 boids"),
    "full push sizes, not their radial parts": (
        "def ring_radius(n, w_s, w_c):\n"
        "    k = np.arange(1, n)\n"
        "    chords = 2 * np.sin(np.pi * k / n)            # |d| / r\n"
        "    return np.sqrt(w_s * (n - 1) / (n * w_c) * np.sum(1 / chords))",
        "incorrect", "only the radial part of each push survives"),
    "the neighbour spacing, not the radius": (
        "def ring_radius(n, w_s, w_c):\n"
        "    r = np.sqrt(w_s * (n - 1) ** 2 / (2 * n * w_c))\n    return 2 * r * np.sin(np.pi / n)",
        "incorrect", "distance to the nearest neighbour"),
    "r squared": ("def ring_radius(n, w_s, w_c):\n    return w_s * (n - 1) ** 2 / (2 * n * w_c)",
                  "incorrect", "check the units"),
    "an unforeseen formula": ("def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * n / w_c) / 3",
                              "incorrect", "start from a pair"),
    "a tuple": ("def ring_radius(n, w_s, w_c):\n    return (1.0, 2.0)", "incorrect", "expected one number"),
    "delegates to the lesson": (
        "from course_lib.lessons import nb10_flocking\n"
        "def ring_radius(n, w_s, w_c):\n    return nb10_flocking.ring_radius(n, w_s, w_c)",
        "incorrect", "uses the reference"),
}


@pytest.mark.parametrize("planted", sorted(RING_PLANTED))
def test_check_ring_radius_planted(planted):
    source, status, nudge = RING_PLANTED[planted]
    got, messages = judged(check.ring_radius, notebook_answer(source, "ring_radius"))
    assert got == status, (planted, messages)
    if nudge:
        assert nudge in messages, (planted, messages)
    assert "(n - 1)² / (2 n" not in messages and "r² = " not in messages     # never the formula


def test_check_ring_radius_escalates_and_is_pending_when_blank():
    pair = notebook_answer(RING_PLANTED["the pair's radius for every n"][0], "ring_radius")
    assert "add up the radial parts" not in judged(check.ring_radius, pair)[1]
    assert "add up the radial parts" in judged(check.ring_radius, pair, attempt=1)[1]

    def pending(n, w_s, w_c):
        raise NotImplementedError()

    assert judged(check.ring_radius, pending)[0] == "pending"


def _grid_source(cell_side="radius", offsets=(-1, 0, 1), compare="<=", keep="i < j"):
    """A vectorized uniform-grid answer (points sorted by cell, each neighbouring cell's
    points found with np.searchsorted) with one thing changed, as a notebook cell would
    write it."""
    return f"""
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    side = {cell_side}
    cell = np.floor(x / side).astype(np.int64)
    cell -= cell.min(axis=0) - 2
    width = cell[:, 1].max() + 3
    key = cell[:, 0] * width + cell[:, 1]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]
    for dx in {offsets}:
        for dy in {offsets}:
            target = key + dx * width + dy
            lo = np.searchsorted(sorted_key, target, "left")
            count = np.searchsorted(sorted_key, target, "right") - lo
            i_all.append(np.repeat(np.arange(len(x)), count))
            start = np.repeat(lo - np.cumsum(count) + count, count)
            j_all.append(order[start + np.arange(count.sum())])
    i, j = np.concatenate(i_all), np.concatenate(j_all)
    d = x[j] - x[i]
    keep = ({keep}) & ((d ** 2).sum(axis=1) {compare} radius ** 2)
    return i[keep], j[keep]
"""


#: A grid that loops in Python over the occupied cells (a dict of cells), as the prompt allows.
_LOOP_OVER_CELLS = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    cells = {}
    for k, c in enumerate(map(tuple, np.floor(x / radius).astype(int))):
        cells.setdefault(c, []).append(k)
    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]
    for (cx, cy), members in cells.items():
        m = np.array(members)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                others = cells.get((cx + dx, cy + dy))
                if others is not None:
                    i_all.append(np.repeat(m, len(others)))
                    j_all.append(np.tile(others, m.size))
    i, j = np.concatenate(i_all), np.concatenate(j_all)
    d = x[j] - x[i]
    keep = (i < j) & ((d ** 2).sum(axis=1) <= radius ** 2)
    return i[keep], j[keep]
"""


#: Sort by x, then compare each point with those less than R to its right: right pairs,
#: but each point meets a strip across the whole domain (O(N^1.5) at fixed density).
_SWEEP = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    order = np.argsort(x[:, 0], kind="stable")
    xs = x[order]
    hi = np.searchsorted(xs[:, 0], xs[:, 0] + radius, "right")
    count = hi - np.arange(len(x)) - 1
    a = np.repeat(np.arange(len(x)), count)
    b = a + 1 + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    d = xs[b] - xs[a]
    keep = (d ** 2).sum(axis=1) <= radius ** 2
    i, j = order[a[keep]], order[b[keep]]
    return np.minimum(i, j), np.maximum(i, j)
"""


NEIGHBOUR_PLANTED = {
    "the notebook's vectorized grid": (None, "correct", None),
    "the same grid, vectorized differently": (_grid_source(), "correct", None),
    "a loop over the occupied cells": (_LOOP_OVER_CELLS, "correct", None),
    "delegates to the library": ("def neighbour_pairs(x, radius):\n"
                                 "    p = cl.neighbors.pairs(x, radius)\n    return p.i, p.j",
                                 "incorrect", "uses the reference: your function calls course_lib.neighbors"),
    "a k-d tree (scipy.spatial is refused)": (
        "def neighbour_pairs(x, radius):\n    from scipy.spatial import cKDTree\n"
        "    p = cKDTree(x).query_pairs(radius, output_type='ndarray')\n    return p[:, 0], p[:, 1]",
        "incorrect", "uses the reference: your function"),
    "same cell only": (_grid_source(offsets=(0,)), "incorrect", "pairs in neighbouring cells are missing"),
    "cells of half the radius, 3 × 3 block": (_grid_source(cell_side="radius / 2"), "incorrect",
                                              "pairs in neighbouring cells are missing"),
    "strict < (broken by pairs at exactly the radius)": (_grid_source(compare="<"), "incorrect",
                                                          "a pair exactly `radius` apart counts"),
    "both orders": (_grid_source(keep="i != j"), "incorrect", "each pair once, with i < j"),
    "itself included": (_grid_source(keep="i <= j"), "incorrect", "a point is paired with itself"),
    "no distance test": (_grid_source(compare="< np.inf +"), "incorrect",
                         "farther apart than the radius"),
    "all pairs, a row at a time (no N × N table: broken by 8000 points)": (
        "def neighbour_pairs(x, radius):\n"
        "    x = np.asarray(x, float)\n"
        "    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]\n"
        "    for k in range(len(x) - 1):\n"
        "        d = x[k + 1:] - x[k]\n"
        "        near = np.flatnonzero(d[:, 0] ** 2 + d[:, 1] ** 2 <= radius ** 2)\n"
        "        i_all.append(np.full(near.size, k))\n"
        "        j_all.append(near + k + 1)\n"
        "    return np.concatenate(i_all), np.concatenate(j_all)",
        "incorrect", "like all pairs tested a row at a time"),
    "every pair in pure Python (stopped by the line budget)": (
        "def neighbour_pairs(x, radius):\n"
        "    i, j = [], []\n"
        "    for a in range(len(x)):\n"
        "        for b in range(a + 1, len(x)):\n"
        "            if (x[a][0] - x[b][0]) ** 2 + (x[a][1] - x[b][1]) ** 2 <= radius ** 2:\n"
        "                i.append(a)\n"
        "                j.append(b)\n"
        "    return np.array(i, dtype=int), np.array(j, dtype=int)",
        "incorrect", "testing every pair in Python"),
    "half the stencil, (0, 1) × (0, 1), with i < j": (_grid_source(offsets=(0, 1)), "incorrect",
                                                     "pairs in neighbouring cells are missing"),
    "a sweep along x, not a grid (its cost depends on the region's shape: broken by a band)": (
        _SWEEP, "incorrect", "that is a sweep along x"),
    "both orders and each point with itself": (_grid_source(keep="i >= 0"), "incorrect",
                                               "that drops both a point paired with itself"),
    "an N × N table": ("def neighbour_pairs(x, radius):\n"
                       "    d2 = ((x[None, :, :] - x[:, None, :]) ** 2).sum(axis=-1)\n"
                       "    i, j = np.nonzero(np.triu(d2 <= radius ** 2, 1))\n    return i, j",
                       "incorrect", "that is an N × N table"),
}


@pytest.fixture(scope="module")
def grid_solution():
    import nbformat
    from notebook_helpers import ROOT
    nb = nbformat.read(ROOT / "solutions" / "10_flocking.ipynb", as_version=4)
    (cell,) = [c for c in nb.cells if c.cell_type == "code" and "def neighbour_pairs(" in c.source]
    return cell.source[: cell.source.index("check.")]


@pytest.mark.parametrize("planted", sorted(NEIGHBOUR_PLANTED))
def test_check_neighbour_pairs_planted(planted, grid_solution):
    source, status, nudge = NEIGHBOUR_PLANTED[planted]
    answer = notebook_answer(grid_solution if source is None else source, "neighbour_pairs")
    got, messages = judged(check.neighbour_pairs, answer)
    assert got == status, (planted, messages)
    if nudge:
        assert nudge in messages, (planted, messages)
    if planted.startswith("all pairs, a row at a time"):   # capped: a ratio quoted as a bound
        quoted = [line for line in messages.splitlines() if "times what it allocated" in line]
        assert quoted and all("at least" in q and "stopped at that cap" in q for q in quoted), messages


def test_check_neighbour_pairs_counts_reversed_copies_as_repeated():
    both = notebook_answer(_grid_source(keep="i >= 0"), "neighbour_pairs")
    messages = judged(check.neighbour_pairs, both)[1]
    first = next(line for line in messages.splitlines() if "pairs found" in line)
    # 3-4-5: 3 pairs, each listed twice (3 repeated, not "0 repeated"), 4 points with themselves
    assert first.endswith("3 of 3 pairs found, 4 not pairs (a point with itself: 4), 3 repeated")
    assert "drops both a point paired with itself and the copy (j, i)" in messages


def test_check_neighbour_pairs_escalates_and_is_pending_when_blank():
    same_cell = notebook_answer(_grid_source(offsets=(0,)), "neighbour_pairs")
    assert "3 × 3 cells" not in judged(check.neighbour_pairs, same_cell)[1]
    assert "3 × 3 cells" in judged(check.neighbour_pairs, same_cell, attempt=1)[1]

    def pending(x, radius):
        raise NotImplementedError()

    assert judged(check.neighbour_pairs, pending)[0] == "pending"


def test_check_neighbour_pairs_names_the_right_mistake():
    """Pairs at exactly the radius are lost both by a strict < and by a search of one cell
    only; the hint must name the one the evidence of every case points to."""
    same_cell = notebook_answer(_grid_source(offsets=(0,)), "neighbour_pairs")
    strict = notebook_answer(_grid_source(compare="<"), "neighbour_pairs")
    half = notebook_answer(_grid_source(offsets=(0, 1)), "neighbour_pairs")
    assert "exactly `radius` apart" not in judged(check.neighbour_pairs, same_cell)[1]
    assert "neighbouring cells are missing" not in judged(check.neighbour_pairs, strict)[1]
    # a half stencil also loses the 3-4-5 pair at exactly R; its other losses say why
    assert "exactly `radius` apart" not in judged(check.neighbour_pairs, half)[1]
    assert "|d|² <= radius², not <" not in judged(check.neighbour_pairs, half, attempt=1)[1]


def test_grid_cost_measure_tells_linear_from_quadratic():
    """The allocation the check measures grows about fourfold for a grid and sixteenfold
    for all pairs (even a row at a time) when the points are four times as many."""
    from course_lib.check import _nb10_cases as cases
    rng = np.random.default_rng(5)
    small, large = rng.uniform(0, 50.0, (2000, 2)), rng.uniform(0, 100.0, (8000, 2))

    def rows(x, radius):
        out = []
        for k in range(len(x) - 1):
            d = x[k + 1:] - x[k]
            out.append(np.flatnonzero(d[:, 0] ** 2 + d[:, 1] ** 2 <= radius ** 2))
        return out

    def table(x, radius):
        return np.nonzero(((x[None] - x[:, None]) ** 2).sum(-1) <= radius ** 2)

    def tree(x, radius):
        return cl.neighbors.pairs(x, radius)

    growth = cases.measured(rows, large, 1.0)[2] / cases.measured(rows, small, 1.0)[2]
    assert growth > 1.5 * check.GROWTH_LIMIT                     # 16 in theory, 14.6 measured
    growth = cases.measured(tree, large, 1.0)[2] / cases.measured(tree, small, 1.0)[2]
    assert growth < check.GROWTH_LIMIT / 1.3                     # 4 in theory
    sweep = notebook_answer(_SWEEP, "neighbour_pairs")
    growth = cases.measured(sweep, large, 1.0)[2] / cases.measured(sweep, small, 1.0)[2]
    assert check.GROWTH_LIMIT * 1.3 < growth < 2 * check.GROWTH_LIMIT   # 8 in theory: a sweep
    _, peak, total = cases.measured(table, small, 1.0)
    assert peak > 2 * check.MEMORY_LIMIT and total >= peak
    assert cases.line_limit(300) == 250_000 and cases.line_limit(8000) == 800_000


# --- the fifth read's two false sentences (cells 31 and 35) ---------------------------------

def _prose() -> str:
    import nbformat
    from notebook_helpers import ROOT
    cells = nbformat.read(ROOT / "solutions" / "10_flocking.ipynb", as_version=4).cells
    return " ".join(" ".join(c.source.split()) for c in cells if c.cell_type == "markdown")


@pytest.mark.roundoff
def test_without_alignment_the_polarization_after_15_s_not_over_the_run(no_alignment):
    """Cell 35 quotes the eight runs' polarization *after 15 s*, rounded: every final value
    rounds into [0.05, 0.11] with a margin far above the rounding spread (< 1e-6, asserted in
    test_key_states_over_eight_seeds). Over the run it does not stay there (random headings
    of 150 boids scatter with SD 0.038), so "stays between" was false."""
    text = _prose()
    assert ("after 15 s the polarization lies between 0.05 and 0.11 (rounded) in the eight runs"
            in text) and "stays between 0.05 and 0.11" not in text
    e = no_alignment
    assert e.final.shape == (8,)
    assert clear(e.final, 0.045, 1e-3) and clear(e.final, 0.115, 1e-3)
    assert np.all((e.final > 0.045) & (e.final < 0.115))
    history = e.polarization[:, e.t > 1.0]
    assert history.min() < 0.045 - 0.02 and history.max() > 0.115 + 0.01     # 0.003 and 0.141


def test_the_alignment_step_becomes_unstable_between_6_and_8_per_s():
    """Cell 31: between 6 and 8 /s the step becomes unstable (f < -1), as Section 5 defines
    it; it overshoots (f < 0) from w_a dt = (n - 1)/n on, at most 5 /s at dt = 0.2 s, where
    every run still orders (test_alignment_sweep_over_eight_seeds: 8 of 8 above 0.9 at 6 /s,
    8 of 8 reversing at 8 /s). Theory puts the instability of a flock between the limit of
    isolated pairs, w_a dt = 1, and that of a crowd, w_a dt -> 2."""
    text = _prose()
    assert "becomes unstable ($f < -1$, Section 5)" in text
    assert "alignment step overshoots and every boid" not in text
    dt = nb10.DT
    assert dt == 0.2

    def factor(w, n):
        return 1.0 - w * dt * n / (n - 1)

    def unstable_from(n):                      # f = -1
        return 2.0 * (n - 1) / (n * dt)

    def overshoots_from(n):                    # f = 0
        return (n - 1) / (n * dt)

    ns = np.arange(2, 151)
    limits = unstable_from(ns)
    assert limits.min() == pytest.approx(1 / dt) and limits.max() < 2 / dt    # 5 to 10 /s
    assert 1 / dt < 6.0 < 8.0 < 2 / dt                                        # inside theory's band
    assert overshoots_from(ns).max() < 5.0 + 1e-12 < 6.0                      # 6 /s already overshoots
    assert np.all(factor(6.0, ns[ns >= 4]) > -1.0)                            # yet is stable for n >= 4
    assert factor(8.0, 2) < factor(8.0, 5) <= -1.0 + 1e-12                    # 8 /s: unstable for n <= 5


def test_summary_does_not_give_away_exercise_2_ring_formula():
    """The Summary must not state Exercise 2's closed form for the ring radius."""
    import json
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    for folder in ("solutions", "notebooks"):
        nb = json.loads((root / folder / "10_flocking.ipynb").read_text())
        summary = next("".join(c["source"]) for c in nb["cells"]
                       if c["cell_type"] == "markdown"
                       and "".join(c["source"]).startswith("## Summary"))
        squashed = summary.replace(" ", "")
        assert "(n-1)^2" not in squashed and "2nw_c" not in squashed, folder
        assert "Exercise 2" in summary, folder


def test_alignment_8_sentence_claims_only_the_final_value():
    """During the run the w_a = 8 /s polarization exceeds random; only the 15 s value is below."""
    import json
    from pathlib import Path

    nb = json.loads((Path(__file__).resolve().parents[1] / "solutions" / "10_flocking.ipynb").read_text())
    text = " ".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")
    text = " ".join(text.split())
    assert "stays below that of random headings" not in text
    assert "after 15 s the polarization is below that of random headings in every run" in text
