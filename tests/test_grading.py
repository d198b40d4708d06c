"""Grading pieces that need no worker: reading files, the codec, the scans, replays, CSV.

The replay test runs every exercise of every kit notebook through the same record ->
JSON -> replay path the grader uses, in this process: the solutions must come out
correct and the stubs pending, so no check in the kit depends on anything a replay
cannot carry.
"""

import ast
import contextlib
import copy
import csv
import io
import json
import platform
import subprocess
import sys
import textwrap

import nbformat
import numpy as np
import pytest
from notebook_helpers import ROOT

from course_lib.check import evaluate, exercise
from course_lib.instructor import codec, grade, landlock
from course_lib.instructor.kit import identify, load_kit
from course_lib.instructor.notebooks import make_student_notebook
from course_lib.instructor.recorder import Recorder
from course_lib.instructor.scan import answer_binding, strip_magics, tamper_findings
from course_lib.instructor.submissions import (
    Cell,
    Student,
    Unreadable,
    choose,
    normalized,
    read_notebook,
    students,
)
from course_lib.instructor.verdicts import FIELDS, Row, judge

KIT = load_kit(ROOT / "solutions")


# --- reading submissions ---------------------------------------------------------------

@pytest.mark.parametrize("content,reason", [
    (b"", "empty"),
    (b"   \n", "empty"),
    (b"{\"cells\": [", "not valid JSON"),
    (bytes(range(256)), "not UTF-8"),
    (b"[1, 2, 3]", "not a notebook"),
    (b'{"answers": 42}', "not a notebook"),
    (b'{"nbformat": 4, "cells": "no"}', "not a list"),
    (b'{"nbformat": 4, "cells": [42]}', "cell 0 is not a notebook cell"),
    (b'{"nbformat": 4, "cells": [{"cell_type": "code", "source": 7}]}', "neither text"),
    (b'{"nbformat": 2, "worksheets": "x"}', "cannot be upgraded"),
])
def test_unreadable_files_say_why(tmp_path, content, reason):
    path = tmp_path / "nb.ipynb"
    path.write_bytes(content)
    with pytest.raises(Unreadable, match=reason):
        read_notebook(path)


def test_too_large_file_is_refused_before_reading(tmp_path):
    path = tmp_path / "big.ipynb"
    path.write_bytes(b" " * 2048)
    with pytest.raises(Unreadable, match="over the"):
        read_notebook(path, max_bytes=1024)


def test_v3_notebooks_are_upgraded_and_sources_joined(tmp_path):
    nb = nbformat.read(ROOT / "solutions" / "02_forward_euler.ipynb", as_version=4)
    nbformat.write(nbformat.convert(copy.deepcopy(nb), 3), tmp_path / "v3.ipynb", version=3)
    read = read_notebook(tmp_path / "v3.ipynb")
    assert "upgraded from nbformat 3" in read.note
    assert [c.source for c in read.code] == [c.source for c in nb.cells if c.cell_type == "code"]
    raw = {"nbformat": 4, "nbformat_minor": 5, "metadata": {},
           "cells": [{"cell_type": "code", "source": ["a = 1\n", "b = 2"], "id": "x"}]}
    (tmp_path / "lines.ipynb").write_text("\ufeff" + json.dumps(raw), "utf-8")  # BOM too
    assert read_notebook(tmp_path / "lines.ipynb").cells == [Cell(0, "code", "a = 1\nb = 2", "x")]


@pytest.mark.parametrize("name", ["02_forward_euler.ipynb", "02_Forward_Euler (1).ipynb",
                                  "02_forward_euler-Copy1.ipynb", "02 forward euler.ipynb.json",
                                  "02_FORWARD_EULER_v2.IPYNB", "02_forward_euler final.txt"])
def test_file_names_normalize_to_the_assignment(name):
    assert normalized(name) == "02_forward_euler"


