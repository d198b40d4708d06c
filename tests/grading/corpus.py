"""A class folder of submissions broken the ways real hand-ins break, with expected rows.

:func:`build` writes one folder per student under ``root`` (notebooks 02 and 05 of the
kit as the two assignments) and returns ``{student: {assignment: [status per exercise]}}``.
Each kind of submission is a small edit of the kit's student or solution notebook.
"""

from __future__ import annotations

import json
import os
import textwrap
from pathlib import Path

import nbformat

from course_lib.instructor.kit import load_kit
from course_lib.instructor.notebooks import make_student_notebook

ROOT = Path(__file__).resolve().parents[2]
A02, A05 = "02_forward_euler", "05_newtons_second_law"
_KIT = load_kit(ROOT / "solutions")
#: The exercises of the two assignments, in order, as the kit defines them.
EX = {a: [e.name for e in _KIT[a].exercises] for a in (A02, A05)}
STUB = "    # YOUR CODE HERE\n    raise NotImplementedError()"
#: Exercises whose check calls the answer's callbacks thousands of times (02's three-grid
#: order: every step of three runs is recorded in the worker and replayed in the grader, a
#: few seconds of CPU). ``Sub.solve()`` leaves them pending unless named; ``correct_02``
#: solves them, which is enough to show they grade.
SLOW = {A02: {"observed_order"}}


class Sub:
    """A submission under construction: the student version, with answers filled in.

    ``full=False`` leaves out the kit's demonstration code cells (the imports, the
    exercises and all Markdown stay): they are the kit's own code, untouched, and most of
    the running time; one kind (``correct_05``) keeps them to show whole notebooks are
    graded alike.
    """

    def __init__(self, assignment: str, full: bool = False):
        self.assignment = assignment
        self.solution = nbformat.read(ROOT / "solutions" / f"{assignment}.ipynb", as_version=4)
        self.nb = make_student_notebook(self.solution)
        if not full:
            code = [c for c in self.nb.cells if c.cell_type == "code"]
            self.nb.cells = [c for c in self.nb.cells if c.cell_type != "code" or c is code[0]
                             or any(f"def {name}(" in c.source for name in EX[assignment])]

    def _cell(self, name: str, nb=None):
        nb = nb or self.nb
        return next(c for c in nb.cells if c.cell_type == "code" and f"def {name}(" in c.source)

    def solve(self, *names: str) -> Sub:
        for name in names or [n for n in EX[self.assignment] if n not in SLOW.get(self.assignment, ())]:
            self._cell(name).source = self._cell(name, self.solution).source
        return self

    def answer(self, name: str, body: str) -> Sub:
        cell = self._cell(name)
        cell.source = cell.source.replace(STUB, textwrap.indent(textwrap.dedent(body).strip(), "    "))
        return self

    def edit(self, name: str, old: str, new: str) -> Sub:
        cell = self._cell(name)
        assert old in cell.source, (name, old)
        cell.source = cell.source.replace(old, new)
        return self

    def add(self, source: str, at: int | None = 2) -> Sub:
        """Insert a code cell at ``at`` (default: right after the imports; None: at the end)."""
        cell = nbformat.v4.new_code_cell(textwrap.dedent(source).strip())
        self.nb.cells.insert(len(self.nb.cells) if at is None else at, cell)
        return self

    def write(self, path: Path, version: int = 4) -> Path:
        path.parent.mkdir(parents=True, exist_ok=True)
        nb = nbformat.convert(self.nb, 3) if version == 3 else self.nb
        nbformat.write(nb, path, version=version)
        return path


def _all(status: str, assignment: str, **exceptions: str) -> list[str]:
    """``status`` for every exercise of ``assignment`` but those named in ``exceptions``."""
    assert set(exceptions) <= set(EX[assignment]), exceptions
    return [exceptions.get(name, status) for name in EX[assignment]]


#: A DNS query for example.com's A record, as a resolver library sends it over UDP.
DNS_QUERY = "12340100000100000000000007" + b"example".hex() + "03" + b"com".hex() + "0000010001"


