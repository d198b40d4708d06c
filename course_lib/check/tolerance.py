"""Judging helpers shared by the checks of notebooks 05-08.

- :func:`precision_rtol`: a tolerance that follows the precision of the answer, so that a
  right answer computed in float32 (seven digits) is accepted while a wrong formula,
  off by a factor, is not.
- :func:`blown_up`: report "your run blew up" (with the step) instead of printing a row
  of ``nan`` as the answer;
- :func:`escalate`: a hint that names the mistake first and adds the fix after another
  wrong attempt (:meth:`~course_lib.check.Checker.pick`);
- :func:`call_whole_array`: run an answer that must work on whole arrays under a budget of
  Python lines (a loop over the particles runs one pass per particle), saying so if not;
- :func:`consistent_hint`: the one mistake that explains every case an answer gets wrong,
  so that two mistakes that coincide on one case (a sign error and a force on the length,
  on a spring compressed to half its rest length) are told apart by the other cases.

Check layer: imports NumPy and the shared :class:`~course_lib.check.Checker` only.
"""

from __future__ import annotations

import numpy as np

from . import Checker, Hint
from ._answers import call_analysis


def precision_rtol(answer, rtol: float) -> float:
    """``rtol``, widened to a few units in the last place of ``answer``'s float dtype.

    >>> precision_rtol(np.float32(1.4142135), 1e-9) > 1e-7
    True
    >>> precision_rtol(1.4142135623730951, 1e-9)
    1e-09
    """
    try:
        dtype = np.asarray(answer).dtype
    except Exception:  # an answer numpy cannot read: Checker.close will say so
        return rtol
    if np.issubdtype(dtype, np.floating) and np.finfo(dtype).eps > 1e-15:
        return max(rtol, 16.0 * float(np.finfo(dtype).eps))
    return rtol


def blown_up(ck: Checker, answer, what: str, *, run: bool = True, hint: str | None = None) -> bool:
    """Record a failed case when ``answer`` holds NaN or inf, and return True then.

    ``run=True`` words it for a simulation (rows are steps: "your run blew up from step
    k on"); ``run=False`` for a computed value ("your function returned NaN or inf").
    ``hint`` replaces the generic hint.
    """
    try:
        a = np.asarray(answer, dtype=float)
    except (TypeError, ValueError):
        return False
    if a.size == 0 or np.all(np.isfinite(a)):
        return False
    if not run or a.ndim == 0:
        ck.expect(False, what, "your function returned NaN or inf",
                  hint=hint or "look for a division by zero (0/0 gives NaN, e.g. a particle's "
                               "distance to itself) or an overflow")
        return True
    rows = np.isfinite(a.reshape(a.shape[0], -1)).all(axis=1)
    step = int(np.argmin(rows))
    ck.expect(False, what, f"your run blew up: its values are NaN or inf from step {step} on",
              hint=hint or "a run that explodes usually has a sign error in the update, or "
                           "uses an acceleration or time from the wrong point of the step")
    return True


def escalate(nudge: str, more: str) -> tuple[str, str]:
    """A hint that escalates: ``nudge`` (the mistake, named) on the first wrong attempt;
    after another one the same words followed by ``more`` (how to fix it), so that the
    fuller hint still says what was wrong.

    >>> escalate("a sign error", "F = -k x")[1]
    'a sign error — F = -k x'
    """
    return nudge, f"{nudge} — {more}"



def consistent_hint(results, rtol: float = 1e-9, atol: float = 1e-12) -> Hint:
    """The hint of the first usual mistake that explains the whole answer, or None.

    ``results`` holds ``(got, expected, mistakes)`` per case, ``mistakes`` mapping a hint to
    the value that mistake gives on that case (the same hints, in the same order, for every
    case). A mistake explains the answer when, on every case, the answer equals the right
    value or that mistake's value, and equals the mistake's (not the right one) at least
    once. Per-case matching alone would blame a sign error for an answer that only went
    wrong on a compressed spring.
    """
    def same(a, b) -> bool:
        try:
            a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        except (TypeError, ValueError):
            return False
        return a.shape == b.shape and bool(np.allclose(a, b, rtol=precision_rtol(a, rtol),
                                                        atol=atol))

    if not results:
        return None
    for hint in results[0][2]:
        explained, shown = True, False
        for got, expected, mistakes in results:
            if same(got, expected):
                continue
            if not same(got, mistakes[hint]):
                explained = False
                break
            shown = True
        if explained and shown:
            return hint
    return None


def call_whole_array(ck: Checker, what: str, budget: int, hint: Hint, func, *args):
    """:func:`~course_lib.check._answers.call_analysis` for an answer that must work on whole
    arrays: more than ``budget`` lines of Python means a loop over the particles (or balls,
    or bodies), and the failure says that rather than "steps through the run"."""
    ok, got = call_analysis(ck, what, budget, hint, func, *args)
    if not ok and ck.failed and "lines of Python" in ck.failed[-1]:
        ck.failed[-1] = ck.failed[-1].replace(
            "it steps through the run instead of evaluating the result",
            "it loops over the particles one at a time instead of working on whole arrays")
    return ok, got
