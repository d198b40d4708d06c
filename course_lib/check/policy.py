"""The "calling the library is not solving the exercise" policy, shared by checks and grader.

An exercise asks the student to *write* a computation that ``course_lib`` already holds
(the library is the reference the checks compare with). The rule is derived, not listed by
hand: **an answer may call no ``course_lib`` callable except what the exercise's prompt
hands over**, i.e. the check's ``allow=`` (``@exercise(allow=(...))``: objects or dotted
names; an allowed class allows its methods) and whatever the check passes to the answer as
an argument (a field ``f``, a network, a random generator). Every other library route to
the quantity fails as "uses the library", whether or not anyone thought of it: the
exercise's own function, a sibling that computes the same thing through another door
(``2 * backward_euler(..., dt/2) - y`` for the implicit midpoint), the checks' private
helpers. Exception classes stay usable. NumPy and SciPy stay allowed, except what a check
lists in ``forbid=`` (e.g. ``"scipy.integrate"`` where an analysis is asked, not a run).

Two readings apply the rule:

- this module reads *bytecode*, not source, so it works on a live function in a kernel
  (:func:`reference_use`) and on code the grader only compiled, never ran
  (:func:`references_in_code` with a static resolver);
- :mod:`course_lib.check.watch` watches the library calls an answer makes while its check
  runs it, which catches names built from strings, defaults and other indirection.

Imports only the standard library.
"""

from __future__ import annotations

import dis
import importlib
import inspect
import sys
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


def _loads_to_call(ins: dis.Instruction, previous: str | None) -> bool:
    """Whether ``ins`` loads a callable the code calls at once (``a.f(...)``, ``f(...)``):
    CPython marks these loads (a method load, or a NULL pushed with or before the name)."""
    if ins.opname == "LOAD_METHOD" or previous == "PUSH_NULL":
        return True
    flagged = ins.opname == "LOAD_GLOBAL" or (ins.opname == "LOAD_ATTR"
                                               and sys.version_info >= (3, 12))
    return flagged and bool((ins.arg or 0) & 1)


def name_chains(code: types.CodeType, called: set | None = None
                ) -> list[tuple[str, str, tuple[str, ...]]]:
    """Dotted names a code object (and its nested functions) loads.

    Returns ``(kind, head, attributes)`` triples: ``kind`` is ``"global"``, ``"deref"``
    (a closure variable) or ``"path"`` (a module path imported inside the function, then
    ``head`` is that dotted path), e.g. ``("global", "cl", ("forward_euler",))``. Given a
    set ``called``, the triples whose last name is called where it is loaded are added to it
    (the rest are only named: assigned, passed or returned).
    """
    chains = []
    for co in _code_objects(code):
        local_imports: dict[str, str] = {}
        base = value = None  # the module an import statement loads, and the name it binds
        from_list = False
        last_const = None
        chain: list | None = None
        previous = None
        for ins in dis.get_instructions(co):
            op = ins.opname
            if op in _LOADS_ATTR and chain is not None:
                chain[2].append(ins.argval)
                chain[3] = _loads_to_call(ins, None)
                previous = op
                continue
            if chain is not None:
                chains.append((chain[0], chain[1], tuple(chain[2])))
                if called is not None and (chain[3] or (not chain[2] and op == "PUSH_NULL")):
                    called.add(chains[-1])
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
                    chain = [_LOADS_HEAD[op], name, [], _loads_to_call(ins, previous)]
                elif name in local_imports:
                    chain = ["path", local_imports[name], [], _loads_to_call(ins, previous)]
            elif op not in ("SWAP", "POP_TOP", "COPY"):
                base = None
            if op == "LOAD_CONST":
                last_const = ins.argval
            previous = op
        if chain is not None:
            chains.append((chain[0], chain[1], tuple(chain[2])))
            if called is not None and chain[3]:
                called.add(chains[-1])
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


