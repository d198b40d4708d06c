"""The grading journal: what a run has graded so far, so that an interrupted run resumes.

``<gradebook>.journal`` beside the gradebook holds JSON lines: the first says what the
run is (a fingerprint of the kit, the library, the limits and the assignments); each
other line holds one submission's rows *with* the details its feedback needs, written
(and flushed to disk) by the grading client as soon as that submission is graded. Running
the same command again reads the journal, keeps every submission whose file is unchanged
(same SHA-256) and grades only the others; a complete run deletes it. A line cut short by
a crash is ignored, and a journal of another kit, library or set of limits is not used.

Nothing here is pickled: rows travel as JSON and are rebuilt field by field.
Imports: the standard library and this package's data classes.
"""

from __future__ import annotations

import ast
import dataclasses
import hashlib
import importlib.util
import json
import os
from pathlib import Path

from .sandbox import Run
from .scan import AST_LOCK
from .submissions import Cell, Notebook
from .verdicts import Row

VERSION = 1


def grading_modules(check_modules: list[str]) -> list[str]:
    """The course_lib modules a verdict can depend on: the grader's, the given check
    modules', and every course_lib module they import at any depth (lazy imports and the
    packages' ``__init__`` included), found by reading their source, not by running it."""
    stack = ["course_lib.instructor.grade", "course_lib.instructor.cluster", *check_modules]
    seen: set[str] = set()
    while stack:
        name = stack.pop()
        if name in seen or not (name == "course_lib" or name.startswith("course_lib.")):
            continue
        origin = _origin(name)
        if origin is None:
            continue
        seen.add(name)
        parts = name.split(".")
        stack += [".".join(parts[:i]) for i in range(1, len(parts))]
        package = name if origin.endswith("__init__.py") else name.rsplit(".", 1)[0]
        stack += _imports(origin, package)
    return sorted(seen)


#: ``origin -> ((mtime_ns, size), imported names)``: a file is read again only once changed.
_IMPORTS: dict[str, tuple[tuple[int, int], list[str]]] = {}


def _imports(origin: str, package: str) -> list[str]:
    """The dotted names the module at ``origin`` (in ``package``) imports, read from its
    source (parsed once per version of the file and process: a grading run asks per run)."""
    stat = os.stat(origin)
    stamp = (stat.st_mtime_ns, stat.st_size)
    cached = _IMPORTS.get(origin)
    if cached is not None and cached[0] == stamp:
        return cached[1]
    with AST_LOCK:  # see scan.AST_LOCK: the grader parses from several threads
        tree = ast.parse(Path(origin).read_bytes())
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            names += [target] + [f"{target}.{a.name}" for a in node.names]
    _IMPORTS[origin] = (stamp, names)
    return names


def _origin(name: str) -> str | None:
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    return spec.origin if spec is not None and spec.origin and spec.origin.endswith(".py") else None


def library_files(names: list[str]) -> dict[str, str]:
    """SHA-256 of the source file of each of the modules ``names`` (as this process would
    import them; "missing" if it has none). Two processes grade alike only if these agree."""
    out = {}
    for name in sorted(names):
        origin = _origin(name)
        try:
            out[name] = hashlib.sha256(Path(origin).read_bytes()).hexdigest() if origin else "missing"
        except OSError:
            out[name] = "unreadable"
    return out


def library_fingerprint(files: dict[str, str]) -> str:
    """One digest of :func:`library_files`."""
    return hashlib.sha256(json.dumps(files, sort_keys=True).encode()).hexdigest()


def file_digest(path: Path | None, note: str = "") -> str:
    """What identifies a submission: its bytes (or, with no file, the grader's note)."""
    if path is None:
        return "none:" + hashlib.sha256(note.encode()).hexdigest()
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as exc:
        return f"unreadable:{exc.errno}"


def lean_run(run: Run) -> Run:
    """``run`` without the recorded calls (the verdicts are made; feedback never reads them)."""
    exercises = {name: {k: v for k, v in record.items() if k != "calls"}
                 for name, record in run.exercises.items()}
    return dataclasses.replace(run, exercises=exercises)


def _plain(value):
    """``value`` as JSON-ready data (data classes become tagged dicts)."""
    if isinstance(value, Run):
        data = dataclasses.asdict(lean_run(value))
        data["cells"] = {str(k): v for k, v in value.cells.items()}
        return {"__run__": data}
    if isinstance(value, Notebook):
        return {"__notebook__": {"note": value.note, "cells": [dataclasses.asdict(c) for c in value.cells]}}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    return str(value)


def _rebuilt(value):
    if isinstance(value, dict):
        if "__run__" in value:
            data = dict(value["__run__"])
            data["cells"] = {int(k): v for k, v in data["cells"].items()}
            return Run(**data)
        if "__notebook__" in value:
            data = value["__notebook__"]
            return Notebook([Cell(**c) for c in data["cells"]], data["note"])
        return {k: _rebuilt(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_rebuilt(v) for v in value]
    return value


def row_to_json(row: Row) -> dict:
    return {f.name: _plain(getattr(row, f.name)) for f in dataclasses.fields(row)}


def row_from_json(data: dict) -> Row:
    return Row(**{k: _rebuilt(v) for k, v in data.items()})


class Journal:
    """``<out>.journal``: the header and one line per graded submission (see the module)."""

    def __init__(self, out_csv: Path, header: dict):
        self.path = Path(out_csv).with_name(Path(out_csv).name + ".journal")
        self.header = {"journal": VERSION, **header}
        self._fh = None

    def load(self) -> dict[tuple[str, str], tuple[str, list[Row]]]:
        """``{(student, assignment): (digest, rows)}`` of an earlier run of the same kind;
        empty if there is none, or if it was made with another kit, library or limits."""
        try:
            lines = self.path.read_bytes().split(b"\n")
        except OSError:
            return {}
        try:
            if json.loads(lines[0]) != self.header:
                return {}
        except ValueError:
            return {}
        done = {}
        for line in lines[1:]:
            try:
                entry = json.loads(line)
                rows = [row_from_json(r) for r in entry["rows"]]
            except (ValueError, KeyError, TypeError):
                continue  # the last line of a run killed while writing it
            done[(entry["student"], entry["assignment"])] = (entry["digest"], rows)
        return done

    def start(self, kept: list[tuple[tuple[str, str], str, list[Row]]]) -> None:
        """Begin a journal holding the header and the submissions ``kept`` from before."""
        tmp = self.path.with_name(self.path.name + ".tmp")
        with tmp.open("w", encoding="utf-8") as fh:
            fh.write(json.dumps(self.header) + "\n")
            for key, digest, rows in kept:
                fh.write(self._line(key, digest, rows))
        os.replace(tmp, self.path)
        self._fh = self.path.open("a", encoding="utf-8")

    @staticmethod
    def _line(key: tuple[str, str], digest: str, rows: list[Row]) -> str:
        entry = {"student": key[0], "assignment": key[1], "digest": digest,
                 "rows": [row_to_json(r) for r in rows]}
        return json.dumps(entry, ensure_ascii=False) + "\n"

    def append(self, key: tuple[str, str], digest: str, rows: list[Row]) -> None:
        """Record one graded submission, on disk before returning."""
        self._fh.write(self._line(key, digest, rows))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def remove(self) -> None:
        """The run is complete: nothing is left to resume."""
        self.close()
        self.path.unlink(missing_ok=True)
