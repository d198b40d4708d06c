"""Grading a whole class folder of broken submissions (tests/grading/corpus.py).

One run of :func:`grade_class` over more than 25 kinds of submission, with short time
limits, on a two-worker ``dask.distributed`` LocalCluster: every submission is graded
inside a Dask worker process, so the sandbox's promises (limits, Landlock, no network,
signed messages, verdicts replayed in the grader) are tested where a cluster runs them.
The tests then check every row, that no original file changed, that no tampering earned
a point, and that the feedback files and the class report exist and say what they
should. (tests/test_grading_cluster.py proves a local run writes the same gradebook.)
"""

import csv
import hashlib
import socket
import time
from pathlib import Path
from types import SimpleNamespace

import nbformat
import pytest
from grading.corpus import A02, A05, EX, build
from notebook_helpers import ROOT

from course_lib.instructor import landlock
from course_lib.instructor.grade import grade_class
from course_lib.instructor.sandbox import COUNTS_QUEUEING, Limits
from course_lib.instructor.verdicts import FIELDS, STATUSES

#: Budgets in CPU seconds: every cell and check of the correct hand-ins here passes at 1.5 s
#: (measured), so 4 s leaves a margin of more than 2.5; the loops that must be stopped spin
#: for the whole budget, so a larger one only burns CPU.
LIMITS = Limits(deadline=60, cell_s=4, exercise_s=4, memory_mb=1024, grace=1.0)


def digest(folder: Path) -> dict[str, str]:
    out = {}
    for path in sorted(folder.rglob("*")):
        if path.is_symlink():
            out[str(path.relative_to(folder))] = "-> " + str(path.readlink())
        elif path.is_file():
            out[str(path.relative_to(folder))] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def kit_digest() -> dict[str, str]:
    return {name: hashlib.sha256((ROOT / "solutions" / f"{name}.ipynb").read_bytes()).hexdigest()
            for name in (A02, A05)}


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as local, distributed.Client(local) as client:
        yield client


@pytest.fixture(scope="module")
def services(tmp_path_factory):
    """Services on the grader's machine that hostile submissions try to reach: a TCP
    listener and a UDP "resolver" on 127.0.0.1, and a Unix socket. Nothing may reach them."""
    folder = tmp_path_factory.mktemp("services")
    with socket.create_server(("127.0.0.1", 0)) as tcp, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp, \
            socket.socket(socket.AF_UNIX) as unix:
        udp.bind(("127.0.0.1", 0))
        unix.bind(str(folder / "service.sock"))
        unix.listen()
        for s in (tcp, udp, unix):
            s.setblocking(False)
        yield SimpleNamespace(tcp=tcp, udp=udp, unix=unix, net={
            "tcp": tcp.getsockname()[1], "udp": udp.getsockname()[1], "unix": folder / "service.sock"})


#: Submissions that try the network, or another thread of the worker, and the attempts each
#: prints as "refused: <what> <error>".
NETWORK = {"network_02": ["tcp", "listen", "unix", "raw", "getaddrinfo", "gethostbyname", "udp"],
           "thread_escape_02": ["write", "tcp"]}


@pytest.fixture(scope="module")
def graded(tmp_path_factory, cluster, services):
    base = tmp_path_factory.mktemp("class")
    root = base / "submissions"
    grader_file = base / "grader" / "notes.txt"
    grader_file.parent.mkdir()
    grader_file.write_text("the instructor's notes")
    expected = build(root, grader_file, services.net)
    before, kit_before = digest(base), kit_digest()
    out = base / "out"
    start = time.monotonic()
    rows = grade_class([root], out / "grades.csv", solutions=ROOT / "solutions", assignments=[A02, A05],
                       limits=LIMITS, feedback_dir=out / "feedback", report=out / "report.html",
                       progress=False, scheduler=cluster)
    seconds = time.monotonic() - start
    print(f"\ngraded {len(expected)} students ({len(rows)} rows) in {seconds:.1f} s")
    return SimpleNamespace(base=base, root=root, out=out, rows=rows, expected=expected, seconds=seconds,
                           before=before, kit_before=kit_before, grader_file=grader_file)


def by_student(rows):
    table: dict = {}
    for r in rows:
        table.setdefault(r.student, {}).setdefault(r.assignment, []).append(r.status)
    return table


def test_the_corpus_has_many_kinds(graded):
    assert len(graded.expected) >= 25


