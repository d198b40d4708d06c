"""Grading a synthetic class locally and on a Dask cluster; resuming interrupted runs.

The synthetic class (:mod:`course_lib.instructor.synth`) has every kind of answer the
grader's tests know (right, wrong, crashing, looping, tampering, huge output, missing):
each gets its expected status in a local run; a run on a two-worker ``LocalCluster`` with
one worker killed in the middle, and a cluster run interrupted then resumed by the command
line given the scheduler's address, each of a few of its students (a submission is one
task however many there are), write the local gradebook's rows of those students, row for
row; and an interrupted
local run resumes where it stopped (with a stand-in for the sandbox, so that each way of
stopping costs nothing).
"""

import csv
import io
import os
import queue
import signal
import socket
import threading
import time

import pytest
from notebook_helpers import ROOT

from course_lib.instructor import grade
from course_lib.instructor.cluster import LibraryMismatch, grade_remote
from course_lib.instructor.journal import Journal, grading_modules, library_files, row_from_json, row_to_json
from course_lib.instructor.sandbox import Limits, Run
from course_lib.instructor.submissions import Cell, Notebook
from course_lib.instructor.synth import KINDS, kinds_for, synth_class
from course_lib.instructor.verdicts import FIELDS, Row

LIMITS = Limits(deadline=60, cell_s=6, exercise_s=1.0, memory_mb=1024)  # what _cli_limits() passes
SOLUTIONS = ROOT / "solutions"
N = len(KINDS)  # students: each kind once (a few kinds prove local and cluster runs agree)


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    return synth_class(tmp_path_factory.mktemp("synth"), N, solutions=SOLUTIONS)


@pytest.fixture(scope="module")
def local(synthetic, tmp_path_factory):
    out = tmp_path_factory.mktemp("local") / "grades.csv"
    rows = grade.grade_class([synthetic["submissions"]], out, solutions=SOLUTIONS, limits=LIMITS, jobs=2,
                             progress=False)
    return rows, out.read_bytes()


def test_the_synthetic_class_has_every_kind_and_is_reproducible(synthetic, tmp_path):
    assert set(synthetic["kinds"].values()) == set(KINDS)
    assert kinds_for(200, seed=3) == kinds_for(200, seed=3) != kinds_for(200, seed=4)
    again = synth_class(tmp_path, N, solutions=SOLUTIONS)
    for student in synthetic["kinds"]:
        for mine, theirs in ((synthetic["submissions"] / student, again["submissions"] / student),):
            assert sorted(p.name for p in mine.iterdir()) == sorted(p.name for p in theirs.iterdir())
    with pytest.raises(ValueError, match="not empty"):
        synth_class(tmp_path, 3, solutions=SOLUTIONS)
    with pytest.raises(ValueError, match="positive integer"):
        synth_class(tmp_path / "x", 0, solutions=SOLUTIONS)


def test_each_kind_gets_its_expected_status(synthetic, local):
    rows, _ = local
    with synthetic["expected"].open() as fh:
        expected = {(r["student"], r["exercise"]): r["status"] for r in csv.DictReader(fh)}
    got = {(r.student, r.exercise): r.status for r in rows}
    assert got == expected
    looping = next(r for r in rows if synthetic["kinds"][r.student] == "looping")
    assert f"did not finish within {LIMITS.exercise_s:g} s" in looping.message
    huge = next(r for r in rows if synthetic["kinds"][r.student] == "huge_output")
    assert any(cell.get("dropped", 0) > 50_000_000 for cell in huge.details["run"].cells.values())