def test_roster_ignores_hidden_files_checkpoints_and_links(tmp_path):
    (tmp_path / "ann" / ".ipynb_checkpoints").mkdir(parents=True)
    (tmp_path / "ann" / ".ipynb_checkpoints" / "02_forward_euler-checkpoint.ipynb").write_text("{}")
    (tmp_path / "ann" / ".hidden.ipynb").write_text("{}")
    (tmp_path / "ann" / "02_forward_euler.ipynb").write_text("{}")
    (tmp_path / "ann" / "link.ipynb").symlink_to(ROOT / "solutions" / "02_forward_euler.ipynb")
    (tmp_path / "ann" / "linked_dir").symlink_to(ROOT / "solutions")
    (tmp_path / ".git").mkdir()
    roster = students([tmp_path])
    assert [s.name for s in roster] == ["ann"]
    assert [p.name for p in roster[0].files] == ["02_forward_euler.ipynb"]


def test_choose_prefers_the_exact_name_then_content(tmp_path):
    a02 = KIT["02_forward_euler"]
    sol = nbformat.read(a02.path, as_version=4)
    nbformat.write(sol, tmp_path / "mine.ipynb")
    pick = choose(Student("s", [tmp_path / "mine.ipynb"]), a02, KIT)
    assert pick.path.name == "mine.ipynb" and "content" in pick.note
    assert choose(Student("s", []), a02, KIT).path is None


def test_identify_by_ids_functions_or_import():
    nb = read_notebook(ROOT / "notebooks" / "05_newtons_second_law.ipynb")
    assert identify(nb.cells, KIT) == "05_newtons_second_law"
    bare = [Cell(0, "code", "def radius_after(r0, dt, n):\n    return 0")]
    assert identify(bare, KIT) == "02_forward_euler"
    assert identify([Cell(0, "code", "x = 1")], KIT) is None


# --- codec -----------------------------------------------------------------------------

@pytest.mark.parametrize("value", [None, True, 3, -2**80, 1.5, float("inf"), 2 - 1j, "text",
                                   [1, (2.5, "a")], {"X": np.arange(4.0), 3: None},
                                   np.float32(0.25), np.bool_(False), np.zeros((2, 3), complex)])
def test_codec_round_trips_exactly(value):
    back = codec.decode(json.loads(json.dumps(codec.encode(value))))
    assert type(back) is type(value)
    assert codec.fingerprint(back) == codec.fingerprint(value)


def test_codec_flags_opaque_values_as_has_opaque_finds_them():
    # the recorder drops a callback's arguments when the flag is set: it must agree with a
    # walk over the encoded value, at any depth, and "opaque" as data must not set it
    values = [None, "opaque", {"opaque": 1}, [1, ("opaque", {"opaque": "x"})], np.arange(3),
              2**1200, [[[2**1200]]], {"k": (1, object())}, [np.array(["s"]), 1.0],
              {1: {2: {3: np.float64(1.0)}}}, (print,), [np.array([1], dtype=object)], []]
    for value in values:
        encoded, opaque = codec.encode_flagged(value)
        assert encoded == codec.encode(value)
        assert opaque == codec.has_opaque(encoded), value
    assert sum(codec.encode_flagged(v)[1] for v in values) == 6


def test_codec_summary_samples_arrays_as_float_pairs():
    s = codec.summary
    assert s(np.array([1, 2], np.int8))["sample"] == [[1.0, 0.0], [2.0, 0.0]]
    assert s(np.complex64(1 - 2j)) == {"array": "c", "shape": [], "sample": [[1.0, -2.0]]}
    big = s(np.arange(1000.0).reshape(10, 100))
    assert big["shape"] == [10, 100] and [p[0] for p in big["sample"]] == [20.0 * k for k in range(48)]
    assert all(type(x) is float for p in big["sample"] + s(np.bool_(True))["sample"] for x in p)
    assert s(np.zeros(0))["sample"] == [] and s(np.array(["a"])) == {"array": "<U1", "shape": [1]}


