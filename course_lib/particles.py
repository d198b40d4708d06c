"""Particle systems in structure-of-arrays layout, and emitters in the style of Reeves (1983).

Holds :class:`ParticleSystem` (one preallocated array per attribute, the live particles
in the first ``n`` rows; a frame emits, updates, and deletes the expired by vectorized
compaction), :class:`Emitter` (count per frame = mean + variance × U(−1, 1), a mean that
may change with time, attributes drawn around a mean, point/disc/ring/sphere shapes), its
samplers, and the exact expected population (:func:`expected_population`, written in
:mod:`course_lib.population`). Core module: imports NumPy and the core's ``_validate`` and
``population`` only.

Reeves calls the half-width of a uniform spread its "variance": an attribute drawn as
``mean + variance × U(−1, 1)`` lies in ``[mean − variance, mean + variance]`` and has the
statistical variance ``variance² / 3``. We keep his word.

Ages are counted, not summed (Reeves counted lifetimes in frames): age = ``steps × dt``,
one rounding, where a sum ``age += dt`` drifts and can keep a particle whose lifetime is
``m dt`` alive a frame too long. An age *reaches* a lifetime within :data:`LIFETIME_RTOL`
(:func:`reached`); the expected population uses the same rule and agrees with a run.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from . import _validate
from ._validate import count, finite_real, mean_and_spread, nonnegative, real_array, vector
from .integrators import BlowUpError
from .population import LIFETIME_RTOL, expected_population, reached, steady_population, survival

__all__ = ["LIFETIME_RTOL", "SHAPES", "Emitter", "ParticleSystem", "around", "expected_population", "reached",
           "reeves_count", "sample_directions", "sample_shape", "steady_population", "survival"]

SHAPES = ("point", "disc", "ring", "sphere")
#: Hidden per-particle arrays: steps lived since the age was last set, and that age (s).
_CLOCK = {"steps": (), "age_at": ()}


class ParticleSystem:
    """Particles as a structure of arrays: ``x`` and ``v`` (``(n, dim)``), ``age`` and
    ``lifetime`` (``(n,)``, s), plus any extra attributes (temperature, colour, ...).

    Parameters
    ----------
    dim : int
        2 or 3 (dimension of positions and velocities).
    capacity : int
        Rows allocated at first; the arrays double when more particles arrive.
    attributes : mapping of str to tuple, optional
        Extra attributes and the shape of one particle's value, e.g.
        ``{"temperature": (), "colour": (3,)}``.

    Notes
    -----
    ``system["x"]`` is a *view* of the live rows. A frame is emit (:meth:`add`), update
    (:meth:`step`, :meth:`advect`) and delete (:meth:`expire`). ``age`` is derived (the age
    added with, plus ``steps × dt``; a new ``dt`` counts again from the current ages).
    """

    def __init__(self, dim: int = 3, capacity: int = 1024,
                 attributes: Mapping[str, tuple[int, ...]] | None = None):
        if isinstance(dim, bool) or dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        capacity = _validate.positive_int("capacity", capacity)
        self.dim, self.n, self._dt = dim, 0, None
        self.shapes = {"x": (dim,), "v": (dim,), "age": (), "lifetime": ()}
        for name, shape in (attributes or {}).items():
            if name in self.shapes or name in _CLOCK:
                raise ValueError(f"attribute {name!r} is built in; choose another name")
            self.shapes[name] = _value_shape(name, shape)
        self._data = {name: np.zeros((capacity, *s)) for name, s in {**self.shapes, **_CLOCK}.items()}

    @property
    def capacity(self) -> int:
        return self._data["x"].shape[0]

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, name: str) -> np.ndarray:
        """The live rows of attribute ``name`` (a view)."""
        if name not in self.shapes:
            raise KeyError(f"no attribute {name!r}; the attributes are {', '.join(self.shapes)}")
        return self._data[name][: self.n]

    def _reserve(self, extra: int) -> None:
        need = self.n + extra
        if need <= self.capacity:
            return
        size = max(need, 2 * self.capacity)
        for name, arr in self._data.items():
            grown = np.zeros((size, *arr.shape[1:]))
            grown[: self.n] = arr[: self.n]
            self._data[name] = grown

    def add(self, **values) -> int:
        """Append ``k`` particles, ``add(x=..., v=..., lifetime=..., ...)``: ``x`` is
        ``(k, dim)``, other attributes broadcast, missing ones (``age``) start at 0."""
        unknown = set(values) - set(self.shapes)
        if unknown:
            raise KeyError(f"unknown attributes {sorted(unknown)}; valid: {', '.join(self.shapes)}")
        if "x" not in values:
            raise ValueError("add needs positions x of shape (k, dim)")
        x = real_array("x", values["x"])
        if x.ndim != 2 or x.shape[1] != self.dim:
            raise ValueError(f"x must have shape (k, {self.dim}), got {x.shape}")
        k = x.shape[0]
        values = {name: _validate.broadcastable(name, value, (k, *self.shapes[name]))
                  for name, value in values.items()}
        if np.any(values.get("lifetime", 1.0) <= 0) or np.any(values.get("age", 0.0) < 0):
            raise ValueError("every lifetime must be > 0 and every age >= 0 (s)")
        self._reserve(k)
        rows = slice(self.n, self.n + k)
        values = {**values, "age_at": values.get("age", 0.0)}
        for name, arr in self._data.items():
            arr[rows] = np.broadcast_to(values.get(name, 0.0), (k, *arr.shape[1:]))
        self.n += k
        return k

    def _tick(self, dt: float) -> None:
        """Count one step of ``dt`` (s) and set every age from its count."""
        steps, age_at = self._data["steps"][: self.n], self._data["age_at"][: self.n]
        if dt != self._dt:                      # a new step size: count again from here
            age_at[...] = self["age"]
            steps[...] = 0.0
            self._dt = dt
        steps += 1.0
        self["age"][...] = age_at + steps * dt

    def step(self, dt: float, acceleration=None) -> None:
        """Symplectic Euler: ``v += dt a``, ``x += dt v``, one step older; ``acceleration``
        (m/s²) broadcasts to ``(n, dim)`` or is a callable ``acceleration(system)``."""
        dt = _validate.positive_finite("dt", dt)
        if acceleration is not None:
            a = self._acceleration(acceleration(self) if callable(acceleration) else acceleration)
        with np.errstate(over="ignore", invalid="ignore"):      # a blow-up is reported below
            if acceleration is not None:
                self["v"][...] += dt * a
            self["x"][...] += dt * self["v"]
        self._tick(dt)
        self._still_finite("step")

    def _acceleration(self, a) -> np.ndarray:
        """``a`` (m/s²) checked: numbers, finite, broadcasting to ``(n, dim)``."""
        a = _validate.real_array("acceleration", a) if np.size(a) else np.zeros((0, self.dim))
        try:
            return np.broadcast_to(a, (self.n, self.dim))
        except ValueError:
            raise ValueError(f"acceleration must have shape ({self.n}, {self.dim}) or broadcast to it "
                             f"(e.g. ({self.dim},)), got {a.shape}") from None

    def _still_finite(self, what: str) -> None:
        """Stop a run whose positions or velocities are no longer finite (a blow-up)."""
        if not (np.all(np.isfinite(self["x"])) and np.all(np.isfinite(self["v"]))):
            raise BlowUpError(f"the particles blew up in {what}: x or v overflowed to inf or NaN "
                              "after this step (too large a dt or force)")

    def advect(self, t: float, dt: float, field: Callable) -> None:
        """Carry the particles by a velocity field ``V(t, x)`` with one midpoint (RK2) step;
        their ``v`` is set to the field's velocity at the midpoint, and they age by ``dt``."""
        dt, t = _validate.positive_finite("dt", dt), finite_real("t", t)
        _validate.callable_arg("field", field, "(t, x)")
        x = self["x"]
        with np.errstate(over="ignore", invalid="ignore"):      # a blow-up is reported below
            mid = x + 0.5 * dt * np.asarray(field(t, x))
            vel = np.asarray(field(t + 0.5 * dt, mid))
            x += dt * vel
        self["v"][...] = vel
        self._tick(dt)
        self._still_finite("advect")

    def compact(self, keep) -> int:
        """Keep the live particles where ``keep`` is True, packed to the front in order
        (one gather per attribute). Returns the number removed."""
        keep = np.asarray(keep, dtype=bool)
        if keep.shape != (self.n,):
            raise ValueError(f"keep must have shape ({self.n},), got {keep.shape}")
        idx = np.flatnonzero(keep)
        for arr in self._data.values() if idx.size < self.n else ():
            arr[: idx.size] = arr[idx]
        removed, self.n = self.n - idx.size, idx.size
        return removed

    def expire(self) -> int:
        """Delete every particle whose age has reached its lifetime; returns how many."""
        return self.compact(~reached(self["age"], self["lifetime"]))


