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


def callable_arg(name: str, value: object, signature: str = "(t, y)") -> Callable:
    """Return ``value``, or raise ``TypeError`` if it cannot be called."""
    if not callable(value):
        raise TypeError(f"{name} must be callable as {name}{signature}, "
                        f"got {type(value).__name__}")
    return value


def positive_int(name: str, value: object) -> int:
    """Return ``value`` as an int, or raise if it is not an integer >= 1."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < 1:
        raise ValueError(f"{name} must be >= 1, got {value}")
    return int(value)


def vector(name: str, value: object, nonzero: bool = False,
           dims: tuple[int, ...] | None = None) -> np.ndarray:
    """Return ``value`` as a finite real 1-D float array (not all zero if ``nonzero``; of a
    length in ``dims`` if given)."""
    arr = state_array(name, value)
    if np.iscomplexobj(arr) or arr.ndim != 1:
        raise ValueError(f"{name} must be a real vector of shape (d,), got {arr.dtype} "
                         f"of shape {arr.shape}")
    if dims is not None and arr.size not in dims:
        raise ValueError(f"{name} must have {' or '.join(map(str, dims))} components, "
                         f"got shape {arr.shape}")
    if nonzero and not np.any(arr):
        raise ValueError(f"{name} must not be the zero vector")
    return arr


def method_options(method: str, y: np.ndarray, name: str, jac: object,
                   implicit: frozenset[str], newtonian: frozenset[str]) -> None:
    """Check that ``jac`` and the state's layout suit ``method`` (the state is ``name``)."""
    if jac is not None:
        if method not in implicit:
            raise ValueError(f"jac is only used by the implicit methods {sorted(implicit)}, "
                             f"not by {method!r}")
        if not (callable(jac) or isinstance(jac, np.ndarray | list | tuple)
                or hasattr(jac, "tocsc")):
            raise TypeError("jac must be callable as jac(t, y), or a (n, n) array or "
                            f"scipy.sparse matrix; got {type(jac).__name__}")
    if method in newtonian and (y.ndim < 1 or y.shape[0] != 2):
        raise ValueError(
            f"method {method!r} needs a Newtonian state {name} = (x, v) stacked along axis 0 "
            f"({name}.shape[0] == 2); got {name} of shape {y.shape}. Build one with "
            "course_lib.systems.stack_state(x, v)."
        )


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


def post_step_checker(post_step: Callable, shape: tuple[int, ...], dtype: np.dtype) -> Callable:
    """``post_step`` whose every result is checked for shape and type (named in errors)."""

    def post(t: float, y: np.ndarray) -> np.ndarray:
        out = post_step(t, y)
        if out is None:
            raise TypeError("post_step must return the new state, got None (a post_step that "
                            "changes y in place should end with `return y`)")
        out = np.asarray(out)
        if out.shape != shape:
            raise ValueError(f"post_step must return an array of the state's shape {shape}, "
                             f"got shape {out.shape}")
        if out.dtype != dtype:
            if out.dtype == object or not np.issubdtype(out.dtype, np.number):
                raise TypeError(f"post_step must return numbers, got dtype {out.dtype}")
            if np.iscomplexobj(out) and not np.iscomplexobj(np.empty(0, dtype)):
                raise TypeError("post_step returned complex values for a real state")
            out = out.astype(dtype)
        return out

    return post


def nonnegative(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise if it is not a finite number >= 0."""
    value = finite_real(name, value)
    if value < 0.0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return value


def real_array(name: str, value: object, shape: tuple[int | None, ...] | None = None) -> np.ndarray:
    """``value`` as a finite real float array (of ``shape``, ``None`` matching any length)."""
    arr = state_array(name, value)
    if np.iscomplexobj(arr):
        raise TypeError(f"{name} must be real, got complex values")
    return arr if shape is None else shape_of(name, arr, shape)


def positions(name: str, value: object, n: int | None = None, dim: int | None = None) -> np.ndarray:
    """``value`` as a finite real array of shape ``(n, dim)`` (a copy; ``None``: any)."""
    return np.array(real_array(name, value, (n, dim)), dtype=float)


def masses(name: str, value: object, n: int) -> np.ndarray:
    """A scalar or ``n`` masses, each finite and > 0, as an array of shape ``(n,)``."""
    arr = real_array(name, value)
    if arr.ndim > 1 or (arr.ndim == 1 and arr.shape != (n,)):
        raise ValueError(f"{name} must be a scalar or have one entry per particle ({n}), "
                         f"got shape {arr.shape}")
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 (kg) for every particle")
    return np.broadcast_to(arr, (n,)).astype(float)


def indices(name: str, value: object, n: int) -> np.ndarray:
    """Particle indices (a sequence of ints in ``[-n, n)``; ``None`` for none) as a 1-D
    array of non-negative ints."""
    arr = np.asarray([] if value is None else value)
    if arr.ndim > 1:
        raise ValueError(f"{name} must be a 1-D list of particle indices, got shape {arr.shape}")
    if arr.size and (arr.dtype == np.bool_ or not np.issubdtype(arr.dtype, np.integer)):
        raise TypeError(f"{name} must hold integer particle indices, got {arr.tolist()!r}")
    if arr.size and (arr.min() < -n or arr.max() >= n):
        raise ValueError(f"{name} must hold particle indices in [0, {n}), got {arr.tolist()}")
    return np.asarray(arr, dtype=np.intp).reshape(-1) % max(n, 1)


def count(name: str, value: object) -> int:
    """Return ``value`` as an int, or raise if it is not an integer >= 0."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < 0:
        raise ValueError(f"{name} must be >= 0, got {value}")
    return int(value)


def positive_array(name: str, value: object) -> np.ndarray:
    """``value`` as a finite real array whose every entry is > 0 (masses, radii)."""
    arr = real_array(name, value)
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 everywhere, got {value!r}")
    return arr


def numbers(name: str, value: object) -> np.ndarray:
    """``value`` as a real float array; NaN allowed (records such as a trajectory keep NaN
    rows after a blow-up), text, objects and complex values refused."""
    try:
        arr = np.asarray(value)
    except Exception as exc:  # pragma: no cover - numpy raises many kinds here
        raise TypeError(f"{name} must be array-like of numbers: {exc}") from None
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_) \
            or np.iscomplexobj(arr):
        raise TypeError(f"{name} must be array-like of real numbers, got dtype {arr.dtype}")
    return arr.astype(float)


def mean_and_spread(name: str, mean: object, spread: object) -> tuple[float, float]:
    """A mean ``name`` > 0 and its spread ``name_variance`` (a Reeves "variance", the
    half-width) in ``[0, mean]``, so that every draw ``mean ± spread`` stays >= 0 (lifetimes)."""
    spread_name = f"{name}_variance"
    mean, spread = positive_finite(name, mean), nonnegative(spread_name, spread)
    if spread > mean:
        raise ValueError(f"{spread_name} must lie in [0, {name}] ({name}s stay >= 0), got {spread!r}")
    return mean, spread


def broadcastable(name: str, value: object, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a finite real array that broadcasts to ``shape``."""
    arr = real_array(name, value)
    try:
        return np.broadcast_to(arr, shape)
    except ValueError:
        raise ValueError(f"{name} must have shape {shape} or broadcast to it, got {arr.shape}") from None


def generator(name: str, value: object) -> np.random.Generator:
    """``value`` if it is a NumPy random ``Generator`` (seeded by the caller)."""
    if not isinstance(value, np.random.Generator):
        raise TypeError(f"{name} must be a numpy Generator, e.g. np.random.default_rng(2026), "
                        f"got {type(value).__name__}")
    return value
