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
  on a spring compressed to half its rest length) are told apart by the other cases;
- :func:`close_worst`: compare arrays of many rows (particles, springs, frames) and, on a
  failure, say how many values differ and show the *worst* row with how far it is off,
  never the whole expected array (which would bury the hint, or give the answer away);
- :func:`case_table`: a table that depends on a fixed case only (the reference frames, what
  the usual slips give), built once per kernel, so a second wrong attempt is judged at once.

Check layer: imports NumPy, the shared :class:`~course_lib.check.Checker` and the answer
helpers of :mod:`course_lib.check._answers`.
"""

from __future__ import annotations

import numpy as np

from . import Checker, Hint
from ._answers import as_array, call_analysis, close, mistake_hint, rtol_for


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


def close_worst(ck: Checker, got, expected, what: str, *, rtol: float, atol: float,
                hint: Hint = None, mistakes: dict | None = None, unit: str = "",
                label="row") -> bool:
    """Compare an array answer of many rows with the expected one; a failure reads
    "``k`` of ``n`` values differ; the worst, ``label`` r: expected [...], got [...] (off by
    ``x`` ``unit``)". Printing the gap matters: two rows that differ by a micrometre print
    alike at six digits. Arrays of up to 3 rows, and answers of another shape, are judged
    by :func:`~course_lib.check._answers.close` (printed whole: small enough to read).
    ``mistakes`` maps hints to the whole arrays the usual slips give; ``label`` names a row
    (``"row"``: "row 7"), or is a function of the row index that names it."""
    e = np.asarray(expected, dtype=float)
    a = as_array(got)
    if a is None or a.shape != e.shape or e.ndim == 0 or e.shape[0] <= 3:
        return close(ck, got, expected, what, rtol=rtol, atol=atol, hint=hint, mistakes=mistakes)
    rtol = rtol_for(a, rtol)
    bad = ~np.isclose(a, e, rtol=rtol, atol=atol)
    if not bad.any():
        return ck.expect(True, what)
    if mistakes:
        for mistake, wrong in mistakes.items():     # at this comparison's own tolerance
            w = np.asarray(wrong, dtype=float)
            if w.shape == a.shape and np.allclose(a, w, rtol=rtol, atol=atol):
                hint = mistake
                break
        else:
            hint = mistake_hint(a, mistakes, hint)
    with np.errstate(invalid="ignore"):
        gap = np.abs(a - e).reshape(e.shape[0], -1)
    gap = np.where(np.isnan(gap), np.inf, gap).max(axis=1)
    r = int(np.argmax(gap))

    def show(x):   # one line, also for a row that is itself 2-D (a particle's x and v)
        x = np.asarray(x) + 0.0
        if x.ndim > 1:
            return "; ".join(show(part) for part in x)
        return np.array2string(x, precision=6, suppress_small=True, separator=", ",
                               max_line_width=10**6)

    name = label(r) if callable(label) else f"{label} {r}"
    return ck.expect(False, what, f"{int(bad.sum())} of {bad.size} values differ; the worst, "
                     f"{name}: expected {show(e[r])}, got {show(a[r])} (off by "
                     f"{gap[r]:.2g}{' ' + unit if unit else ''})", hint)


#: Tables of the checks' fixed cases, keyed by (check, case label); see :func:`case_table`.
_TABLES: dict[tuple[str, str], object] = {}


def _freeze(value):
    """``value`` with every array in it (at the top or as a dict's value) made read-only."""
    for arr in (value.values() if isinstance(value, dict) else (value,)):
        if isinstance(arr, np.ndarray):
            arr.flags.writeable = False
    return value


def case_table(check: str, case: str, build, *args):
    """``build(*args)`` for the case labelled ``case`` of the check ``check``, built on first use
    and reused by every later attempt in the same kernel.

    Only for what depends on the case alone, never on the answer: the reference frames of a
    run, the results of the usual slips. Arrays come back read-only, so that no caller can
    change what the next attempt is judged against.
    """
    key = (check, case)
    if key not in _TABLES:
        _TABLES[key] = _freeze(build(*args))
    return _TABLES[key]
