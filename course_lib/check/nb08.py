"""Checks for notebook 08, hair as chains of masses and springs.

An answer may call no course_lib function (:mod:`course_lib.check.policy`) except the spring
forces the hair-loop check hands it. The hair loop runs under a budget of Python lines per
step that a loop over the particles exceeds; the step-limit exercise asks for a computation
with the stiffness matrix, so it also refuses ``scipy.integrate`` and a search by simulation
written by hand (:func:`~course_lib.check._answers.call_analysis`). Hints name the slip the
answer reproduces, or what the data that broke it show. Case data of the hair loop:
:mod:`course_lib.check._nb08_cases`.
"""

from __future__ import annotations

import numpy as np

from .. import hair, springs, strands
from . import Checker, exercise
from ._answers import as_array, call_analysis, close
from ._nb08_cases import loop_cases, loop_mistakes, reference
from .tolerance import blown_up, call_whole_array, case_table, close_worst, escalate, precision_rtol


def _rows(i, j, rest) -> np.ndarray:
    """Springs as sorted rows (min end, max end, rest length): order and orientation free."""
    i, j, rest = (np.asarray(a, dtype=float).ravel() for a in (i, j, rest))
    rows = np.column_stack((np.minimum(i, j), np.maximum(i, j), rest))
    return rows[np.lexsort((rows[:, 2], rows[:, 1], rows[:, 0]))]


def _families(n: int, offsets) -> tuple[np.ndarray, np.ndarray]:
    i = np.concatenate([np.arange(n - o) for o in offsets])
    j = np.concatenate([np.arange(o, n) for o in offsets])
    return i, j


@exercise(allow=())
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
        pairs = got[:, :2]
        twice = len(np.unique(pairs, axis=0)) < len(pairs)
        if twice and np.array_equal(np.unique(pairs, axis=0), expected[:, :2]):
            ck.expect(False, what, f"expected {len(expected)} springs, got {got.shape[0]}: some "
                      f"pairs of particles are listed more than once", hint=escalate(
                          "a spring joins two particles once: you listed some springs twice, "
                          "e.g. as (i, j) and as (j, i)", "keep i < j: (s, s + offset) for "
                          "each family, once"))
            continue
        if got.shape != expected.shape:
            counts = {o: int(np.sum(np.abs(np.asarray(j, int) - np.asarray(i, int)) == o))
                      for o in (1, 2, 3)}
            short = [o for o, want in ((1, n - 1), (2, n - 2), (3, n - 3)) if counts[o] != want]
            ck.expect(False, what, f"expected {len(expected)} springs ({n - 1} edges, {n - 2} "
                      f"bending, {n - 3} torsion), got {got.shape[0]}: {counts[1]} one apart, "
                      f"{counts[2]} two apart, {counts[3]} three apart",
                      hint=(f"the family {short[0]} apart has the wrong count: (s, s+{short[0]}) "
                            f"runs over s = 0 ... n-{short[0] + 1}") if short else None)
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
                hint = None
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
        # a failure shows the worst spring only: the whole table would be the answer
        close_worst(ck, got, expected, what, rtol=precision_rtol(rest, 1e-12), atol=1e-15,
                    mistakes=mistakes, unit="m",
                    label=lambda r: f"spring (i, j, rest) number {r} in sorted order")


#: Lines of Python one substep of whole-array code needs at most (a loop over 48 particles
#: runs at least 48 more).
LINES_PER_STEP = 40


