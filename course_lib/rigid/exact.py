"""The exact torque-free spin of a rigid body: Euler's equations by Jacobi elliptic functions.

Order the principal moments ``I1 < I2 < I3``; ``E`` is the kinetic energy and ``M = |L|``.
The body's angular velocity stays on the intersection of the energy ellipsoid and the
momentum sphere. When ``M² > 2 E I2`` it circles the axis of ``I3``:

    Ω1 = A1 cn(τ, m),  Ω2 = A2 sn(τ, m),  Ω3 = s A3 dn(τ, m),   τ = ±λ t + τ0,

    A1² = (2E I3 − M²) / (I1 (I3 − I1)),   A2² = (2E I3 − M²) / (I2 (I3 − I2)),
    A3² = (M² − 2E I1) / (I3 (I3 − I1)),   λ² = (I3 − I2)(M² − 2E I1) / (I1 I2 I3),
    m = (I2 − I1)(2E I3 − M²) / ((I3 − I2)(M² − 2E I1)),

with ``s = sign Ω3(0)``, ``τ0`` from ``Ω(0)`` and the sign of ``λ t`` from the direction
Euler's equations run round the orbit; when ``M² < 2 E I2`` it circles the axis of ``I1`` (swap the roles
of 1 and 3). ``Ω`` is periodic with period ``T = 4 K(m) / λ``, ``K`` the complete elliptic
integral of the first kind (Landau & Lifshitz, *Mechanics*, §37). A spin started close to
the intermediate axis flips over (the Dzhanibekov effect) twice per period: ``Ω2``
changes sign every ``T/2``. Uses :func:`scipy.special.ellipj`, :func:`~scipy.special.ellipk`
and :func:`~scipy.special.ellipkinc`. Imports NumPy, SciPy and the core.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipj, ellipk, ellipkinc

from .. import _validate
from .inertia import check_moments


def _setup(inertia, omega0):
    """Everything the formulas need, in the ordered frame ``I1 < I2 < I3`` (with the
    permutation back), the polar axis circled last."""
    moments = check_moments("inertia", inertia)
    omega0 = _validate.shape_of("omega0", _validate.state_array("omega0", omega0), (3,))
    if moments.shape != (3,) or np.iscomplexobj(omega0):
        raise ValueError("inertia and omega0 must be real and of shape (3,)")
    order = np.argsort(moments)
    Ib, w = moments[order], omega0[order]
    if not (Ib[0] < Ib[1] < Ib[2]):
        raise ValueError(f"the exact solution here needs three distinct moments, got {moments.tolist()}")
    E2 = float(np.sum(Ib * w * w))               # 2 E
    M2 = float(np.sum((Ib * w) ** 2))            # |L|²
    if M2 < E2 * Ib[1]:                          # circling axis 1: mirror the ordering
        order, Ib, w = order[::-1], Ib[::-1], w[::-1]
    return order, Ib, w, E2, M2


def parameters(inertia, omega0) -> dict:
    """``m`` (the elliptic parameter, in [0, 1)), ``lam`` (λ, 1/s), the amplitudes ``A`` in
    the ordered frame, the ``period`` ``4K(m)/λ`` (s) of ``Ω``, and ``order`` (the ordered
    axes: ``order[2]`` is the axis the spin circles, ``order[1]`` the intermediate one)."""
    order, Ib, _w, E2, M2 = _setup(inertia, omega0)
    I1, I2, I3 = Ib
    a13 = E2 * I3 - M2
    a31 = M2 - E2 * I1
    lam2 = (I3 - I2) * a31 / (I1 * I2 * I3)
    m = (I2 - I1) * a13 / ((I3 - I2) * a31)
    if not 0.0 <= m < 1.0:
        raise ValueError("the spin lies on the separatrix (M² = 2 E I2): its period is infinite")
    amps = np.sqrt(np.maximum([a13 / (I1 * (I3 - I1)), a13 / (I2 * (I3 - I2)),
                               a31 / (I3 * (I3 - I1))], 0.0))
    lam = float(np.sqrt(lam2))
    return {"m": float(m), "lam": lam, "A": amps, "period": 4.0 * float(ellipk(m)) / lam,
            "order": order}


def period(inertia, omega0) -> float:
    """Period (s) of the body angular velocity of a torque-free spin (``4K(m)/λ``); a spin
    near the intermediate axis flips every half period."""
    return parameters(inertia, omega0)["period"]


def omega(inertia, omega0, t) -> np.ndarray:
    """The exact body angular velocity (rad/s), shape ``(len(t), 3)``, at times ``t`` (s)
    of a torque-free spin with principal moments ``inertia`` from ``omega0`` at ``t = 0``."""
    p = parameters(inertia, omega0)
    _, _Ib, w, _, _ = _setup(inertia, omega0)
    A1, A2, A3 = p["A"]
    s3 = 1.0 if w[2] >= 0 else -1.0
    cn0 = w[0] / A1 if A1 > 0 else 1.0
    sn0 = w[1] / A2 if A2 > 0 else 0.0
    tau0 = float(ellipkinc(np.arctan2(sn0, cn0), p["m"]))
    # The formulas trace the whole orbit; which way round depends on the handedness of
    # the ordered axes and on which pole is circled: take the way Euler's equations go.
    sn, cn, dn, _ = ellipj(tau0, p["m"])
    along = np.array([-A1 * sn * dn, A2 * cn * dn, -s3 * A3 * p["m"] * sn * cn])
    moments, w0 = np.asarray(inertia, dtype=float), np.asarray(omega0, dtype=float)
    rhs = (np.cross(moments * w0, w0) / moments)[p["order"]]
    lam = p["lam"] if float(along @ rhs) >= 0 else -p["lam"]
    sn, cn, dn, _ = ellipj(lam * np.asarray(t, dtype=float) + tau0, p["m"])
    ordered = np.stack((A1 * cn, A2 * sn, s3 * A3 * dn), axis=-1)
    out = np.empty_like(ordered)
    out[..., p["order"]] = ordered
    return out


def crossings(t, values) -> np.ndarray:
    """Times (s) at which ``values`` (one per time in ``t``) changes sign, each located by
    linear interpolation between the two samples around it."""
    t, values = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    k = np.flatnonzero(np.signbit(values[:-1]) != np.signbit(values[1:]))
    return t[k] - values[k] * (t[k + 1] - t[k]) / (values[k + 1] - values[k])


def measured_period(t, omega, axis: int) -> float:
    """The period (s) of a run's body angular velocity ``omega`` (steps, 3), measured from
    the sign changes of its component ``axis`` (the intermediate axis for a flip): two
    per period, so ``T = 2 (t_last − t_first) / (crossings − 1)``. Raises ``ValueError``
    with fewer than two crossings."""
    times = crossings(t, np.asarray(omega)[:, axis])
    if len(times) < 2:
        raise ValueError(f"the run changes the sign of omega[:, {axis}] {len(times)} times; "
                         "run it longer to measure a period")
    return 2.0 * float(times[-1] - times[0]) / (len(times) - 1)
