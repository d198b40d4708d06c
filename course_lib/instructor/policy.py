"""The "using the reference is not solving the exercise" policy, shared by checks and grader.

An exercise asks the student to *write* a computation that ``course_lib`` already holds
(the library is the reference the checks compare with). An answer whose function body
reaches one of these references is reported as **uses the reference** and earns nothing,
in the notebook's check and in the grader alike. A reference, for the exercise checked by
``check`` (an ``@exercise`` function of ``course_lib.check.nbNN``), is any callable that

- is defined in ``course_lib.check`` (the checkers and their helpers, e.g.
  ``check.radius_formula``);
- is defined in ``course_lib`` and bears the exercise's name, or that name without a
  trailing ``_step`` (``forward_euler_step`` -> ``course_lib.forward_euler``);
- is listed in the check's ``references`` (``@exercise(reference=...)``).

Other library functions stay allowed (a solution may build on ``cl.fields.vortex``).

The functions read *bytecode*, not source, so they work on a live function in a kernel
(:func:`reference_use`) and on code the grader only compiled, never ran
(:func:`references_in_code` with a static resolver). Imports only the standard library.
"""

from __future__ import annotations

import dis
import importlib
import inspect
import types
from collections.abc import Callable, Iterator

_LOADS_HEAD = {"LOAD_GLOBAL": "global", "LOAD_NAME": "global", "LOAD_DEREF": "deref",
               "LOAD_CLASSDEREF": "deref", "LOAD_FAST": "local"}
_LOADS_ATTR = {"LOAD_ATTR", "LOAD_METHOD"}
_STORES = {"STORE_FAST", "STORE_NAME", "STORE_GLOBAL", "STORE_DEREF"}


def _code_objects(code: types.CodeType) -> Iterator[types.CodeType]:
    yield code
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _code_objects(const)


def name_chains(code: types.CodeType) -> list[tuple[str, str, tuple[str, ...]]]:
    """Dotted names a code object (and its nested functions) loads.

    Returns ``(kind, head, attributes)`` triples: ``kind`` is ``"global"``, ``"deref"``
    (a closure variable) or ``"path"`` (a module path imported inside the function, then
    ``head`` is that dotted path), e.g. ``("global", "cl", ("forward_euler",))``.
    """
    chains = []
    for co in _code_objects(code):
        local_imports: dict[str, str] = {}
        base = value = None  # the module an import statement loads, and the name it binds
        from_list = False
        last_const = None
        chain: list | None = None
        for ins in dis.get_instructions(co):
            op = ins.opname
            if op in _LOADS_ATTR and chain is not None:
                chain[2].append(ins.argval)
                continue
            if chain is not None:
                chains.append((chain[0], chain[1], tuple(chain[2])))
                chain = None
            if op == "IMPORT_NAME":
                module = str(ins.argval)
                from_list = bool(last_const)
                base = value = module if from_list else module.split(".")[0]
                chains.append(("path", module, ()))
            elif op == "IMPORT_FROM" and base is not None:
                value = f"{base if from_list else value}.{ins.argval}"
                chains.append(("path", value, ()))
            elif op in _STORES and base is not None:
                local_imports[ins.argval] = value
                value = base
            elif op in _LOADS_HEAD:
                base = None
                name = ins.argval
                if _LOADS_HEAD[op] != "local":
                    chain = [_LOADS_HEAD[op], name, []]
                elif name in local_imports:
                    chain = ["path", local_imports[name], []]
            elif op not in ("SWAP", "POP_TOP", "COPY"):
                base = None
            if op == "LOAD_CONST":
                last_const = ins.argval
        if chain is not None:
            chains.append((chain[0], chain[1], tuple(chain[2])))
    return chains


def import_path(path: str) -> object | None:
    """The object at a dotted ``course_lib`` path (importing modules as needed), or None."""
    if not (path == "course_lib" or path.startswith("course_lib.")):
        return None
    parts = path.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except Exception:  # not a module (or a broken one): try a shorter prefix
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr, None)
            if obj is None:
                return None
        return obj
    return None


