"""Helpers for checks: call a student's function, read its answer, judge it at its precision.

Shared by the checks of notebooks 01-04. The point of each helper is that feedback blames
the student only for what the student's code did:

- :func:`call` runs the student's function for one case and records an exception it
  raises as that case's failure (``NotImplementedError`` still means "pending"), so an
  error in the checker itself is never reported as the student's;
- :func:`as_array` reads an answer as a float (or complex) array without raising, so a
  list, a tuple, a NumPy scalar or a ``(1,)`` array are all judged on their values;
- :func:`rtol_for` widens a tolerance to the precision the answer carries, so a right
  answer computed in float32 is accepted (it has about 7 significant digits).

Imports NumPy and :class:`course_lib.check.Checker` only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import Checker

#: Relative tolerance granted per unit round-off of the answer's own precision.
_ROUNDOFF_FACTOR = 64.0


def call(ck: Checker, what: str, func: Callable, *args, **kwargs) -> tuple[bool, object]:
    """``(True, func(*args, **kwargs))``, or ``(False, None)`` after recording the exception.

    ``NotImplementedError`` propagates (the exercise is pending).
    """
    try:
        return True, func(*args, **kwargs)
    except NotImplementedError:
        raise
    except Exception as exc:  # the student's code failed on this case: say where and how
        ck.expect(False, what, f"your function raised {type(exc).__name__}: {exc}")
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


def rtol_for(answer, rtol: float) -> float:
    """``rtol``, or more if the answer carries fewer digits than float64 (float32: ~8e-6)."""
    arr = as_array(answer, complex_ok=True)
    if arr is None or not np.issubdtype(arr.dtype, np.inexact):
        return rtol
    return max(rtol, _ROUNDOFF_FACTOR * float(np.finfo(arr.dtype).eps))
