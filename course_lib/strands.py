"""Rest shapes of hair strands and the springs built on them.

A strand is a row of particles. Its springs, after Selle, Lentine & Fedkiw (2008), join
particles one apart (edges), two apart (bending) and three apart (torsion), with rest
lengths measured on the strand's *rest shape*. The shape decides what the springs can
resist: on a straight strand bending springs act only to second order, and on any
*planar* rest shape (straight, a planar curl, a zigzag) a twist changes no distance to
first order, so torsion springs resist nothing; a curly, helical strand has first-order
twist stiffness.

- :func:`helix`: the rest shape of a curly strand;
- :func:`strand_network`: edge, bending and torsion springs on any rest shape;
- :func:`twist`, :func:`twist_angle`: turn the part of a strand beyond a particle about
  the strand's own direction there, and measure that turn.

Core module: imports NumPy and :mod:`course_lib.springs` only.
"""

from __future__ import annotations

import numpy as np

from . import _validate
from .springs import SpringNetwork

#: Offsets of the spring families: (offset, kind).
FAMILIES = ((1, "edge"), (2, "bend"), (3, "twist"))


def _frame(axis) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A right-handed orthonormal frame (e1, e2, a) with ``a`` along ``axis``."""
    a = np.asarray(axis, dtype=float)
    norm = np.linalg.norm(a)
    if a.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise ValueError(f"axis must be a non-zero 3-vector, got {axis!r}")
    a = a / norm
    trial = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    e1 = trial - a * (trial @ a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1), a


def helix(n: int = 16, length: float = 0.3, radius: float = 0.01, turn: float = np.pi / 3,
          root=(0.0, 0.0, 0.0), axis=(0.0, -1.0, 0.0)) -> np.ndarray:
    """Rest positions (m), shape ``(n, 3)``, of a helical strand starting at ``root``.

    Consecutive particles are ``turn`` rad apart around a helix of ``radius`` (m) about
    ``axis`` and one segment ``s = length / (n - 1)`` apart in space, so the helix rises
    by ``√(s² - (2 r sin(turn/2))²)`` per segment.
    """
    if _validate.positive_int("n", n) < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    seg = _validate.positive_finite("length", length) / (n - 1)
    radius, turn = _validate.nonnegative("radius", radius), _validate.finite_real("turn", turn)
    root = _validate.real_array("root", root, (3,))
    chord = 2.0 * radius * abs(np.sin(0.5 * turn))
    if not seg > chord:
        raise ValueError(f"radius {radius!r} and turn {turn!r} need a chord {chord:.3g} m "
                         f"shorter than the segment {seg:.3g} m")
    rise = np.sqrt(seg**2 - chord**2)
    e1, e2, a = _frame(axis)
    phase = float(turn) * np.arange(n)
    return (root
            + radius * ((np.cos(phase) - 1.0)[:, None] * e1 + np.sin(phase)[:, None] * e2)
            + (rise * np.arange(n))[:, None] * a)


def strand_network(x0, k_edge: float, k_bend: float = 0.0, k_twist: float = 0.0,
                   c_edge: float = 0.0, c_bend: float = 0.0) -> SpringNetwork:
    """Edge ``(i, i+1)``, bending ``(i, i+2)`` and torsion ``(i, i+3)`` springs on the rest
    shape ``x0`` (shape ``(n, 3)``), rest lengths measured on it; a family of zero
    stiffness is left out. Springs are labelled ``"edge"``, ``"bend"``, ``"twist"``."""
    x0 = _validate.positions("x0", x0, None, 3)
    n = x0.shape[0]
    k_edge = _validate.positive_finite("k_edge", k_edge)
    k_bend, k_twist = _validate.nonnegative("k_bend", k_bend), _validate.nonnegative("k_twist", k_twist)
    c_edge, c_bend = _validate.nonnegative("c_edge", c_edge), _validate.nonnegative("c_bend", c_bend)
    stiff = {"edge": (k_edge, c_edge), "bend": (k_bend, c_bend), "twist": (k_twist, 0.0)}
    ii, jj, kk, cc, kinds = [], [], [], [], []
    for offset, kind in FAMILIES:
        k, c = stiff[kind]
        if k > 0 and n > offset:
            i = np.arange(n - offset)
            ii.append(i)
            jj.append(i + offset)
            kk.append(np.full(i.size, float(k)))
            cc.append(np.full(i.size, float(c)))
            kinds.append(np.full(i.size, kind))
    if not ii:
        raise ValueError("k_edge must be > 0 (a strand needs its edges)")
    i, j = np.concatenate(ii), np.concatenate(jj)
    rest = np.linalg.norm(x0[i] - x0[j], axis=1)
    return SpringNetwork(i, j, rest, np.concatenate(kk), np.concatenate(cc), n,
                         np.concatenate(kinds))


def _rotate(p, axis_unit, angle):
    """Rodrigues: rotate vectors ``p`` (…, 3) by ``angle`` about the unit ``axis_unit``."""
    c, s = np.cos(angle), np.sin(angle)
    return p * c + np.cross(axis_unit, p) * s + np.outer(p @ axis_unit, axis_unit) * (1 - c)


def twist(x, angle: float, cut: int) -> np.ndarray:
    """A copy of ``x`` (shape ``(n, 3)``) with particles ``cut+1 ...`` turned by ``angle``
    (rad) about the line through ``x[cut]`` along the strand there, ``x[cut] - x[cut-1]``."""
    x = _validate.positions("x", x, None, 3)
    angle = _validate.finite_real("angle", angle)
    if isinstance(cut, bool) or not isinstance(cut, int | np.integer) or not 1 <= cut < x.shape[0] - 1:
        raise ValueError(f"cut must lie in [1, {x.shape[0] - 2}], got {cut!r}")
    u = x[cut] - x[cut - 1]
    u /= np.linalg.norm(u)
    x[cut + 1:] = x[cut] + _rotate(x[cut + 1:] - x[cut], u, angle)
    return x


def twist_angle(x, x_rest, cut: int, tip: int = -1) -> np.ndarray:
    """Signed angle (rad) by which particle ``tip`` is turned about the axis of
    :func:`twist` (through ``x_rest[cut]`` along ``x_rest[cut] - x_rest[cut-1]``), from
    its rest position. ``x`` may be one state ``(n, 3)`` or many ``(F, n, 3)``."""
    x = _validate.real_array("x", x)
    x_rest = _validate.positions("x_rest", x_rest, None, 3)
    if x.shape[-2:] != x_rest.shape:
        raise ValueError(f"x must have the shape of x_rest {x_rest.shape} (or (F, n, 3)), got {x.shape}")
    if isinstance(cut, bool) or not isinstance(cut, int | np.integer) or not 1 <= cut < x_rest.shape[0] - 1:
        raise ValueError(f"cut must lie in [1, {x_rest.shape[0] - 2}], got {cut!r}")
    center = x_rest[cut]
    u = center - x_rest[cut - 1]
    u /= np.linalg.norm(u)
    r0 = x_rest[tip] - center
    r0 -= u * (r0 @ u)
    r = x[..., tip, :] - center
    r = r - np.multiply.outer(r @ u, u)
    return np.arctan2(np.cross(r0, r) @ u, r @ r0)