def _walk(obj: object, attrs: tuple[str, ...]) -> Iterator[tuple[str, object]]:
    """Follow attributes through modules only; yield every object reached with its name."""
    name = getattr(obj, "__name__", "?")
    yield name, obj
    for attr in attrs:
        if not isinstance(obj, types.ModuleType):
            return
        obj = getattr(obj, attr, None)
        if obj is None:
            return
        name = f"{name}.{attr}"
        yield name, obj


def _reference_name(obj: object, names: set[str], explicit: tuple) -> str | None:
    if isinstance(obj, types.ModuleType) or not callable(obj):
        return None
    module = getattr(obj, "__module__", None)
    if not isinstance(module, str) or not (module == "course_lib" or module.startswith("course_lib.")):
        return None
    qualname = getattr(obj, "__qualname__", getattr(obj, "__name__", "?"))
    if any(obj is ref for ref in explicit) or module.startswith("course_lib.check") \
            or getattr(obj, "__name__", None) in names:
        return f"{module}.{qualname}"
    return None


def exercise_names(check: Callable) -> tuple[set[str], tuple]:
    """The names that mark a reference for ``check`` and its explicit references."""
    name = getattr(check, "__name__", "")
    explicit = tuple(import_path(r) if isinstance(r, str) else r
                     for r in getattr(check, "references", ()))
    return {name, name.removesuffix("_step")}, explicit


def references_in_code(code: types.CodeType, resolve: Callable[[str, str], object | None],
                       check: Callable) -> list[str]:
    """References to the exercise's reference that ``code`` contains, as dotted names.

    ``resolve(kind, head)`` returns the object a ``"global"`` or ``"deref"`` head names (or
    None); ``"path"`` heads are imported with :func:`import_path`.
    """
    names, explicit = exercise_names(check)
    found: list[str] = []
    for kind, head, attrs in name_chains(code):
        obj = import_path(head) if kind == "path" else resolve(kind, head)
        if obj is None:
            continue
        for _, reached in _walk(obj, attrs):
            ref = _reference_name(reached, names, explicit)
            if ref and ref not in found:
                found.append(ref)
    return found


def answer_is_reference(answer: object, check: Callable) -> str | None:
    """Dotted name of ``answer`` if the answer *is* a course_lib function, else None."""
    if not (inspect.isfunction(answer) or inspect.isbuiltin(answer) or inspect.isclass(answer)
            or inspect.ismethod(answer)):
        return None
    module = getattr(answer, "__module__", None)
    if isinstance(module, str) and (module == "course_lib" or module.startswith("course_lib.")):
        return f"{module}.{getattr(answer, '__qualname__', '?')}"
    return None


def message(found: list[str], itself: bool = False) -> str:
    """The verdict line for an answer that uses the reference."""
    what = ("your answer is the library's own " if itself else "your function calls ") + ", ".join(found)
    return (f"uses the reference: {what}. Write the computation yourself (NumPy and SciPy "
            "are fine); an answer that calls the library's version of the exercise earns no points")


def reference_use(check: Callable, answer: object) -> str | None:
    """Why ``answer`` (a live function) counts as using the reference of ``check``, or None.

    Only functions written in a notebook or script (module ``__main__``) are judged: a
    check handed the library's own function (as the tests do) still verifies it. The
    grader judges the function a notebook defines under the exercise's name, and there a
    name bound to a library function does count (:func:`answer_is_reference`).
    """
    code = getattr(answer, "__code__", None)
    if not (inspect.isfunction(answer) and isinstance(code, types.CodeType)
            and getattr(answer, "__module__", None) == "__main__"):
        return None
    glb = getattr(answer, "__globals__", {})
    free = dict(zip(code.co_freevars, answer.__closure__ or (), strict=False))

    def resolve(kind: str, head: str) -> object | None:
        if kind == "deref":
            try:
                return free[head].cell_contents
            except (KeyError, ValueError):
                return None
        return glb.get(head)

    found = references_in_code(code, resolve, check)
    return message(found) if found else None
