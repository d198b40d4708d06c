"""Grading on a ``dask.distributed`` cluster: one task per submission, same sandbox.

:func:`grade_on_cluster` is what :func:`.grade.grade_class` uses when it is given a
scheduler. The client (the instructor's process) reads each submission and sends its
bytes with the task, so the workers need no shared file system; it keeps a bounded
number of tasks in flight (a few per worker thread), and yields each submission's rows
as they come back; :func:`.grade.grade_class` alone writes the gradebook and journal.

On a worker, :func:`grade_remote` grades exactly as a local run does: the same
:func:`.grade.grade_task`, the same sandboxed worker process (resource limits, Landlock,
no network, signed messages, verdicts replayed into the checks). Each Dask worker
prepares one private runtime (:class:`.sandbox.Runtime`) inside its own Dask scratch
folder on first use, which Dask deletes with the worker.

Promises, and who keeps them:

- a task whose worker dies is run again on another worker by the Dask scheduler (up to
  ``distributed.scheduler.allowed-failures`` times, 3 by default); a submission that kills
  every worker it reaches gets ``error`` rows saying so, and is never lost; a result
  lost with its worker after it finished but before the client took it is waited for
  again (the scheduler recomputes it); any other failure of a task (not the submission's
  doing) stops the run, which then resumes;
- the client takes the first result of each submission and ignores any other, so none is
  written twice;
- a worker whose ``course_lib`` differs from the client's (another version of the checks)
  refuses to grade, and the run stops saying so: mixed versions would grade unalike.

Imports: ``distributed`` (only when a cluster is used), the standard library, this package.
"""

from __future__ import annotations

import dataclasses
import shutil
import tempfile
import threading
import uuid
from collections.abc import Iterator
from pathlib import Path

from .journal import grading_modules, lean_run, library_files
from .runtime import Runtime
from .sandbox import Limits, Run
from .task import Task, _rows, grade_task
from .verdicts import Row

#: Tasks kept in flight per worker thread of the cluster (the rest wait on the client). One:
#: a second task would wait in a busy worker's queue (the scheduler hands each worker
#: ceil(1.1 x threads) tasks) while another worker sat idle until work stealing moved it,
#: 1.8 s of a 19 s run measured; a task is seconds long, the round trip to refill milliseconds.
PER_THREAD = 1
_RUNTIME: Runtime | None = None
_LOCK = threading.Lock()


class LibraryMismatch(RuntimeError):
    """A worker's course_lib is not the client's: the run must stop."""


def prepare_worker() -> Runtime:
    """This worker process's private runtime, made once, in the Dask worker's scratch folder
    (Dask removes it with the worker, and purges it if the worker was killed).

    :func:`grade_remote` calls it before its first submission; ``client.run(prepare_worker)``
    prepares every worker of a cluster at once, before any work is sent."""
    global _RUNTIME
    with _LOCK:
        if _RUNTIME is None:
            try:
                from distributed import get_worker

                base = Path(get_worker().local_directory)
            except (ImportError, ValueError):  # called outside a Dask worker
                base = Path(tempfile.gettempdir())
            _RUNTIME = Runtime(Path(tempfile.mkdtemp(prefix="course-grade-", dir=base)))
            _RUNTIME.ready()               # its fork server's imports, before any submission
        return _RUNTIME


def grade_remote(task: Task, data: bytes | None, kit, limits: Limits, library: dict[str, str]) -> list[Row]:
    """Grade one submission on a worker: ``data`` is the file's bytes (None: no file);
    ``library`` the client's :func:`.journal.library_files`."""
    mine = library_files(list(library))
    if mine != library:
        differ = sorted(k for k in set(mine) | set(library) if mine.get(k) != library.get(k))
        raise LibraryMismatch(f"this worker's course_lib differs from the grading client's in {differ[:5]}"
                              f"{' and more' if len(differ) > 5 else ''}: install the same version of the "
                              "kit on every worker")
    runtime = prepare_worker()
    if task.path is None or data is None:
        return _lean(grade_task(task, runtime, kit, limits))
    inbox = Path(tempfile.mkdtemp(dir=runtime.root))
    try:
        local = inbox / task.path.name  # the same name: messages quote it
        local.write_bytes(data)
        rows = grade_task(dataclasses.replace(task, path=local), runtime, kit, limits)
    finally:
        shutil.rmtree(inbox, ignore_errors=True)
    for r in rows:
        r.file = str(task.path)
    return _lean(rows)


def _lean(rows: list[Row]) -> list[Row]:
    """Rows without the recorded calls, which are large and were only needed for the verdicts."""
    for r in rows:
        if isinstance(r.details.get("run"), Run):
            r.details["run"] = lean_run(r.details["run"])
    return rows


def _read(task: Task) -> bytes | None:
    if task.path is None:
        return None
    try:
        return Path(task.path).read_bytes()
    except OSError:
        return None  # the worker then reports it unreadable, as a local run would


