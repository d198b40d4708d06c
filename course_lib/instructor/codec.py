"""Values crossing from the sandboxed worker to the grader: encoding without pickle.

The worker runs student code, so everything it sends is untrusted. Values travel as JSON
with tags for what JSON lacks (tuples, dicts with any keys, complex numbers) and NumPy
arrays as ``.npy`` bytes (base64), read back with ``allow_pickle=False``: decoding can
build only numbers, strings, lists, tuples, dicts and plain arrays, never run code. What
cannot be encoded (an object of the student's class, a generator, an object array)
becomes an :class:`Opaque` placeholder that every numeric check rejects.

Both sides also compute :func:`fingerprint` of the arguments a check passes, so the
grader can tell whether the worker's check saw the same inputs as its own.
Imports: standard library and NumPy only (the worker imports this module too).
"""

from __future__ import annotations

import base64
import hashlib
import io
import math
import re

import numpy as np

MAX_DEPTH = 32
MAX_ITEMS = 200_000
MAX_STRING = 20_000


class EncodingLimit(Exception):
    """A value is too large or too deeply nested to send."""


class Opaque:
    """Stands for a returned value the codec cannot carry; it behaves like no number."""

    type_name = "object"

    def __repr__(self) -> str:
        return f"<{self.type_name} object>"


_OPAQUE: dict[str, type] = {}


def opaque(type_name: str) -> Opaque:
    """An :class:`Opaque` whose class bears the student's type name (checks print it)."""
    name = re.sub(r"[^A-Za-z0-9_. ()]", "_", str(type_name))[:80] or "object"
    if name not in _OPAQUE:
        _OPAQUE[name] = type(name, (Opaque,), {"type_name": name})
    return _OPAQUE[name]()


#: ``(dtype, shape) -> the header np.save writes``, for small arrays (a check's callbacks
#: send thousands of them: one np.save each cost more than the call being recorded).
_NPY_HEADERS: dict[tuple[str, tuple], bytes] = {}


def _npy(arr: np.ndarray) -> str:
    """``np.save(arr)`` as base64; the same bytes, built from a remembered header when
    ``arr`` is small and C-ordered."""
    if arr.size <= 64 and arr.flags.c_contiguous and arr.dtype.kind in "biufc":
        key = (arr.dtype.str, arr.shape)
        header = _NPY_HEADERS.get(key)
        if header is None:
            buf = io.BytesIO()
            np.save(buf, np.zeros(arr.shape, arr.dtype), allow_pickle=False)
            header = buf.getvalue()[: buf.tell() - arr.nbytes]
            if len(_NPY_HEADERS) < 4096:
                _NPY_HEADERS[key] = header
        return base64.b64encode(header + arr.tobytes()).decode("ascii")
    buf = io.BytesIO()
    np.save(buf, arr, allow_pickle=False)
    return base64.b64encode(buf.getvalue()).decode("ascii")


class _Budget:
    def __init__(self, max_bytes: int):
        self.bytes = max_bytes
        self.items = MAX_ITEMS
        self.opaque = False  # whether anything was encoded as opaque

    def spend(self, items: int = 1, nbytes: int = 0) -> None:
        self.items -= items
        self.bytes -= nbytes
        if self.items < 0 or self.bytes < 0:
            raise EncodingLimit("the returned value is too large to grade")


def encode(value: object, max_bytes: int = 32 << 20) -> object:
    """A JSON-ready form of ``value``; raises :class:`EncodingLimit` past the size limits."""
    return _encode(value, _Budget(max_bytes), 0)


def encode_flagged(value: object, max_bytes: int = 32 << 20) -> tuple[object, bool]:
    """:func:`encode`, and whether the result holds something opaque (what
    :func:`has_opaque` would say, known without a second walk over the result: the
    recorder asks for every callback call, thousands per check)."""
    budget = _Budget(max_bytes)
    encoded = _encode(value, budget, 0)
    return encoded, budget.opaque


def _encode(v: object, budget: _Budget, depth: int) -> object:
    if depth > MAX_DEPTH:
        raise EncodingLimit("the returned value is nested too deeply to grade")
    budget.spend()
    if v is None or type(v) in (bool, int, str):
        if type(v) is str:
            budget.spend(nbytes=len(v))
            return {"str": v[:MAX_STRING]}
        if type(v) is int and abs(v) > 1 << 1000:
            budget.opaque = True
            return {"opaque": "int (too large)"}
        return v
    if type(v) is float:
        return v if math.isfinite(v) else {"float": repr(v)}
    if type(v) is complex:
        return {"complex": [repr(v.real), repr(v.imag)]}
    if isinstance(v, np.ndarray | np.generic):
        arr = np.asarray(v)
        plain = type(v) is np.ndarray or type(v) is arr.dtype.type
        if arr.dtype.kind not in "biufc" or not plain:
            budget.opaque = True
            return {"opaque": f"numpy {arr.dtype} {type(v).__name__}"}
        budget.spend(items=arr.size, nbytes=arr.nbytes)
        return {"npy": _npy(np.array(arr, order="C")), "scalar": isinstance(v, np.generic)}
    if isinstance(v, list | tuple):
        tag = "tuple" if isinstance(v, tuple) else "list"
        return {tag: [_encode(x, budget, depth + 1) for x in list(v)]}
    if isinstance(v, dict):
        return {"dict": [[_encode(k, budget, depth + 1), _encode(x, budget, depth + 1)]
                         for k, x in list(v.items())]}
    budget.opaque = True
    return {"opaque": type(v).__qualname__}