def _library_module(obj: object) -> str | None:
    """The ``course_lib`` module that defines ``obj`` (None outside the library, and for the
    grader's own machinery, which the tamper scan watches instead)."""
    module = getattr(obj, "__module__", None)
    if not isinstance(module, str) or not (module == "course_lib" or module.startswith("course_lib.")):
        return None
    return None if module.startswith("course_lib.instructor") else module


def _as_objects(items) -> list:
    return [import_path(r) if isinstance(r, str) else r for r in items]


def exercise_rules(check: Callable) -> dict:
    """What ``check`` lets an answer use: ``allow`` (objects), ``forbid`` (explicit objects)
    and ``prefixes`` (dotted module prefixes outside the library that are refused)."""
    allow = [a for a in _as_objects(getattr(check, "allow", ())) if a is not None]
    forbid, prefixes = [], []
    for r in (*getattr(check, "references", ()), *getattr(check, "forbid", ())):
        if isinstance(r, str) and not r.startswith("course_lib"):
            prefixes.append(r)
        elif (obj := import_path(r) if isinstance(r, str) else r) is not None:
            forbid.append(obj)
    return {"allow": allow, "forbid": forbid, "prefixes": tuple(prefixes)}


def _allowed(obj: object, allow: list) -> bool:
    if any(obj is a for a in allow):
        return True
    owner = getattr(obj, "__self__", None)  # a bound method of an allowed instance or class
    if owner is not None and any(owner is a or type(owner) is a for a in allow):
        return True
    qualname = getattr(obj, "__qualname__", "")
    module = getattr(obj, "__module__", None)
    return any(inspect.isclass(a) and a.__module__ == module and qualname.startswith(a.__qualname__ + ".")
               for a in allow)


def _reference_name(obj: object, rules: dict) -> str | None:
    if isinstance(obj, types.ModuleType) or not callable(obj):
        return None
    qualname = getattr(obj, "__qualname__", getattr(obj, "__name__", "?"))
    if any(obj is f for f in rules["forbid"]):
        return f"{getattr(obj, '__module__', '?')}.{qualname}"
    module = getattr(obj, "__module__", None)
    if rules["prefixes"] and isinstance(module, str) and module.startswith(rules["prefixes"]):
        return f"{module}.{qualname}"
    library = _library_module(obj)
    if library is None or (inspect.isclass(obj) and issubclass(obj, BaseException)):
        return None
    return None if _allowed(obj, rules["allow"]) else f"{library}.{qualname}"


def references_in_code(code: types.CodeType, resolve: Callable[[str, str], object | None],
                       check: Callable, named: list | None = None) -> list[str]:
    """Library callables ``code`` reaches that ``check`` does not allow, as dotted names.

    ``resolve(kind, head)`` returns the object a ``"global"`` or ``"deref"`` head names (or
    None); ``"path"`` heads are imported with :func:`import_path`. Given a list ``named``,
    the names no load calls on the spot (assigned, passed, imported) are added to it.
    """
    rules = exercise_rules(check)
    found: list[str] = []
    called: set = set()
    via_call: set[str] = set()
    for kind, head, attrs in name_chains(code, called):
        if kind == "path" and rules["prefixes"] and f"{head}.".startswith(
                tuple(p.rstrip(".") + "." for p in rules["prefixes"])):
            # an import inside the function of a refused module (a C class such as cKDTree is
            # invisible to the run-time watch, so the import itself is what counts)
            name = ".".join((head, *attrs))
            if name not in found:
                found.append(name)
            continue
        obj = import_path(head) if kind == "path" else resolve(kind, head)
        if obj is None:
            continue
        for _, reached in _walk(obj, attrs):
            ref = _reference_name(reached, rules)
            if ref and ref not in found:
                found.append(ref)
            if ref and (kind, head, attrs) in called:
                via_call.add(ref)
    if named is not None:
        named.extend(f for f in found if f not in via_call)
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


