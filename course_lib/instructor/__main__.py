"""``python -m course_lib.instructor COMMAND``: student, execute, figures, grade, release,
nbgrader, synth-class, export, clips (``--help`` lists them)."""

from __future__ import annotations

import argparse
import sys
from collections import Counter, defaultdict
from pathlib import Path


def _grade_parser(sub) -> None:
    p = sub.add_parser("grade", help="grade a class folder: gradebook CSV, feedback, class report")
    p.add_argument("paths", type=Path, nargs="+",
                   help="class folders (one subfolder per student) or single notebooks")
    p.add_argument("--out", type=Path, default=Path("grades.csv"), help="the gradebook (CSV)")
    p.add_argument("--assignment", nargs="+", action="extend", default=None,
                   help="assignments to expect from every student (default: those handed in)")
    p.add_argument("--solutions", type=Path, default=None, help="the kit's solutions folder")
    p.add_argument("--feedback", type=Path, default=None,
                   help="folder for per-student feedback (default: <out>-feedback)")
    p.add_argument("--report", type=Path, default=None,
                   help="class report HTML (default: <out>-report.html)")
    p.add_argument("--jobs", type=int, default=None, help="notebooks graded at once (default: cores)")
    p.add_argument("--timeout", type=float, default=180.0, help="seconds per notebook, all included")
    p.add_argument("--cell-timeout", type=float, default=30.0,
                   help="CPU seconds per code cell (the wall clock may run 3x as long)")
    p.add_argument("--exercise-timeout", type=float, default=20.0,
                   help="CPU seconds per exercise check (the wall clock may run 3x as long)")
    p.add_argument("--memory", type=int, default=2048, help="address-space limit per notebook (MB)")
    p.add_argument("--student", nargs="+", action="extend", default=None,
                   help="grade only these students (folder names), e.g. to regrade")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="grade on this dask.distributed cluster (e.g. tcp://10.0.0.5:8786), one task "
                        "per submission; without it, grading runs on this machine")
    p.add_argument("--restart", action="store_true",
                   help="grade everything again, ignoring what an interrupted run left to resume")


def _more_parsers(sub) -> None:
    p = sub.add_parser("synth-class", help="write a synthetic class (load tests): submissions, roster, "
                                           "expected statuses")
    p.add_argument("out", type=Path)
    p.add_argument("--n", type=int, default=100, help="number of students")
    p.add_argument("--assignment", nargs="+", action="extend", default=None,
                   help="assignments each student hands in (default: 05_newtons_second_law)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--full", action="store_true", help="keep the notebooks' demonstration cells")
    p = sub.add_parser("export", help="the gradebook in an LMS's import format (canvas, moodle, brightspace)")
    p.add_argument("lms", choices=["canvas", "moodle", "brightspace"])
    p.add_argument("gradebook", type=Path, nargs="?", default=Path("grades.csv"))
    p.add_argument("--roster", type=Path, required=True, help="roster CSV (see docs/INSTRUCTORS.md)")
    p.add_argument("--key", default="student", help="roster column naming the submission folders")
    p.add_argument("--item", nargs="+", action="extend", default=[], metavar="ASSIGNMENT=TITLE",
                   help="the LMS's title of an assignment's grade item")
    p.add_argument("--out", type=Path, default=None, help="default: <gradebook>-<lms>.csv")
    p = sub.add_parser("clips", help="render each notebook's showcase animation as a clip (MP4 or GIF)")
    p.add_argument("out", type=Path, nargs="?", default=Path("clips"))
    p.add_argument("--only", nargs="+", default=None, help="notebooks by number or name, e.g. 08 11")
    p.add_argument("--format", choices=["mp4", "gif"], default="mp4")
    p.add_argument("--dpi", type=float, default=None, help="default: each figure's own")
    p.add_argument("--list", action="store_true", help="list the showcases and exit")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


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
    _grade_parser(sub)
    _more_parsers(sub)
    p = sub.add_parser("release", help="build the package students receive (no solutions)")
    p.add_argument("out", type=Path, nargs="?", default=Path("dist/student"))
    p = sub.add_parser("nbgrader", help="export nbgrader source notebooks (a course folder)")
    p.add_argument("out", type=Path, nargs="?", default=Path("nbgrader"))
    args = parser.parse_args(argv)

    if args.command == "student":
        from .notebooks import make_student_versions

        for path in make_student_versions(args.solutions, args.notebooks):
            print(f"wrote {path}")
    elif args.command == "execute":
        from .notebooks import execute_notebook

        for path in args.paths:
            print(f"executing {path} ...", flush=True)
            execute_notebook(path)
    elif args.command == "figures":
        from .notebooks import extract_figures

        for path in extract_figures(args.notebook, args.outdir):
            print(path)
    elif args.command == "grade":
        return _grade(args)
    elif args.command in ("synth-class", "export", "clips"):
        from . import cli_more

        return cli_more.run(args)
    elif args.command == "release":
        from .release import build_release

        print(f"wrote the student release to {build_release(args.out)}")
    else:
        from .nbgrader_export import export_nbgrader

        for path in export_nbgrader(args.out):
            print(f"wrote {path}")
    return 0


def _grade(args) -> int:
    from .grade import grade_class
    from .sandbox import Limits

    out = args.out
    feedback = args.feedback or out.with_name(f"{out.stem}-feedback")
    report = args.report or out.with_name(f"{out.stem}-report.html")
    limits = Limits(deadline=args.timeout, cell_s=args.cell_timeout, exercise_s=args.exercise_timeout,
                    memory_mb=args.memory)
    try:
        rows = grade_class(args.paths, out, solutions=args.solutions, assignments=args.assignment,
                           limits=limits, jobs=args.jobs, feedback_dir=feedback, report=report,
                           progress=not args.no_progress, only=args.student,
                           scheduler=args.scheduler, resume=not args.restart)
    except KeyboardInterrupt:
        print(f"interrupted: {out} holds what was graded; run the same command again to resume",
              file=sys.stderr)
        return 130
    except (ValueError, RuntimeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        if out.with_name(out.name + ".journal").exists():
            print("the submissions graded so far are kept: run the same command again to resume",
                  file=sys.stderr)
        return 2
    totals: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    for r in rows:
        totals[r.student][0] += r.points
        totals[r.student][1] += r.possible
    for student, (got, possible) in totals.items():
        print(f"{student}: {got}/{possible} points")
    print("verdicts: " + ", ".join(f"{n} {s}" for s, n in Counter(r.status for r in rows).most_common()))
    print(f"wrote {out}, {feedback}/ and {report}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
