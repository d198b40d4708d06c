"""Position-based dynamics for springs: PBD (Müller et al. 2007) and XPBD (Macklin, Müller &
Chentanez 2016), with small steps (Macklin et al. 2019).

A step of length ``h`` first *predicts* every free particle without the springs,
``p = x + h v + h² g``, then corrects ``p`` spring by spring so that each spring's
constraint ``C = |p_i - p_j| - L`` is (nearly) met, and sets ``v = (p - x)/h``.

- **PBD** moves the ends by ``s`` times the full correction, ``Δλ = -s C/(w_i + w_j)``
  (``w = 1/m``). Its stiffness ``s`` has no unit, and more iterations make the same ``s``
  stiffer: the stretch a weight leaves shrinks like ``(1 - s)^n`` with ``n`` iterations.
- **XPBD** gives each spring a *compliance* ``α = 1/k`` (m/N) and keeps a multiplier
  ``λ`` per spring over the iterations of a step:

      Δλ = (-C - α̃ λ - γ u·(d - d₀)) / ((1 + γ)(w_i + w_j) + α̃),   α̃ = α/h²,  γ = α c/h,

  where ``d - d₀`` is how far the spring's vector moved in this step (the ``γ`` term is
  damping along the spring, ``c`` in N s/m). Its fixed point solves ``C + α̃ λ = 0``: the
  spring force ``k C`` of implicit Euler, whatever the number of iterations it took to
  get there. Unconverged, it is softer than ``k``.

The springs are corrected by independent sets (:class:`~.constraints.ColouredSprings`),
Gauss–Seidel over the sets, each set one whole-array operation. Small steps: one step of
length ``h`` is ``substeps`` steps of ``h/substeps``, each with ``iterations`` sweeps;
Macklin et al. (2019) found many small steps with one sweep each far more accurate than
one step with many sweeps for the same work.

Core module: imports NumPy and the package's :mod:`.base` and :mod:`.constraints`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate
from .base import SpringSolver
from .constraints import ColouredSprings


def delta_lambda(C, lam, w, compliance, h: float, gamma=0.0, rate=0.0) -> np.ndarray:
    """XPBD's multiplier update (kg m) for constraints ``C`` (m) with multipliers ``lam``.

    ``Δλ = (-C - α̃ λ - γ rate) / ((1 + γ) w + α̃)`` with ``α̃ = compliance/h²``; ``w`` is
    the sum of the inverse masses the constraint moves (1/kg), ``compliance`` ``1/k`` (m/N),
    ``h`` the (small) step (s), ``gamma`` and ``rate`` the damping term (``γ = α c/h`` and
    ``u·(d - d₀)`` for a spring). Arrays broadcast.
    """
    alpha = np.asarray(compliance, dtype=float) / (h * h)
    return (-np.asarray(C, dtype=float) - alpha * lam - gamma * np.asarray(rate, dtype=float)) / (
        (1.0 + np.asarray(gamma, dtype=float)) * w + alpha)


@dataclass
class SweepInfo:
    """What one step did: small steps taken and constraint sweeps in all."""

    substeps: int
    sweeps: int


class XPBD(SpringSolver):
    """Extended position-based dynamics for a spring network (compliance ``1/k``).

    Parameters
    ----------
    network, mass, pinned, gravity, external
        As for :class:`~course_lib.largestep.base.SpringSolver`.
    iterations : int
        Gauss–Seidel sweeps over all springs per small step, >= 1.
    substeps : int
        Small steps per :meth:`step`, >= 1.
    damping : bool
        Use each spring's damping ``c`` (the ``γ`` term); ``False`` ignores it.

    Attributes
    ----------
    info : SweepInfo or None
        The last step.
    """

    def __init__(self, network, mass, *, pinned=None, gravity=None, external=None,
                 iterations: int = 1, substeps: int = 1, damping: bool = True):
        super().__init__(network, mass, pinned=pinned, gravity=gravity, external=external)
        self.iterations = _validate.positive_int("iterations", iterations)
        self.substeps = _validate.positive_int("substeps", substeps)
        self.damping = bool(damping)
        self.inverse_mass = np.where(self._free, 1.0 / self.mass, 0.0)
        self.springs = ColouredSprings(network, self.inverse_mass)
        self.info: SweepInfo | None = None

    def _begin(self, h: float) -> None:
        """Per small step, before the sweeps: reset the multipliers, set ``α`` and ``γ``."""
        self._h = h
        for q in self.springs.sets:
            q["lambda"] = np.zeros(q["s"].size)
            q["compliance"] = 1.0 / q["k"]
            q["gamma"] = q["c"] / (q["k"] * h) if self.damping else np.zeros(q["s"].size)

    def _rule(self, q, length, u, d):
        """``Δλ`` of every spring of one set (:func:`delta_lambda`)."""
        damped = self.damping and q["c"].any()
        rate = np.einsum("sd,sd->s", u, d - q["d0"]) if damped else 0.0
        delta = delta_lambda(length - q["rest"], q["lambda"], q["w"], q["compliance"], self._h,
                             q["gamma"], rate)
        q["lambda"] += delta
        return delta

    def step(self, x, v, dt: float, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """One step of length ``dt`` (s) from ``(x, v)`` (both ``(N, d)``, finite), taken as
        :attr:`substeps` small steps; returns the new ``(x, v)``."""
        _validate.finite_real("t", t)
        x, v = self.check_state(x, v)
        h = _validate.positive_finite("dt", dt) / self.substeps
        free = self._free[:, None]
        inv_m = self.inverse_mass[:, None]
        x, v = x.copy(), np.where(free, v, 0.0)
        for k in range(self.substeps):
            push = self.external_force(t + k * h, x, v) * inv_m
            p = x + h * v + (h * h) * push
            self._begin(h)
            for q in self.springs.sets:
                ends = x[q["ends"]]
                q["d0"] = ends[:q["s"].size] - ends[q["s"].size:]
            for _ in range(self.iterations):
                self.springs.sweep(p, self._rule)
            v = (p - x) / h
            x = p
        self.info = SweepInfo(self.substeps, self.substeps * self.iterations)
        return x, v


class PBD(XPBD):
    """Plain position-based dynamics: each sweep moves every spring's ends by ``stiffness``
    (in ``(0, 1]``, no unit) times the correction that would restore its rest length.
    The network's ``k`` only selects which springs take part; ``c`` is not used."""

    def __init__(self, network, mass, *, stiffness: float = 1.0, **options):
        s = _validate.positive_finite("stiffness", stiffness)
        if s > 1.0:
            raise ValueError(f"stiffness must lie in (0, 1], got {s}")
        super().__init__(network, mass, damping=False, **options)
        self.stiffness = s

    def _begin(self, h: float) -> None:
        pass

    def _rule(self, q, length, u, d):
        return self.stiffness * (q["rest"] - length) / q["w"]