# --- random draws in the style of Reeves ---------------------------------------------------


def around(mean, variance, size, rng: np.random.Generator) -> np.ndarray:
    """``mean + variance × U(−1, 1)``, ``size`` draws (Reeves' attribute rule)."""
    mean, variance, size = finite_real("mean", mean), nonnegative("variance", variance), count("size", size)
    return mean + variance * rng.uniform(-1.0, 1.0, size)


def _value_shape(name: str, shape) -> tuple[int, ...]:
    """The shape of one particle's value of attribute ``name``: a tuple of ints >= 0."""
    if not isinstance(shape, tuple | list) or not all(
            isinstance(k, int | np.integer) and not isinstance(k, bool) and k >= 0 for k in shape):
        raise TypeError(f"attributes[{name!r}] must be the shape of one particle's value, a tuple of "
                        f"ints such as () or (3,), got {shape!r}")
    return tuple(int(k) for k in shape)


def reeves_count(mean: float, variance: float, rng: np.random.Generator) -> int:
    """Particles this frame: ``mean + variance × U(−1, 1)``, rounded at random,
    ``⌊y + u⌋`` with ``u ~ U(0, 1)``, which keeps the mean exactly ``mean`` (if
    ``mean >= variance``); never negative."""
    mean, variance = finite_real("mean", mean), nonnegative("variance", variance)
    rng = _validate.generator("rng", rng)
    y = mean + variance * rng.uniform(-1.0, 1.0)
    return max(0, int(np.floor(y + rng.random())))