@pytest.fixture(scope="module")
def dask_cluster():
    """One two-worker LocalCluster (one process and one thread each) for this file's tests.

    A LocalCluster hard-closes the nanny of a worker that died if, ``lost-worker-timeout``
    (15 s) later, its view shows no worker of that name: when a test killed a worker and
    the next test killed the one its nanny had started in its place, the first timer
    fired between the second death and the restart and closed the nanny for good (a
    fresh-clone run on a loaded machine saw the cluster stay at one worker). The nannies
    restart their workers themselves, so the timer is pushed past the tests."""
    distributed = pytest.importorskip("distributed")
    import dask
    with dask.config.set({"distributed.deploy.lost-worker-timeout": "1h"}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield cluster, client


def _cli_limits() -> list[str]:
    return ["--timeout", str(LIMITS.deadline), "--cell-timeout", str(LIMITS.cell_s),
            "--exercise-timeout", str(LIMITS.exercise_s), "--memory", str(LIMITS.memory_mb)]


@pytest.mark.parametrize(("address", "says"), [
    ("closed", "cannot reach 'tcp://127.0.0.1:{port}' (Connection refused)"),
    ("nonsense", "'nonsense' is not a scheduler address (missing port number"),
])
def test_an_unreachable_scheduler_stops_at_once_with_a_clear_error(synthetic, tmp_path, capsys, address,
                                                                   says):
    pytest.importorskip("distributed")
    from course_lib.instructor.__main__ import main

    with socket.socket() as s:  # a port nothing listens on (bound, then closed)
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}" if address == "closed" else address
    out = tmp_path / "grades.csv"
    out.write_text("an earlier run's gradebook")
    start = time.monotonic()
    code = main(["grade", str(synthetic["submissions"]), "--out", str(out), "--solutions", str(SOLUTIONS),
                 "--no-progress", "--scheduler", address])
    seconds = time.monotonic() - start
    err = capsys.readouterr().err
    assert code == 2 and "error: scheduler: " + says.format(port=port) in err, err
    assert "start the scheduler" in err and "resume" not in err
    assert seconds < 15  # not the Dask client's 30 s of retries; the probe alone waits <= 5 s
    assert out.read_text() == "an earlier run's gradebook" and not (tmp_path / "grades.csv.journal").exists()


_APPEND = Journal.append


def _appended(monkeypatch, hook=None) -> list:
    """Record the submissions whose rows the client writes to the journal; ``hook(n)`` is
    called after the n-th one is written."""
    keys: list = []
    real = _APPEND  # not an earlier test's stand-in

    def append(self, key, digest, rows):
        real(self, key, digest, rows)
        keys.append(key)
        if hook is not None:
            hook(len(keys))

    monkeypatch.setattr(Journal, "append", append)
    return keys


def _students(synthetic, *kinds: str) -> list[str]:
    """One student of each of ``kinds`` (a cluster run of a few proves what a run of all
    would: each submission is one task, graded alike)."""
    return sorted(next(s for s, k in synthetic["kinds"].items() if k == kind) for kind in kinds)


def _rows_of(gradebook: bytes, students: list[str]) -> list[dict]:
    """The gradebook's rows of ``students``, in its order (the header checked too)."""
    table = list(csv.DictReader(io.StringIO(gradebook.decode("utf-8"))))
    assert table and list(table[0]) == FIELDS
    return [r for r in table if r["student"] in students]


def _grade_tasks_on(client) -> list[str]:
    return client.run_on_scheduler(lambda dask_scheduler: [str(k) for k in dask_scheduler.tasks
                                                           if str(k).startswith("grade-")])


def test_an_interrupted_cluster_run_resumes_on_the_command_line(synthetic, local, dask_cluster, tmp_path,
                                                               monkeypatch, capsys):
    """A run on the cluster (four students) is interrupted; the command line, given the
    scheduler's address, resumes it where it stopped and writes the one-machine gradebook's
    rows, row for row."""
    from course_lib.instructor.__main__ import main

    cluster, client = dask_cluster
    out = tmp_path / "grades.csv"
    students = _students(synthetic, "right", "wrong", "crashing", "tampering")

    def interrupt(n):
        if n == 2:
            raise KeyboardInterrupt  # Ctrl-C with submissions in flight on the cluster

    first = _appended(monkeypatch, interrupt)
    with pytest.raises(KeyboardInterrupt):
        grade.grade_class([synthetic["submissions"]], out, solutions=SOLUTIONS, limits=LIMITS,
                          progress=False, scheduler=client, only=students)
    assert len(first) == 2 and (tmp_path / "grades.csv.journal").exists()
    with out.open() as fh:  # a valid gradebook of what was graded (the last one may be only in the journal)
        assert {first[0][0]} <= {r["student"] for r in csv.DictReader(fh)} <= {s for s, _ in first}
    deadline = time.monotonic() + 30
    while _grade_tasks_on(client) and time.monotonic() < deadline:  # the tasks in flight were cancelled
        time.sleep(0.1)
    assert not _grade_tasks_on(client)
    capsys.readouterr()
    second = _appended(monkeypatch)
    monkeypatch.chdir(tmp_path)
    code = main(["grade", str(synthetic["submissions"]), "--out", str(out), "--solutions", str(SOLUTIONS),
                 *_cli_limits(), "--no-progress", "--scheduler", cluster.scheduler_address,
                 "--student", *students])
    printed = capsys.readouterr()
    assert code == 0, printed.err[-3000:]
    assert f"resuming: 2 of {len(students)} submissions" in printed.err
    assert not set(first) & set(second) and len(first) + len(second) == len(students)  # each once
    rows = _rows_of(out.read_bytes(), students)
    assert rows == _rows_of(local[1], students)  # the one-machine gradebook's rows, row for row
    assert len(rows) == len(_rows_of(out.read_bytes(), list(synthetic["kinds"])))  # no other student
    assert "wrote " in printed.out and (tmp_path / "grades-report.html").exists()
    assert not (tmp_path / "grades.csv.journal").exists()