def test_every_submission_ran_in_a_dask_worker_under_landlock(graded):
    runs = {id(r.details["run"]): r.details["run"] for r in graded.rows if r.details.get("run")}
    assert len(runs) >= 25
    if landlock.abi_version():
        assert all(run.landlock == landlock.abi_version() for run in runs.values())
    assert not (graded.out / "grades.csv.journal").exists()  # a complete run leaves none


def test_every_student_gets_one_row_per_expected_exercise(graded):
    assert set(by_student(graded.rows)) == set(graded.expected)
    for r in graded.rows:
        assert r.status in STATUSES and r.message
    assert len(graded.rows) == len(graded.expected) * (len(EX[A02]) + len(EX[A05]))


@pytest.mark.parametrize("kind", ["statuses"])
def test_each_kind_gets_its_expected_rows(graded, kind):
    actual = by_student(graded.rows)
    wrong = {s: (want, actual.get(s)) for s, want in graded.expected.items() if actual.get(s) != want}
    detail = "\n".join(f"{r.student} {r.exercise}: {r.status}: {r.message}" for r in graded.rows
                       if r.student in wrong)
    assert not wrong, f"{wrong}\n{detail}"


def test_no_original_is_modified_and_nothing_is_planted(graded):
    after = digest(graded.base)
    produced = {k for k in after if k.startswith("out/")}
    assert {k: v for k, v in after.items() if k not in produced} == graded.before
    assert kit_digest() == graded.kit_before
    assert graded.grader_file.read_text() == "the instructor's notes"


@pytest.mark.skipif(landlock.abi_version() == 0, reason="kernel without Landlock: no confinement")
def test_writes_outside_the_working_folder_are_refused(graded):
    nb = nbformat.read(graded.out / "feedback" / "writes_outside_02" / f"{A02}.ipynb", as_version=4)
    printed = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    assert printed.count("refused:") == 4 and "Permission denied" in printed
    assert not (graded.root / "planted.txt").exists()


def test_no_tampering_earns_a_point(graded):
    for r in graded.rows:
        if r.student.startswith(("tamper", "forged")) and r.file:  # the assignment handed in
            assert r.status == "tampered" and r.points == 0, (r.student, r.exercise, r.message)
            assert r.message.startswith("tampering: ")
    hidden = [r for r in graded.rows if r.student == "tamper_hidden_02"]
    assert "RESULTS" in hidden[0].message  # seen only at run time: the code hides the name


def test_messages_explain_each_verdict(graded):
    msg = {(r.student, r.exercise): r.message for r in graded.rows}
    assert "START of the step" in msg[("wrong_02", "forward_euler_step")]
    assert "uses the reference" in msg[("uses_reference_02", "forward_euler_step")]
    assert "radius_formula" in msg[("uses_reference_02", "radius_after")]
    assert "SIGSEGV" in msg[("segfault_05", "velocity_verlet_step")]
    assert "does not compile" in msg[("syntax_error_02", "forward_euler_step")]
    assert "ZeroDivisionError" in msg[("exception_02", "forward_euler_step")]
    # stopped by its CPU alarm (4 s), however busy the machine: the wall-clock watch (3 x 4 s)
    # does not count the time the loop waited for a CPU, where the kernel reports it
    looped = msg[("loop_in_exercise_02", "radius_after")]
    if COUNTS_QUEUEING:
        assert "did not finish within" in looped, looped
    else:  # no scheduler statistics: on a machine busy enough, the wall watch may strike first
        assert "did not finish within" in looped or "killed after 12 s (time limit)" in looped, looped
    assert "MemoryError" in msg[("memory_hog_02", "drift_dt")]
    assert "SystemExit" in msg[("exit_in_exercise_02", "drift_dt")]
    assert "is notebook 05_newtons_second_law" in msg[("another_assignment", "drift_dt")]
    assert "not valid JSON" in msg[("invalid_json_02", "drift_dt")]
    assert "empty" in msg[("empty_file_05", "impact_time")]
    assert "no code cells" in msg[("zero_cells_02", "drift_dt")]
    assert "does not define forward_euler_step" in msg[("renamed_function_02", "forward_euler_step")]
    notes = {r.student: r.details.get("note", "") for r in graded.rows if r.assignment == A02}
    assert "02_forward_euler-Copy1.ipynb" in notes["several_notebooks"]
    v3 = next(r for r in graded.rows if r.student == "nbformat_v3_05" and r.assignment == A05)
    assert "upgraded from nbformat 3" in v3.details["note"]


