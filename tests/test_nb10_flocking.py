"""Every number quoted in solutions/10_flocking.ipynb, its widget, and its exercise checks."""

import time

import numpy as np
import pytest

from course_lib import boids as B
from course_lib.check import RESULTS
from course_lib.check import nb10 as check
from course_lib.lessons import nb10_flocking as nb10


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
    i, j, _ = B.all_pairs(x, v, rules)
    count = np.bincount(i, minlength=300)
    assert len(i) == 1991 and f"{count.mean():.2f}" == "6.64" and np.sum(count == 0) == 0
    t = B.tree_pairs(x, v, rules)
    assert np.array_equal(i, t[0]) and np.array_equal(j, t[1])
    for a, b in zip(B.steering(x, v, rules, "all_pairs"), B.steering(x, v, rules, "tree"),
                    strict=True):
        assert np.abs(a - b).max() < 5e-14


def test_tree_wins_at_a_few_hundred_boids():
    timings = nb10.neighbour_timings([400, 800])
    assert np.all(timings["tree"] * 5 < timings["all_pairs"])


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


def test_big_flock_orders():
    run = nb10.run_flock(n=300, box=28.0, steps=300)
    assert f"{run.polarization[-1]:.3f}" == "0.938" and f"{run.random_polarization:.3f}" == "0.051"
    assert f"{run.nn[-1]:.3f}" == "0.723" and f"{run.random_nn:.3f}" == "0.809"
    assert run.nn[-1] < run.random_nn                                 # denser than random
    assert f"{run.t[np.argmax(run.polarization > 0.5)]:.2f}" == "1.80"
    assert run.t[-1] == pytest.approx(60.0)


def test_alignment_relaxation_is_exact_and_its_step_limit():
    for w, factor in [(2.5, 0.737), (12.5, -0.316), (22.5, -1.368)]:
        assert 1 - w * 0.1 * 20 / 19 == pytest.approx(factor, abs=5e-4)
        rms, exact, drift = nb10.relaxation(w)
        ok = exact > 1e-8 * rms[0]
        assert np.abs(rms / exact - 1)[ok].max() < 1e-10
        assert drift < 1e-12
    assert 1 / nb10.DT == pytest.approx(5.0)                   # two boids alone: w dt < 1
    assert 2 / nb10.DT == pytest.approx(10.0)                  # everyone in view: w dt < 2 (n large)


def test_alignment_sweep_table():
    table = {2.0: (0.518, 0.996), 4.0: (0.998, 1.000), 6.0: (0.977, 0.999),
             8.0: (0.090, -0.797), 12.0: (0.010, -0.953)}
    for w, (pol, rev) in table.items():
        run = nb10.run_flock(alignment=w)
        assert round(run.polarization[-1], 3) == pol and round(run.reversal, 3) == rev
    assert 6.0 * nb10.DT == pytest.approx(1.2) and 8.0 * nb10.DT == pytest.approx(1.6)
    assert nb10.run_flock(alignment=8.0).polarization[-1] < 1.5 * B.random_polarization(nb10.N_BOIDS)


def test_predator_numbers():
    flee = nb10.chase()
    bare = nb10.chase(flee_strength=0.0)
    assert flee.t[-1] == pytest.approx(15.0)
    assert f"{np.median(flee.closest):.2f}" == "1.55" and np.all(flee.closest > 0.5)   # never
    assert f"{flee.closest.min():.3f}" == "0.854"
    first = np.argmin(flee.closest)
    assert flee.t[first] == pytest.approx(3.0, abs=0.3)                # "about 3 s in"
    assert f"{np.median(bare.closest):.2f}" == "0.20" and round(100 * np.mean(bare.closest < 0.5)) == 81
    assert f"{bare.closest.min():.3f}" == "0.006"
    peak = np.argmax(flee.closest[first:]) + first                     # grows, then shrinks
    assert flee.closest[peak] > 2.0 and flee.closest[-1] < flee.closest[peak] - 0.8


def test_key_states():
    quoted = {"default": {}, "separation 0": {"separation": 0.0}, "alignment 0": {"alignment": 0.0},
              "cohesion 0": {"cohesion": 0.0}}
    values = {"default": (0.52, 0.68), "separation 0": (0.30, 0.00), "alignment 0": (0.09, 0.77),
              "cohesion 0": (0.76, 1.15)}
    for label, kw in quoted.items():
        run = nb10.run_flock(**kw)
        assert (round(run.polarization[-1], 2), round(run.nn[-1], 2)) == values[label]
        if label == "cohesion 0":
            assert run.nn[-1] > run.random_nn                        # spread out, beyond random
            assert f"{run.random_nn:.2f}" == "0.82"
        if label == "separation 0":
            assert f"{run.nn[-1] * 1000:.0f}" == "5"                  # "drops to 5 mm"
        if label == "alignment 0":
            assert f"{run.random_polarization:.2f}" == "0.07"
    assert nb10.DT * nb10.STEPS == pytest.approx(15.0)


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


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb10.{name}"]["status"]


def _right(i, j, d, n):
    push = d / np.einsum("pk,pk->p", d, d)[:, None]
    S = np.zeros((n, 2))
    np.add.at(S, i, -push)
    return S


def test_check_separation(capsys):
    check.separation(_right)
    assert _status("separation") == "correct"
    capsys.readouterr()

    def buffered(i, j, d, n):
        S = np.zeros((n, 2))
        S[i] -= d / np.einsum("pk,pk->p", d, d)[:, None]
        return S

    def unit(i, j, d, n):
        S = np.zeros((n, 2))
        np.add.at(S, i, -d / np.linalg.norm(d, axis=1)[:, None])
        return S

    def mean(i, j, d, n):
        return _right(i, j, d, n) / np.maximum(np.bincount(i, minlength=n), 1)[:, None]

    def at_j(i, j, d, n):
        S = np.zeros((n, 2))
        np.add.at(S, j, -d / np.einsum("pk,pk->p", d, d)[:, None])
        return S

    def in_place(i, j, d, n):
        d /= np.einsum("pk,pk->p", d, d)[:, None]
        S = np.zeros((n, 2))
        np.add.at(S, i, -d)
        return S

    for func, hint in [(lambda i, j, d, n: -_right(i, j, d, n), "sign"), (buffered, "buffers"),
                       (unit, "not |d|"), (mean, "do not average"), (at_j, "accumulate at i"),
                       (in_place, "changed its input"),
                       (lambda i, j, d, n: -d / np.einsum("pk,pk->p", d, d)[:, None], "one row per boid")]:
        check.separation(func)
        assert _status("separation") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(i, j, d, n):
        raise NotImplementedError()

    check.separation(pending)
    assert _status("separation") == "pending"


def test_check_flock_breaker(capsys):
    check.flock_breaker(lambda: ("separation", "A"))
    assert _status("flock_breaker") == "correct"
    check.flock_breaker(lambda: ("Separation ", "a"))
    assert _status("flock_breaker") == "correct"
    capsys.readouterr()
    for answer, hint in [(("cohesion", "A"), "spacing grows"), (("alignment", "A"), "headings stay random"),
                         (("separation", "B"), "not chance"), (("separation", "C"), "never stop"),
                         (("separation", "D"), "parallel boids keep"), (("gravity", "A"), "one of"),
                         ("separation", "(weight, letter)")]:
        check.flock_breaker(lambda answer=answer: answer)
        assert _status("flock_breaker") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending():
        raise NotImplementedError()

    check.flock_breaker(pending)
    assert _status("flock_breaker") == "pending"
