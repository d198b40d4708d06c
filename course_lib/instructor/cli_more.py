"""The newer commands of ``python -m course_lib.instructor``: synth-class, export, clips.

Kept apart from :mod:`.__main__` (which parses every command) so each stays short.
Imports: the standard library; the command's module when it runs.
"""

from __future__ import annotations

import sys
from pathlib import Path


def run(args) -> int:
    """Run ``args.command`` (parsed by :mod:`.__main__`); return the exit status."""
    try:
        return {"synth-class": _synth, "export": _export, "clips": _clips}[args.command](args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _synth(args) -> int:
    from collections import Counter

    from .synth import synth_class

    made = synth_class(args.out, args.n, solutions=None, assignments=args.assignment, seed=args.seed,
                       full=args.full)
    kinds = Counter(made["kinds"].values())
    print(f"wrote {len(made['kinds'])} students to {made['submissions']} "
          f"({', '.join(f'{n} {k}' for k, n in kinds.most_common())})")
    print(f"wrote {made['roster']} and {made['expected']}")
    return 0


def _export(args) -> int:
    from .lms import export_grades

    items = {}
    for spec in args.item:
        name, sep, title = spec.partition("=")
        if not sep or not name or not title:
            raise ValueError(f"item: {spec!r} is not ASSIGNMENT=TITLE")
        items[name] = title
    out = args.out or args.gradebook.with_name(f"{args.gradebook.stem}-{args.lms}.csv")
    done = export_grades(args.gradebook, args.roster, args.lms, out, key=args.key, items=items)
    print(f"wrote {done['path']}: {done['students']} students, {len(done['assignments'])} grade items")
    if done["not_graded"]:
        print(f"note: {len(done['not_graded'])} roster entries have no graded submission and are not in "
              f"the file: {', '.join(done['not_graded'][:10])}", file=sys.stderr)
    return 0


def _clips(args) -> int:
    from course_lib.lessons.showcase import render_showcases, showcases

    if args.list:
        for number, entry in showcases().items():
            print(f"{number}  {entry.name:28s} {entry.module}.{entry.function}")
        return 0
    for path in render_showcases(Path(args.out), only=args.only, fmt=args.format, dpi=args.dpi,
                                 progress=not args.no_progress):
        print(f"wrote {path}")
    return 0