@exercise(allow=())
def hair_frames(ck: Checker, func) -> None:
    """``func(x0, spring_forces, mass, pinned, damping, head, frames, substeps, fps)``: the
    substepped symplectic Euler loop with pinned roots and the head's projection; compared
    with :func:`course_lib.hair.simulate`, and no particle may end inside the head."""
    for what, x0, net, mass, pinned, damping, head, frames, substeps, fps in loop_cases():
        run = (x0, net, mass, pinned, damping, head, frames, substeps, fps)
        expected = case_table("hair_frames", what, reference, *run)
        budget = LINES_PER_STEP * frames * substeps + 200
        ok, got = call_whole_array(ck, what, budget, escalate(
            "each substep is a few operations on whole (N, 3) arrays: no loop over particles",
            "masks such as inside = dist < R pick the particles to change"),
            func, x0.copy(), net.forces, mass.copy(), list(pinned), damping,
            (head[0].copy(), head[1]), frames, substeps, fps)
        if not ok:
            continue
        answer = as_array(got)
        if answer is None or answer.shape != expected.shape:
            shape = None if answer is None else answer.shape
            hint = None
            if shape == (frames * substeps + 1, *expected.shape[1:]):
                hint = "you returned every substep: keep one state per frame, every substeps-th"
            elif shape == (frames, *expected.shape[1:]):
                hint = "include the starting state: frames + 1 pictures, the first at t = 0"
            ck.expect(False, what, f"expected frames of shape {expected.shape}, got "
                      f"{shape if shape is not None else type(got).__name__}", hint)
            continue
        if blown_up(ck, answer, what, hint=escalate(
                "the run explodes at a step symplectic Euler survives: check the order of the "
                "updates and the signs", "forward Euler (moving x with the old v) explodes on "
                "stiff springs: update v from the forces first, then x with the new v")):
            continue
        right = np.allclose(answer, expected, rtol=0.0, atol=1e-9)
        mistakes = {} if right else case_table("hair_frames: slips", what, loop_mistakes, *run)
        # one row per particle and frame: a wrong answer is summarised by its worst row
        n = len(x0)
        close_worst(ck, answer.reshape(-1, 3), expected.reshape(-1, 3), f"{what}: the frames",
                    rtol=0.0, atol=1e-9, unit="m",
                    label=lambda r, n=n: f"frame {r // n}, particle {r % n}",
                    mistakes={h: w.reshape(-1, 3) for h, w in mistakes.items()})
        center, radius = head
        depth = radius - np.linalg.norm(answer - center, axis=-1).min()
        ck.expect(depth <= 1e-9 * radius, f"{what}: no particle inside the head",
                  f"a particle ends a frame {depth * 1e3:.3g} mm inside it",
                  hint="after each substep, project every free particle inside the head back "
                       "to its surface")
        shift = np.abs(answer[:, pinned] - x0[pinned]).max(axis=(0, 2))
        moved = [p for p, d in zip(pinned, shift, strict=True) if d > 1e-12]
        held = [p for p in pinned if p not in moved]
        ck.expect(not moved, f"{what}: the pinned particles stay put",
                  f"pinned particle{'s' if len(moved) > 1 else ''} {moved} moved, by up to "
                  f"{shift.max():.3g} m", hint=escalate(
                      f"you held only particle{'s' if len(held) > 1 else ''} {held} of the "
                      f"pinned list {list(pinned)}: every particle listed stays put, in any "
                      "order", "mark all of them at once, e.g. free[list(pinned)] = 0") if held
                  else "the pinned particles get no velocity and no projection: they stay "
                       "exactly where they are")


def _step_cases():
    """(what, network, x, mass, pinned, fps): strands and a 2D cloth at rest, equal and
    unequal masses, pinned particles not only at the start of the list, and a squeezed
    strand whose stiffness matrix is not positive definite."""
    x0, net = springs.hair_chain(**hair.STRAND)
    yield ("the notebook's strand (edges only, root pinned)", net, x0,
           np.full(16, hair.MASS), [0], 30.0)
    xz, zig = springs.hair_chain(**hair.STRAND, k_bend=2000.0, zigzag=0.3)
    yield ("a tapered zigzag strand (0.2 g to 0.05 g), clamped [0, 1]", zig, xz,
           np.linspace(2e-4, 5e-5, 16), [0, 1], 30.0)
    xc, cloth = springs.cloth_grid(4, 4, spacing=0.05, k_struct=500.0, k_shear=50.0, k_bend=5.0)
    yield ("a 4 × 4 cloth in 2D, corners pinned as [15, 0]", cloth,
           xc[:, :2], np.full(16, 2e-3), [15, 0], 60.0)
    yield ("the strand squeezed to a third of its length (its buckling modes have negative "
           "eigenvalues twice the size of the largest positive one)", net, x0 / 3.0,
           np.full(16, hair.MASS), [0], 30.0)


def _top(K, mass, dofs, dim, per_coordinate=True):
    """sqrt of the largest eigenvalue of M^{-1/2} K M^{-1/2} on ``dofs`` (0 if none > 0)."""
    m = np.repeat(mass, dim)[dofs] if per_coordinate else np.full(len(dofs), mass)
    w = 1.0 / np.sqrt(m)
    lam = np.linalg.eigvalsh(w[:, None] * K[np.ix_(dofs, dofs)] * w[None, :])
    return float(np.sqrt(max(lam[-1], 0.0)))


def _substeps(dt_max: float, fps: float) -> int:
    """Fewest substeps per frame whose step 1 / (fps S) is below ``dt_max`` (strictly)."""
    return int(np.floor(1.0 / (fps * dt_max))) + 1


