"""Fluid-to-wall neighbour search for SPH, with SciPy's k-d tree (private).

Fluid pairs come from :func:`course_lib.neighbors.pairs`; :func:`cross_pairs` lists the
(fluid, wall) pairs against a wall's tree, built once since walls do not move.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def cross_pairs(x: np.ndarray, tree: cKDTree, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Index arrays ``(i, k)``: fluid particle ``x[i]`` within ``radius`` of point ``k``
    of ``tree`` (a wall's particles)."""
    if tree.n == 0 or len(x) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    found = cKDTree(x).sparse_distance_matrix(tree, radius, output_type="ndarray")
    return found["i"].astype(np.intp), found["j"].astype(np.intp)
