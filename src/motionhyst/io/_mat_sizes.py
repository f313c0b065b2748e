"""The sizes a MATLAB level-5 file declares for the values inside its structures and cells.

``scipy.io.whosmat`` lists a structure as 1x1: the sizes of its fields are declared only in
the fields' own headers, inside the variable's (often compressed) data.  A structure of a few
MB on disk can declare GBs of zeros; :func:`declared_values` walks the headers, inflating a
compressed variable a block at a time and keeping none of its values, so that the reader
can refuse a variable above the memory budget before ``loadmat`` allocates it.

Level 5 layout (MATLAB's "MAT-File Format"): a 128-byte header whose bytes 126-127 are ``IM``
(little-endian) or ``MI``; then data elements, each an 8-byte tag (type, byte count) or a
small element (count in the tag's upper 16 bits, its data in the tag's last 4 bytes), padded
to 8 bytes.  A variable is an ``miMATRIX`` element (or one inside an ``miCOMPRESSED``
element): array flags, dimensions, name, then for a structure the field name length, the
field names and one ``miMATRIX`` per field and element; for a cell one per element.
"""

from __future__ import annotations

import math
import struct
import zlib
from collections.abc import Callable, Iterable
from pathlib import Path

__all__ = ["declared_values"]

_MI_INT8, _MI_INT32, _MI_UINT32, _MI_MATRIX, _MI_COMPRESSED = 1, 5, 6, 14, 15
_CELL, _STRUCT, _OBJECT, _SPARSE = 1, 2, 3, 5
_BLOCK = 1 << 20


class _Malformed(Exception):
    """Headers this walk does not understand: scipy reads the file and says what is wrong."""


class _Stream:
    """The bytes of one top-level element, read in order: from the file, or inflated a block
    at a time from a compressed element (a skipped stretch is inflated and dropped)."""

    def __init__(self, fh, size: int, compressed: bool) -> None:
        self.fh, self.left = fh, size
        self.inflate = zlib.decompressobj() if compressed else None
        self.buf = b""
        self.pos = 0

    def _more(self, want: int) -> bytes:
        if self.inflate is None:
            raw = self.fh.read(min(want, self.left))
            self.left -= len(raw)
            return raw
        if self.inflate.unconsumed_tail:
            return self.inflate.decompress(self.inflate.unconsumed_tail, _BLOCK)
        if self.left <= 0:
            return b""
        raw = self.fh.read(min(self.left, 1 << 16))
        self.left -= len(raw)
        if not raw:
            self.left = 0
        return self.inflate.decompress(raw, _BLOCK)

    def read(self, n: int) -> bytes:
        while len(self.buf) < n:
            more = self._more(max(n - len(self.buf), 1 << 16))
            if not more and (self.inflate is None or not self.inflate.unconsumed_tail) \
                    and self.left <= 0:
                raise _Malformed("the element ends early")
            self.buf += more
        out, self.buf = self.buf[:n], self.buf[n:]
        self.pos += n
        return out

    def skip(self, n: int) -> None:
        if self.inflate is None and not self.buf:
            if n > self.left:
                raise _Malformed("the element ends early")
            self.fh.seek(n, 1)
            self.left -= n
            self.pos += n
            return
        while n > 0:
            step = min(n, _BLOCK)
            self.read(step)
            n -= step


def _tag(s: _Stream, order: str) -> tuple[int, int, bytes | None]:
    """A data element's type and byte count; a small element's data too."""
    kind, size = struct.unpack(order + "II", s.read(8))
    if kind >> 16:  # small data element: up to 4 bytes in the tag
        small = kind >> 16
        raw = struct.pack(order + "I", size)
        return kind & 0xFFFF, small, raw[:small]
    return kind, size, None


def _element(s: _Stream, order: str) -> tuple[int, bytes]:
    """The next data element of a matrix: its type and (padded-off) data."""
    kind, size, small = _tag(s, order)
    if small is not None:
        return kind, small
    if size > 1 << 16:  # flags, dimensions and names are small
        raise _Malformed("a header element too large")
    data = s.read(size)
    s.skip(-size % 8)
    return kind, data


