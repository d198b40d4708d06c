"""Notebook 10 (flocking): the drawings of the studies over many seeds.

Holds the cost of the two neighbour searches (:func:`draw_crossover`), a flock's order over
an ensemble of seeds (:func:`draw_ensemble`), the same flock under two roundings
(:func:`draw_divergence`), the alignment sweep (:func:`draw_sweep`), the predator
(:func:`draw_chase`) and the pillars (:func:`draw_pillars`). Imports matplotlib and the
lessons' computations; the core never imports this module.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import EXACT_STYLE
from .nb10_drawings import _boids


def _seed_lines(ax, t, values, color, seed: int = 0):
    """One thin line per seed of ``values`` (seeds × times) against ``t``, ``seed``'s bold:
    every run is seen, not only the range an outlier sets."""
    for k, row in enumerate(values):
        if k != seed:
            ax.plot(t, row, color=color, lw=0.8, alpha=0.55,
                    label=f"the other {len(values) - 1} seeds" if k == (1 if seed == 0 else 0) else None)
    ax.plot(t, values[seed], color=color, lw=2.0, label=f"seed {seed} (left)")


def draw_crossover(sizes, timings: dict):
    """Cost of one step against the number of boids for both neighbour searches, the bracket
    of sizes where their order flips, and the local slopes of the all-pairs cost."""
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    sizes = np.asarray(sizes, dtype=float)
    a, t = np.asarray(timings["all_pairs"]), np.asarray(timings["tree"])
    ok = np.isfinite(a)
    ax.loglog(sizes[ok], 1e3 * a[ok], "o-", color="C3", label="all pairs (N × N arrays)")
    ax.loglog(sizes, 1e3 * t, "o-", color="C0", label="k-d tree (cKDTree)")
    ref = np.flatnonzero(ok)[-1]
    ax.loglog(sizes[ok], 1e3 * a[ref] * (sizes[ok] / sizes[ref]) ** 2, ":", color="C3", lw=1,
              label="∝ N² (through the last point)")
    ax.loglog(sizes, 1e3 * t[-1] * sizes / sizes[-1], ":", color="C0", lw=1, label="∝ N")
    for k in np.flatnonzero(ok[1:] & ok[:-1]):          # local slope of the all-pairs cost
        slope = np.log(a[k + 1] / a[k]) / np.log(sizes[k + 1] / sizes[k])
        ax.text(np.sqrt(sizes[k] * sizes[k + 1]), 1e3 * np.sqrt(a[k] * a[k + 1]) * 1.6,
                f"{slope:.1f}", fontsize=7, color="C3", ha="center")
    tree_wins = ok & (t < a)
    flips = np.flatnonzero(~tree_wins[:-1] & tree_wins[1:] & ok[:-1])
    if flips.size:
        lo, hi = sizes[flips[0]], sizes[flips[0] + 1]
        ax.axvspan(lo, hi, color="0.85", zorder=0)
        ax.text(np.sqrt(lo * hi), 1e3 * np.nanmax(a), f"crossover\nbetween\n{lo:.0f} and {hi:.0f}",
                fontsize=8, ha="center", va="top", color="0.3")
    ax.set(xlabel="number of boids N", ylabel="one step (ms, CPU time)",
           title="neighbour search: all pairs against a k-d tree (red numbers: local slopes)")
    ax.title.set_fontsize(10)
    ax.legend(fontsize=8, loc="lower right")
    return fig


def draw_ensemble(ens, box: float, seed: int = 0):
    """One run's final flock, and the polarization and spacing over time across seeds."""
    fig, (ax0, ax1, ax2) = plt.subplots(1, 3, figsize=(12, 3.7), constrained_layout=True,
                                        width_ratios=(0.9, 1, 1))
    x, v = ens.finals[seed]
    _boids(ax0, x, v, box, f"seed {seed}: {len(x)} boids after {ens.t[-1]:.0f} s")
    ax0.set_ylabel("y (m)")
    _seed_lines(ax1, ens.t, ens.polarization, "C0", seed)
    ax1.axhline(ens.random_polarization, **EXACT_STYLE)
    ax1.text(ens.t[-1], ens.random_polarization + 0.015, r"random headings: $\sqrt{\pi}/(2\sqrt{N})$",
             ha="right", va="bottom", fontsize=8)
    ax1.set(xlabel="t (s)", ylabel="polarization", ylim=(0, 1.3), yticks=np.linspace(0, 1, 6),
            title="common heading")
    ax1.legend(loc="upper center", ncols=2, fontsize=8, framealpha=1.0)
    _seed_lines(ax2, ens.t_nn, ens.nn, "C2", seed)
    ax2.axhline(ens.random_nn, **EXACT_STYLE, label="random positions (exact)")
    ax2.set(xlabel="t (s)", ylabel="mean distance (m)", ylim=(0, 1.3),
            title="distance to the nearest neighbour")
    ax2.legend(loc="lower right", fontsize=8, framealpha=0.9)
    return fig