def public_name(name: str) -> str:
    """``name`` as a user imports it: from its first private segment on, only its last name
    (``scipy.integrate._ivp.ivp.solve_ivp`` -> ``scipy.integrate.solve_ivp``)."""
    parts = name.split(".")
    private = [k for k, p in enumerate(parts[:-1]) if p.startswith("_") and not p.startswith("__")]
    return ".".join(parts[:private[0]] + parts[-1:]) if private else name


def refused_names(check: Callable) -> tuple[str, ...]:
    """What ``check`` refuses outside the library (``forbid=``), as public names, each once."""
    rules = exercise_rules(check)
    objs = [f"{getattr(o, '__module__', '?')}.{getattr(o, '__qualname__', '?')}"
            for o in rules["forbid"] if _library_module(o) is None]
    return tuple(dict.fromkeys(public_name(n) for n in (*rules["prefixes"], *objs)))


def _listed(names: list[str]) -> str:
    short = sorted(names, key=len)[:2]   # a long list: its two shortest names, then a count
    head, last = (short, f"{len(names) - 2} more") if len(names) > 4 else (names[:-1], names[-1])
    return ", ".join(head) + (" and " if head else "") + last


def message(found: list[str], itself: bool = False, named: list[str] = (),
            refused: tuple[str, ...] = ()) -> str:
    """The verdict line for an answer that uses the library (the grader matches its start).
    With any of ``found`` in ``named`` (only named, never called) it says "uses", not "calls";
    it names each of ``refused`` (:func:`refused_names`) once and never calls one fine."""
    verb = "uses " if any(f in found for f in named) else "calls "
    found = list(dict.fromkeys(public_name(f) for f in found))
    found = [f for f in found if not any(g.startswith(f + ".") for g in found)]  # most specific
    what = ("your answer is the library's own " if itself else "your function " + verb) + ", ".join(found[:3])
    outside = [f for f in found if not f.startswith(("course_lib", "a function of course_lib"))]
    extra = [r for r in refused if r not in found and any(f.startswith(r + ".") for f in outside)]
    if outside and len(outside) == len(found):       # only a refused outside library
        which = f", and this exercise refuses {_listed(extra)}" if extra else (
            ", which this exercise refuses")
        return (f"uses the reference: {what}{which}: it asks you to write the computation "
                "yourself (anything the check passes to your function is fine); an answer "
                "that calls it earns no points")
    but = f", except {_listed(list(refused))}, which would do it for you;" if refused else ", and"
    fine = ("anything the check passes to your function is fine, but this exercise refuses "
            + (_listed(extra) if extra else "the others named here")) if outside else (
        f"NumPy and SciPy are fine{but} so is anything the check passes to your function")
    return (f"uses the reference: {what}. This exercise asks you to write that computation "
            f"yourself ({fine}); an answer that calls the library's version earns no points")


def _defaults(answer: object) -> list:
    kw = getattr(answer, "__kwdefaults__", None) or {}
    return [*(getattr(answer, "__defaults__", None) or ()), *kw.values()]


def reference_use(check: Callable, answer: object) -> str | None:
    """Why ``answer`` (a live function) counts as using the library for ``check``, or None.

    Only functions written in a notebook or script (module ``__main__``, or none at all, as
    for code run by ``exec``) are judged: a check handed the library's own function (as the
    tests do) still verifies it. The grader judges the function a notebook defines under the
    exercise's name, and there a name bound to a library function does count
    (:func:`answer_is_reference`). Default argument values are judged too.
    """
    code = getattr(answer, "__code__", None)
    if not (inspect.isfunction(answer) and isinstance(code, types.CodeType)
            and getattr(answer, "__module__", None) in ("__main__", None)):
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

    named: list[str] = []
    found = references_in_code(code, resolve, check, named)
    rules = exercise_rules(check)
    defaults = [r for d in _defaults(answer) if (r := _reference_name(d, rules)) and r not in found]
    return (message(found + defaults, named=named + defaults, refused=refused_names(check))
            if found or defaults else None)