def _dependencies(dask_scheduler) -> dict[str, list[str]]:
    """Each task the scheduler holds -> the keys of the data it needs."""
    return {str(key): [str(d.key) for d in ts.dependencies] for key, ts in dask_scheduler.tasks.items()}


def _busy(client) -> list[str]:
    """The workers with a grading task in hand, once the scheduler has placed every task the
    client is waiting for (a task submitted a moment ago may not be placed yet)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if busy := [w for w, keys in client.processing().items() if keys]:
            return busy
        if not any(f.status == "pending" for f in client.futures.values()):
            return []
        time.sleep(0.05)
    return []


def _holding(client):
    """``(state, worker)``: the client's state of a finished grading result no one has taken
    yet (the client releases each result it takes) and the worker that holds it, after
    waiting up to a minute for one."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        held = [(client.futures[key], ws[0]) for key, ws in client.who_has().items()
                if str(key).startswith("grade-") and ws and key in client.futures]
        if held and held[0][0].status == "finished":
            time.sleep(0.2)  # as_completed has queued it as finished by now: the race to test
            return held[0]
        time.sleep(0.05)
    return None


@pytest.mark.parametrize("victim", ["busy", "holding"])
def test_a_cluster_with_a_killed_worker_writes_the_local_gradebook(synthetic, local, dask_cluster, tmp_path,
                                                                   monkeypatch, victim):
    """The client is held after the first result it writes until a worker has been killed
    (no task in flight needs data held only by workers), so the kill always lands in the
    middle of the run: on a worker with a task in hand ("busy"), or on one that holds a
    finished result which the client has seen complete but not taken yet ("holding", the
    case a fresh-clone run met by chance): either must be computed again."""
    _, client = dask_cluster
    out = tmp_path / "grades.csv"
    students = _students(synthetic, "right", "wrong", "looping")  # three tasks on two workers
    waiting: queue.Queue = queue.Queue()  # one event per held result; None: the run ended
    killed: list = []

    def hold(n):
        if not killed:
            go_on = threading.Event()
            waiting.put(go_on)
            assert go_on.wait(120), "the test did not let the client go on"

    _appended(monkeypatch, hold)
    done: dict = {}

    def run():
        try:
            done["rows"] = grade.grade_class([synthetic["submissions"]], out, solutions=SOLUTIONS,
                                             limits=LIMITS, progress=False, scheduler=client, only=students)
        except BaseException as exc:  # reported by the main thread
            done["error"] = exc
        finally:
            waiting.put(None)

    thread = threading.Thread(target=run)
    thread.start()
    try:
        while (go_on := waiting.get(timeout=300)) is not None:
            if victim == "busy":
                busy = _busy(client) if not killed else []
            else:
                held = _holding(client) if not killed else None
                busy = [held[1]] if held else []
            if busy and not killed:  # the client is held: no result of this run is taken meanwhile
                # no task may need data that lives only on workers (scattered): Dask's memory
                # manager trims its replicas, and the kill below would then cancel the task
                deps = client.run_on_scheduler(_dependencies)
                assert deps and not any(deps.values()), deps
                pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                os.kill(pid, signal.SIGKILL)
                killed.append(busy[0])
                if victim == "holding":  # the client hears of the lost result before it goes on
                    deadline = time.monotonic() + 120
                    while held[0].status == "finished" and time.monotonic() < deadline:
                        time.sleep(0.01)
                    assert held[0].status in ("lost", "pending"), held[0].status
            go_on.set()
    finally:
        thread.join(timeout=300)
    assert "error" not in done, done.get("error")
    assert killed, f"no worker was {victim} while the client was waiting"
    # the nanny starts a new worker process: seconds on a quiet machine, over a minute on
    # a loaded one (a fresh-clone make test saw it miss a 60 s wait)
    # (wait_for_workers(2) alone can return while the scheduler still lists the killed one)
    deadline = time.monotonic() + 240
    while (killed[0] in client.nthreads() or len(client.nthreads()) < 2) and time.monotonic() < deadline:
        time.sleep(0.5)
    assert killed[0] not in client.nthreads() and len(client.nthreads()) == 2  # the nanny replaced it
    rows = _rows_of(out.read_bytes(), students)
    assert rows == _rows_of(local[1], students)  # row for row: nothing lost, nothing twice
    assert len(rows) == len(_rows_of(out.read_bytes(), list(synthetic["kinds"])))  # no other student
    keys = [(r.student, r.assignment, r.exercise) for r in done["rows"]]
    assert len(keys) == len(set(keys)) == len(rows)