def _plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x, y, z = (normal / np.linalg.norm(normal)).tolist()  # crosses by hand: np.cross's IEEE ops
    p, q, r = (1.0, 0.0, 0.0) if abs(x) < 0.9 else (0.0, 1.0, 0.0)
    a, b, d = ((c := np.array([y * r - z * q, z * p - x * r, x * q - y * p])) / np.linalg.norm(c)).tolist()
    return np.array([a, b, d]), np.array([y * d - z * b, z * a - x * d, x * b - y * a])


def sample_shape(shape: str, k: int, rng: np.random.Generator, center=(0.0, 0.0, 0.0),
                 radius: float = 1.0, normal=(0.0, 1.0, 0.0)) -> np.ndarray:
    """``k`` points (m) of a generation shape, shape ``(k, dim)`` with ``dim = len(center)``.

    ``"point"``: all at ``center``; ``"disc"``: uniform over the disc of ``radius``
    (``r = R √u``, so that equal areas get equal counts); ``"ring"``: uniform on its
    circle; ``"sphere"``: uniform on the sphere's surface (3D only). In 3D the disc and
    ring lie in the plane through ``center`` normal to ``normal``.
    """
    _validate.choice("shape", shape, SHAPES)
    k, radius, c = count("k", k), nonnegative("radius", radius), vector("center", center, dims=(2, 3))
    normal = vector("normal", normal, nonzero=True, dims=(3,))
    if shape == "point":
        return np.tile(c, (k, 1))
    if shape == "sphere" and c.size != 3:
        raise ValueError("shape 'sphere' needs a 3D center; use 'ring' in 2D")
    if shape == "sphere":
        u = rng.normal(size=(k, 3))
        return c + radius * u / np.linalg.norm(u, axis=1, keepdims=True)
    r = radius * (np.sqrt(rng.random(k)) if shape == "disc" else np.ones(k))
    phi = rng.uniform(0.0, 2.0 * np.pi, k)
    if c.size == 2:
        return c + np.stack((r * np.cos(phi), r * np.sin(phi)), axis=1)
    e1, e2 = _plane_basis(normal)
    return c + (r * np.cos(phi))[:, None] * e1 + (r * np.sin(phi))[:, None] * e2