def _ints(kind: int, data: bytes, order: str) -> tuple[int, ...]:
    if kind not in (_MI_INT32, _MI_UINT32) or len(data) % 4:
        raise _Malformed("integers expected")
    return struct.unpack(order + ("i" if kind == _MI_INT32 else "I") * (len(data) // 4), data)


def _matrix(s: _Stream, size: int, order: str, name: str,
            found: Callable[[str, int], None], top: set[str] | None = None) -> str:
    """Walk one ``miMATRIX`` of `size` bytes: `found` (name, values) for each array of
    values inside it; the matrix's own name.  A top-level variable (its name read from the
    element) is walked only if it is among `top`."""
    if size == 0:  # an empty field
        return name
    end = s.pos + size
    flags = _ints(*_element(s, order), order)
    cls, complex_ = flags[0] & 0xFF, bool(flags[0] & 0x800)
    dims = _ints(*_element(s, order), order)
    if any(d < 0 for d in dims):
        raise _Malformed("negative dimensions")
    kind, own = _element(s, order)
    if top is not None:
        name = own.decode("latin-1")
        if name not in top:
            return name
    count = math.prod(dims)
    if cls in (_STRUCT, _OBJECT):
        if cls == _OBJECT:
            _element(s, order)  # the class name
        length = _ints(*_element(s, order), order)[0]
        kind, raw = _element(s, order)
        if length <= 0 or len(raw) % length:
            raise _Malformed("field names")
        fields = [raw[i:i + length].split(b"\0")[0].decode("latin-1")
                  for i in range(0, len(raw), length)]
        for _ in range(count):
            for field in fields:
                kind, sub, _ = _tag(s, order)
                if kind != _MI_MATRIX:
                    raise _Malformed("a field that is not a matrix")
                _matrix(s, sub, order, f"{name}.{field}", found)
    elif cls == _CELL:
        for i in range(count):
            kind, sub, _ = _tag(s, order)
            if kind != _MI_MATRIX:
                raise _Malformed("a cell that is not a matrix")
            _matrix(s, sub, order, f"{name}{{{i + 1}}}", found)
    else:  # numbers, text, a sparse matrix (its nonzeros)
        values = flags[1] if cls == _SPARSE and len(flags) > 1 else count
        found(name, values * (2 if complex_ else 1))
    if s.pos > end:
        raise _Malformed("a matrix longer than its tag")
    s.skip(end - s.pos)
    return name


def declared_values(path: str | Path, names: Iterable[str],
                    found: Callable[[str, int], None]) -> None:
    """Call `found` (name, values) for each array inside the variables `names` of a MATLAB
    level-5 file, in the file's order, from the sizes it declares (no value is kept).

    A structure's field is named ``var.field``, a cell's element ``var{i}``; an array of
    numbers gives its element count (twice for complex numbers), a sparse matrix its
    nonzeros.  `found` may raise to stop the walk (a budget exceeded).  A file this walk
    does not understand is left to the reader: the walk stops without a word.

    Parameters
    ----------
    path : str or Path
        MATLAB level-5 file (``-v6`` or ``-v7``).
    names : iterable of str
        The top-level variables to walk.
    found : callable
        Called with (name, values) for each array of values.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> from scipy.io import savemat
    >>> from motionhyst.io._mat_sizes import declared_values
    >>> path = tempfile.mkdtemp() + "/r.mat"
    >>> savemat(path, {"data": {"t": np.zeros((1000, 1)), "u": np.ones(10)}})
    >>> declared_values(path, ["data"], lambda name, n: print(name, n))
    data.t 1000
    data.u 10
    """
    wanted = set(names)
    try:
        with open(path, "rb") as fh:
            header = fh.read(128)
            if len(header) < 128 or header[126:128] not in (b"IM", b"MI"):
                return
            order = "<" if header[126:128] == b"IM" else ">"
            while wanted:
                raw = fh.read(8)
                if len(raw) < 8:
                    return
                kind, size = struct.unpack(order + "II", raw)
                start = fh.tell()
                if kind == _MI_COMPRESSED:
                    s = _Stream(fh, size, compressed=True)
                    inner_kind, inner, _ = _tag(s, order)
                    if inner_kind != _MI_MATRIX:
                        raise _Malformed("a compressed element that is not a matrix")
                elif kind == _MI_MATRIX:
                    s, inner = _Stream(fh, size, compressed=False), size
                else:
                    raise _Malformed("a top-level element that is not a matrix")
                wanted.discard(_matrix(s, inner, order, "", found, top=wanted))
                fh.seek(start + size + (-size % 8 if kind == _MI_MATRIX else 0))
    except (_Malformed, struct.error, zlib.error, OSError, UnicodeDecodeError):
        return
