"""Input checks shared by the solvers and models.

Every check raises ``TypeError`` or ``ValueError`` whose message names the offending
argument, so that a student who passes the wrong thing learns what was expected.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from numbers import Real

import numpy as np


def positive_finite(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise if it is not a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, Real | np.floating | np.integer):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def finite_real(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, Real | np.floating | np.integer):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


def state_array(name: str, value: object) -> np.ndarray:
    """Return ``value`` as a finite float (or complex) ndarray with at least one entry."""
    try:
        arr = np.asarray(value)
    except Exception as exc:  # pragma: no cover - numpy raises many kinds here
        raise TypeError(f"{name} must be array-like of numbers: {exc}") from None
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_
    ):
        raise TypeError(f"{name} must be array-like of numbers, got dtype {arr.dtype}")
    if arr.size == 0:
        raise ValueError(f"{name} must have at least one entry, got shape {arr.shape}")
    if np.iscomplexobj(arr):
        arr = arr.astype(complex)
    else:
        arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite; it contains NaN or inf")
    return arr


def callable_arg(name: str, value: object) -> Callable:
    if not callable(value):
        raise TypeError(f"{name} must be callable as {name}(t, y), got {type(value).__name__}")
    return value


def shape_of(name: str, arr: np.ndarray, shape: tuple[int | None, ...]) -> np.ndarray:
    """Check ``arr.shape`` against ``shape``, where ``None`` matches any length."""
    ok = arr.ndim == len(shape) and all(s is None or s == a for s, a in zip(shape, arr.shape, strict=False))
    if not ok:
        want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name} must have shape {want}, got {arr.shape}")
    return arr


def choice(name: str, value: object, choices) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, one of {', '.join(sorted(choices))}")
    if value not in choices:
        raise ValueError(
            f"unknown {name} {value!r}; valid choices are: {', '.join(sorted(choices))}"
        )
    return value
