"""Ready-made spring networks: chains, hair strands, cloth grids, a mass on a spring.

Each builder checks its arguments and raises a ``ValueError`` (or ``TypeError``) that
names the offending argument, then returns rest positions and a
:class:`~course_lib.springs.network.SpringNetwork` whose rest lengths are measured on those
positions (so the network starts at rest, force-free).

Core module: imports NumPy, :mod:`course_lib._validate`, the network and (lazily, in
:func:`anchored_spring`) :mod:`course_lib.systems`.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np

from .. import _validate
from .network import SpringNetwork


def _count(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an integer >= {minimum}, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _nonnegative(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, Real | np.floating | np.integer):
        raise TypeError(f"{name} must be a real number >= 0, got {type(value).__name__}")
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return value


def _vector(name: str, value, nonzero: bool = False) -> np.ndarray:
    arr = _validate.shape_of(name, _validate.state_array(name, value), (3,))
    if nonzero and not np.any(arr):
        raise ValueError(f"{name} must be a nonzero vector, got {arr.tolist()}")
    return arr


def chain_pairs(n: int, offset: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs ``(i, i + offset)`` along a chain of ``n`` particles.

    ``offset=1`` gives the edges, 2 the bending springs, 3 the torsion springs of
    Selle, Lentine & Fedkiw (2008).
    """
    n = _count("n", n, 2)
    offset = _count("offset", offset, 1)
    i = np.arange(max(n - offset, 0))
    return i, i + offset


def _network(x0: np.ndarray, families, n: int) -> SpringNetwork:
    """One network from ``(i, j, k, c, kind)`` families, rest lengths measured on ``x0``."""
    families = [f for f in families if f[2] > 0 and f[0].size]
    i = np.concatenate([f[0] for f in families])
    j = np.concatenate([f[1] for f in families])
    k = np.concatenate([np.full(f[0].size, f[2]) for f in families])
    c = np.concatenate([np.full(f[0].size, f[3]) for f in families])
    kind = np.concatenate([np.full(f[0].size, f[4]) for f in families])
    rest = np.linalg.norm(x0[i] - x0[j], axis=1)
    return SpringNetwork(i, j, rest, k, c, n, kind)


def hair_chain(
    n: int = 12,
    length: float = 0.3,
    k_edge: float = 500.0,
    k_bend: float = 0.0,
    k_twist: float = 0.0,
    c_edge: float = 0.0,
    c_bend: float = 0.0,
    root=(0.0, 0.0, 0.0),
    direction=(1.0, 0.0, 0.0),
    curl: float = 0.0,
    zigzag: float = 0.0,
) -> tuple[np.ndarray, SpringNetwork]:
    """A strand of ``n`` particles joined by edge springs (i, i+1), bending springs (i, i+2)
    and, optionally, torsion springs (i, i+3).

    Parameters
    ----------
    n : int
        Number of particles (>= 2); particle 0 is the root.
    length : float
        Total rest length of the strand (m), > 0.
    k_edge : float
        Stiffness of the edge springs (N/m), > 0: without edges there is no strand.
    k_bend, k_twist : float
        Stiffness of the bending and torsion families (N/m), >= 0; zero omits the family.
    c_edge, c_bend : float
        Damping along edge and bending springs (N s/m), >= 0.
    root : array_like, shape (3,)
        Position of particle 0 (m).
    direction : array_like, shape (3,)
        Nonzero direction in which the strand is laid out straight.
    curl : float
        Turn angle (rad) between successive segments in the plane of ``direction`` and
        ``y``: 0 lays the strand straight; a small curl gives the bending springs a
        curved rest shape (rest lengths are measured on the initial shape).
    zigzag : float
        Offset of every odd particle along the side direction, in units of the segment
        length: a non-zero zigzag makes the rest shape non-collinear, so the bending
        springs resist bending to first order (on a straight strand they do not).

    Returns
    -------
    x0 : ndarray, shape (n, 3)
        Rest positions (m).
    network : SpringNetwork
        The springs, labelled ``"edge"``, ``"bend"`` and ``"twist"``.
    """
    n = _count("n", n, 2)
    length = _validate.positive_finite("length", length)
    k_edge = _validate.positive_finite("k_edge", k_edge)
    k_bend, k_twist = _nonnegative("k_bend", k_bend), _nonnegative("k_twist", k_twist)
    c_edge, c_bend = _nonnegative("c_edge", c_edge), _nonnegative("c_bend", c_bend)
    root = _vector("root", root)
    d = _vector("direction", direction, nonzero=True)
    curl, zigzag = _validate.finite_real("curl", curl), _validate.finite_real("zigzag", zigzag)
    seg = length / (n - 1)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    side = up - d * (up @ d)
    side /= np.linalg.norm(side)
    angles = curl * np.arange(n - 1)
    steps = seg * (np.cos(angles)[:, None] * d + np.sin(angles)[:, None] * side)
    x0 = root + np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])
    x0[1::2] += zigzag * seg * side
    families = [(*chain_pairs(n, off), k, c, name) for off, k, c, name in
                [(1, k_edge, c_edge, "edge"), (2, k_bend, c_bend, "bend"), (3, k_twist, 0.0, "twist")]
                if n > off]
    return x0, _network(x0, families, n)