def has_opaque(data: object) -> bool:
    """Whether an encoded value holds something the codec could not carry."""
    if isinstance(data, dict):
        return "opaque" in data or any(has_opaque(v) for v in data.values())
    if isinstance(data, list):
        return any(has_opaque(v) for v in data)
    return False


def decode(data: object, depth: int = 0) -> object:
    """The value :func:`encode` produced ``data`` from; raises ValueError if malformed."""
    if depth > MAX_DEPTH + 1:
        raise ValueError("nested too deeply")
    if data is None or type(data) in (bool, int, float):
        return data
    if type(data) is not dict or len(data) not in (1, 2):
        raise ValueError(f"unexpected encoded value of type {type(data).__name__}")
    (tag, payload), *rest = data.items()
    if tag == "str" and type(payload) is str:
        return payload
    if tag == "float" and payload in ("nan", "inf", "-inf"):
        return float(payload)
    if tag == "complex" and type(payload) is list and len(payload) == 2:
        return complex(float(payload[0]), float(payload[1]))
    if tag in ("list", "tuple") and type(payload) is list:
        items = [decode(x, depth + 1) for x in payload]
        return tuple(items) if tag == "tuple" else items
    if tag == "dict" and type(payload) is list:
        out = {}
        for pair in payload:
            if type(pair) is not list or len(pair) != 2:
                raise ValueError("malformed dict entry")
            key = decode(pair[0], depth + 1)
            out[key if isinstance(key, str | int | float | bool | tuple) or key is None
                else repr(key)] = decode(pair[1], depth + 1)
        return out
    if tag == "npy" and type(payload) is str:
        arr = _load_npy(base64.b64decode(payload, validate=True))
        if arr.dtype.kind not in "biufc":
            raise ValueError(f"array of dtype {arr.dtype}")
        scalar = rest and rest[0] == ("scalar", True)
        return arr[()] if scalar and arr.ndim == 0 else arr
    if tag == "opaque" and type(payload) is str:
        return opaque(payload)
    raise ValueError(f"unknown tag {tag!r}")


#: The header ``np.save`` writes for a C-ordered array of one plain type (format 1.0).
_NPY_HEADER = re.compile(rb"\{'descr': '([<>|][biufc][0-9]{1,2})', 'fortran_order': False, "
                         rb"'shape': \((|[0-9]{1,12},|[0-9]{1,12}(?:, [0-9]{1,12})+)\), \} *\n")


def _load_npy(raw: bytes) -> np.ndarray:
    """``np.load(..., allow_pickle=False)`` of ``.npy`` bytes, read directly when the header
    is the plain one ``np.save`` writes (thousands of small arrays per check: ``np.load``
    parses each header as a Python literal); anything else goes to ``np.load``."""
    if raw[:8] == b"\x93NUMPY\x01\x00" and len(raw) >= 10:
        end = 10 + int.from_bytes(raw[8:10], "little")
        match = _NPY_HEADER.fullmatch(raw[10:end])
        if match:
            dtype = np.dtype(match.group(1).decode("ascii"))
            shape = tuple(int(n) for n in match.group(2).split(b",") if n.strip())
            if len(raw) - end == math.prod(shape) * dtype.itemsize:
                return np.frombuffer(raw, dtype=dtype, offset=end).reshape(shape).copy()
    return np.load(io.BytesIO(raw), allow_pickle=False)


def fingerprint(value: object) -> str:
    """A short digest of an argument structure, equal in the worker and in the grader."""
    h = hashlib.sha256()
    _feed(h, value, 0)
    return h.hexdigest()[:24]