def build(root: Path, grader_file: Path, net: dict) -> dict[str, dict[str, list[str]]]:
    """Write the class folder; ``grader_file`` is a file of the grader's that one submission
    tries to overwrite by its absolute path; ``net`` the services the grader's machine
    offers that submissions try to reach: ``tcp`` and ``udp`` ports on 127.0.0.1 and a
    ``unix`` socket path (the test listens on them, so a success would be seen)."""
    expected: dict[str, dict[str, list[str]]] = {}

    def student(name: str, **rows) -> Path:
        folder = root / name
        folder.mkdir(parents=True, exist_ok=True)
        expected[name] = {A02: rows.get("s02", _all("missing", A02)),
                          A05: rows.get("s05", _all("missing", A05))}
        return folder

    def nb02(name: str) -> Path:
        return root / name / f"{A02}.ipynb"

    def nb05(name: str) -> Path:
        return root / name / f"{A05}.ipynb"

    ok02, ok05 = _all("correct", A02, observed_order="pending"), _all("correct", A05)
    student("correct_02", s02=_all("correct", A02))
    Sub(A02).solve(*EX[A02]).write(nb02("correct_02"))
    student("correct_05", s05=ok05)
    Sub(A05, full=True).solve().write(nb05("correct_05"))
    student("blank_both", s02=_all("pending", A02), s05=_all("pending", A05))
    Sub(A02).write(nb02("blank_both"))
    Sub(A05).write(nb05("blank_both"))
    student("partial_05", s05=_all("pending", A05, symplectic_euler_step="correct", impact_time="correct"))
    Sub(A05).solve("symplectic_euler_step", "impact_time").write(nb05("partial_05"))
    student("wrong_02", s02=_all("pending", A02, forward_euler_step="incorrect", radius_after="incorrect"))
    (Sub(A02).answer("forward_euler_step", "return y + dt * f(t + dt, y)")
     .answer("radius_after", "return r0 * (1 + dt**2) ** n").write(nb02("wrong_02")))
    student("syntax_error_02", s02=_all("correct", A02, forward_euler_step="error", observed_order="pending"))
    (Sub(A02).solve().edit("forward_euler_step", "return y + dt * f(t, y)", "return y + dt * f(t, y")
     .write(nb02("syntax_error_02")))
    student("exception_02", s02=_all("pending", A02, forward_euler_step="error", radius_after="correct",
                                      drift_dt="correct"))
    (Sub(A02).solve("radius_after", "drift_dt").answer("forward_euler_step", "return 1 // 0")
     .add("raise RuntimeError('a demo cell that breaks')", at=4).write(nb02("exception_02")))
    student("loop_in_exercise_02", s02=_all("pending", A02, forward_euler_step="correct",
                                             radius_after="timeout", drift_dt="correct"))
    (Sub(A02).solve("forward_euler_step", "drift_dt")
     .answer("radius_after", "while True:\n    pass").write(nb02("loop_in_exercise_02")))
    student("stubborn_loop_top_02", s02=ok02)
    Sub(A02).solve().add("""
        import time
        try:                     # computes until the grader's alarm, and ignores it:
            while True:          # must be killed, then skipped
                pass
        except BaseException:
            pass
        while True:              # then waits (no CPU) and swallows whatever comes
            try:
                time.sleep(0.1)
            except BaseException:
                pass
        """).write(nb02("stubborn_loop_top_02"))
    student("os_exit_top_05", s05=ok05)
    Sub(A05).solve().add("import os\nos._exit(3)").write(nb05("os_exit_top_05"))
    student("segfault_05", s05=_all("correct", A05, velocity_verlet_step="error"))
    (Sub(A05).solve(*(n for n in EX[A05] if n != "velocity_verlet_step"))
     .answer("velocity_verlet_step", "import ctypes\nreturn ctypes.string_at(0)").write(nb05("segfault_05")))
    student("deleted_check_calls_02", s02=ok02)
    sub = Sub(A02).solve()
    for cell in sub.nb.cells:
        cell.source = "\n".join(ln for ln in cell.source.splitlines() if "check" not in ln)
    sub.write(nb02("deleted_check_calls_02"))
    student("edited_check_calls_02", s02=_all("pending", A02))
    (Sub(A02).edit("forward_euler_step", "check.forward_euler_step(forward_euler_step)",
                   "check.forward_euler_step(cl.forward_euler)")
     .edit("radius_after", "check.radius_after(radius_after)",
           "check.radius_after(lambda r0, dt, n: r0 * (1 + dt**2) ** (n / 2))")
     .write(nb02("edited_check_calls_02")))
    tampered02, tampered05 = _all("tampered", A02), _all("tampered", A05)
    student("tamper_results_02", s02=tampered02)
    Sub(A02).add("""
        from course_lib.check import RESULTS
        for key in ("nb02.forward_euler_step", "nb02.radius_after", "nb02.drift_dt"):
            RESULTS[key] = {"status": "correct", "passed": 4, "total": 4, "points": 100}
        """, at=None).write(nb02("tamper_results_02"))
    student("tamper_patch_05", s05=tampered05)
    Sub(A05).add("""
        import course_lib.check as C
        C.Checker.close = lambda *args, **kwargs: True
        check.symplectic_euler_step = lambda fn: print("correct")
        """).write(nb05("tamper_patch_05"))
    student("tamper_summary_02", s02=tampered02)
    Sub(A02).add("""
        from course_lib import check as grader
        grader.summary = lambda: {k: {"status": "correct", "passed": 1, "total": 1, "points": 1300}
                                  for k in grader.REGISTRY}
        """).write(nb02("tamper_summary_02"))
    student("tamper_hidden_02", s02=tampered02)
    Sub(A02).add("""
        mod = getattr(cl, "che" + "ck")
        getattr(mod, "RES" + "ULTS")["nb02.radius_after"] = {"status": "correct"}
        """).write(nb02("tamper_hidden_02"))
    student("tamper_check_data_02", s02=tampered02)
    (Sub(A02).answer("forward_euler_step", "return y").add("""
        cases = getattr(getattr(cl, "che" + "ck"), "nb0" + "2")
        getattr(cases, "_STEP" + "_CASES").clear()
        """).write(nb02("tamper_check_data_02")))
    student("forged_output_02", s02=tampered02)
    Sub(A02).add("""
        print("\\u2705 forward_euler_step: correct (4 of 4 checks passed)")
        print("@@GRADE@@" + '{"nb02.forward_euler_step": {"status": "correct", "points": 1300}}')
        """, at=None).write(nb02("forged_output_02"))
    student("invalid_json_02", s02=_all("unreadable", A02))
    nb02("invalid_json_02").write_text('{"cells": [ {"cell_type": "code", "source": "x = ', "utf-8")
    student("empty_file_05", s05=_all("unreadable", A05))
    nb05("empty_file_05").write_bytes(b"")
    student("json_not_notebook_02", s02=_all("unreadable", A02))
    nb02("json_not_notebook_02").write_text(json.dumps({"answers": [1, 2, 3]}), "utf-8")
    student("binary_05", s05=_all("unreadable", A05))
    nb05("binary_05").write_bytes(bytes(range(256)) * 4)
    student("zero_cells_02", s02=_all("missing", A02))
    nb = nbformat.v4.new_notebook()
    nbformat.write(nb, nb02("zero_cells_02"))
    student("huge_output_02", s02=ok02)
    Sub(A02).solve().add("for _ in range(60):\n    print('x' * 1_000_000)").write(nb02("huge_output_02"))
    student("stderr_flood_05", s05=ok05)
    Sub(A05).solve().add("""
        import sys, warnings
        for _ in range(200):
            sys.stderr.write("warning! " * 100_000)
            sys.__stderr__.write("raw " * 1_000_000)
        warnings.warn("and one real warning")
        """).write(nb05("stderr_flood_05"))
    student("memory_hog_02", s02=_all("pending", A02, forward_euler_step="correct", radius_after="correct",
                                       drift_dt="error"))
    (Sub(A02).solve("forward_euler_step", "radius_after")
     .answer("drift_dt", "return float(np.ones((100_000, 100_000)).sum())")
     .add("hog = [bytearray(2**26) for _ in range(10_000)]").write(nb02("memory_hog_02")))
    student("another_assignment", s02=_all("wrong-assignment", A02), s05=ok05)
    Sub(A05).solve().write(nb02("another_assignment"))
    student("planted_package_02", s02=_all("pending", A02))
    Sub(A02).write(nb02("planted_package_02"))
    fake = root / "planted_package_02" / "course_lib" / "check"
    fake.mkdir(parents=True)
    (fake.parent / "__init__.py").write_text("")
    (fake / "__init__.py").write_text("")
    (fake / "nb02.py").write_text("def __getattr__(name):\n    return lambda fn: print('correct')\n")
    student("nbformat_v3_05", s05=ok05)
    Sub(A05).solve().write(nb05("nbformat_v3_05"), version=3)
    student("odd_extension_02", s02=ok02)
    Sub(A02).solve().write(root / "odd_extension_02" / "02_Forward_Euler (1).ipynb.json")
    student("several_notebooks", s02=ok02, s05=_all("pending", A05))
    Sub(A02).solve().write(nb02("several_notebooks"))
    copy = Sub(A02).write(root / "several_notebooks" / "02_forward_euler-Copy1.ipynb")
    Sub(A05).write(nb05("several_notebooks"))
    Sub(A02).solve().write(root / "several_notebooks" / "scratch" / "Untitled.ipynb")
    os.utime(copy, (2e9, 2e9))  # newer than the real one: the exact name still wins
    student("nested_folders", s02=ok02)
    Sub(A02).solve().write(root / "nested_folders" / A02 / f"{A02}.ipynb")
    student("writes_outside_02", s02=ok02)
    victim = nb02("correct_02")
    Sub(A02).solve().add(f"""
        for target in ["../../victim.txt", {str(victim)!r}, {str(grader_file)!r},
                       {str(root / 'planted.txt')!r}]:
            try:
                with open(target, "w") as fh:
                    fh.write("overwritten by a classmate")
            except OSError as exc:
                print("refused:", target, exc)
        """).write(nb02("writes_outside_02"))
    attempts = """
        def attempt(what, action):
            try:
                action()
                print("REACHED:", what)
            except OSError as exc:  # gaierror included
                print("refused:", what, exc)
        """
    student("network_02", s02=ok02)  # every way out, one after the other: each must fail
    Sub(A02).solve().add(attempts + f"""
        import socket
        attempt("tcp", lambda: socket.create_connection(("127.0.0.1", {net['tcp']}), timeout=2))
        attempt("listen", lambda: socket.create_server(("127.0.0.1", 0)))
        attempt("unix", lambda: socket.socket(socket.AF_UNIX).connect({str(net['unix'])!r}))
        attempt("raw", lambda: socket.socket(socket.AF_INET, socket.SOCK_RAW, socket.IPPROTO_ICMP))
        attempt("getaddrinfo", lambda: socket.getaddrinfo("example.com", 443))
        attempt("gethostbyname", lambda: socket.gethostbyname("pypi.org"))
        query = bytes.fromhex({DNS_QUERY!r})  # what the resolver sends, to a resolver the test runs
        attempt("udp", lambda: socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                .sendto(query, ("127.0.0.1", {net['udp']})))
        """).write(nb02("network_02"))
    student("thread_escape_02", s02=ok02)  # another thread of the worker does the work
    Sub(A02).solve().add(f"""
        import os, socket, threading, time
        seen = []
        def attempt():
            if seen:
                return
            seen.append("thread " + threading.current_thread().name)
            for what, action in [
                    ("write", lambda: open({str(grader_file)!r}, "w").write("written by a thread")),
                    ("tcp", lambda: socket.create_connection(("127.0.0.1", {net['tcp']}), timeout=2))]:
                try:
                    action()
                    seen.append("REACHED: " + what)
                except OSError as exc:
                    seen.append(f"refused: {{what}} {{exc}}")
        for thread in threading.enumerate():  # what each other thread calls now calls attempt
            for cell in getattr(getattr(thread, "_target", None), "__closure__", None) or ():
                if callable(cell.cell_contents):
                    cell.cell_contents = lambda *a, real=cell.cell_contents: (attempt(), real(*a))[1]
        time.sleep(1.2)
        attempt()  # from here if no other thread did
        print(*seen, sep=chr(10))
        """).write(nb02("thread_escape_02"))
    student("uses_reference_02", s02=_all("pending", A02, forward_euler_step="incorrect",
                                           radius_after="incorrect", drift_dt="correct"))
    (Sub(A02).solve("drift_dt").answer("forward_euler_step", "return cl.forward_euler(f, t, y, dt)")
     .answer("radius_after", "return check.radius_formula(r0, dt, n)").write(nb02("uses_reference_02")))
    student("mutates_input_02", s02=_all("pending", A02, forward_euler_step="incorrect",
                                          radius_after="correct", drift_dt="correct"))
    (Sub(A02).solve("radius_after", "drift_dt")
     .answer("forward_euler_step", "y += dt * f(t, y)\nreturn y").write(nb02("mutates_input_02")))
    student("odd_returns_05", s05=_all("correct", A05, impact_time="incorrect"))
    (Sub(A05).solve(*(n for n in EX[A05] if n != "impact_time"))
     .answer("impact_time", "return (x for x in t)").write(nb05("odd_returns_05")))
    student("odd_returns_02", s02=_all("pending", A02, forward_euler_step="correct", radius_after="incorrect",
                                        drift_dt="incorrect"))
    (Sub(A02).solve("forward_euler_step").answer("radius_after", "return {'r': r0 * (1 + dt**2) ** (n / 2)}")
     .answer("drift_dt", "return '0.01'").write(nb02("odd_returns_02")))
    student("renamed_function_02", s02=_all("correct", A02, forward_euler_step="missing",
                                            observed_order="pending"))
    (Sub(A02).solve().edit("forward_euler_step", "def forward_euler_step(", "def my_step(")
     .write(nb02("renamed_function_02")))
    student("exit_in_exercise_02", s02=_all("pending", A02, forward_euler_step="correct",
                                             radius_after="correct", drift_dt="error"))
    (Sub(A02).solve("forward_euler_step", "radius_after")
     .answer("drift_dt", "import sys\nsys.exit('giving up')").write(nb02("exit_in_exercise_02")))
    student("nothing_handed_in")
    (root / "nothing_handed_in" / "README.txt").write_text("I will hand in next week")
    student("symlink_to_solution")
    (root / "symlink_to_solution" / f"{A02}.ipynb").symlink_to(ROOT / "solutions" / f"{A02}.ipynb")
    return expected
