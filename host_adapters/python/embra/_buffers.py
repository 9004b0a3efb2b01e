"""Flat xyz arrays between Python and C without copies where the caller's data allows it.

Inputs accept a numpy array (used in place when it is already contiguous float64 / int32), any
object exposing a contiguous buffer of doubles or 32-bit ints (``array.array``, ``memoryview``),
or nested sequences of numbers (``[(x, y, z), ...]``), which are packed once. Outputs are numpy
``(n, 3)`` arrays when numpy is installed (filled in place by C) and flat ``array.array('d')``
otherwise; a caller may pass its own writable buffer as ``out``.
"""

import ctypes
from array import array
from ctypes import POINTER, c_double, c_int32

try:
    import numpy as np
except ImportError:  # numpy is optional
    np = None

_INT32_CODE = next(code for code in ("i", "l") if array(code).itemsize == 4)
INT32_MIN, INT32_MAX = -2**31, 2**31 - 1


def have_numpy():
    return np is not None


def _flatten(values, name):
    flat = []
    for v in values:
        if isinstance(v, (str, bytes)):
            raise TypeError(f"{name}: expected numbers, got {type(v).__name__}")
        try:
            flat.extend(v)
        except TypeError:
            flat.append(v)
    return flat


def check_rows(obj, width, name):
    """Refuses data whose shape says its rows are not `width` wide: a 2-D array of shape (n, k) with
    k != width (a transposed (3, n) array, quads passed as triangles), or a nested sequence whose
    rows are not all `width` long. Flat data passes (its length is checked by the caller)."""
    if obj is None:
        return
    shape = getattr(obj, "shape", None)
    if shape is not None:
        if len(shape) == 2 and shape[1] != width:
            raise ValueError(f"{name}: expected an (n, {width}) array, got shape {tuple(shape)}")
        if len(shape) > 2:
            raise ValueError(f"{name}: expected an (n, {width}) or flat array, got shape {tuple(shape)}")
        return
    if isinstance(obj, (str, bytes)):
        return
    try:
        rows = list(obj) if not isinstance(obj, (array, memoryview)) else []
    except TypeError:
        return
    nested = [hasattr(r, "__len__") and not isinstance(r, (str, bytes)) for r in rows]
    if any(nested):
        for i, r in enumerate(rows):
            if not nested[i] or len(r) != width:
                got = len(r) if nested[i] else "a single number"
                raise ValueError(f"{name}: expected rows of {width}, row {i} has {got}")


def _from_memoryview(obj, fmt, ctype, pointer_type):
    try:
        mv = memoryview(obj)
    except TypeError:
        return None
    if mv.format not in fmt or not mv.c_contiguous or mv.itemsize != ctypes.sizeof(ctype):
        return None
    n = mv.nbytes // mv.itemsize
    if mv.readonly:
        buf = (ctype * n).from_buffer_copy(mv)
    else:
        buf = (ctype * n).from_buffer(mv.cast("B"))
    return ctypes.cast(buf, pointer_type), n, (buf, mv)


def doubles_in(obj, name):
    """(pointer, number of doubles, keep-alive) for input data; (None, 0, None) for None."""
    if obj is None:
        return None, 0, None
    if np is not None and (isinstance(obj, np.ndarray) or hasattr(obj, "__array_interface__")):
        a = np.ascontiguousarray(obj, dtype=np.float64)  # no copy when already contiguous float64
        return a.ctypes.data_as(POINTER(c_double)), int(a.size), a
    view = _from_memoryview(obj, ("d", "@d", "<d", "=d"), c_double, POINTER(c_double))
    if view is not None:
        return view
    try:
        a = array("d", _flatten(obj, name))
    except TypeError as e:
        raise TypeError(f"{name}: expected numbers or sequences of 3 numbers ({e})") from None
    buf = (c_double * len(a)).from_buffer(a)
    return ctypes.cast(buf, POINTER(c_double)), len(a), (buf, a)


def ints_in(obj, name):
    """(pointer, number of int32, keep-alive) for index data; (None, 0, None) for None."""
    if obj is None:
        return None, 0, None
    if np is not None and (isinstance(obj, np.ndarray) or hasattr(obj, "__array_interface__")):
        src = np.asarray(obj)
        if src.size and (src.min() < INT32_MIN or src.max() > INT32_MAX):
            raise OverflowError(f"{name}: an index does not fit in int32")
        a = np.ascontiguousarray(src, dtype=np.int32)
        return a.ctypes.data_as(POINTER(c_int32)), int(a.size), a
    view = _from_memoryview(obj, ("i", "@i", "<i", "=i", "l", "@l"), c_int32, POINTER(c_int32))
    if view is not None:
        return view
    flat = _flatten(obj, name)
    for v in flat:
        if not isinstance(v, int) or isinstance(v, bool):
            if not (hasattr(v, "__index__")):
                raise TypeError(f"{name}: expected integer indices, got {type(v).__name__}")
        if not INT32_MIN <= int(v) <= INT32_MAX:
            raise OverflowError(f"{name}: index {int(v)} does not fit in int32")
    a = array(_INT32_CODE, [int(v) for v in flat])
    buf = (c_int32 * len(a)).from_buffer(a)
    return ctypes.cast(buf, POINTER(c_int32)), len(a), (buf, a)


def doubles_out(count, out, name, width=3):
    """(result object, pointer, capacity in doubles, keep-alive) for `count` xyz triples (or, with
    width 1, `count` single values) written by C."""
    if out is None:
        if np is not None:
            result = np.empty((count, 3) if width == 3 else (count * width,), dtype=np.float64)
            return result, result.ctypes.data_as(POINTER(c_double)), width * count, None
        result = array("d", bytes(8 * width * count))
    else:
        result = out
    if np is not None and isinstance(result, np.ndarray):
        if result.dtype != np.float64 or not result.flags.c_contiguous or not result.flags.writeable:
            raise TypeError(f"{name}: out must be a writable C-contiguous float64 array")
        return result, result.ctypes.data_as(POINTER(c_double)), int(result.size), None
    view = _from_memoryview(result, ("d", "@d", "<d", "=d"), c_double, POINTER(c_double))
    if view is None or memoryview(result).readonly:
        raise TypeError(f"{name}: out must be a writable contiguous buffer of doubles")
    pointer, n, keep = view
    return result, pointer, n, keep


def d3(values, name):
    """A c_double[3] from three numbers (length checked here; finiteness by the C library)."""
    v = list(values) if not (np is not None and isinstance(values, np.ndarray)) else values.ravel().tolist()
    if len(v) != 3:
        raise ValueError(f"{name}: expected 3 numbers, got {len(v)}")
    return (c_double * 3)(*v)


def d4(values, name):
    v = list(values) if not (np is not None and isinstance(values, np.ndarray)) else values.ravel().tolist()
    if len(v) != 4:
        raise ValueError(f"{name}: expected 4 numbers, got {len(v)}")
    return (c_double * 4)(*v)


def int32(value, name):
    """A Python int that must fit an int32 (ctypes would silently wrap it)."""
    v = int(value.__index__()) if hasattr(value, "__index__") else None
    if v is None:
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__}")
    if not INT32_MIN <= v <= INT32_MAX:
        raise OverflowError(f"{name}: {v} does not fit in int32")
    return v