def _feed(h, v: object, depth: int) -> None:
    if depth > 8:
        h.update(b"<deep>")
    elif isinstance(v, np.ndarray | np.generic):
        arr = np.asarray(v)
        h.update(f"a{arr.dtype.str}{arr.shape}".encode())
        if arr.dtype.kind in "biufc":
            h.update(np.array(arr, order="C").tobytes())
    elif isinstance(v, bool | int | str | type(None)):
        h.update(f"{type(v).__name__}:{v!r}".encode())
    elif isinstance(v, float):
        h.update(f"f{v.hex()}".encode())
    elif isinstance(v, complex):
        h.update(f"c{v.real.hex()}{v.imag.hex()}".encode())
    elif isinstance(v, list | tuple):
        h.update(f"{type(v).__name__}[{len(v)}]".encode())
        for x in v:
            _feed(h, x, depth + 1)
    elif isinstance(v, dict):
        h.update(f"d[{len(v)}]".encode())
        for k in sorted(v, key=repr):
            _feed(h, k, depth + 1)
            _feed(h, v[k], depth + 1)
    else:  # functions and other objects: what they are, not where they live in memory
        name = getattr(v, "__qualname__", None) or type(v).__qualname__
        h.update(f"o{getattr(v, '__module__', '')}.{name}".encode())


SAMPLE = 48


def summary(value: object, depth: int = 0) -> object:
    """A small JSON description of an argument structure, compared with :func:`same`.

    Numbers are kept, arrays by shape, kind and an evenly spaced sample, functions
    by name: enough to see that the worker's check passed the same inputs as the
    grader's, with a tolerance for the last bits that BLAS threads may change.
    """
    if depth > 6:
        return "<deep>"
    if isinstance(value, np.ndarray | np.generic):
        arr = np.asarray(value)
        if arr.dtype.kind not in "biufc":
            return {"array": str(arr.dtype), "shape": list(arr.shape)}
        flat = arr.ravel()
        sample = flat[:: max(1, flat.size // SAMPLE)][:SAMPLE]
        real = sample.real.astype(float)  # [re, im] pairs, built by NumPy (thousands per check)
        imag = sample.imag.astype(float) if arr.dtype.kind == "c" else np.zeros_like(real)
        pairs = np.stack((real, imag), 1).tolist()
        return {"array": arr.dtype.kind, "shape": list(arr.shape), "sample": pairs}
    if isinstance(value, bool | int | str | type(None)):
        return {"exact": f"{type(value).__name__}:{value!r}"[:200]}
    if isinstance(value, float | complex):
        return {"number": [complex(value).real, complex(value).imag]}
    if isinstance(value, list | tuple):
        return {type(value).__name__: [summary(x, depth + 1) for x in list(value)[:64]], "n": len(value)}
    if isinstance(value, dict):
        keys = sorted(value, key=repr)[:64]
        return {"dict": [[repr(k)[:100], summary(value[k], depth + 1)] for k in keys], "n": len(value)}
    name = getattr(value, "__qualname__", None) or type(value).__qualname__
    return {"object": f"{getattr(value, '__module__', '')}.{name}"[:300]}


def same(a: object, b: object, rtol: float = 1e-7, atol: float = 1e-12) -> bool:
    """Whether two :func:`summary` results describe the same value (floats within tolerance)."""
    if a == b:  # the usual case in a replay, compared in C; equal floats are within tolerance
        return True
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return False
        if all(isinstance(x, int | float) for x in a + b):  # np.allclose's test, equal_nan=True
            return all(_close(float(x), float(y), rtol, atol) for x, y in zip(a, b, strict=True))
        return all(same(x, y, rtol, atol) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k], rtol, atol) for k in a)
    return a == b


def _close(x: float, y: float, rtol: float, atol: float) -> bool:
    """``np.isclose(x, y, rtol, atol, equal_nan=True)``, without NumPy's per-call overhead."""
    if x == y:
        return True
    if math.isnan(x) or math.isnan(y):
        return math.isnan(x) and math.isnan(y)
    if math.isinf(x) or math.isinf(y):
        return False
    return abs(x - y) <= atol + rtol * abs(y)


_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,60}$")
_EXCEPTIONS: dict[str, type] = {}


class StudentException(Exception):
    """Base of the exceptions rebuilt from what a student's function raised."""


def exception_record(exc: BaseException) -> dict:
    """What the worker sends about an exception the student's function raised."""
    try:
        text = str(exc)
    except Exception:
        text = "<unprintable>"
    return {"type": type(exc).__name__, "message": text[:2000],
            "pending": isinstance(exc, NotImplementedError)}


def rebuild_exception(record: dict) -> Exception:
    """An exception with the student's exception's name and message (never a BaseException
    such as SystemExit, so replaying it cannot stop the grader)."""
    message = str(record.get("message", ""))[:2000]
    if record.get("pending"):
        return NotImplementedError(message)
    name = str(record.get("type", "Exception"))
    name = name if _IDENT.match(name) else "Exception"
    cls = _EXCEPTIONS.get(name)
    if cls is None:
        cls = _EXCEPTIONS[name] = type(name, (StudentException,), {})
    return cls(message)
