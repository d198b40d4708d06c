"""The force of a single Hooke spring between two points (the formula students write first).

Core module: imports NumPy and :mod:`course_lib._validate` only.
"""

from __future__ import annotations

import numpy as np

from .. import _validate


def spring_force_pair(x1, x2, k: float, rest: float) -> np.ndarray:
    """Hooke force on particle 1 of a single spring: ``-k (|x1 - x2| - L) (x1 - x2)/|x1 - x2|``.

    Zero where the two ends coincide (the direction is undefined there).
    """
    x1, x2 = _validate.real_array("x1", x1), _validate.real_array("x2", x2)
    if x1.shape[-1:] != x2.shape[-1:]:
        raise ValueError(f"x1 and x2 must have the same last axis (d), got {x1.shape} and {x2.shape}")
    k, rest = _validate.nonnegative("k", k), _validate.nonnegative("rest", rest)
    d = x1 - x2
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    inv = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0.0)
    return -k * (length - rest) * d * inv