def test_a_worker_with_another_course_lib_refuses_to_grade(synthetic):
    kit = grade.load_kit(SOLUTIONS)
    task = grade.Task("s0001", kit["05_newtons_second_law"], None, "nothing")
    mine = library_files(grading_modules(["course_lib.check.nb05"]))
    assert {"course_lib.check.nb05", "course_lib.lessons.nb05_newton", "course_lib.instructor.verdicts",
            "course_lib.integrators", "course_lib"} <= set(mine)  # what 05's verdicts depend on
    others = [n for n in mine if n.startswith("course_lib.check.nb") and n != "course_lib.check.nb05"]
    assert not others
    assert grade_remote(task, None, kit, LIMITS, mine)[0].status == "missing"
    with pytest.raises(LibraryMismatch, match=r"course_lib\.fields"):
        grade_remote(task, None, kit, LIMITS, {**mine, "course_lib.fields": "0" * 64})


# --- resuming (the sandbox replaced by a stand-in that records who was graded) ------------

def _fake(calls: list, stop_at: int | None = None):
    def fake(task, runtime, kit, limits):
        if stop_at is not None and len(calls) == stop_at:
            raise KeyboardInterrupt
        calls.append(task.student)
        run = Run(cells={0: {"status": "ok", "output": f"hello {task.student}", "dropped": 0}}, attempts=1)
        nb = Notebook([Cell(0, "code", "print('hello')", "a1")])
        return [Row(task.student, task.assignment.name, e.name, "correct" if i else "incorrect", e.points,
                    f"verdict {i}", str(task.path or ""), 1, 2,
                    details={"run": run, "notebook": nb, "cell": 0, "counts": (1, 2),
                             "failed_cases": ["case 1\n  hint: x"]})
                for i, e in enumerate(task.assignment.exercises)]
    return fake


class _NoSandbox:
    """Stands in for the sandbox's Runtime (a copy of course_lib, a warmed matplotlib: seconds
    of CPU per run) where a stand-in grades."""

    landlock = 1

    def cleanup(self):
        pass


def _grade(synthetic, out, **options):
    options = {"limits": LIMITS, **options}
    return grade.grade_class([synthetic["submissions"]], out, solutions=SOLUTIONS, jobs=1, progress=False,
                             **options)