def _lost(task: Task, exc: BaseException) -> list[Row]:
    return _rows(task, "error", "every cluster worker that graded this notebook died "
                 f"({type(exc).__name__}); look at it by hand, or regrade it with --student {task.student}")


def grade_on_cluster(tasks: list[Task], kit, limits: Limits, scheduler) -> Iterator[tuple[int, list[Row]]]:
    """``(index, rows)`` for each of ``tasks`` as the cluster finishes it.

    ``scheduler`` is a scheduler address (``tcp://host:8786``) or a ``distributed.Client``.
    """
    try:
        from distributed import Client, as_completed
        from distributed.scheduler import KilledWorker
    except ImportError as exc:  # pragma: no cover - distributed is a dependency of the kit
        raise ValueError("scheduler: grading on a cluster needs the 'distributed' package") from exc
    own = not isinstance(scheduler, Client)
    client = connect(str(scheduler)) if own else scheduler
    run = uuid.uuid4().hex[:8]
    library = library_files(grading_modules(sorted({t.assignment.check_module for t in tasks})))
    futures: dict = {}
    try:
        # The kit and the library's hashes go with each task (about 20 kB each), not
        # scattered: scattered data lives only on workers, and once Dask's active memory
        # manager has trimmed its replicas, killing the worker that holds the last copy
        # cancels every task that needs it, instead of running it again elsewhere.
        waiting = iter(range(len(tasks)))
        queue = as_completed()

        def top_up() -> Iterator[tuple[int, list[Row]]]:
            """Submit until the window is full; submissions that need no sandbox (no file,
            or a file over the size limit) are graded here at once, exactly as a worker would."""
            target = max(PER_THREAD * sum(client.nthreads().values()), 1)
            while len(futures) < target:
                i = next(waiting, None)
                if i is None:
                    return
                t = tasks[i]
                if t.path is None or _too_big(t.path):
                    yield i, grade_task(t, None, kit, limits)  # read_notebook refuses it first
                    continue
                f = client.submit(grade_remote, t, _read(t), kit, limits, library,
                                  key=f"grade-{run}-{i}", pure=False)
                futures[f] = i
                queue.add(f)

        yield from top_up()
        for future in queue:
            if future.status in ("lost", "pending"):
                # finished, then its worker died before this loop took the result: the
                # scheduler computes it again (the client still wants it); wait for that run
                queue.add(future)
                continue
            i = futures.pop(future)
            if future.status == "finished":
                rows = future.result()
            elif future.status == "error" and isinstance(future.exception(), KilledWorker):
                rows = _lost(tasks[i], future.exception())
            elif future.status == "error":  # not the submission's doing: stop, resumable
                exc = future.exception()
                raise RuntimeError(f"grading {tasks[i].student}'s {tasks[i].assignment.name} failed "
                                   f"on the cluster: {type(exc).__name__}: {exc}") from exc
            else:
                raise RuntimeError(f"the cluster dropped the task of {tasks[i].student} "
                                   f"({future.status}); run the same command again to resume")
            future.release()
            yield i, rows
            yield from top_up()
    finally:
        if futures:
            client.cancel(list(futures), force=True)
        if own:
            client.close()


#: Seconds to wait for a scheduler's port to answer before saying it cannot be reached.
PROBE_S = 5.0


def connect(address: str):
    """A client of the scheduler at ``address``; ValueError naming it if there is none.

    A TCP or TLS address is tried first with a plain connection, so a wrong address or a
    scheduler that is not running is reported in at most :data:`PROBE_S` seconds (the Dask
    client would retry for its whole 30 s timeout)."""
    import socket

    from distributed import Client
    from distributed.comm.addressing import parse_address, parse_host_port

    hint = "start the scheduler (`dask scheduler`) or pass the address it prints, e.g. tcp://10.0.0.5:8786"
    try:
        scheme, location = parse_address(address, strict=False)
        if scheme in ("tcp", "tls"):
            host, port = parse_host_port(location)
            socket.create_connection((host, port), timeout=PROBE_S).close()
    except ValueError as exc:
        raise ValueError(f"scheduler: {address!r} is not a scheduler address ({exc}); {hint}") from None
    except OSError as exc:
        why = exc.strerror or str(exc) or type(exc).__name__
        raise ValueError(f"scheduler: cannot reach {address!r} ({why}); {hint}") from None
    try:
        return Client(address, timeout="30s")
    except Exception as exc:  # anything but a Dask scheduler answering
        raise ValueError(f"scheduler: {address!r} did not answer as a Dask scheduler "
                         f"({type(exc).__name__}: {str(exc)[:200]}); {hint}") from None


def _too_big(path: Path) -> bool:
    from .submissions import MAX_BYTES

    try:
        return Path(path).stat().st_size > MAX_BYTES
    except OSError:
        return True
