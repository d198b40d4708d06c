"""Widgets: time from a control change to a recomputed, redrawn figure.

Each widget is built by its lesson's factory and driven the way a student drives it, by
setting a control's ``.value``. Times are CPU seconds of the benchmark thread (wall time in
the note): the update is serial, and the wall clock on a shared machine counts other
processes too (outside a kernel the view computes and draws off-screen
with Agg, the same compute and draw functions the notebook runs; a kept figure, a
:class:`~course_lib.widgets.BlitPlot`, also encodes the PNG the student's image receives). We time its default
settings, then sweep the settings that cost most (every method at the smallest step, the
largest step, stiffness and damping at their ends) and report the slowest; the hair
widget is also timed on bending stiffnesses it has never seen (a fresh equilibrium), and
the large-step cloth widget on the first visit to each of its stiffnesses.
"""

from __future__ import annotations

import importlib
import itertools
import pkgutil
import time

import matplotlib

matplotlib.use("Agg")

from benchmarks.timing import Row

DEFAULT_TARGET = 0.100   # s, one update at the default settings
ANYWHERE_TARGET = 0.250  # s, one update anywhere on the sliders

#: (label, notebook prefix, factory name[, controls whose every value is timed on its first
#: visit, from a freshly built widget])
WIDGETS = [
    ("02 spiral explorer", "nb02", "spiral_explorer"),
    ("03 stability explorer", "nb03", "stability_explorer"),
    ("04 follower explorer", "nb04", "follower_explorer"),
    ("05 energy explorer", "nb05", "energy_explorer"),
    ("07 spring widget", "nb07", "spring_explorer"),
    ("08 hair widget", "nb08", "held_strand_explorer"),
    ("12 large-step cloth widget (32²)", "nb12", "frame_explorer", ("stiffness",)),
]


def main_control(view) -> str:
    """The control a student moves first: the time step, else the first slider."""
    if "dt" in view.controls:
        return "dt"
    return next(n for n, c in view.controls.items() if hasattr(c, "min"))


def find_factory(prefix: str, name: str):
    """The widget factory ``name`` in one of ``course_lib.lessons.<prefix>_*``."""
    import course_lib.lessons as lessons

    for info in sorted(pkgutil.iter_modules(lessons.__path__), key=lambda m: m.name):
        if info.name.startswith(prefix + "_"):
            module = importlib.import_module(f"course_lib.lessons.{info.name}")
            if hasattr(module, name):
                return getattr(module, name)
    raise LookupError(f"no {name} in course_lib.lessons.{prefix}_*")


def option_values(control) -> list:
    return [o[1] if isinstance(o, tuple) else o for o in control.options]


def nudge(control):
    """A value next to the control's current one (so that setting it is a real change)."""
    lo, hi, value = control.min, control.max, control.value
    if isinstance(value, int):                            # an IntSlider: one notch
        return value + 1 if value < hi else value - 1
    if hasattr(control, "base"):                          # log slider: min/max are exponents
        lo, hi = control.base**lo, control.base**hi
    step = 1.01 if value * 1.01 <= hi else 0.99
    return min(max(value * step, lo), hi) if value else (lo + hi) / 2


#: Wall-clock seconds of every timed update, next to their CPU seconds (see :func:`timed_update`).
WALL_TIMES: dict[float, float] = {}


def timed_update(view, name: str, value=None) -> float:
    """CPU seconds (this thread) of one control change: compute and draw are serial, so on
    a busy machine this estimates a quiet machine's wait better than the wall clock."""
    control = view.controls[name]
    start, wall = time.thread_time(), time.perf_counter()
    control.value = nudge(control) if value is None else value
    seconds = time.thread_time() - start
    WALL_TIMES[seconds] = time.perf_counter() - wall
    return seconds


def slider_ends(control):
    if hasattr(control, "base"):
        return [control.base**control.min, control.base**control.max]
    return [control.min, control.max]


