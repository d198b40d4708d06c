"""Helpers for checks: call a student's function, read its answer, judge it at its precision.

Shared by the checks of notebooks 01-04. The point of each helper is that feedback blames
the student only for what the student's code did:

- :func:`call` runs the student's function for one case and records an exception it
  raises as that case's failure (``NotImplementedError`` still means "pending"), so an
  error in the checker itself is never reported as the student's;
- :func:`as_array` reads an answer as a float (or complex) array without raising, so a
  list, a tuple, a NumPy scalar or a ``(1,)`` array are all judged on their values;
- :func:`rtol_for` widens a tolerance to the precision the answer carries, so a right
  answer computed in float32 is accepted (it has about 7 significant digits);
- :func:`close` compares at that precision, names the usual mistake an answer matches
  (:func:`mistake_hint`), and summarises a large wrong array by its worst row;
- :func:`pure_call` and :func:`step_cases` check one-step methods ``step(f, t, y, dt)``
  (notebooks 02, 04, 05); :func:`kutta3` is a method the course never teaches, a black box
  for the checks of 02 and 03;
- :func:`call_analysis` runs an answer that the prompt asks to be an analysis (a formula,
  not a loop over the steps) with a budget of lines of Python in the student's own code,
  so that a step-by-step simulation is told so instead of passing.

Imports NumPy and :class:`course_lib.check.Checker` only.
"""

from __future__ import annotations

import sys
import sysconfig
from collections.abc import Callable

import numpy as np

from . import Checker, Hint

#: Relative tolerance granted per unit round-off of the answer's own precision.
_ROUNDOFF_FACTOR = 64.0


def call(ck: Checker, what: str, func: Callable, *args, error_hint=None, **kwargs
         ) -> tuple[bool, object]:
    """``(True, func(*args, **kwargs))``, or ``(False, None)`` after recording the exception.

    ``NotImplementedError`` propagates (the exercise is pending). ``error_hint(exc)`` may
    return the hint for the exception the answer raised (e.g. an IndexError on a 1-D input).
    """
    try:
        return True, func(*args, **kwargs)
    except NotImplementedError:
        raise
    except Exception as exc:  # the student's code failed on this case: say where and how
        ck.expect(False, what, f"your function raised {type(exc).__name__}: {exc}",
                  error_hint(exc) if error_hint else None)
        return False, None


def as_array(answer, *, complex_ok: bool = False) -> np.ndarray | None:
    """The answer as a float (or, if ``complex_ok``, complex) ndarray; None if it is not one.

    Keeps the answer's precision (float32 stays float32) so that :func:`rtol_for` can see it.
    """
    try:
        arr = np.asarray(answer)
    except Exception:
        return None
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        return None
    if np.iscomplexobj(arr) and not complex_ok:
        return None
    if arr.dtype == bool or np.issubdtype(arr.dtype, np.integer):
        arr = arr.astype(float)
    return arr


def as_scalar(answer) -> float | None:
    """A single real number from a float, NumPy scalar or one-element array; else None."""
    arr = as_array(answer)
    if arr is None or arr.size != 1:
        return None
    return float(arr.reshape(()))


def one_number(ck: Checker, what: str, got, kind: str = "") -> float | None:
    """The answer as one real number, or None after recording "expected one number" (with
    ``kind``, e.g. "a step in s", saying which) for anything else, NaN and inf included."""
    value = as_scalar(got)
    if value is None or not np.isfinite(value):
        ck.expect(False, what, f"expected one number{f' ({kind})' if kind else ''}, "
                  f"got {got!r}"[:160])
        return None
    return value


def rtol_for(answer, rtol: float) -> float:
    """``rtol``, or more if the answer carries fewer digits than float64 (float32: ~8e-6)."""
    arr = as_array(answer, complex_ok=True)
    if arr is None or not np.issubdtype(arr.dtype, np.inexact):
        return rtol
    return max(rtol, _ROUNDOFF_FACTOR * float(np.finfo(arr.dtype).eps))


def mistake_hint(actual, mistakes: dict[Hint, object], default: Hint = None) -> Hint:
    """The hint of the first typical mistake ``actual`` matches (any shape), else ``default``.

    ``mistakes`` maps a hint to the value a typical wrong answer gives; unlike
    :meth:`Checker.close`, a mistake of any shape is recognised.
    """
    a = as_array(actual)
    if a is None:
        return default
    rtol = rtol_for(a, 1e-9)
    for hint, wrong in mistakes.items():
        w = np.asarray(wrong, dtype=float)
        if w.shape == a.shape and np.allclose(a, w, rtol=rtol, atol=rtol * 1e-3):
            return hint
    return default


