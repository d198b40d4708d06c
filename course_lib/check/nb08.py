"""Checks for notebook 08, hair as chains of masses and springs."""

from __future__ import annotations

import numpy as np

from .. import hair, springs
from ..lessons import nb08_hair_chains as lesson
from . import Checker, exercise


def _reference(n):
    e, b = springs.chain_pairs(n, 1), springs.chain_pairs(n, 2)
    return np.r_[e[0], b[0]], np.r_[e[1], b[1]]


@exercise
def chain_spring_indices(ck: Checker, func) -> None:
    """``func(n) -> (i, j)``: edges (i, i+1) then bending springs (i, i+2) of a chain."""
    for n in (3, 5, 12):
        i_ref, j_ref = _reference(n)
        i, j = (np.asarray(a) for a in func(n))
        what = f"n = {n}"
        if i.shape != i_ref.shape or j.shape != j_ref.shape:
            ck.expect(False, what, f"expected {i_ref.size} springs, got {i.size} and {j.size} indices",
                      hint=f"off by one? a chain of {n} particles has n - 1 = {n - 1} edges "
                           f"(0,1) ... ({n - 2},{n - 1}) and n - 2 = {n - 2} bending springs "
                           f"(0,2) ... ({n - 3},{n - 1})")
            continue
        if j.max() >= n or i.min() < 0:
            ck.expect(False, what, f"index {int(j.max())} is out of range for {n} particles",
                      hint="off by one: the last bending spring is (n-3, n-1)")
            continue
        ck.close(np.stack((i, j)), np.stack((i_ref, j_ref)), what,
                 hint="list the edges first, then the bending springs, each in increasing i, "
                      "with i < j (compare with course_lib.springs.chain_pairs)")


@exercise
def max_strain_for_substeps(ck: Checker, func) -> None:
    """``func(substep_counts) -> list``: max edge strain for each substep budget."""
    counts = [10, 20, 40]
    got = np.asarray(func(counts), dtype=float)
    expected = np.asarray(lesson.max_strain_vs_substeps(counts), dtype=float)
    at_frames = []
    for s in counts:
        x0, net = springs.hair_chain(**{**hair.STRAND, "k_edge": lesson.stiffest_edge(s)})
        run = hair.simulate(x0, net, frames=12, substeps=s)
        at_frames.append(np.max(np.abs(net.strain(run.frames))))
    ck.close(got, expected, f"max |strain| for substeps {counts}", rtol=1e-6, mistakes={
        "you measured the strain at the frames only (run.frames); take the maximum over every "
        "substep (run.x)": at_frames,
    })
    ck.expect(got.shape == (3,) and bool(np.all(np.diff(got) < 0)),
              "the error decreases as the substeps grow", f"got {got}")