def test_codec_same_compares_summaries_within_tolerance():
    s = codec.summary
    x = np.array([1.0, np.nan, -2.5])
    pairs = [(x, x.copy(), True), (x, x * (1 + 1e-9), True), (x, x * (1 + 1e-5), False),
             (x, x[:2], False), ([x, 3, "a"], [x.copy(), 3, "a"], True), ([x, 3], [x, 4], False),
             ({"k": 1.0}, {"k": 1.0 + 1e-12}, True), ({"k": 1.0}, {"j": 1.0}, False),
             (2 + 1j, 2 + 1j, True), (True, 1, False), (None, None, True)]
    for a, b, expected in pairs:
        sa, sb = json.loads(json.dumps(s(a))), json.loads(json.dumps(s(b)))
        assert codec.same(sa, sb) is expected and codec.same(sb, sa) is expected, (a, b)


def test_codec_never_carries_code_or_objects():
    for value in (object(), (x for x in []), np.array([object()]), lambda: 1):
        back = codec.decode(json.loads(json.dumps(codec.encode(value))))
        assert isinstance(back, codec.Opaque)
        with pytest.raises(TypeError):
            np.asarray(back, dtype=float)
    with pytest.raises(ValueError):
        codec.decode({"pickle": "gASVCAAAAAAAAACMBG9zlC4="})
    obj_npy = {"npy": codec._npy(np.arange(3)).replace("A", "B", 1)}
    with pytest.raises(ValueError):
        codec.decode(obj_npy)
    with pytest.raises(codec.EncodingLimit):
        codec.encode(np.zeros(10**6), max_bytes=10**5)


def test_rebuilt_exceptions_keep_name_and_never_stop_the_grader():
    for exc in (ZeroDivisionError("x"), SystemExit(3), KeyboardInterrupt()):
        rebuilt = codec.rebuild_exception(codec.exception_record(exc))
        assert type(rebuilt).__name__ == type(exc).__name__ and isinstance(rebuilt, Exception)
    assert isinstance(codec.rebuild_exception(codec.exception_record(NotImplementedError())),
                      NotImplementedError)


# --- static scans ----------------------------------------------------------------------

def test_kit_notebooks_raise_no_tampering_and_use_no_reference(tmp_path):
    for path in sorted((ROOT / "solutions").glob("*.ipynb")):
        student = tmp_path / path.name
        nbformat.write(make_student_notebook(nbformat.read(path, as_version=4)), student)
        for version in (path, student):
            nb = read_notebook(version)
            assert tamper_findings(nb.cells) == [], version
            if path.stem in KIT:
                a = KIT[path.stem]
                for e in a.exercises:
                    binding = answer_binding(nb.cells, e.name, a.check(e))
                    assert binding.kind == "def" and binding.reference is None, (version, e.name)


TAMPER = {
    "check.RESULTS['nb02.x'] = {}": "modifies course_lib",
    "from course_lib.check import RESULTS": "internals",
    "import course_lib.check as c\nc.Checker.close = None": "modifies course_lib",
    "check.forward_euler_step = print": "modifies course_lib",
    "setattr(check, 'drift_dt', print)": "setattr",
    "np.allclose = lambda *a, **k: True": "imported module",
    "import sys\nsys.modules['course_lib.check'] = None": "replaces modules",
    "import gc\ngc.get_objects()": "searches",
    "import inspect\ninspect.currentframe().f_back": "frames",
    "import os\nos.write(3, b'x')": "raw file descriptors",
    "import signal\nsignal.alarm(0)": "signal",
    "print('\u2705 drift_dt: correct')": "forged verdict",
    "open(cl.__file__)": "course_lib's files",
    "open('../solutions/02_forward_euler.ipynb')": "solutions folder",
    "x = __import__('course_lib')": "__import__",
}


@pytest.mark.parametrize("code", TAMPER, ids=list(TAMPER.values()))
def test_tampering_is_found_without_running_the_code(code):
    head = "import numpy as np\nimport course_lib as cl\nfrom course_lib.check import nb02 as check\n"
    found = tamper_findings([Cell(0, "code", head), Cell(1, "code", code)])
    assert any(TAMPER[code] in f.what for f in found), found


