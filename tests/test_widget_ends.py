"""Every widget of the course answers every one of its sliders at both ends.

A ``FloatLogSlider`` at an end holds ``base**min`` or ``base**max``, which is one rounding
off the end itself (``10**log10(0.05)`` is ``0.049999999999999996``): a compute function that
checks its range strictly raised there (notebook 04's follower explorer did). Widgets are
found by name (``*_explorer`` factories in ``course_lib.lessons``), so a new one is covered
without being listed.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import matplotlib
import pytest

import course_lib.lessons as lessons

matplotlib.use("Agg")


def _factories():
    for info in sorted(pkgutil.iter_modules(lessons.__path__), key=lambda m: m.name):
        if not info.name.startswith("nb"):
            continue
        module = importlib.import_module(f"course_lib.lessons.{info.name}")
        for name, obj in vars(module).items():
            if name.endswith("_explorer") and inspect.isfunction(obj) and obj.__module__ == module.__name__:
                yield f"{info.name}.{name}", obj


FACTORIES = dict(_factories())


def _ends(control):
    if hasattr(control, "base"):
        return [control.base**control.min, control.base**control.max]
    return [control.min, control.max]


def test_the_widgets_are_found():
    assert len(FACTORIES) >= 6, sorted(FACTORIES)


@pytest.mark.parametrize("name", sorted(FACTORIES))
def test_every_slider_end_gives_a_picture(name):
    view = FACTORIES[name]()
    sliders = [k for k, c in view.controls.items() if hasattr(c, "min")]
    assert sliders, f"{name} has no slider"
    for key in sliders:
        control = view.controls[key]
        start = control.value
        for end in _ends(control):
            if control.value == end:
                continue  # already drawn there (no change event)
            view.result = None
            control.value = end
            assert view.result is not None, f"{name}: {key} = {end!r} gave no result"
        control.value = start
