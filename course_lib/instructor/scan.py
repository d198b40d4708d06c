"""Reading a submission's code without running it: tampering and use of the reference.

Runs in the grader's process on the notebook's text (``ast.parse`` and ``compile`` only;
nothing the student wrote is executed here). It finds

- **tampering** (:func:`tamper_findings`): writes to ``course_lib`` or to any imported
  module's attributes, reads of the checker's internals (``RESULTS``, ``Checker``,
  private names), introspection that reaches the grader's worker (frames, ``gc``,
  ``sys.modules``), signal and resource-limit calls, raw writes to file descriptors,
  forged verdict lines, and looking for ``course_lib``'s files or the solutions;
- how the notebook binds each exercise's name (:func:`answer_binding`) and whether that
  function uses the reference (the rule of :mod:`.policy`, applied to compiled bytecode).

IPython syntax (``%magic``, ``!shell``) is neutralised by :func:`strip_magics` the same
way here and in the worker. Imports: the standard library and :mod:`course_lib.check.policy`.
"""

from __future__ import annotations

import ast
import re
import threading
import types
from dataclasses import dataclass

from course_lib.check import policy

_MAGIC = re.compile(r"^(\s*)([%!].*)$")
_ASSIGNED_MAGIC = re.compile(r"^(\s*[\w.]+\s*=\s*)[%!].*$")


def strip_magics(source: str) -> str:
    """Python for a cell: IPython magics and shell escapes become ``pass`` (a leading
    ``%%cell_magic`` line is dropped and the body kept)."""
    lines = source.splitlines()
    if lines and lines[0].lstrip().startswith("%%"):
        lines[0] = "pass  # cell magic ignored by the grader"
    out = []
    for line in lines:
        if m := _ASSIGNED_MAGIC.match(line):
            out.append(f"{m.group(1)}None  # IPython syntax ignored by the grader")
        elif m := _MAGIC.match(line):
            out.append(f"{m.group(1)}pass  # IPython syntax ignored by the grader")
        else:
            out.append(line)
    return "\n".join(out)


#: CPython 3.11 keeps the AST converter's recursion depth in per-interpreter state, so two
#: threads converting at once can fail with "SystemError: AST constructor recursion depth
#: mismatch" (python/cpython#106905). The grader scans submissions from several threads:
#: every conversion between source, AST objects and code takes this lock.
AST_LOCK = threading.Lock()


def parse(source: str) -> ast.Module | None:
    try:
        with AST_LOCK:
            return ast.parse(strip_magics(source))
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None


@dataclass(frozen=True)
class Finding:
    cell: int
    line: int
    what: str

    def __str__(self) -> str:
        return f"cell {self.cell}, line {self.line}: {self.what}"


_CHECK_INTERNALS = {"RESULTS", "REGISTRY", "summary", "Checker", "exercise", "evaluate"}
_INTROSPECTION = {"f_back", "f_locals", "f_globals", "tb_frame", "gi_frame", "cr_frame",
                  "__closure__", "__globals__", "__code__", "__wrapped__", "__builtins__",
                  "__subclasses__", "__dict__"}
_FORBIDDEN = {
    "sys.modules": "replaces modules", "sys._getframe": "inspects the grader's frames",
    "sys.settrace": "traces the grader", "sys.setprofile": "traces the grader",
    "gc.get_objects": "searches the process's objects", "gc.get_referrers": "searches objects",
    "gc.get_referents": "searches objects", "inspect.currentframe": "inspects frames",
    "inspect.stack": "inspects frames", "inspect.getouterframes": "inspects frames",
    "importlib.reload": "reloads modules", "resource.setrlimit": "changes its resource limits",
    "os.write": "writes to raw file descriptors", "os.fdopen": "opens raw file descriptors",
    "os.dup2": "redirects file descriptors", "os.dup": "duplicates file descriptors",
    "os.kill": "sends signals", "os.killpg": "sends signals", "os.setsid": "leaves its session",
}
_FILE_ATTRS = {"__file__", "__path__", "__spec__", "__loader__"}
_FORGED = ("@@GRADE@@", "✓", "○", "\u2705", "\u23f3")


class Aliases:
    """Names bound by imports (and plain ``a = b.c`` assignments) to dotted module paths."""

    def __init__(self, trees: list[ast.Module]):
        self.map: dict[str, str] = {}
        self.modules: set[str] = set()
        for tree in trees:
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    for a in node.names:
                        top = a.name.split(".")[0]
                        self.map[a.asname or top] = a.name if a.asname else top
                        self.modules.add(a.asname or top)
                elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                    for a in node.names:
                        if a.name != "*":
                            self.map[a.asname or a.name] = f"{node.module}.{a.name}"
                elif (isinstance(node, ast.Assign) and len(node.targets) == 1
                      and isinstance(node.targets[0], ast.Name) and (path := self.path(node.value))):
                    self.map[node.targets[0].id] = path

    def path(self, node: ast.AST) -> str | None:
        """The dotted path an expression names (``cl.check.RESULTS`` -> ``course_lib.check.RESULTS``)."""
        attrs = []
        while isinstance(node, ast.Attribute):
            attrs.append(node.attr)
            node = node.value
        if isinstance(node, ast.Name) and node.id in self.map:
            return ".".join([self.map[node.id], *reversed(attrs)])
        return None