def _omega_mistakes(K, mass, pinned, dim) -> dict:
    """Wrong ω_max that the usual slips give."""
    n = len(mass)
    free = np.setdiff1d(np.arange(n), pinned)
    dofs = (free[:, None] * dim + np.arange(dim)).ravel()
    rows = np.setdiff1d(np.arange(n * dim), pinned)             # pinned rows, not particles
    scale = np.repeat(1.0 / np.sqrt(mass), dim)[dofs]
    with np.errstate(all="ignore"):
        assumed = [p * 3 + c for p in free for c in range(3) if p * 3 + c < n * dim]
        biggest = np.abs(np.linalg.eigvalsh(scale[:, None] * K[np.ix_(dofs, dofs)] * scale)).max()
    out = {
        escalate("the pinned particles cannot move: drop their rows and columns of K first",
                 "keep the rows p·d ... p·d + d - 1 of every particle p that is not pinned, "
                 "and the same columns"): _top(K, mass, np.arange(n * dim), dim),
        escalate("each particle owns d rows of K: particle p is rows p·d ... p·d + d - 1, so dropping "
         "row p is not dropping particle p", "d = K.shape[0] // len(mass); the free rows are "
         "p·d + (0 ... d-1) for every particle p not pinned"): _top(K, mass, rows, dim),
        "pinned lists every pinned particle, in any order: you dropped particle 0 only":
            _top(K, mass, np.arange(dim, n * dim), dim),
        "each coordinate has its own mass (this strand is tapered): scale K by 1/√m on both "
        "sides, row by row, not by one mass": _top(K, float(mass[0]), dofs, dim, False),
        "the mean mass is not the mass of each particle: scale K by 1/√m row by row":
            _top(K, float(np.mean(mass)), dofs, dim, False),
        "divide by the masses: ω² are the eigenvalues of M⁻¹K, not of K":
            np.sqrt(max(np.linalg.eigvalsh(K[np.ix_(dofs, dofs)])[-1], 0.0)),
        "the eigenvalues of M⁻¹K are ω²: take the square root":
            float(np.linalg.eigvalsh(scale[:, None] * K[np.ix_(dofs, dofs)] * scale)[-1]),
        escalate("the largest eigenvalue, not the largest in size: a negative eigenvalue is a "
                 "mode that buckles (grows), not one that vibrates, and sets no step limit",
                 "take the largest (most positive) eigenvalue of M⁻¹K"): float(np.sqrt(biggest)),
    }
    if dim != 3:
        out[escalate("this network is in 2D: each particle owns d = 2 rows of K, not 3",
                     "d = K.shape[0] // len(mass)")] = _top(K, mass, np.array(assumed), dim)
    return out


@exercise(allow=(), forbid=("scipy.integrate",))
def step_limit(ck: Checker, func) -> None:
    """``func(K, mass, pinned, fps) -> (omega_max, dt_max, substeps)``: the explicit step
    limit from the stiffness matrix, and the substeps a frame needs."""
    for what, net, x, mass, pinned, fps in _step_cases():
        K, dim = springs.stiffness_matrix(net, x), x.shape[1]
        omega = springs.max_frequency(net, x, mass, pinned)
        dt_max, substeps = 2.0 / omega, _substeps(2.0 / omega, fps)
        ok, got = call_analysis(ck, what, 400, (
            "the exercise asks for the limit from the matrix (its eigenvalues): your function "
            "searches for it step by step (a simulation or a bisection)"), func, K.copy(),
            mass.copy(), list(pinned), fps)
        if not ok:
            if "lines of Python" in ck.failed[-1]:
                break                   # a simulation: one case says it, the rest would repeat
            if dim != 3 and "raised IndexError" in ck.failed[-1]:
                ck.failed[-1] += ("\n      hint: this network is in 2D: each particle owns "
                                  "K.shape[0] // len(mass) rows of K, not 3")
            continue
        answer = as_array(got)
        if answer is None or answer.shape != (3,):
            ck.expect(False, what, f"return three numbers (omega_max, dt_max, substeps), got "
                      f"{got!r}"[:150])
            continue
        if blown_up(ck, answer, what, run=False, hint=(
                "a compressed spring makes some eigenvalues of M⁻¹K negative: their square "
                "roots are NaN. Only the largest one matters")):
            continue
        w_got, dt_got, s_got = (float(a) for a in answer)
        rtol = precision_rtol(got, 1e-9)
        mistakes = _omega_mistakes(K, mass, pinned, dim)
        near = None
        if 0.5 < w_got / omega < 2.0 and not any(np.isclose(w_got, w, rtol=rtol)
                                                for w in mistakes.values()):
            near = escalate(
                f"your ω_max is {100 * abs(w_got / omega - 1):.2g} % off: an estimate (the "
                "rule of thumb 2√(k/m), a bound from the diagonal of K) is not the largest "
                "eigenvalue, which the bending springs, the finite strand and unequal masses "
                "all move", "compute the eigenvalues of M^(-1/2) K M^(-1/2) on the free "
                "coordinates and take the square root of the largest")
        w_ok = close(ck, w_got, omega, f"{what}: ω_max (rad/s)", rtol=rtol, hint=near,
                     mistakes=mistakes)
        follows = w_got > 0 and np.isclose(dt_got, 2.0 / w_got, rtol=rtol)
        close(ck, dt_got, dt_max, f"{what}: largest stable step (s)", rtol=rtol, mistakes={
            "symplectic Euler is stable for ω dt < 2: the limit is 2/ω_max, not 1/ω_max":
                1.0 / w_got if w_got > 0 else np.nan},
            hint=None if w_ok or not follows else
            "your step is 2 / (your ω_max), the right rule: fix ω_max and it follows")
        follows = dt_got > 0 and s_got == _substeps(dt_got, fps)
        close(ck, s_got, substeps, f"{what}: substeps at {fps:g} fps", rtol=0.0,
              atol=1e-300, mistakes={"round up: with one substep fewer the step is longer than "
                                     "the limit": substeps - 1},
                 hint=None if not follows else
                 "your count follows from your step, the right rule: fix the step and it follows")