def draw_divergence(runs: dict, rates: dict):
    """RMS distance between a flock and its twin under a second rounding (log scale), with
    the fitted exponential, and the polarization of both runs."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 3.9), constrained_layout=True,
                                   width_ratios=(1.3, 1))
    for k, (label, (t, d, pol)) in enumerate(runs.items()):
        ax1.semilogy(t, d, color=f"C{k}", label=label)
        band = (d > 1e-13) & (d < 1e-3)
        slope, intercept = np.polyfit(t[band], np.log(d[band]), 1)     # the rate's own fit
        ax1.semilogy(t[band], np.exp(intercept + slope * t[band]), **{**EXACT_STYLE, "linewidth": 1.0})
        ax2.plot(t, pol[0], color="0.3", lw=2.5, alpha=0.4)
        ax2.plot(t, pol[1], color=f"C{k}", lw=1, label=f"twin: {label}")
        ax1.text(0.98, 0.08 + 0.08 * k, f"{label}: × e every {1 / rates[label]:.1f} s",
                 transform=ax1.transAxes, color=f"C{k}", fontsize=8, ha="right")
    ax1.axhline(np.finfo(float).eps, color="0.6", lw=1, ls=":")
    ax1.text(0.5, 3e-16, "ε = 2.2e-16", fontsize=8, va="bottom", color="0.4")
    ax1.plot([], [], **EXACT_STYLE, label="fitted exponential")
    ax1.set(xlabel="t (s)", ylabel="RMS distance between the twins (m)", ylim=(1e-17, 50),
            title="the same flock, two roundings")
    ax1.legend(fontsize=8, loc="upper left")
    ax2.plot([], [], color="0.3", lw=2.5, alpha=0.4, label="the flock itself")
    ax2.set(xlabel="t (s)", ylabel="polarization", ylim=(0, 1.02), title="order of both runs")
    ax2.legend(fontsize=8, loc="lower right")
    return fig


def ens_end(results: dict) -> float:
    """Length (s) of the runs of a sweep."""
    return float(next(iter(results.values())).t[-1])


def draw_sweep(results: dict, dt: float, within: float | None = None):
    """Final polarization of each seed against the alignment weight, and the time each seed
    first passes 0.5 (with a line at ``within`` s, the time the notebook counts against)."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 3.6), constrained_layout=True)
    weights = np.array(list(results))
    never_y, never_label = 1.06 * ens_end(results), f"never, in the {ens_end(results):.0f} s run"
    for k, (w, ens) in enumerate(results.items()):
        jitter = np.linspace(-0.12, 0.12, len(ens.final))
        ax1.plot(w + jitter, ens.final, "o", ms=4, color="C0", label="one seed" if k == 0 else None)
        finite = np.isfinite(ens.t_order)
        ax2.plot(w + jitter[finite], ens.t_order[finite], "o", ms=4, color="C1",
                 label="one seed" if k == 0 else None)
        if not finite.all():
            ax2.plot(w + jitter[~finite], np.full((~finite).sum(), never_y), "^", ms=5, mfc="none",
                     color="C1", label=never_label)
            never_label = None
    ax1.axhline(results[weights[0]].random_polarization, **EXACT_STYLE, label="random headings")
    for ax in (ax1, ax2):
        ax.axvspan(1.0 / dt, 2.0 / dt, color="0.9", zorder=0)
        ax.set_xlabel("alignment weight $w_a$ (1/s)")
        sec = ax.secondary_xaxis("top", functions=(lambda w: w * dt, lambda s: s / dt))
        sec.set_xlabel(r"$w_a\,\Delta t$")
    ax1.set(ylabel="polarization after 15 s", ylim=(0, 1.02))
    ax2.axhline(ens_end(results), color="0.6", lw=1, ls=":")
    if within is not None:
        ax2.axhline(within, color="C1", lw=1, ls="--")
        ax2.text(weights[-1] + 1.9, within + 0.25, f"{within:g} s", color="C1", fontsize=8,
                 ha="right", va="bottom")
    ax2.set(ylabel="first time above 0.5 (s)", ylim=(0, 1.12 * ens_end(results)))
    ax1.legend(fontsize=8, loc="center left")
    ax2.legend(fontsize=8, loc="center right")
    fig.suptitle("one dot per seed; grey: $1 < w_a\\Delta t < 2$, between the limits for two boids "
                 "and for many", fontsize=10)
    return fig