def test_magics_become_harmless_python():
    src = "%matplotlib inline\nfiles = !ls\nif True:\n    !rm -rf /\nx = 1"
    assert strip_magics(src).splitlines()[4] == "x = 1"
    compile(strip_magics(src), "cell", "exec")
    assert "rm" not in strip_magics(src).split("#")[0]


@pytest.mark.parametrize("body,flagged", [
    ("return cl.forward_euler(f, t, y, dt)", "course_lib"),
    ("from course_lib.integrators import forward_euler as fe\n    return fe(f, t, y, dt)", "forward_euler"),
    ("step = cl.forward_euler\n    return step(f, t, y, dt)", "forward_euler"),
    ("return (lambda: check.forward_euler_step)()", "check"),
    ("return y + dt * f(t, y)", None),
    # the library rule is derived: any library call the prompt does not hand over counts
    ("return y + dt * cl.fields.vortex(t, y)", "course_lib.fields.vortex"),
    ("return 2 * cl.backward_euler(f, t, y, dt / 2) - y", "backward_euler"),
    ("return y + dt * f(t, y) if cl.BlowUpError else y", None),
])
def test_reference_use_in_the_grader_and_in_the_check(body, flagged):
    head = "import course_lib as cl\nfrom course_lib.check import nb02 as check\n"
    source = f"def forward_euler_step(f, t, y, dt):\n    {body}\n"
    a02 = KIT["02_forward_euler"]
    check = a02.check(a02.exercises[0])
    binding = answer_binding([Cell(0, "code", head), Cell(1, "code", source)], "forward_euler_step", check)
    namespace = {"__name__": "__main__"}
    exec(compile(head + source, "<cell>", "exec"), namespace)
    verdict = evaluate(check, namespace["forward_euler_step"])
    if flagged:
        assert flagged in binding.reference and "uses the reference" in binding.reference
        assert verdict["status"] == "incorrect" and "uses the reference" in verdict["failed_cases"][0]
    else:
        assert binding.reference is None and verdict["reference"] is None
    # the worker judges through a Recorder, whose bookkeeping runs with the watch paused:
    # the student's function (and what it calls) is still watched, and the watch comes back
    before = sys.getprofile()
    with contextlib.redirect_stdout(io.StringIO()):
        recorded = evaluate(check, Recorder(namespace["forward_euler_step"], 8 << 20))
    assert sys.getprofile() is before and recorded["status"] == verdict["status"]
    if flagged in ("course_lib", "forward_euler", "backward_euler"):  # calls made at run time
        assert "uses the reference" in recorded["reference"]
    elif flagged is None:
        assert recorded["reference"] is None


# --- replaying recorded calls ----------------------------------------------------------

def _record(check, fn) -> dict:
    recorder = Recorder(fn, 8 << 20)
    with contextlib.redirect_stdout(io.StringIO()):
        evaluate(check, recorder)
    return json.loads(json.dumps({"calls": recorder.calls}))


@pytest.mark.parametrize("name", sorted(KIT))
def test_every_kit_exercise_replays_to_the_same_verdict(name):
    a = KIT[name]
    for nb, expected in ((nbformat.read(a.path, as_version=4), "correct"),
                         (make_student_notebook(nbformat.read(a.path, as_version=4)), "pending")):
        code = [c.source for c in nb.cells if c.cell_type == "code"]
        namespace = {"__name__": "__main__"}
        with contextlib.redirect_stdout(io.StringIO()):
            exec(code[0], namespace)
            for src in code:
                if any(f"def {e.name}(" in src for e in a.exercises):
                    exec(src, namespace)
        for e in a.exercises:
            status, message, _ = judge(a.check(e), _record(a.check(e), namespace[e.name]), 10)
            assert status == expected, (name, e.name, message)