def sweep(factory, quick: bool):
    """Every method at each end of the step slider, and each other slider at its ends:
    returns ``(seconds, settings)`` of the slowest update."""
    view = factory()
    controls, key = view.controls, main_control(view)
    sliders = [n for n, c in controls.items() if hasattr(c, "min") and n != key]
    methods = option_values(controls["method"]) if "method" in controls else [None]
    settings = [{"method": m, key: v} for m, v in itertools.product(methods, slider_ends(controls[key]))]
    settings += [{name: end} for name in sliders for end in slider_ends(controls[name])]
    if quick:
        settings = settings[:2]
    worst = (0.0, {})
    for setting in settings:
        setting = {k: v for k, v in setting.items() if v is not None}
        try:                                              # the others at their defaults
            fresh = factory(**setting)
        except TypeError:
            fresh = factory()
            for name, value in setting.items():
                fresh.controls[name].value = value
        seconds = min(timed_update(fresh, key) for _ in range(1 if quick else 2))
        worst = max(worst, (seconds, setting), key=lambda w: w[0])
    return worst


def run(quick: bool = False) -> list[Row]:
    from course_lib.plotting import use_course_style

    use_course_style()
    rows = []
    for k, (label, prefix, name, *visits) in enumerate(WIDGETS):
        try:
            # a quick run (the test suite's smoke test) finds every factory but builds and
            # sweeps the first widget only: every widget is built and its sliders set at
            # their ends by tests/test_widget_ends.py
            factory = find_factory(prefix, name)
            if quick and k > 0:
                continue
            rows += widget_rows(label, factory, quick)
            if visits and not quick:
                rows += first_visit_rows(label, factory, visits[0])
        except Exception as exc:                          # one broken widget fails its row only
            rows.append(Row(f"widget {label}", None, "runs", False,
                            note=f"crashed: {type(exc).__name__}: {exc}"[:100]))
    return rows


def widget_rows(label: str, factory, quick: bool) -> list[Row]:
    rows = []
    view = factory()
    times = sorted(timed_update(view, main_control(view)) for _ in range(1 if quick else 7))
    median = times[len(times) // 2]
    rows.append(Row(f"widget {label}: one update, default settings", median,
                    f"≤ {DEFAULT_TARGET * 1e3:.0f} ms", median <= DEFAULT_TARGET,
                    note=f"wall {WALL_TIMES[median] * 1e3:.0f} ms"))
    seconds, where = sweep(factory, quick)
    text = ", ".join(f"{k} = {v:.3g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in where.items())
    rows.append(Row(f"widget {label}: slowest update over the sliders", seconds,
                    f"≤ {ANYWHERE_TARGET * 1e3:.0f} ms", seconds <= ANYWHERE_TARGET,
                    note=f"at {text}; wall {WALL_TIMES[seconds] * 1e3:.0f} ms"))
    if "k_bend" in view.controls:
        lo, hi = slider_ends(view.controls["k_bend"])
        fresh = [lo * (hi / lo) ** f for f in (0.123, 0.357, 0.579, 0.791, 0.913)]
        times = sorted(timed_update(view, "k_bend", k) for k in fresh[: 1 if quick else 5])
        mid = times[len(times) // 2]
        rows.append(Row(f"widget {label}: new bending stiffness (fresh equilibrium)", mid,
                        f"≤ {ANYWHERE_TARGET * 1e3:.0f} ms", mid <= ANYWHERE_TARGET,
                        note=f"wall {WALL_TIMES[mid] * 1e3:.0f} ms"))
    return rows


def first_visit_rows(label: str, factory, names) -> list[Row]:
    """For each control in ``names``: every value but the default, each the first time a
    freshly built widget sees it (what the widget did not prepare at construction shows
    here); the slowest, against the default-settings target."""
    rows = []
    for name in names:
        view = factory()
        values = [v for v in option_values(view.controls[name]) if v != view.controls[name].value]
        times = {v: timed_update(view, name, v) for v in values}
        value, seconds = max(times.items(), key=lambda kv: kv[1])
        rows.append(Row(f"widget {label}: first visit to each {name} (slowest of {len(values)})",
                        seconds, f"≤ {DEFAULT_TARGET * 1e3:.0f} ms", seconds <= DEFAULT_TARGET,
                        note=f"at {name} = {value:g}; wall {WALL_TIMES[seconds] * 1e3:.0f} ms"))
    return rows
