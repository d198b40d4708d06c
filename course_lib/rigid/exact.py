"""The exact torque-free spin of a rigid body: Euler's equations by Jacobi elliptic functions.

Order the principal moments ``I1 < I2 < I3``; ``E`` is the kinetic energy and ``M = |L|``.
The body angular velocity stays on the intersection of the energy ellipsoid and the
momentum sphere, which circles the axis of ``I1`` or that of ``I3``. The sign of
``D = M² − 2 E I2 = Σ I_i Ω_i² (I_i − I2)`` says which.

``D < 0``: it circles the smallest axis (a spin started near the intermediate axis with a
nudge about the smallest one), and

    Ω1 = s A1 dn(τ, m),  Ω2 = A2 sn(τ, m),  Ω3 = A3 cn(τ, m),   τ = s λ t + τ0,
    A1² = (2E I3 − M²) / (I1 (I3 − I1)),  A2² = (M² − 2E I1) / (I2 (I2 − I1)),
    A3² = (M² − 2E I1) / (I3 (I3 − I1)),  λ² = (I2 − I1)(2E I3 − M²) / (I1 I2 I3),
    m = (I3 − I2)(M² − 2E I1) / ((I2 − I1)(2E I3 − M²)).

``D > 0``: it circles the largest axis; swap the roles of 1 and 3 (``Ω1 = A1 cn``,
``Ω3 = s A3 dn``, and the same swap in ``A``, ``λ`` and ``m``). Here ``s = ±1`` is the sign
of the ``dn`` component, which never changes, and ``τ0`` puts ``(sn τ0, cn τ0)`` at the
start. If the ordered axes are a left-handed triple of the body's, Euler's equations
change sign and so does ``λ t``. ``Ω`` has the period ``T = 4 K(m) / λ``, ``K`` the complete
elliptic integral of the first kind (Landau & Lifshitz, *Mechanics*, §37); near the
intermediate axis ``Ω2`` changes sign every ``T/2``: the body flips over (the Dzhanibekov
effect). Uses :func:`scipy.special.ellipj`, :func:`~scipy.special.ellipk` and
:func:`~scipy.special.ellipkinc`. Imports NumPy, SciPy and the core.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipj, ellipk, ellipkinc

from .. import _validate
from .inertia import check_moments

#: What each ordered axis (1, 2, 3) follows, for D < 0 and for D > 0.
FUNCTIONS = {"smallest": ("dn", "sn", "cn"), "largest": ("cn", "sn", "dn")}


def _setup(inertia, omega0):
    moments = check_moments("inertia", inertia)
    omega0 = _validate.shape_of("omega0", _validate.state_array("omega0", omega0), (3,))
    if moments.shape != (3,) or np.iscomplexobj(omega0):
        raise ValueError("inertia and omega0 must be real and of shape (3,)")
    order = np.argsort(moments)
    Ib, w = moments[order], omega0[order]
    if not (Ib[0] < Ib[1] < Ib[2]):
        raise ValueError(f"the exact solution here needs three distinct moments, got {moments.tolist()}")
    return order, Ib, w


def parameters(inertia, omega0) -> dict:
    """Everything the exact solution needs, for principal moments ``inertia`` (3,) (kg m²)
    and a start ``omega0`` (3,) (rad/s) in the body frame.

    Returns a dict with ``D`` (``M² − 2E I2``, kg² m⁴/s², computed without cancellation),
    ``circles`` (``"smallest"`` if ``D < 0``, else ``"largest"``), ``m`` (in [0, 1)),
    ``lam`` (λ > 0, 1/s), ``period`` (``4K(m)/λ``, s), and per body axis the signed
    ``amplitudes`` (3,) and ``functions`` (``"sn"``, ``"cn"`` or ``"dn"``), with ``rate``
    (``±λ``) and ``tau0``, such that ``Ω_i(t) = amplitudes[i] · functions[i](rate t + tau0, m)``.
    ``order`` lists the body axes from the smallest moment to the largest (``order[1]``
    is the intermediate axis). Raises ``ValueError`` on the separatrix (``D = 0``).
    """
    order, Ib, w = _setup(inertia, omega0)
    I1, I2, I3 = Ib
    energy = Ib * w * w                                       # I_i Ω_i², summing to 2E
    D = float(np.sum(energy * (Ib - I2)))                     # M² − 2E I2
    above1 = float(np.sum(energy * (Ib - I1)))                # M² − 2E I1 ≥ 0
    below3 = float(np.sum(energy * (I3 - Ib)))                # 2E I3 − M² ≥ 0
    if D == 0.0:
        raise ValueError("the spin lies on the separatrix (M² = 2 E I2): its period is infinite")
    if D < 0:
        circles, dn_axis, cn_axis = "smallest", 0, 2
        lam2 = (I2 - I1) * below3 / (I1 * I2 * I3)
        m = (I3 - I2) * above1 / ((I2 - I1) * below3)
        amps = np.sqrt([below3 / (I1 * (I3 - I1)), above1 / (I2 * (I2 - I1)), above1 / (I3 * (I3 - I1))])
    else:
        circles, dn_axis, cn_axis = "largest", 2, 0
        lam2 = (I3 - I2) * above1 / (I1 * I2 * I3)
        m = (I2 - I1) * below3 / ((I3 - I2) * above1)
        amps = np.sqrt([below3 / (I1 * (I3 - I1)), below3 / (I2 * (I3 - I2)), above1 / (I3 * (I3 - I1))])
    m = min(max(float(m), 0.0), np.nextafter(1.0, 0.0))
    lam = float(np.sqrt(lam2))
    s = 1.0 if w[dn_axis] >= 0 else -1.0
    # Euler's equations keep their form under a cyclic relabelling of the axes only.
    handed = float(np.linalg.det(np.eye(3)[order]))
    # a spin about the circled axis itself has no sn or cn part: start at τ0 = 0
    sn0 = w[1] / amps[1] if amps[1] > 0 else 0.0
    cn0 = w[cn_axis] / amps[cn_axis] if amps[cn_axis] > 0 else 1.0
    tau0 = float(ellipkinc(np.arctan2(sn0, cn0), m))
    signed = amps.copy()
    signed[dn_axis] *= s
    amplitudes, functions = np.empty(3), [""] * 3
    for k, axis in enumerate(order):
        amplitudes[axis], functions[axis] = signed[k], FUNCTIONS[circles][k]
    return {"D": D, "circles": circles, "m": m, "lam": lam, "period": 4.0 * float(ellipk(m)) / lam,
            "amplitudes": amplitudes, "functions": tuple(functions), "rate": s * handed * lam,
            "tau0": tau0, "order": order}


def period(inertia, omega0) -> float:
    """Period (s) of the body angular velocity of a torque-free spin (``4K(m)/λ``); a spin
    near the intermediate axis flips every half period."""
    return parameters(inertia, omega0)["period"]


def omega(inertia, omega0, t) -> np.ndarray:
    """The exact body angular velocity (rad/s), shape ``(len(t), 3)``, at times ``t`` (s)
    of a torque-free spin with principal moments ``inertia`` from ``omega0`` at ``t = 0``."""
    p = parameters(inertia, omega0)
    sn, cn, dn, _ = ellipj(p["rate"] * np.asarray(t, dtype=float) + p["tau0"], p["m"])
    values = {"sn": sn, "cn": cn, "dn": dn}
    return np.stack([a * values[f] for a, f in zip(p["amplitudes"], p["functions"], strict=True)],
                    axis=-1)


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