def test_replay_keeps_hints_mutations_and_exceptions():
    a02 = KIT["02_forward_euler"]
    check = a02.check(a02.exercises[0])

    def at_end(f, t, y, dt):
        return y + dt * f(t + dt, y)

    def in_place(f, t, y, dt):
        y += dt * f(t, y)
        return y

    def crashes(f, t, y, dt):
        return y[5]

    status, message, _ = judge(check, _record(check, at_end), 10)
    assert status == "incorrect" and "START of the step" in message
    status, message, details = judge(check, _record(check, in_place), 10)
    assert status == "incorrect" and any("changed its input" in c for c in details["failed_cases"])
    status, message, _ = judge(check, _record(check, crashes), 10)
    assert status == "error" and "IndexError" in message


def test_replay_refuses_records_made_with_other_inputs():
    a02 = KIT["02_forward_euler"]
    check = a02.check(a02.exercises[1])
    def fresh():
        return _record(check, lambda r0, dt, n, k: r0 * ((1 - k * dt) ** 2 + dt**2) ** (n / 2))

    assert judge(check, fresh(), 10)[0] == "correct"
    record = fresh()
    record["calls"][1]["sig"] = {"exact": "float:0.0"}
    assert judge(check, record, 10)[0] == "tampered"
    record = fresh()
    record["calls"] = record["calls"][:2]
    assert judge(check, record, 10)[0] == "tampered"
    record["calls"][-1] = {"sig": record["calls"][-1]["sig"], "timeout": True}
    assert judge(check, {**record, "timeout": True}, 10)[0] == "timeout"


@exercise
def three_grids(ck, func) -> None:
    """A check that watches what the answer does with a function it is given."""
    asked = []

    def run(h):
        asked.append(float(h))
        return np.exp(-np.arange(3.0) * h)

    got = func(run, 0.1)
    ck.expect(sorted(asked) == [0.025, 0.05, 0.1], "runs dt, dt/2 and dt/4", f"ran {asked}")
    ck.close(got, np.exp(-np.arange(3.0) * 0.025), "the finest run")


def test_replay_repeats_calls_to_function_arguments():
    def good(run, dt):
        runs = [run(dt), run(dt / 2), run(dt / 4)]
        return runs[-1]

    def lazy(run, dt):
        return run(dt / 4)

    assert judge(three_grids, _record(three_grids, good), 10)[0] == "correct"
    status, message, _ = judge(three_grids, _record(three_grids, lazy), 10)
    assert status == "incorrect" and "ran [0.025]" in message
    record = _record(three_grids, good)
    record["calls"][0]["callbacks"][1]["sig"] = codec.summary(np.zeros(3))
    assert judge(three_grids, record, 10)[0] == "tampered"


# --- sandbox pieces and the gradebook ----------------------------------------------------