def cloth_grid(
    nx: int = 10,
    ny: int = 10,
    spacing: float = 0.1,
    k_struct: float = 1000.0,
    k_shear: float = 100.0,
    k_bend: float = 10.0,
    c: float = 0.0,
) -> tuple[np.ndarray, SpringNetwork]:
    """A rectangular cloth of ``nx × ny`` particles in the x-y plane (z = 0).

    Particle ``(r, q)`` (row ``r`` along y, column ``q`` along x) has index ``r * nx + q``.
    Structural springs join grid neighbours, shear springs the diagonals of each cell, bend
    springs particles two apart along rows and columns.

    Parameters
    ----------
    nx, ny : int
        Particles along x and y, each >= 2.
    spacing : float
        Distance between grid neighbours (m), > 0.
    k_struct : float
        Structural stiffness (N/m), > 0.
    k_shear, k_bend : float
        Shear and bending stiffness (N/m), >= 0; zero omits the family.
    c : float
        Damping along every spring (N s/m), >= 0.

    Returns
    -------
    x0 : ndarray, shape (nx * ny, 3)
        Rest positions (m).
    network : SpringNetwork
        Springs labelled ``"struct"``, ``"shear"``, ``"bend"``.
    """
    nx, ny = _count("nx", nx, 2), _count("ny", ny, 2)
    spacing = _validate.positive_finite("spacing", spacing)
    k_struct = _validate.positive_finite("k_struct", k_struct)
    k_shear, k_bend = _nonnegative("k_shear", k_shear), _nonnegative("k_bend", k_bend)
    c = _nonnegative("c", c)
    idx = np.arange(nx * ny).reshape(ny, nx)
    gx, gy = np.meshgrid(np.arange(nx) * spacing, np.arange(ny) * spacing)
    x0 = np.stack((gx.ravel(), gy.ravel(), np.zeros(nx * ny)), axis=1)
    families = [
        (np.r_[idx[:, :-1].ravel(), idx[:-1, :].ravel()],
         np.r_[idx[:, 1:].ravel(), idx[1:, :].ravel()], k_struct, c, "struct"),
        (np.r_[idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()],
         np.r_[idx[1:, 1:].ravel(), idx[1:, :-1].ravel()], k_shear, c, "shear"),
        (np.r_[idx[:, :-2].ravel(), idx[:-2, :].ravel()],
         np.r_[idx[:, 2:].ravel(), idx[2:, :].ravel()], k_bend, c, "bend"),
    ]
    return x0, _network(x0, families, nx * ny)


def anchored_spring(k: float, m: float = 1.0, c: float = 0.0, rest: float = 1.0,
                    stretch: float = 0.1):
    """A mass ``m`` on a damped spring tied to a fixed anchor, in 3D.

    The anchor is particle 0 (pinned, at the origin); the mass is particle 1, released at
    rest at ``(rest + stretch, 0, 0)``. Along the spring this is the 1D oscillator
    ``m x'' = -k x - c x'`` for the stretch ``x``.

    Parameters
    ----------
    k : float
        Stiffness (N/m), > 0.
    m : float
        Mass (kg), > 0.
    c : float
        Damping along the spring (N s/m), >= 0.
    rest : float
        Rest length (m), > 0.
    stretch : float
        Initial stretch (m), with ``rest + stretch > 0``.

    Returns
    -------
    system : NewtonianSystem
    y0 : ndarray, shape (2, 2, 3)
    network : SpringNetwork
    """
    from ..systems import NewtonianSystem, stack_state

    k, m = _validate.positive_finite("k", k), _validate.positive_finite("m", m)
    c, rest = _nonnegative("c", c), _validate.positive_finite("rest", rest)
    stretch = _validate.finite_real("stretch", stretch)
    if rest + stretch <= 0:
        raise ValueError(f"stretch must be > -rest = {-rest:g} (the mass would sit on the "
                         f"anchor or beyond it), got {stretch:g}")
    net = SpringNetwork([1], [0], [rest], [k], [c], 2, np.array(["spring"]))
    x0 = np.array([[0.0, 0.0, 0.0], [rest + stretch, 0.0, 0.0]])
    return NewtonianSystem(net.force, m, pinned=[0]), stack_state(x0, np.zeros_like(x0)), net