def test_an_interrupted_run_resumes_where_it_stopped(synthetic, tmp_path, monkeypatch):
    monkeypatch.setattr(grade, "Runtime", _NoSandbox)
    calls: list = []
    monkeypatch.setattr(grade, "grade_task", _fake(calls))
    _grade(synthetic, tmp_path / "whole.csv", feedback_dir=tmp_path / "fb-whole")
    whole = (tmp_path / "whole.csv").read_bytes()
    assert not (tmp_path / "whole.csv.journal").exists() and len(calls) == N

    out = tmp_path / "grades.csv"
    first: list = []
    monkeypatch.setattr(grade, "grade_task", _fake(first, stop_at=3))
    with pytest.raises(KeyboardInterrupt):
        _grade(synthetic, out)
    assert len(first) == 3 and (tmp_path / "grades.csv.journal").exists()
    with out.open() as fh:  # a valid gradebook of what was graded
        assert {r["student"] for r in csv.DictReader(fh)} == set(first)
    second: list = []
    monkeypatch.setattr(grade, "grade_task", _fake(second))
    rows = _grade(synthetic, out, feedback_dir=tmp_path / "fb")
    assert sorted(first + second) == sorted(calls)  # each student graded once over both runs
    assert out.read_bytes() == whole and not (tmp_path / "grades.csv.journal").exists()
    resumed = next(r for r in rows if r.student == first[0])
    assert isinstance(resumed.details["run"], Run) and resumed.details["run"].cells[0]["output"]
    for student in calls:  # feedback from the journal's rows equals feedback graded now
        assert (tmp_path / "fb" / f"{student}.md").read_text() == \
            (tmp_path / "fb-whole" / f"{student}.md").read_text()


def test_a_journal_cut_short_changed_files_and_other_limits_are_regraded(synthetic, tmp_path, monkeypatch):
    monkeypatch.setattr(grade, "Runtime", _NoSandbox)
    out = tmp_path / "grades.csv"
    journal = tmp_path / "grades.csv.journal"
    first: list = []
    monkeypatch.setattr(grade, "grade_task", _fake(first, stop_at=4))
    with pytest.raises(KeyboardInterrupt):
        _grade(synthetic, out)
    journal.write_bytes(journal.read_bytes()[:-40])  # the machine died while writing a line
    changed = next(s for s in first[:3] if synthetic["kinds"][s] != "missing")
    notebook = next((synthetic["submissions"] / changed).glob("*.ipynb"))
    saved = journal.read_bytes()
    notebook.write_text(notebook.read_text() + " ")  # handed in again
    try:
        again: list = []
        monkeypatch.setattr(grade, "grade_task", _fake(again))
        _grade(synthetic, out)
        assert first[3] in again and changed in again and len(again) == N - 2
        journal.write_bytes(saved)
        fresh: list = []
        monkeypatch.setattr(grade, "grade_task", _fake(fresh))
        _grade(synthetic, out, limits=Limits(deadline=61))  # another run: nothing is reused
        assert len(fresh) == N
        journal.write_bytes(saved)
        fresh.clear()
        _grade(synthetic, out, resume=False)  # --restart
        assert len(fresh) == N
    finally:
        notebook.write_text(notebook.read_text()[:-1])


def test_rows_survive_the_journal_exactly():
    run = Run(cells={3: {"status": "killed", "error": "x"}}, exercises={"f": {"calls": [1], "found": True}},
              changes=["c"], violation=None, landlock=6, seconds=1.5, attempts=2)
    row = Row("ann", "05", "f", "error", 2, "why", "/x.ipynb", 1, 3,
              details={"run": run, "notebook": Notebook([Cell(0, "code", "x = 1", None)], "n"),
                       "failed_cases": ["a"], "cell": 0, "note": ""})
    back = row_from_json(row_to_json(row))
    assert back.csv() == row.csv() and back.details["run"].cells == run.cells
    assert back.details["run"].exercises == {"f": {"found": True}}  # recorded calls are not kept
    assert back.details["notebook"] == row.details["notebook"]


def test_synth_class_command_line(tmp_path, capsys):
    from course_lib.instructor.__main__ import main

    assert main(["synth-class", str(tmp_path / "c"), "--n", "9", "--seed", "2"]) == 0
    out = capsys.readouterr().out
    assert "wrote 9 students" in out and (tmp_path / "c" / "roster.csv").exists()
    with (tmp_path / "c" / "roster.csv").open() as fh:
        assert [r["student"] for r in csv.DictReader(fh)] == [f"s{i:04d}" for i in range(1, 10)]
    assert main(["synth-class", str(tmp_path / "d"), "--n", "2", "--assignment", "99_nothing"]) == 2
    assert "unknown ['99_nothing']" in capsys.readouterr().err
