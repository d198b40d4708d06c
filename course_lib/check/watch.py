"""The run-time half of the library rule: which library calls an answer makes while checked.

:mod:`course_lib.check.policy` reads an answer's bytecode; that misses a library function
reached through a name built from strings, a default argument, ``importlib``, or a NumPy
helper that calls it back. :class:`LibraryWatch` wraps the answer so that, only while the
answer runs, a profile hook (:func:`sys.setprofile`) records every call *into* the library
made from code that is not the library's own (the student's frames, or NumPy/functools
calling back). Calls the library makes internally are not recorded, so an allowed building
block may use whatever it likes. Not recorded either:

- what the check handed the answer (callables among the arguments, at any nesting of
  lists, tuples and dicts, and the methods of library objects passed in: a spring network,
  a particle system);
- what the exercise allows (``@exercise(allow=...)``), exception classes, and the
  grader's own machinery (``course_lib.instructor``);
- methods called on a library object the answer holds (a ``Trajectory`` that an allowed
  ``integrate`` returned): the call that made the object is what is judged, since a
  constructor (``__init__``) is recorded like any function.

Dotted prefixes outside the library that a check forbids (``forbid=("scipy.integrate",)``)
are watched too, for Python and C functions alike. Imports only the standard library.
"""

from __future__ import annotations

import functools
import inspect
import sys
import types
from collections.abc import Callable, Iterable


def _is_library(module: str) -> bool:
    return (module == "course_lib" or module.startswith("course_lib.")) \
        and not module.startswith("course_lib.instructor")


def codes_of(value: object, depth: int = 3, seen: set | None = None) -> set[types.CodeType]:
    """Code objects a value hands over: a function's, a bound method's, a partial's target,
    a library object's methods (its whole class), recursively through containers."""
    seen = set() if seen is None else seen
    out: set[types.CodeType] = set()
    if depth < 0 or id(value) in seen:
        return out
    seen.add(id(value))
    code = getattr(value, "__code__", None)
    if isinstance(code, types.CodeType):
        out.add(code)
    for attr in ("__func__", "func", "__wrapped__"):
        inner = getattr(value, attr, None) if not isinstance(value, type) else None
        if inner is not None and callable(inner):
            out |= codes_of(inner, depth - 1, seen)
    cls = value if isinstance(value, type) else type(value)
    if _is_library(getattr(cls, "__module__", "") or ""):
        for klass in cls.__mro__:
            for member in vars(klass).values():
                for fn in (member, getattr(member, "__func__", None), getattr(member, "fget", None),
                           getattr(member, "fset", None)):
                    if isinstance(getattr(fn, "__code__", None), types.CodeType):
                        out.add(fn.__code__)
    if isinstance(value, list | tuple | set | frozenset):
        for item in list(value)[:64]:
            out |= codes_of(item, depth - 1, seen)
    elif isinstance(value, dict):
        for item in list(value.values())[:64]:
            out |= codes_of(item, depth - 1, seen)
    return out


class LibraryWatch:
    """Records the library calls an answer makes; see the module docstring.

    Parameters
    ----------
    allow : iterable
        Library objects the exercise allows (functions, classes, instances).
    prefixes : tuple of str
        Dotted module prefixes outside the library that are refused too.
    """

    def __init__(self, allow: Iterable = (), prefixes: tuple[str, ...] = ()):
        self.allowed = set().union(*(codes_of(a) for a in allow)) if allow else set()
        self.prefixes = tuple(prefixes)
        self.found: list[str] = []
        self._handed: set[types.CodeType] = set()

    def _record(self, name: str) -> None:
        if name not in self.found and len(self.found) < 20:
            self.found.append(name)

    def _hook(self, frame, event, arg):
        if event == "call":
            module = frame.f_globals.get("__name__", "") or ""
            library = _is_library(module)
            if not (library or (self.prefixes and module.startswith(self.prefixes))):
                return
            caller = frame.f_back
            caller_module = (caller.f_globals.get("__name__", "") or "") if caller else ""
            if library and caller_module.startswith("course_lib"):
                return  # the library (or the grader's recorder) calling the library
            if self.prefixes and module.startswith(self.prefixes) and caller_module.startswith(self.prefixes):
                return
            code = frame.f_code
            if code in self.allowed or code in self._handed:
                return
            if library and code.co_argcount and code.co_varnames[0] == "self":
                # A method of an object the answer already holds: it came from the check, an
                # allowed function, or a constructor call that is itself judged here.
                if code.co_name not in ("__init__", "__new__") or self._is_exception(frame):
                    return
            qualname = code.co_qualname
            # a function made by a factory has no name of its own: name its module
            self._record(f"a function of {module}" if "<locals>" in qualname else f"{module}.{qualname}")
        elif event == "c_call" and self.prefixes:
            module = getattr(arg, "__module__", None) or ""
            caller_module = frame.f_globals.get("__name__", "") or ""
            if module.startswith(self.prefixes) and not caller_module.startswith(self.prefixes):
                self._record(f"{module}.{getattr(arg, '__qualname__', '?')}")

    @staticmethod
    def _is_exception(frame) -> bool:
        this = frame.f_locals.get("self")
        return isinstance(this, BaseException)

    def wrap(self, answer: Callable) -> Callable:
        """``answer`` with the watch on while it runs (and off again after, even on error)."""

        @functools.wraps(answer)
        def watched(*args, **kwargs):
            self._handed |= codes_of(args) | codes_of(kwargs)
            previous = sys.getprofile()
            sys.setprofile(self._hook)
            try:
                return answer(*args, **kwargs)
            finally:
                sys.setprofile(previous)

        return watched


def watched_answer(answer: object) -> bool:
    """Whether ``answer`` is judged: anything but the library's own functions and classes
    (a check handed ``course_lib.forward_euler`` by a test still verifies it)."""
    if inspect.isfunction(answer) or inspect.isbuiltin(answer) or inspect.isclass(answer) \
            or inspect.ismethod(answer):
        return not _is_library(getattr(answer, "__module__", "") or "")
    return callable(answer)