def _in_course_lib(path: str | None) -> bool:
    return bool(path) and (path == "course_lib" or path.startswith("course_lib."))


def _store_targets(node: ast.AST) -> list[ast.AST]:
    if isinstance(node, ast.Assign):
        return node.targets
    if isinstance(node, ast.AugAssign | ast.AnnAssign):
        return [node.target]
    if isinstance(node, ast.Delete):
        return node.targets
    return []


def _root(node: ast.AST) -> ast.AST:
    while isinstance(node, ast.Attribute | ast.Subscript):
        node = node.value
    return node


def tamper_findings(cells: list) -> list[Finding]:
    """Every place a notebook's code cells (``index``, ``kind``, ``source``) interfere with grading."""
    parsed = [(c.index, t) for c in cells if c.kind == "code" and (t := parse(c.source)) is not None]
    aliases = Aliases([t for _, t in parsed])
    found: list[Finding] = []
    for index, tree in parsed:
        def flag(node: ast.AST, what: str, index: int = index) -> None:
            found.append(Finding(index, getattr(node, "lineno", 0), what))

        for node in ast.walk(tree):
            for target in _store_targets(node):
                if isinstance(target, ast.Attribute | ast.Subscript):
                    path = aliases.path(_root(target))
                    if _in_course_lib(path):
                        flag(node, f"modifies course_lib ({ast.unparse(target)})")
                    elif (isinstance(target, ast.Attribute) and isinstance(target.value, ast.Name)
                          and target.value.id in aliases.modules):
                        flag(node, f"replaces {ast.unparse(target)} in an imported module")
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("course_lib.check"):
                for a in node.names:
                    if a.name in _CHECK_INTERNALS or a.name.startswith("_") or a.name == "*":
                        flag(node, f"imports the checker's internals ({a.name})")
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                    and node.func.id in ("setattr", "delattr") and node.args:
                path = aliases.path(node.args[0])
                if path is not None:
                    flag(node, f"{node.func.id} on {path}")
            if isinstance(node, ast.Attribute):
                path = aliases.path(node)
                if path and path.startswith("course_lib.check") and (
                        node.attr in _CHECK_INTERNALS or node.attr.startswith("_")):
                    flag(node, f"reaches the checker's internals ({ast.unparse(node)})")
                elif path and _in_course_lib(path) and node.attr in _FILE_ATTRS:
                    flag(node, f"looks for course_lib's files ({ast.unparse(node)})")
                elif path in _FORBIDDEN or (path or "").startswith("signal."):
                    flag(node, f"{_FORBIDDEN.get(path, 'handles signals')} ({path})")
                elif node.attr in _INTROSPECTION:
                    flag(node, f"introspection that can reach the grader ({node.attr})")
            if isinstance(node, ast.Name) and node.id in ("__import__", "__builtins__"):
                flag(node, f"uses {node.id}")
            if isinstance(node, ast.alias) and node.name.split(".")[0] in ("signal", "builtins"):
                flag(tree, f"imports {node.name}")
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                if any(mark in node.value for mark in _FORGED):
                    flag(node, "prints a forged verdict line")
                if re.search(r"(^|[/\\])solutions([/\\]|$)", node.value):
                    flag(node, "looks for the solutions folder")
    return sorted(set(found), key=lambda f: (f.cell, f.line, f.what))


@dataclass
class Binding:
    """How a notebook binds an exercise's name: the cell, and whether it uses the reference."""

    cell: int | None = None
    kind: str = "missing"
    reference: str | None = None


def _function_code(node: ast.FunctionDef) -> types.CodeType | None:
    node = ast.FunctionDef(**{**node.__dict__, "decorator_list": []})
    try:
        with AST_LOCK:
            module = compile(ast.fix_missing_locations(ast.Module([node], [])), "<answer>",
                             "exec")
    except (SyntaxError, ValueError, TypeError, RecursionError):
        return None
    return next((c for c in module.co_consts if isinstance(c, types.CodeType)), None)


def answer_binding(cells: list, name: str, check) -> Binding:
    """The last top-level binding of ``name`` in the code cells, judged by the reference rule."""
    parsed = [(c.index, t) for c in cells if c.kind == "code" and (t := parse(c.source)) is not None]
    aliases = Aliases([t for _, t in parsed])
    last: tuple[int, ast.AST] | None = None
    for index, tree in parsed:
        for node in tree.body:
            if isinstance(node, ast.FunctionDef) and node.name == name:
                last = (index, node)
            elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name
                                                      for t in node.targets):
                last = (index, node)
            elif isinstance(node, ast.Import | ast.ImportFrom) and any(
                    (a.asname or a.name) == name for a in node.names):
                last = (index, node)
    if last is None:
        return Binding()
    index, node = last
    if isinstance(node, ast.FunctionDef):
        code = _function_code(node)
        def resolve(kind: str, head: str) -> object | None:
            return policy.import_path(aliases.map.get(head, "")) if kind == "global" else None

        found = policy.references_in_code(code, resolve, check) if code else []
        return Binding(index, "def", policy.message(found, refused=policy.refused_names(check))
                       if found else None)
    target = aliases.map.get(name) if not isinstance(node, ast.Assign) else aliases.path(node.value)
    obj = policy.import_path(target) if target else None
    itself = policy.answer_is_reference(obj, check) if obj is not None else None
    return Binding(index, "assignment", policy.message([itself], itself=True) if itself else None)
