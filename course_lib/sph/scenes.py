"""Scenes to validate an SPH liquid against experiment: a water column, the dam break.

- :func:`water_column`: water at rest in a box, whose pressure must be hydrostatic,
  ``p = ρ₀ g (H - y)``.
- :func:`dam_break_simulation` and :func:`dam_break`: the collapse of a column of width
  ``a`` and height ``2a`` (Martin & Moyce's n² = 2) against the back wall of a long
  tank. :func:`dam_break` returns Martin & Moyce's dimensionless surge-front position
  ``Z = z/a`` against ``T = t √(2g/a)``, with ``z`` the front's distance from the back wall.
  The column is released all at once, or by a gate (:func:`~course_lib.sph.boundary.gate`)
  lifted at a given speed.
- :data:`MARTIN_MOYCE`: their measured front (n² = 2, a = 2.25 in), and
  :func:`front_errors`, a run's front against it (with a release delay); :func:`ritter_front`:
  Ritter's (1892) shallow-water front, which advances at ``2√(g h₀)``: ``Z = 1 + 2T``
  for ``h₀ = 2a``.

Core module.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from . import boundary
from .params import Params
from .simulation import Simulation

#: Standard gravity (m/s²).
G = 9.81

#: Martin & Moyce (1952), the surge front of the n² = 2 column (a = 2.25 in), in their
#: variables: column 0 T = t √(2g/a), column 1 Z = z/a. Typed from their table as we
#: know it (the front was timed as it passed marks along the floor, which is why Z moves
#: in steps of 1/9 and then 2/9); an independent digitisation of their Figure 3 (PySPH's
#: dam-break example data) agrees within 2.5 %.
MARTIN_MOYCE = np.array([
    [0.41, 1.11], [0.84, 1.22], [1.19, 1.44], [1.43, 1.67], [1.63, 1.89], [1.83, 2.11],
    [1.98, 2.33], [2.20, 2.56], [2.32, 2.78], [2.51, 3.00], [2.65, 3.22], [2.83, 3.44],
    [2.98, 3.67], [3.11, 3.89], [3.33, 4.11]])


def ritter_front(T) -> np.ndarray:
    """Ritter's (1892) dam-break front for a column of height ``2a``, in Martin & Moyce's
    variables: it moves at ``2√(g · 2a)``, so ``Z = 1 + 2T``."""
    return 1.0 + 2.0 * _validate.real_array("T", T)


def front_errors(t, z, a: float, table=None, delay: float = 0.0, g: float = G) -> np.ndarray:
    """Relative errors ``Z_run / Z - 1`` of a simulated front at the times of ``table``.

    ``t`` (s, increasing) and ``z`` (m, from the back wall) are the run's times and fronts
    for a column of width ``a`` (m); ``table`` (K, 2) holds ``(T, Z)`` in Martin & Moyce's
    variables (default :data:`MARTIN_MOYCE`). The run is turned into ``T = t √(2g/a)``,
    ``Z = z/a``, delayed by ``delay`` (its front at ``T`` is the one it had at ``T - delay``)
    and interpolated linearly at the table's times.
    """
    a, g = _validate.positive_finite("a", a), _validate.positive_finite("g", g)
    delay = _validate.nonnegative("delay", delay)
    table = MARTIN_MOYCE if table is None else _validate.real_array("table", table, (None, 2))
    t, z = _validate.real_array("t", t, (None,)), _validate.real_array("z", z, (None,))
    if len(t) != len(z) or len(t) < 2:
        raise ValueError(f"t and z must hold the same number (>= 2) of samples, got {len(t)} "
                         f"and {len(z)}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must increase")
    T_run = t * np.sqrt(2.0 * g / a)
    Z_run = z / a
    return np.interp(table[:, 0] - delay, T_run, Z_run) / table[:, 1] - 1.0


def lattice(width: float, height: float, spacing: float, origin=(0.0, 0.0)) -> np.ndarray:
    """Particles at the centres of the ``spacing``-sided cells filling a ``width × height``
    rectangle whose lower-left corner is ``origin`` (m); shape (N, 2), rows by x."""
    nx, ny = round(float(width) / spacing), round(float(height) / spacing)
    if nx < 1 or ny < 1:
        raise ValueError(f"a {width} × {height} m block holds no particle of spacing {spacing} m")
    gx, gy = np.meshgrid((np.arange(nx) + 0.5) * spacing, (np.arange(ny) + 0.5) * spacing,
                         indexing="ij")
    return np.stack([gx.ravel(), gy.ravel()], axis=1) + np.asarray(origin, dtype=float)


def liquid(spacing: float, depth: float, **changes) -> Params:
    """Water-like parameters for a liquid ``depth`` m deep on a lattice of side ``spacing``.

    The fastest flow expected is a fall from the full depth, ``U = √(2 g depth)``; the
    speed of sound (WCSPH) is ``10 U`` (Mach 0.1), and a particle ten times faster than
    ``U`` means the run has blown up. The artificial viscosity
    ``ν = 0.05 √(g depth) Δx`` vanishes as the lattice is refined; the walls are no-slip
    with the same ν. Gravity waves travel at ``√(g depth)``, so no step exceeds
    ``λ Δx / √(g depth)`` (λ the ``cfl``, 0.4 by default). ``changes`` override any of these.
    """
    wave = np.sqrt(G * depth)
    nu = 0.05 * wave * spacing
    fall = np.sqrt(2.0 * G * depth)
    base = {"spacing": spacing, "sound_speed": 10.0 * fall, "speed_limit": 10.0 * fall, "viscosity": nu,
            "wall_viscosity": nu,
            "max_dt": changes.get("cfl", 0.4) * spacing / wave}
    return Params(**{**base, **changes})


def water_column(width: float = 0.5, depth: float = 0.5, spacing: float = 0.025,
                 method: str = "iisph", **changes) -> Simulation:
    """Water ``depth`` m deep at rest in a box ``width`` m wide, on a lattice."""
    width, depth = _validate.positive_finite("width", width), _validate.positive_finite("depth", depth)
    spacing = _validate.positive_finite("spacing", spacing)
    params = liquid(spacing, depth, **changes)
    wall = boundary.box(width, 1.5 * depth, spacing, params.rho0, params.h, params.kernel)
    return Simulation(lattice(width, depth, spacing), params, wall, method=method)


def column_spacing(n_particles: int, a: float = 1.0) -> tuple[float, int]:
    """The spacing (m) that fills an ``a × 2a`` column with about ``n_particles``
    particles, and the particle count it gives (``2 k²``, ``k = a/Δx``)."""
    if not (isinstance(n_particles, int | np.integer) and n_particles >= 8):
        raise ValueError(f"n_particles must be an int >= 8, got {n_particles!r}")
    k = max(round(float(np.sqrt(n_particles / 2.0))), 2)
    return a / k, 2 * k * k


def dam_break_simulation(n_particles: int = 1250, method: str = "iisph", a: float = 1.0,
                         tank: float = 6.0, gate_speed: float | None = None, **changes) -> Simulation:
    """Martin & Moyce's n² = 2 column: ``a × 2a`` (m) of water at rest against the back
    wall (x = 0) of a tank ``tank · a`` long, released at t = 0: all at once
    (``gate_speed=None``), or by a gate at ``x = a`` lifted at ``gate_speed`` (m/s)."""
    a, tank = _validate.positive_finite("a", a), _validate.positive_finite("tank", tank)
    spacing, _ = column_spacing(n_particles, a)
    params = liquid(spacing, 2.0 * a, **changes)
    wall = boundary.box(tank * a, 2.5 * a, spacing, params.rho0, params.h, params.kernel)
    barrier = None
    if gate_speed is not None:
        barrier = boundary.gate(a, 2.5 * a, spacing, params.rho0, params.h, params.kernel,
                                speed=gate_speed)
    return Simulation(lattice(a, 2.0 * a, spacing), params, wall, method=method, gate=barrier)


def front(x: np.ndarray, spacing: float) -> float:
    """The surge front's distance from the back wall (m): the rightmost particle's
    centre plus half a spacing (each particle stands for a cell of side Δx)."""
    return float(np.max(x[:, 0])) + 0.5 * spacing


def dam_break(n_particles: int = 1250, t_end: float | None = None, method: str = "iisph",
              a: float = 1.0, **changes) -> tuple[np.ndarray, np.ndarray]:
    """Run Martin & Moyce's dam break and return ``(T, Z)`` after every step (and at 0).

    ``t_end`` (s) defaults to ``T = 3.5``, i.e. ``3.5 √(a/(2g))``; ``T = t √(2g/a)``,
    ``Z = z/a``. ``changes`` go to :func:`dam_break_simulation`: ``gate_speed`` (m/s)
    releases the column by a gate lifted at that speed instead of all at once, and any
    :class:`~course_lib.sph.params.Params` field (e.g. ``wall_velocity="no-slip"``) changes
    the liquid. Raises ``RuntimeError`` if the run turns unstable.
    """
    sim = dam_break_simulation(n_particles, method, a, **changes)
    t_end = 3.5 * np.sqrt(a / (2 * G)) if t_end is None else float(t_end)
    fronts = [front(sim.x, sim.params.spacing)]
    sim.run(t_end, on_step=lambda s: fronts.append(front(s.x, s.params.spacing)))
    if not sim.stable:
        raise RuntimeError(sim.message)
    t = np.concatenate([[0.0], sim.history["t"]])
    return t * np.sqrt(2 * G / a), np.array(fronts) / a
