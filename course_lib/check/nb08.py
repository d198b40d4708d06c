"""Checks for notebook 08, hair as chains of masses and springs.

Every exercise names the course_lib functions it must not call (``@exercise(reference=...)``,
see :mod:`course_lib.check.policy`): an answer that calls them earns nothing.
"""

from __future__ import annotations

import numpy as np

from .. import hair, springs, strands
from ..lessons import nb08_hair_runs as lesson
from . import Checker, exercise
from .tolerance import blown_up, precision_rtol


def _rows(i, j, rest) -> np.ndarray:
    """Springs as sorted rows (min end, max end, rest length): order and orientation free."""
    i, j, rest = (np.asarray(a, dtype=float).ravel() for a in (i, j, rest))
    rows = np.column_stack((np.minimum(i, j), np.maximum(i, j), rest))
    return rows[np.lexsort((rows[:, 2], rows[:, 1], rows[:, 0]))]


def _families(n: int, offsets) -> tuple[np.ndarray, np.ndarray]:
    i = np.concatenate([np.arange(n - o) for o in offsets])
    j = np.concatenate([np.arange(o, n) for o in offsets])
    return i, j


@exercise(reference=(strands.strand_network, springs.hair_chain, springs.chain_pairs))
def strand_springs(ck: Checker, func) -> None:
    """``func(x0) -> (i, j, rest)``: edges, bending and torsion springs on a rest shape."""
    cases = [("a curly (helical) strand of 16 particles",
              strands.helix(16, 0.3, radius=0.01, turn=np.pi / 3)),
             ("a helix of 7 particles, another pitch",
              strands.helix(7, 0.12, radius=0.004, turn=1.1, axis=(1.0, 1.0, 0.0))),
             ("the shortest strand with a torsion spring: 4 particles",
              strands.helix(4, 0.06, radius=0.005, turn=np.pi / 2))]
    for what, x0 in cases:
        n = len(x0)
        seg = np.linalg.norm(x0[1] - x0[0])
        i_ref, j_ref = _families(n, (1, 2, 3))
        expected = _rows(i_ref, j_ref, np.linalg.norm(x0[i_ref] - x0[j_ref], axis=1))
        try:
            i, j, rest = func(x0.copy())
        except (TypeError, ValueError) as exc:
            ck.expect(False, what, f"return three arrays i, j, rest ({exc})")
            continue
        i, j, rest = (np.asarray(a) for a in (i, j, rest))
        if not (i.shape == j.shape == rest.shape and i.ndim == 1):
            ck.expect(False, what, f"i, j and rest must be 1-D arrays of one length, got shapes "
                                   f"{i.shape}, {j.shape}, {rest.shape}")
            continue
        if blown_up(ck, rest, what, run=False):
            continue
        if i.size and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n):
            ck.expect(False, what, f"an index is out of range for {n} particles",
                      hint="off by one: the last torsion spring is (n-4, n-1)")
            continue
        got = _rows(i, j, rest)
        if got.shape != expected.shape:
            counts = {o: int(np.sum(np.abs(np.asarray(j, int) - np.asarray(i, int)) == o))
                      for o in (1, 2, 3)}
            ck.expect(False, what, f"expected {len(expected)} springs ({n - 1} edges, {n - 2} "
                      f"bending, {n - 3} torsion), got {got.shape[0]}: {counts[1]} one apart, "
                      f"{counts[2]} two apart, {counts[3]} three apart",
                      hint="three families: (s, s+1) for s < n-1, (s, s+2) for s < n-2, "
                           "(s, s+3) for s < n-3")
            continue
        if not np.array_equal(got[:, :2], expected[:, :2]):
            ends = np.asarray(j, int) - np.asarray(i, int)
            if np.array_equal(np.sort(np.abs(ends)), np.sort(np.abs(j_ref - i_ref))):
                hint = "the pairs are not (s, s+offset): check each family's first index"
            elif np.all(np.abs(ends) == 1):
                hint = ("your bending/torsion springs join neighbours, e.g. (i+1, i+2): those "
                        "are edges again. A bending spring skips one particle, (i, i+2); a "
                        "torsion spring skips two, (i, i+3)")
            else:
                hint = "list (s, s+1), (s, s+2) and (s, s+3)"
            ck.expect(False, what, "these are not the springs (s, s+1), (s, s+2), (s, s+3)",
                      hint=hint)
            continue
        mistakes = {
            "measure each rest length on the rest shape x0, |x0[i] - x0[j]|: on a curly strand "
            "a bending spring is shorter than two segments": _rows(i_ref, j_ref,
                                                                 seg * np.abs(j_ref - i_ref)),
            "every spring got the segment length; measure each one on x0": _rows(
                i_ref, j_ref, np.full(i_ref.size, seg)),
        }
        ck.close(got, expected, what, rtol=precision_rtol(rest, 1e-12), atol=1e-15,
                 mistakes=mistakes, hint="rest = |x0[i] - x0[j]| for every spring")


@exercise(allow=(hair.simulate, lesson.stiffest_edge, "course_lib.springs.hair_chain"))
def max_strain_for_substeps(ck: Checker, func) -> None:
    """``func(substep_counts) -> list``: max edge strain for each substep budget."""
    counts = [10, 20, 40]
    got = func(list(counts))
    if blown_up(ck, got, f"max |strain| for substeps {counts}", run=False):
        return
    got = np.asarray(got, dtype=float)
    expected = np.asarray(lesson.max_strain_vs_substeps(counts), dtype=float)
    at_frames = []
    for s in counts:
        x0, net = springs.hair_chain(**{**hair.STRAND, "k_edge": lesson.stiffest_edge(s)})
        run = hair.simulate(x0, net, frames=12, substeps=s)
        at_frames.append(np.max(np.abs(net.strain(run.frames))))
    ck.close(got, expected, f"max |strain| for substeps {counts}", rtol=1e-6, mistakes={
        "you measured the strain at the frames only (run.frames); take the maximum over every "
        "substep (run.x)": at_frames,
    }, hint="for each S: build the strand with k_edge = lesson.stiffest_edge(S), simulate, "
            "then np.max(np.abs(net.strain(run.x)))")
    ck.expect(got.shape == (3,) and bool(np.all(np.diff(got) < 0)),
              "the error decreases as the substeps grow", f"got {got}")