def draw_chase(chases: list, box: float):
    """Seed 0's chase (distance to the nearest boid, the flock at the end, with and without
    the flee rule), and the median distance of every seed."""
    fig, axes = plt.subplots(1, 4, figsize=(14, 3.6), constrained_layout=True,
                             width_ratios=(1.3, 1.0, 1.0, 0.8))
    first, labels = chases[0], {3.0: "boids flee", 0.0: "no flee rule"}
    for k, (strength, closest) in enumerate(first.closest.items()):
        t = 0.2 * np.arange(1, len(closest) + 1)
        axes[0].plot(t, closest, color=f"C{k}", label=labels.get(strength, f"{strength:g} m²/s²"))
        ax = axes[k + 1]
        _boids(ax, first.x[strength], first.v[strength], box, f"seed 0, {labels.get(strength)}")
        ax.plot(first.path[strength][:, 0], first.path[strength][:, 1], ".", color="0.3", ms=2)
        ax.plot(*first.path[strength][-1], "X", color="black", ms=10)
        medians = [np.median(c.closest[strength]) for c in chases]
        axes[3].plot(np.full(len(medians), k), medians, "o", color=f"C{k}")
    axes[0].axhline(0.5, color="0.6", lw=1, ls=":")
    axes[0].set(xlabel="t (s) since the predator entered", ylabel="to the nearest boid (m)",
                title="seed 0: how close the predator gets")
    axes[0].legend(fontsize=8)
    axes[1].set_ylabel("y (m)")
    axes[3].set(xticks=[0, 1], xticklabels=["flee", "no rule"], xlim=(-0.5, 1.5),
                ylabel="median distance (m)", title=f"{len(chases)} seeds")
    return fig


def draw_pillars(results: dict, centers, radii, box: float):
    """The flock among the pillars at the end of seed 0's run, with and without steering to
    avoid them; ``results`` maps a label to ``(fraction inside, smallest gap, x, v)``."""
    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 4.0), constrained_layout=True)
    for ax, (label, (inside, _, x, v)) in zip(np.atleast_1d(axes), results.items(), strict=True):
        _boids(ax, x, v, box, f"{label}\n{100 * inside:.1f} % of boid-steps inside a pillar")
        for c, r in zip(centers, radii, strict=True):
            ax.add_patch(plt.Circle(c, r, color="0.55", alpha=0.6, lw=0))
        ax.title.set_fontsize(9)
    np.atleast_1d(axes)[0].set_ylabel("y (m)")
    return fig