@pytest.mark.skipif(landlock.abi_version() == 0, reason="kernel without Landlock")
def test_landlock_confines_a_process(tmp_path):
    (tmp_path / "inside").mkdir()
    secret = tmp_path / "secret.txt"
    secret.write_text("solution")
    code = textwrap.dedent(f"""
        import sys
        from course_lib.instructor import landlock
        landlock.restrict([sys.prefix, sys.base_prefix, "/usr", "/lib"], [{str(tmp_path / 'inside')!r}])
        open({str(tmp_path / 'inside' / 'ok.txt')!r}, "w").write("fine")
        for action in (lambda: open({str(secret)!r}).read(), lambda: open({str(secret)!r}, "w")):
            try:
                action()
                print("ALLOWED")
            except PermissionError:
                print("denied")
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["denied", "denied"]
    assert (tmp_path / "inside" / "ok.txt").read_text() == "fine" and secret.read_text() == "solution"


@pytest.mark.skipif(sys.platform != "linux" or platform.machine() not in ("x86_64", "aarch64"),
                    reason="seccomp filters: Linux on x86_64 or aarch64")
def test_seccomp_takes_every_socket_away_from_every_thread():
    code = textwrap.dedent("""
        import ctypes, socket, threading
        from course_lib.instructor import seccomp
        go, seen = threading.Event(), []
        def late():  # a thread that exists before the filter is installed
            go.wait()
            try:
                socket.socket()
                seen.append("ALLOWED")
            except PermissionError:
                seen.append("denied")
        thread = threading.Thread(target=late)
        thread.start()
        print(seccomp.deny_sockets())
        go.set()
        thread.join()
        print(*seen)
        for family, kind in [(socket.AF_INET, socket.SOCK_STREAM), (socket.AF_INET, socket.SOCK_DGRAM),
                             (socket.AF_INET6, socket.SOCK_DGRAM), (socket.AF_UNIX, socket.SOCK_STREAM),
                             (socket.AF_NETLINK, socket.SOCK_RAW)]:
            try:
                socket.socket(family, kind)
                print("ALLOWED")
            except PermissionError:
                print("denied")
        a, b = socket.socketpair()  # reaches nothing outside the process
        a.send(b"ok")
        print(b.recv(2).decode())
        libc = ctypes.CDLL(None, use_errno=True)
        if seccomp.platform.machine() == "x86_64":  # the x32 ABI's socket(): around the filter?
            print("denied" if libc.syscall(0x40000000 | 41, 2, 1, 0) == -1 and ctypes.get_errno() == 1
                  else "ALLOWED")
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    out = out.split()
    assert out[0] == "True" and out[1] == "denied"
    assert set(out[2:7]) == {"denied"} and out[7] == "ok" and "ALLOWED" not in out


def test_an_interrupted_run_leaves_a_valid_gradebook(tmp_path, monkeypatch):
    for name in ("amy", "ben", "cy"):
        (tmp_path / "class" / name).mkdir(parents=True)
        nbformat.write(nbformat.read(ROOT / "notebooks" / "02_forward_euler.ipynb", as_version=4),
                       tmp_path / "class" / name / "02_forward_euler.ipynb")
    calls = []

    def fake(task, runtime, kit, limits):
        calls.append(task.student)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return [Row(task.student, task.assignment.name, e.name, "pending", e.points, "stub")
                for e in task.assignment.exercises]

    monkeypatch.setattr(grade, "grade_task", fake)
    out = tmp_path / "grades.csv"
    with pytest.raises(KeyboardInterrupt):
        grade.grade_class([tmp_path / "class"], out, solutions=ROOT / "solutions", jobs=1, progress=False)
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == FIELDS and len(rows) == 2 * len(KIT["02_forward_euler"].exercises)
    assert {r["student"] for r in rows} == set(calls[:2])


def _holds_ast_lock(node, parents) -> bool:
    return any(isinstance(p, ast.With) and any("AST_LOCK" in ast.unparse(item.context_expr)
                                               for item in p.items) for p in parents[node])


def test_every_ast_conversion_in_the_grader_takes_the_lock():
    """The grader scans from several threads, and CPython 3.11's AST converter keeps its
    recursion depth per interpreter (python/cpython#106905: "AST constructor recursion depth
    mismatch" once broke a grading run here). Every ``ast.parse`` and every ``compile`` of an
    AST in a module the grader's threads use must sit inside ``with AST_LOCK``."""
    threaded = ["scan", "kit", "grade", "verdicts", "submissions", "feedback", "report",
                "recorder", "policy", "codec", "sandbox", "journal", "cluster", "task"]
    unguarded = []
    for name in threaded:
        path = ROOT / "course_lib" / "instructor" / f"{name}.py"
        tree = ast.parse(path.read_text())
        parents: dict = {}
        stack = [(tree, [])]
        while stack:
            node, chain = stack.pop()
            parents[node] = chain
            stack += [(child, [*chain, node]) for child in ast.iter_child_nodes(node)]
        for node in parents:
            if not isinstance(node, ast.Call):
                continue
            func = ast.unparse(node.func)
            if func == "ast.parse" or (func == "compile" and node.args
                                       and not isinstance(node.args[0], ast.Constant)
                                       and "ast." in ast.unparse(node.args[0])):
                if not _holds_ast_lock(node, parents):
                    unguarded.append(f"{name}.py:{node.lineno}: {ast.unparse(node)[:60]}")
    assert not unguarded, "\n".join(unguarded)
    from course_lib.instructor import kit, scan
    assert kit.AST_LOCK is scan.AST_LOCK
