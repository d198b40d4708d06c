"""Every number quoted in solutions/10_flocking.ipynb, its widget, and its exercise checks."""

import time

import numpy as np
import pytest

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
    rounding? No polarization up to each run's first crossing (or ``within``) lies within
    ``margin`` of 0.5."""
    for pol, t_order in zip(ens.polarization, ens.t_order, strict=True):
        end = min(t_order, within)
        if not clear(pol[ens.t <= end + 1e-9], 0.5, margin):
            return False
    return True


@pytest.mark.roundoff
def test_the_flock_forms_in_seven_runs_of_eight(flock60):
    assert clear(flock60.final, 0.9, 0.01) and first_crossing_clear(flock60, 12.0, 1e-6)
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


@pytest.mark.roundoff
def test_the_same_flock_under_two_roundings():
    """Each quoted bound holds with a margin of an e-folding (a factor e = 2.7, the growth
    of two to three seconds), so that another machine's rounding does not cross it; the
    twins share the flock itself."""
    e = np.e
    both = studies.twins(0, 600)
    assert np.array_equal(both["ulp"][1], studies.divergence(0, 600, "ulp")[1])
    for t, d, pol in both.values():
        at = {s: np.flatnonzero(np.isclose(t, s))[0] for s in (1, 5, 15, 60)}
        assert d[at[1]] < 1e-14 / e and d[at[15]] < 1e-8 / e and d[at[60]] < 1.0 / e
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
    counts = {w: (int(np.sum(e.final > 0.9)), int(np.sum(e.t_order <= 7.0)), int(np.sum(e.reversal < 0)))
              for w, e in sweep.items()}
    assert counts == {2.0: (4, 5, 0), 4.0: (8, 8, 0), 6.0: (8, 8, 0), 8.0: (0, 0, 8)}
    default = sweep[2.0]
    assert np.sum(default.t_order > 7.0) == 3 and np.sum(np.isinf(default.t_order)) == 1
    assert np.all(sweep[8.0].final < sweep[8.0].random_polarization)              # "below random"
    rev8, final8 = sweep[8.0].reversal, sweep[8.0].final            # the printed ranges
    assert (f"{rev8.min():.2f}", f"{rev8.max():.2f}") == ("-0.92", "-0.83")
    assert (f"{final8.min():.2f}", f"{final8.max():.2f}") == ("0.01", "0.06")
    assert final8.max() < sweep[8.0].random_polarization                  # "at most 0.06, against 0.072"
    for e in sweep.values():                   # 15 s runs: the twins are within 1e-8 m there
        assert clear(e.final, 0.9, 1e-3) and first_crossing_clear(e, 7.0, 1e-6)
        assert clear(e.reversal, 0.0, 0.5)
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
    assert (f"{at_floor.min():.0%}", f"{at_floor.max():.0%}") == ("78%", "91%")
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
    assert all(r[0] > 0.01 for r in ignoring) and all(r[0] < 0.1 for r in ignoring)   # "a few percent"
    _centers, radii = studies.PILLARS
    assert sorted(radii.tolist()) == [1.0, 1.5, 2.0]


@pytest.mark.roundoff
def test_key_states_over_eight_seeds(flock60):
    random_nn = flock60.random_nn
    ens = {"default": flock60.until(15.0), "separation 0": studies.ensemble(separation=0.0),
           "alignment 0": studies.ensemble(alignment=0.0), "cohesion 0": studies.ensemble(cohesion=0.0)}
    below_10cm = {k: int(np.sum(e.spacing < 0.1)) for k, e in ens.items()}
    assert below_10cm == {"default": 0, "separation 0": 8, "alignment 0": 0, "cohesion 0": 0}
    assert np.all(ens["cohesion 0"].spacing > random_nn) and np.all(ens["default"].spacing < random_nn)
    assert np.sum(ens["alignment 0"].spacing < random_nn) == 5
    assert np.all(ens["alignment 0"].final < 0.15)
    assert np.all(ens["separation 0"].final > 0.15)          # "while the flock still orders"
    for e in ens.values():                                    # 15 s runs: clear of each threshold
        assert clear(e.spacing, 0.1, 1e-3) and clear(e.spacing, random_nn, 1e-3)
        assert clear(e.final, 0.15, 1e-3)
    assert not np.any(ens["default"].final < 0.15) and not np.any(ens["cohesion 0"].final < 0.15)
    assert f"{random_nn:.2f}" == "0.82" and f"{flock60.random_polarization:.2f}" == "0.07"


def test_flock_explorer_view():
    view = nb10.flock_explorer()
    assert view.result.rules.alignment == 2.0 and len(view.result.x) == 150
    view.controls["separation"].value = 0.0
    assert view.result.rules.separation == 0.0 and view.result.nn[-1] < 0.05
    t0 = time.perf_counter()
    view.controls["alignment"].value = 3.0
    elapsed = time.perf_counter() - t0
    assert view.result.rules.alignment == 3.0
    assert elapsed < 1.0                       # 100 ms target in benchmarks/bench_boids.py


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
}


@pytest.mark.parametrize("planted", sorted(SEPARATION_PLANTED))
def test_check_separation_planted(planted):
    answer, status, nudge = SEPARATION_PLANTED[planted]
    got, messages = judged(check.separation, answer)
    assert got == status, (planted, messages)
    if nudge:
        assert nudge in messages, (planted, messages)


def test_check_separation_escalates_and_is_pending_when_blank():
    assert "np.add.at" not in judged(check.separation, _buffered)[1]
    assert "np.add.at" in judged(check.separation, _buffered, attempt=1)[1]

    def pending(i, j, d, n):
        raise NotImplementedError()

    assert judged(check.separation, pending)[0] == "pending"


def test_check_flock_breaker(capsys):
    assert judged(check.flock_breaker, lambda: ("separation", "C"))[0] == "correct"
    assert judged(check.flock_breaker, lambda: ["Separation ", "c"])[0] == "correct"
    for answer, hint in [(("cohesion", "C"), "nothing pulls the boids together"),
                         (("alignment", "C"), "headings never agree"),
                         (("separation", "A"), "disorder does not pile boids up"),
                         (("separation", "B"), "keep the offset between them"),
                         (("separation", "D"), "no group would ever form"), (("gravity", "A"), "one of"),
                         ("separation", "(weight, letter)")]:
        status, messages = judged(check.flock_breaker, lambda answer=answer: answer)
        assert status == "incorrect" and hint in messages, (answer, messages)
    # each distractor is a misconception the notebook's runs refute (key-state ensembles)
    assert set(check.REASONS) == {"A", "B", "C", "D"}

    def pending():
        raise NotImplementedError()

    assert judged(check.flock_breaker, pending)[0] == "pending"


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
        "incorrect", "that is all pairs, a row at a time"),
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
    assert growth < check.GROWTH_LIMIT / 1.5                     # 4 in theory
    _, peak, total = cases.measured(table, small, 1.0)
    assert peak > 2 * check.MEMORY_LIMIT and total >= peak
    assert cases.line_limit(300) == 250_000 and cases.line_limit(8000) == 800_000