def test_stopped_cells_are_rerun_without_them(graded):
    for student, assignment in (("stubborn_loop_top_02", A02), ("os_exit_top_05", A05)):
        row = next(r for r in graded.rows if r.student == student and r.assignment == assignment)
        run = row.details["run"]
        assert run.attempts == 2 and run.cells[2]["status"] == "killed"
        assert "again without this cell" in run.cells[2]["error"]


def test_output_floods_are_capped(graded):
    row = next(r for r in graded.rows if r.student == "huge_output_02")
    cell = row.details["run"].cells[2]
    assert len(cell["output"]) <= LIMITS.output_chars and cell["dropped"] > 50_000_000


def test_gradebook_csv_has_every_row(graded):
    with (graded.out / "grades.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == FIELDS and len(table) == len(graded.rows)
    assert sum(int(r["points"]) for r in table) == sum(r.points for r in graded.rows)
    correct = [r for r in table if r["student"] == "correct_05" and r["assignment"] == A05]
    assert [r["points"] for r in correct] == [r["possible"] for r in correct] and correct


def test_feedback_for_every_student(graded):
    for student in graded.expected:
        page = (graded.out / "feedback" / f"{student}.md").read_text("utf-8")
        assert f"# Feedback for {student}" in page
        for names in EX.values():
            assert all(f"`{name}`" in page for name in names)
    page = (graded.out / "feedback" / "wrong_02.md").read_text("utf-8")
    assert "✗" in page and "hint:" in page
    page = (graded.out / "feedback" / "exception_02.md").read_text("utf-8")
    assert "Where it stopped" in page and "1 // 0" in page
    nb = nbformat.read(graded.out / "feedback" / "correct_02" / f"{A02}.ipynb", as_version=4)
    nbformat.validate(nb)
    assert sum("**Grader" in c.source for c in nb.cells if c.cell_type == "markdown") == len(EX[A02])


def test_class_report_is_self_contained(graded):
    html = (graded.out / "report.html").read_text("utf-8")
    assert html.count("data:image/png;base64,") >= 3
    assert "<script" not in html and "http://" not in html and "https://" not in html
    assert "radius_after" in html and "most frequent mistakes" in html.lower()


def _printed(rows, student: str) -> str:
    run = next(r.details["run"] for r in rows if r.student == student and r.details.get("run"))
    return "".join(cell.get("output") or "" for cell in run.cells.values())


def _nothing_reached(services) -> None:
    for listener in (services.tcp, services.unix):
        with pytest.raises(BlockingIOError):
            listener.accept()[0].close()  # a connection a submission made
    with pytest.raises(BlockingIOError):
        services.udp.recvfrom(512)  # a datagram a submission sent (the DNS query)


def _no_network(rows, services) -> None:
    for student, attempts in NETWORK.items():
        run = next(r.details["run"] for r in rows if r.student == student and r.details.get("run"))
        assert run.sockets_denied, "the worker could not deny sockets (no seccomp?)"
        printed = _printed(rows, student)
        assert "REACHED" not in printed, printed
        refused = [ln.split()[1] for ln in printed.splitlines() if ln.startswith("refused:")]
        assert refused == attempts, printed
    assert "Permission denied" in _printed(rows, "network_02")
    assert "thread parent-watch" in _printed(rows, "thread_escape_02")  # the thread did try
    _nothing_reached(services)


@pytest.mark.skipif(landlock.abi_version() == 0, reason="kernel without Landlock: no confinement")
def test_no_submission_reaches_the_network_or_escapes_through_a_thread_in_a_dask_worker(graded, services):
    _no_network(graded.rows, services)
    assert graded.grader_file.read_text() == "the instructor's notes"


@pytest.mark.skipif(landlock.abi_version() == 0, reason="kernel without Landlock: no confinement")
def test_no_submission_reaches_the_network_when_graded_here(graded, services, tmp_path):
    out = tmp_path / "out"
    rows = grade_class([graded.root], out / "grades.csv", solutions=ROOT / "solutions", assignments=[A02],
                       limits=LIMITS, progress=False, only=sorted(NETWORK), jobs=2)
    _no_network(rows, services)
    assert graded.grader_file.read_text() == "the instructor's notes"
    statuses = by_student(rows)
    assert {s: statuses[s][A02] for s in NETWORK} == {s: graded.expected[s][A02] for s in NETWORK}