def sample_directions(k: int, rng: np.random.Generator, direction=(0.0, 1.0, 0.0),
                      spread: float = 0.0) -> np.ndarray:
    """``k`` unit vectors (``(k, dim)``) within ``spread`` (rad) of ``direction``, uniform
    over the cone's cap in 3D (``cos θ`` uniform), uniform in angle in 2D."""
    k, spread = count("k", k), nonnegative("spread", spread)
    d = vector("direction", direction, nonzero=True, dims=(2, 3))
    d = d / np.linalg.norm(d)
    if d.size == 2:
        a = np.arctan2(d[1], d[0]) + rng.uniform(-spread, spread, k)
        return np.stack((np.cos(a), np.sin(a)), axis=1)
    cos_t = rng.uniform(np.cos(spread), 1.0, k)
    sin_t = np.sqrt(1.0 - cos_t**2)
    phi = rng.uniform(0.0, 2.0 * np.pi, k)
    e1, e2 = _plane_basis(d)
    return (cos_t[:, None] * d + (sin_t * np.cos(phi))[:, None] * e1
            + (sin_t * np.sin(phi))[:, None] * e2)


@dataclass
class Emitter:
    """A particle source after Reeves (1983); every spread is a Reeves "variance".

    ``count``: mean particles per frame, or a function of time ``t`` (s) for a mean that
    changes. New particles start on ``shape`` with speed ``speed ± speed_variance`` (m/s)
    within ``spread`` (rad) of ``direction`` (default +y), plus ``radial`` (m/s) outwards
    from ``center``; lifetimes ``lifetime ± lifetime_variance`` (s). ``attributes`` maps
    an extra attribute to ``(mean, variance)``.
    """

    count: float | Callable[[float], float] = 10.0
    count_variance: float = 0.0
    shape: str = "point"
    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.0
    normal: tuple = (0.0, 1.0, 0.0)
    speed: float = 1.0
    speed_variance: float = 0.0
    direction: tuple | None = None
    spread: float = 0.0
    radial: float = 0.0
    lifetime: float = 1.0
    lifetime_variance: float = 0.0
    attributes: Mapping[str, tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self):
        _validate.choice("shape", self.shape, SHAPES)
        for name in ("count", "count_variance", "radius", "speed_variance", "spread", "speed", "radial"):
            if not callable(getattr(self, name)):
                (finite_real if name in ("speed", "radial") else nonnegative)(name, getattr(self, name))
        vector("normal", self.normal, nonzero=True)
        mean_and_spread("lifetime", self.lifetime, self.lifetime_variance)
        dim = vector("center", self.center, dims=(2, 3)).size
        self.direction = (0.0, 1.0, 0.0)[:dim] if self.direction is None else self.direction
        if vector("direction", self.direction, nonzero=True).shape != (dim,):
            raise ValueError(f"direction must have {dim} components like center, got {self.direction}")

    def mean_count(self, t: float) -> float:
        """Mean particles per frame at time ``t`` (s)."""
        return float(self.count(t)) if callable(self.count) else float(self.count)

    def sample(self, k: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
        """Initial attributes of ``k`` new particles (a dict of arrays)."""
        x = sample_shape(self.shape, k, rng, self.center, self.radius, self.normal)
        speed = around(self.speed, self.speed_variance, k, rng)
        v = speed[:, None] * sample_directions(k, rng, self.direction, self.spread)
        if self.radial:
            out = x - np.asarray(self.center, dtype=float)
            norm = np.linalg.norm(out, axis=1, keepdims=True)
            v += self.radial * np.divide(out, norm, out=np.zeros_like(out), where=norm > 0)
        out = {"x": x, "v": v, "lifetime": around(self.lifetime, self.lifetime_variance, k, rng)}
        for name, (mean, var) in self.attributes.items():
            out[name] = around(mean, var, k, rng)
        return out

    def emit(self, system: ParticleSystem, t: float, rng: np.random.Generator) -> int:
        """Add this frame's particles to ``system``; returns how many."""
        k = reeves_count(self.mean_count(t), self.count_variance, rng)
        return system.add(**self.sample(k, rng)) if k else 0