def close(ck: Checker, got, expected, what: str, *, hint: Hint = None,
           mistakes: dict | None = None, rtol: float = 1e-9, atol: float | None = None) -> bool:
    """Compare at the precision of the student's answer (float32 accepted); a large wrong
    array is summarised by its worst entry instead of printed whole.

    ``atol`` (the answer's units) defaults to a thousandth of ``rtol`` times the largest
    expected magnitude; pass one when the answer is a difference of larger numbers.
    """
    expected = np.asarray(expected, dtype=float)
    rtol = rtol_for(got, rtol)
    single = as_array(got)
    if single is not None and single.size == expected.size == 1:
        got = single.reshape(expected.shape)  # a number returned as a (1,) array is a number
    if atol is None:
        atol = max(1e-12, rtol * 1e-3 * (float(np.max(np.abs(expected))) if expected.size else 1.0))
    answer = as_array(got)
    if answer is None or answer.shape != expected.shape:
        return ck.close(got, expected, what, rtol=rtol, atol=atol, hint=hint, mistakes=mistakes)
    bad = ~np.isclose(answer, expected, rtol=rtol, atol=atol)
    if expected.size <= 12:
        if not bad.any():
            return ck.expect(True, what)
        for mistake, wrong in (mistakes or {}).items():  # matched at this comparison's tolerance
            w = np.asarray(wrong, dtype=float)
            if w.shape == answer.shape and np.allclose(answer, w, rtol=rtol, atol=atol):
                hint = mistake
                break
        return ck.expect(False, what, differ(answer, expected, rtol), hint)
    if not bad.any():
        return ck.expect(True, what)
    if mistakes:
        hint = mistake_hint(answer, mistakes, hint)
    with np.errstate(invalid="ignore"):     # the row that is off the most (NaN counts as most)
        gap = np.abs(answer - expected).reshape(len(expected), -1)
    gap = np.where(np.isnan(gap), np.inf, gap).max(axis=1)
    row = int(np.argmax(gap))
    return ck.expect(False, what, f"{int(bad.sum())} of {bad.size} values differ; the worst, row "
                     f"{row}: expected {np.round(expected[row], 6)}, got {np.round(answer[row], 6)}"
                     f" (off by {gap[row]:.2g})", hint)


def _fmt(x) -> str:
    x = np.asarray(x)
    if np.issubdtype(x.dtype, np.inexact):
        x = x + 0.0  # -0.0 prints as "-0."; + 0.0 makes it 0.0
    return np.array2string(x, precision=6, suppress_small=True, separator=", ")


def differ(answer, expected, rtol: float) -> str:
    """"expected ..., got ..."; when the two print alike (equal to 6 digits), also by how
    much they differ relative to the expected size, and what the check allows."""
    a, e = _fmt(answer), _fmt(expected)
    text = f"expected {e}, got {a}"
    if a == e:
        answer, expected = np.asarray(answer, dtype=float), np.asarray(expected, dtype=float)
        scale = max(float(np.max(np.abs(expected))), 1e-300)
        gap = float(np.max(np.abs(answer - expected))) / scale
        text += (f" (alike to the printed digits, but {gap:.1e} apart relative to the size; "
                 f"the check allows {rtol:.0e})")
    return text


def pure_call(ck: Checker, what: str, student: Callable, f: Callable, t: float,
              y: np.ndarray, dt: float, error_hint=None) -> tuple[bool, object]:
    """Call a one-step method ``student(f, t, y, dt)`` on a copy of ``y``, like :func:`call`
    (``error_hint`` as there); a function that overwrites its input fails the case with its
    own hint."""
    y_in = y.copy()
    ok, got = call(ck, what, student, f, t, y_in, dt, error_hint=error_hint)
    if ok and not np.array_equal(y_in, y):
        ck.expect(False, what, "your function changed its input y",
                  "build a new array instead of updating y in place (y += ...)")
        return False, None
    return ok, got


