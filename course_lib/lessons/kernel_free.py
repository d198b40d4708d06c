"""Kernel-free explorers: one precomputed player per widget, beside the live widget.

Each function runs the live widget's own pure function (``run_experiment``, ``run_spring``,
``run_held_strand``, ``run_flock``) for a list of values of the widget's key control,
draws each result with the widget's own drawing function, and returns a
:class:`course_lib.players.Player` whose slider scrubs through them (HTML, no kernel, at
most 300 kB). The values straddle the method's stability limit, so a reader of a static
page sees the verdict and the picture flip. Imports the lessons' public functions and
:mod:`course_lib.players` only.

In a notebook, beside the widget::

    # NBVAL_IGNORE_OUTPUT
    from course_lib.lessons import kernel_free
    kernel_free.stability_player()
"""

from __future__ import annotations

from ..players import Player, parameter_player
from ..plotting import METHOD_LABELS

#: Time steps (s) of the stability player: forward Euler on dx/dt = -x turns unstable at 2.
STABILITY_DTS = (0.05, 0.1, 0.2, 0.5, 1.0, 1.5, 1.9, 2.1, 2.5, 3.0, 4.0)
#: Spring stiffnesses (N/m) of the spring player: at dt = 0.1 s and m = 1 kg, symplectic
#: Euler is stable for k < (2 / dt)² m = 400 N/m.
SPRING_KS = (5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 300.0, 350.0, 450.0, 600.0, 1000.0)
#: Bending stiffnesses (N/m) of the hair player: at dt = 1e-4 s the strand's limit
#: 2 / ω_max falls below dt between 9000 and 9500 N/m.
HAIR_KBENDS = (1.0, 30.0, 300.0, 1000.0, 3000.0, 6000.0, 9000.0, 9500.0, 10000.0)


def stability_player(problem: str = "decay", method: str = "forward_euler", rate: float = 1.0,
                     dts=STABILITY_DTS) -> Player:
    """The stability explorer's ``dt`` slider, precomputed (notebook 03)."""
    from .nb03_explorer_plot import draw_experiment
    from .nb03_stability import run_experiment

    return parameter_player(
        run_experiment, draw_experiment, "dt", dts,
        fixed={"problem": problem, "method": method, "rate": rate}, unit="s",
        title=f"Without a kernel: {METHOD_LABELS[method]} on the {problem} problem "
              f"(rate {rate:g} /s); slide the time step dt",
        caption=lambda r: r.verdict,
    )


def _verdict(run) -> str:
    limit = f"(limit {run.dt_limit:.3g} s)"
    return f"stable {limit}" if run.stable else f"BLOWN UP {limit}: {run.message}"


def spring_player(dt: float = 0.1, c: float = 0.0, method: str = "symplectic_euler",
                  ks=SPRING_KS) -> Player:
    """The spring widget's stiffness slider, precomputed at a fixed ``dt`` (notebook 07)."""
    from .nb07_spring_view import SpringPlot
    from .nb07_springs import run_spring

    # One figure redrawn in place, as the widget does; black, grey and one method colour
    # need no more than 16 palette entries, which keeps eleven frames at full resolution.
    return parameter_player(
        run_spring, SpringPlot(), "k", ks, fixed={"dt": dt, "c": c, "method": method},
        unit="N/m", caption=_verdict, colors=16,
        title=f"Without a kernel: a 1 kg mass, {METHOD_LABELS[method]}, dt = {dt:g} s; "
              "slide the stiffness k",
    )


def hair_player(dt: float = 1e-4, damping: float = 2e-3, k_bends=HAIR_KBENDS) -> Player:
    """The hair widget's bending-stiffness slider, precomputed at a fixed ``dt`` (notebook 08)."""
    from .nb08_hair_chains import run_held_strand
    from .nb08_hair_view import MAX_STEPS, T_END, HeldStrandPlot

    return parameter_player(
        run_held_strand, HeldStrandPlot(), "k_bend", k_bends,
        fixed={"dt": dt, "damping": damping, "max_steps": MAX_STEPS, "t_end": T_END},
        unit="N/m", label="k_bend", fmt="{:g}",
        caption=_verdict,
        title=f"Without a kernel: a held strand, symplectic Euler, dt = {dt:g} s; "
              "slide the bending stiffness",
    )


#: Alignment weights (1/s) of the flocking player: the flock orders as the weight grows, until
#: the explicit alignment step becomes unstable, f < -1 (at dt = 0.2 s, between 6 and 8 /s;
#: notebook 10, Section 5), and every boid's heading flips each step.
FLOCK_ALIGNMENTS = (0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0)


def _flock_caption(run) -> str:
    pol = float(run.polarization[-1])
    if run.reversal < 0.5:
        state = "the alignment step is unstable (f < -1): headings flip every step"
    elif pol > 0.9:
        state = "one aligned flock"
    else:
        state = "not aligned yet"
    return (f"polarization {pol:.2f} (a random flock: {run.random_polarization:.2f}), "
            f"heading kept between steps {run.reversal:+.2f}: {state}")


def flocking_player(separation: float = 0.3, cohesion: float = 1.0,
                    alignments=FLOCK_ALIGNMENTS) -> Player:
    """The flocking widget's alignment slider, precomputed (notebook 10)."""
    from .nb10_drawings import draw_flock
    from .nb10_flocking import run_flock

    return parameter_player(
        run_flock, draw_flock, "alignment", alignments,
        fixed={"separation": separation, "cohesion": cohesion}, unit="/s",
        caption=_flock_caption,
        title="Without a kernel: 150 boids, dt = 0.2 s; slide the alignment weight",
    )


def spiral_player() -> Player:
    """Notebook 02's spiral explorer: the dt slider, precomputed."""
    from .nb02_spiral_view import spiral_player as player

    return player()


def follower_player() -> Player:
    """Notebook 04's follower explorer: the κ dt slider, precomputed."""
    from .nb04_follower_view import follower_player as player

    return player()


#: The players, by the notebook that shows them (for the site and the tests).
PLAYERS = {
    "02_forward_euler": spiral_player,
    "03_stability": stability_player,
    "04_beyond_euler": follower_player,
    "07_springs": spring_player,
    "08_hair_chains": hair_player,
    "10_flocking": flocking_player,
}
