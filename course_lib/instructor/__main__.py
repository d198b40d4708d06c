"""``python -m course_lib.instructor {student,execute,grade}``."""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

from .grade import grade_paths
from .notebooks import execute_notebook, extract_figures, make_student_versions


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.instructor", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("student", help="regenerate student notebooks from the solutions")
    p.add_argument("solutions", type=Path, nargs="?", default=Path("solutions"))
    p.add_argument("notebooks", type=Path, nargs="?", default=Path("notebooks"))
    p = sub.add_parser("execute", help="run notebooks in place, storing their outputs")
    p.add_argument("paths", type=Path, nargs="+")
    p = sub.add_parser("figures", help="save a notebook's PNG outputs to a folder for review")
    p.add_argument("notebook", type=Path)
    p.add_argument("outdir", type=Path)
    p = sub.add_parser("grade", help="run submissions and collect the exercise verdicts")
    p.add_argument("paths", type=Path, nargs="+", help="submitted notebooks or folders of them")
    p.add_argument("--out", type=Path, default=Path("grades.csv"))
    args = parser.parse_args(argv)

    if args.command == "student":
        for path in make_student_versions(args.solutions, args.notebooks):
            print(f"wrote {path}")
    elif args.command == "execute":
        for path in args.paths:
            print(f"executing {path} ...", flush=True)
            execute_notebook(path)
    elif args.command == "figures":
        for path in extract_figures(args.notebook, args.outdir):
            print(path)
    else:
        rows = grade_paths(args.paths, args.out)
        totals: dict[str, list[int]] = defaultdict(lambda: [0, 0])
        for r in rows:
            totals[r["submission"]][0] += r["points"]
            totals[r["submission"]][1] += r["possible"]
        for sub_name, (got, possible) in totals.items():
            print(f"{sub_name}: {got}/{possible} points")
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
