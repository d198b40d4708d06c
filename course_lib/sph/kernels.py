"""SPH smoothing kernels: Monaghan's cubic spline and Müller's poly6 and spiky.

Each kernel ``W(r, h, dim)`` is vectorised over the distance ``r`` (m, any shape) and
returns values in 1/m^dim, normalised so that its integral over the plane (``dim = 2``)
or space (``dim = 3``; ``dim = 1`` works too) is 1. Each paper measures ``h`` its own
way, and :data:`SUPPORT` gives the radius beyond which a kernel is zero, in units of h:

- ``"cubic"``: the cubic B-spline of Monaghan (1992), support ``2h``; with ``q = r/h``,
  ``σ (1 - 3/2 q² + 3/4 q³)`` for ``q < 1`` and ``σ/4 (2 - q)³`` for ``1 ≤ q < 2``, with
  ``σ = 2/(3h)``, ``10/(7π h²)``, ``1/(π h³)`` in 1, 2, 3 dimensions;
- ``"poly6"``: ``σ (h² - r²)³`` of Müller, Charypar & Gross (2003), support ``h``,
  ``σ = 35/(32 h⁷)``, ``4/(π h⁸)``, ``315/(64π h⁹)``;
- ``"spiky"``: ``σ (h - r)³`` of the same paper, support ``h``, ``σ = 2/h⁴``,
  ``10/(π h⁵)``, ``15/(π h⁶)``; its gradient does not vanish at ``r = 0``, so close
  particles still repel (Müller et al. use it for the pressure force).

:data:`GRADIENTS` holds ``dW/dr`` (1/m^(dim+1)); :func:`gradient` turns it into the
vector ``∇_i W(|x_i - x_j|)`` for pair offsets. Core module: NumPy only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: Support radius of each kernel, in units of its own h.
SUPPORT = {"cubic": 2.0, "poly6": 1.0, "spiky": 1.0}
DIMS = (1, 2, 3)

_SIGMA = {  # normalisation constant times h^(dim + power of h in the polynomial)
    "cubic": {1: 2.0 / 3.0, 2: 10.0 / (7.0 * np.pi), 3: 1.0 / np.pi},
    "poly6": {1: 35.0 / 32.0, 2: 4.0 / np.pi, 3: 315.0 / (64.0 * np.pi)},
    "spiky": {1: 2.0, 2: 10.0 / np.pi, 3: 15.0 / np.pi},
}


def _args(r, h, dim) -> tuple[np.ndarray, float, int]:
    if dim not in DIMS:
        raise ValueError(f"dim must be one of {DIMS}, got {dim!r}")
    h = float(h)
    if not (np.isfinite(h) and h > 0):
        raise ValueError(f"h must be a positive length (m), got {h!r}")
    return np.asarray(r, dtype=float), h, dim


def normalisation(name: str, h: float, dim: int) -> float:
    """The constant σ of kernel ``name`` (1/m^dim for the cubic spline; for poly6 and
    spiky σ carries the extra powers of h of their polynomials)."""
    power = {"cubic": dim, "poly6": dim + 6, "spiky": dim + 3}[check_name(name)]
    return _SIGMA[name][dim] / h**power


def cubic(r, h: float, dim: int = 2) -> np.ndarray:
    """Monaghan's (1992) cubic spline ``W(r, h)`` (1/m^dim), support ``2h``."""
    r, h, dim = _args(r, h, dim)
    q = np.abs(r) / h
    q2 = q * q
    inner = 1.0 - 1.5 * q2 + 0.75 * q2 * q
    rest = np.clip(2.0 - q, 0.0, None)
    outer = 0.25 * rest * rest * rest
    return normalisation("cubic", h, dim) * np.where(q < 1.0, inner, outer)


def poly6(r, h: float, dim: int = 2) -> np.ndarray:
    """Müller et al.'s (2003) poly6 kernel ``W(r, h)`` (1/m^dim), support ``h``."""
    r, h, dim = _args(r, h, dim)
    return normalisation("poly6", h, dim) * np.clip(h * h - r * r, 0.0, None) ** 3


def spiky(r, h: float, dim: int = 2) -> np.ndarray:
    """Müller et al.'s (2003) spiky kernel ``W(r, h)`` (1/m^dim), support ``h``."""
    r, h, dim = _args(r, h, dim)
    return normalisation("spiky", h, dim) * np.clip(h - np.abs(r), 0.0, None) ** 3


def cubic_dr(r, h: float, dim: int = 2) -> np.ndarray:
    """``dW/dr`` of the cubic spline (1/m^(dim+1)); 0 at ``r = 0`` and beyond ``2h``."""
    r, h, dim = _args(r, h, dim)
    q = np.abs(r) / h
    inner = -3.0 * q + 2.25 * q * q
    rest = np.clip(2.0 - q, 0.0, None)
    outer = -0.75 * rest * rest
    return normalisation("cubic", h, dim) / h * np.where(q < 1.0, inner, outer)


def poly6_dr(r, h: float, dim: int = 2) -> np.ndarray:
    """``dW/dr`` of poly6 (1/m^(dim+1)): ``-6σ r (h² - r²)²`` inside the support."""
    r, h, dim = _args(r, h, dim)
    inside = np.clip(h * h - r * r, 0.0, None)
    return -6.0 * normalisation("poly6", h, dim) * r * inside**2


def spiky_dr(r, h: float, dim: int = 2) -> np.ndarray:
    """``dW/dr`` of spiky (1/m^(dim+1)): ``-3σ (h - r)²`` inside the support."""
    r, h, dim = _args(r, h, dim)
    return -3.0 * normalisation("spiky", h, dim) * np.clip(h - np.abs(r), 0.0, None) ** 2


#: Kernel name -> ``W(r, h, dim)``, vectorised over r (m), values in 1/m^dim.
KERNELS: dict[str, Callable[..., np.ndarray]] = {"cubic": cubic, "poly6": poly6, "spiky": spiky}
#: Kernel name -> ``dW/dr (r, h, dim)`` in 1/m^(dim+1).
GRADIENTS: dict[str, Callable[..., np.ndarray]] = {
    "cubic": cubic_dr, "poly6": poly6_dr, "spiky": spiky_dr}


def check_name(name: str) -> str:
    """``name`` if it is a kernel of :data:`KERNELS`, else a ``ValueError`` listing them."""
    if name not in KERNELS:
        raise ValueError(f"unknown kernel {name!r}; valid choices are: {', '.join(KERNELS)}")
    return name


def gradient(name: str, d: np.ndarray, r: np.ndarray, h: float) -> np.ndarray:
    """``∇_i W(|x_i - x_j|)`` (1/m^(dim+1)) for offsets ``d = x_i - x_j`` of shape
    ``(P, dim)`` with lengths ``r`` (P,). Pairs at ``r = 0`` get a zero gradient."""
    d = np.asarray(d, dtype=float)
    r = np.asarray(r, dtype=float)
    dwdr = GRADIENTS[check_name(name)](r, h, d.shape[1])
    scale = np.divide(dwdr, r, out=np.zeros_like(r), where=r > 0)
    return d * scale[:, None]
