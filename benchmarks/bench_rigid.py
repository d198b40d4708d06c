"""Rigid bodies (notebook 14): invariant drift per integrator, and the flip period.

Numbers, not timings. The spinning box of the notebook (0.3 kg, 20 × 10 × 5 cm, 10 rad/s
about its intermediate axis, nudged by 0.1 rad/s) runs for 8 s at Δt = 0.01 s with every
method of ``course_lib.rigid.free``; each row gives the relative drift of ``|L|`` and of
the kinetic energy at the end and at worst. The targets are what each method promises:
round-off for a conserved quantity (16 eps per step), growth for the explicit methods,
decay for backward Euler, a bounded energy error for the splitting. Last, the flip period
measured with 100 steps per period against ``4K(m)/λ`` (target: within 1 %).
"""

from __future__ import annotations

import numpy as np

from benchmarks.timing import Row
from course_lib import rigid
from course_lib.lessons import nb14_rigid_bodies as nb14
from course_lib.rigid import exact

EPS = float(np.finfo(float).eps)


def _verdict(method: str, row: dict, roundoff: float) -> tuple[str, bool]:
    if method in ("implicit_midpoint",):
        return "|L| and E kept to round-off", row["L_max"] < roundoff and row["E_max"] < roundoff
    if method == "splitting":
        return ("|L| to round-off, E bounded (< 1e-3)",
                row["L_max"] < roundoff and row["E_max"] < 1e-3 and abs(row["E_end"]) < row["E_max"])
    if method == "baraff_euler":
        return "|L| to round-off, E grows", row["L_max"] < roundoff and bool(np.all(np.diff(row["dE"]) > 0))
    if method == "forward_euler":
        return "|L| and E grow", bool(np.all(np.diff(row["dL"]) > 0) and np.all(np.diff(row["dE"]) > 0))
    if method == "backward_euler":
        return "|L| and E decay", bool(np.all(np.diff(row["dL"]) < 0) and np.all(np.diff(row["dE"]) < 0))
    return "drift ≤ 1e-5 (4th order)", row["L_max"] < 1e-5 and row["E_max"] < 1e-5


def run(quick: bool = False) -> list[Row]:
    t_end = 2.0 if quick else nb14.DRIFT_T
    rows = nb14.drift_table(dt=nb14.DRIFT_DT, t_end=t_end)
    steps = round(t_end / nb14.DRIFT_DT)
    roundoff = 16 * EPS * steps
    out = []
    for method, row in rows.items():
        target, ok = _verdict(method, row, roundoff)
        note = (f"|L|: end {row['L_end']:+.1e}, worst {row['L_max']:.1e}; "
                f"E: end {row['E_end']:+.1e}, worst {row['E_max']:.1e}")
        out.append(Row(f"free body, {method}, dt = {nb14.DRIFT_DT} s, {t_end:g} s", None, target, ok,
                       note=note))
    T = exact.period(nb14.spin_moments(), nb14.SPIN["omega0"])
    t, omega, _ = rigid.free_body(nb14.spin_moments(), nb14.SPIN["omega0"], T / 100, 220,
                                  "implicit_midpoint")
    error = exact.measured_period(t, omega, 1) / T - 1
    out.append(Row("flip period, implicit midpoint, 100 steps per period", None, "within 1 % of 4K(m)/λ",
                   abs(error) < 0.01, note=f"T = {T:.4f} s, measured {T * (1 + error):.4f} s ({error:+.2%})"))
    return out
