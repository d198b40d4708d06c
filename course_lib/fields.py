"""Velocity fields ``V(t, X)`` that move particles: ``dX/dt = V(t, X)``.

Every field follows the ``f(t, y)`` convention of :func:`course_lib.integrate`, with
positions ``X`` of shape ``(..., 2)`` (one particle ``(2,)``, or many ``(N, 2)``), so a
field can be integrated directly: ``integrate(vortex, X0, (0, 1), 0.1)``. Every field
returns a new array. Imports: numpy, ``_validate`` (core layer).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import _validate

Field = Callable[[float, np.ndarray], np.ndarray]


def _positions(X) -> np.ndarray:
    try:
        X = np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"X must be an array of numbers of shape (..., 2), got {type(X).__name__}") from None
    if X.ndim < 1 or X.shape[-1] != 2:
        raise ValueError(f"X must have shape (..., 2) (2D positions), got {X.shape}")
    return X


def radial(t: float, X) -> np.ndarray:
    """Radial expansion ``V = (x, y)`` (1/s × m): particles stream away from the origin."""
    return _positions(X).copy()


def vortex(t: float, X) -> np.ndarray:
    """Rotational vortex ``V = (-y, x)``: counter-clockwise circles, one radian per second."""
    X = _positions(X)
    return np.stack((-X[..., 1], X[..., 0]), axis=-1)


def constant_wind(velocity=(7.0, 2.0)) -> Field:
    """A uniform field ``V = velocity`` (m/s), the same at every point and time.

    Parameters
    ----------
    velocity : array_like, shape (2,)
        The wind (m/s); the syllabus example is ``(7, 2)``.
    """
    w = _validate.shape_of("velocity", _validate.state_array("velocity", velocity), (2,))

    def wind(t: float, X) -> np.ndarray:
        return np.broadcast_to(w, _positions(X).shape).copy()

    wind.__doc__ = f"Constant wind V = ({w[0]:g}, {w[1]:g}) m/s."
    return wind


def scaled(field: Field, factor: float) -> Field:
    """The field multiplied by a constant ``factor``."""
    _validate.callable_arg("field", field)
    factor = _validate.finite_real("factor", factor)

    def g(t: float, X) -> np.ndarray:
        return factor * field(t, X)

    return g


def compose(*fields: Field) -> Field:
    """The sum of several fields: velocities add, so ``compose(vortex, wind)`` drifts."""
    if not fields:
        raise ValueError("compose needs at least one field")
    for i, fld in enumerate(fields):
        _validate.callable_arg(f"fields[{i}]", fld)

    def total(t: float, X) -> np.ndarray:
        out = fields[0](t, X)
        for fld in fields[1:]:
            out = out + fld(t, X)
        return out

    return total


def grid(extent: float = 2.0, n: int = 15) -> tuple[np.ndarray, np.ndarray]:
    """A square ``n × n`` grid on ``[-extent, extent]²`` (m) for quiver and stream plots."""
    extent = _validate.positive_finite("extent", extent)
    n = _validate.positive_int("n", n)
    s = np.linspace(-extent, extent, n)
    return np.meshgrid(s, s)


def sample(field: Field, Xg: np.ndarray, Yg: np.ndarray, t: float = 0.0):
    """Evaluate ``field`` on a meshgrid; returns the components ``(U, V)``."""
    V = field(t, np.stack((Xg, Yg), axis=-1))
    return V[..., 0], V[..., 1]
