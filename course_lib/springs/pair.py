"""The force of a single Hooke spring between two points (the formula students write first).

Core module: imports NumPy only.
"""

from __future__ import annotations

import numpy as np


def spring_force_pair(x1, x2, k: float, rest: float) -> np.ndarray:
    """Hooke force on particle 1 of a single spring: ``-k (|x1 - x2| - L) (x1 - x2)/|x1 - x2|``.

    Zero where the two ends coincide (the direction is undefined there).
    """
    d = np.asarray(x1, dtype=float) - np.asarray(x2, dtype=float)
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    inv = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0.0)
    return -k * (length - rest) * d * inv