def step_cases(ck: Checker, student: Callable, cases, reference: Callable,
               mistakes_for: Callable, hint: Hint, rtol: float = 1e-12,
               atol: float | None = None) -> None:
    """Check a student's one-step method ``student(f, t, y, dt)`` on several cases.

    ``cases`` holds ``(what, f, t, y, dt)``; ``reference`` is the course_lib step and
    ``mistakes_for(f, t, y, dt)`` returns ``{hint: wrong_value}`` for the usual slips. The
    reference and the mistakes are computed first, from the pristine ``y``; the student gets
    a copy (:func:`pure_call`). An answer holding NaN or inf is said to be one, not printed;
    a float32 answer is judged at float32 precision.
    """
    for what, f, t, y, dt in cases:
        y = np.asarray(y, dtype=float)
        expected, mistakes = reference(f, t, y.copy(), dt), mistakes_for(f, t, y.copy(), dt)
        ok, got = pure_call(ck, what, student, f, t, y, dt)
        if not ok:
            continue
        answer = as_array(got)
        if answer is not None and answer.size and not np.all(np.isfinite(answer)):
            ck.expect(False, what, "your step returned NaN or inf",
                      "look for a division by zero or an overflow in the update")
            continue
        close(ck, got, expected, what, rtol=rtol, atol=atol, hint=hint, mistakes=mistakes)


def kutta3(f, t, y, dt):
    """Kutta's third-order method (R = 1 + z + z²/2 + z³/6): a black box the checks of
    notebooks 02 and 03 measure students' tools on, since the course never teaches it."""
    k1 = f(t, y)
    k2 = f(t + 0.5 * dt, y + 0.5 * dt * k1)
    k3 = f(t + dt, y - dt * k1 + 2.0 * dt * k2)
    return y + dt / 6.0 * (k1 + 4.0 * k2 + k3)


class TooManyLines(BaseException):
    """Raised inside an answer that runs more lines of its own Python than a formula needs
    (a BaseException, so that the answer's own ``except Exception`` does not swallow it).
    Its message explains itself: the grader reports it by name and message."""


#: Modules whose frames are not the student's code (their lines are not counted).
_LIBRARIES = ("numpy", "scipy", "course_lib", "importlib")  # importlib: a first import inside
#: Folders whose files are not the student's code either: the standard library and the
#: installed packages. The grader's replay decodes recorded answers with ``base64`` and
#: friends inside the answer's call; their lines must not count against the student.
_LIBRARY_DIRS = tuple(sorted({sysconfig.get_paths()[k] for k in
                              ("stdlib", "platstdlib", "purelib", "platlib")}))


def _is_library(frame) -> bool:
    module = frame.f_globals.get("__name__", "") or ""
    filename = frame.f_code.co_filename
    return (module.startswith(_LIBRARIES) or filename.startswith(_LIBRARY_DIRS)
            or filename.startswith("<frozen "))


def call_analysis(ck: Checker, what: str, budget: int, hint: Hint, func: Callable, *args,
                  why: str = "it steps through the run instead of evaluating the result"
                  ) -> tuple[bool, object]:
    """Like :func:`call`, for an exercise that asks for an analysis (or for no Python loop):
    at most ``budget`` lines of Python may run in the answer's own frames (NumPy, SciPy and
    the library not counted).

    A formula runs a handful of lines whatever the arguments; a loop over a million steps
    runs a million. Counting lines (``sys.settrace``), not seconds, gives the same verdict on
    every machine, and stops a long loop at once. On overrun the case fails with ``hint``;
    ``why`` says what so many lines mean for this exercise (e.g. "it loops over the
    particles").
    """
    count = 0
    why = f"your function ran more than {budget} lines of Python here: {why}"

    def line(frame, event, arg):
        nonlocal count
        if event == "line":
            count += 1
            if count > budget:
                raise TooManyLines(why)
        return line

    def calls(frame, event, arg):
        return None if _is_library(frame) else line

    previous = sys.gettrace()
    sys.settrace(calls)
    over, got = False, None
    try:
        got = func(*args)
    except NotImplementedError:
        raise
    except TooManyLines:
        over = True
    except Exception as exc:
        # the grader's recorder hands the check a copy of the answer's exception, by name
        over = type(exc).__name__ == TooManyLines.__name__
        if not over:
            ck.expect(False, what, f"your function raised {type(exc).__name__}: {exc}")
            return False, None
    finally:
        sys.settrace(previous)
    if over or count > budget:  # also when the answer caught it and carried on untraced
        ck.expect(False, what, why, hint)
        return False, None
    return True, got
