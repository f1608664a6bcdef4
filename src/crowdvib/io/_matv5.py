"""Structural check of a MATLAB v5 file before scipy parses it.

scipy's Cython MAT v5 reader (``scipy.io.matlab._mio5_utils``, seen with scipy 1.17.1) can crash
the interpreter with a segmentation fault on a damaged file, e.g. a numeric array whose data
element claims a matrix type (found by fuzzing crowdvib's reader, issue 9). No ``except`` can
catch that, so the file's element structure is walked here first: every tag, size, dimension
and element type must be consistent with the MAT-File Format (MathWorks, "MAT-File Format",
version 5 layout), and only a file that passes reaches ``scipy.io.loadmat``.

Variables of the classes a record file uses — numeric (double, single, integers; logical is
uint8), char, cell and struct — are checked element by element; other variables (objects,
function handles, sparse matrices) are skipped unread, so their headers must be sound but their
contents never reach scipy.
"""

import math
import struct
import zlib
from pathlib import Path

from .._resources import memory_limit
from ..errors import DataError
from ._common import quote, where

__all__ = ["check_mat_v5"]

# Element types (miINT8 … miUTF32) → size of one value [bytes].
_NUMERIC = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 9: 8, 12: 8, 13: 8}
_TEXT = {**_NUMERIC, 16: 1, 17: 2, 18: 4}
_MATRIX, _COMPRESSED = 14, 15
_CELL, _STRUCT, _CHAR = 1, 2, 4
_NUMERIC_CLASSES = range(6, 16)     # mxDOUBLE_CLASS … mxUINT64_CLASS
_MAX_DEPTH = 32                     # cells in cells: deeper than any record file needs


def _elements(buffer, order, prefix):
    """Yield (type, payload) of the consecutive data elements of ``buffer``."""
    position = 0
    while position < len(buffer):
        if len(buffer) - position < 8:
            raise DataError(f"{prefix}a data element is cut short (truncated file?)")
        first, second = struct.unpack_from(order + "II", buffer, position)
        if first >> 16:   # small data element: type and size share the first word
            kind, size = first & 0xFFFF, first >> 16
            if size > 4:
                raise DataError(f"{prefix}a small data element claims {size} bytes (at most 4)")
            yield kind, buffer[position + 4:position + 4 + size]
            position += 8
            continue
        kind, size, start = first, second, position + 8
        if start + size > len(buffer):
            raise DataError(f"{prefix}a data element of {size} bytes runs past the end of the "
                            "file (truncated file?)")
        yield kind, buffer[start:start + size]
        # Elements are padded to 8 bytes, except compressed ones (MAT-File Format, v5).
        position = start + size + (0 if kind == _COMPRESSED else -size % 8)


def _take(parts, prefix, what, kinds):
    part = next(parts, None)
    if part is None:
        raise DataError(f"{prefix}{what} is missing (truncated or damaged file?)")
    if part[0] not in kinds:
        raise DataError(f"{prefix}{what} has element type {part[0]}, expected one of "
                        f"{sorted(kinds)} (damaged file?)")
    return part


class _Unsupported(Exception):
    """A variable of a class crowdvib does not read (skipped, not an error)."""


def _check_matrix(payload, order, prefix, depth):
    """Check one miMATRIX element (recursing into cells and structs); returns its name."""
    if depth > _MAX_DEPTH:
        raise DataError(f"{prefix}cells nested deeper than {_MAX_DEPTH} levels")
    if not payload:
        return ""           # an empty array: MATLAB writes the tag alone
    parts = _elements(payload, order, prefix)
    _, flags = _take(parts, prefix, "array flags", {6})
    _, shape = _take(parts, prefix, "dimensions", {5})
    _, name = _take(parts, prefix, "array name", {1, 2})
    label = name.decode("ascii", "replace")
    inner = f"{prefix}variable {quote(label)}: " if depth == 0 and label else prefix
    if len(flags) != 8 or len(shape) < 8 or len(shape) % 4:
        raise DataError(f"{inner}array flags or dimensions are malformed (damaged file?)")
    word = struct.unpack_from(order + "I", flags)[0]
    kind, is_complex = word & 0xFF, bool(word & 0x800)
    dims = struct.unpack(order + f"{len(shape) // 4}i", shape)
    if min(dims) < 0:
        raise DataError(f"{inner}negative dimension in {dims} (damaged file?)")
    count = math.prod(dims)
    if kind in _NUMERIC_CLASSES or kind == _CHAR:
        types = _NUMERIC if kind != _CHAR else _TEXT
        for part in ("real part", "imaginary part")[:1 + is_complex]:
            mdtype, data = _take(parts, inner, part, set(types))
            if kind == _CHAR and mdtype == 16:
                continue            # UTF-8 text: characters of varying width
            if len(data) != count * types[mdtype]:
                raise DataError(f"{inner}{part} holds {len(data)} bytes, {count} value(s) of "
                                f"{types[mdtype]} byte(s) need {count * types[mdtype]} "
                                "(truncated or damaged file?)")
    elif kind == _CELL:
        for _ in range(count):
            _check_matrix(_take(parts, inner, "cell element", {_MATRIX})[1], order, inner,
                          depth + 1)
    elif kind == _STRUCT:
        _, length = _take(parts, inner, "field name length", {5})
        width = struct.unpack_from(order + "i", length)[0] if len(length) == 4 else 0
        _, names = _take(parts, inner, "field names", {1})
        if width <= 0 or len(names) % width:
            raise DataError(f"{inner}field names are malformed (damaged file?)")
        for _ in range(count * (len(names) // width)):
            _check_matrix(_take(parts, inner, "struct field", {_MATRIX})[1], order, inner,
                          depth + 1)
    else:
        raise _Unsupported(kind)
    return label


def _inflated(payload, prefix):
    """A compressed element's bytes, refused once they pass half the memory available (a small
    element may inflate a thousandfold)."""
    limit = memory_limit()
    inflater = zlib.decompressobj()
    data = inflater.decompress(payload, limit)
    if inflater.unconsumed_tail:
        raise DataError(f"{prefix}a compressed element of {len(payload)} bytes expands past "
                        f"{limit} bytes, more than half the memory available (damaged or "
                        "hostile file?)")
    return data


def check_mat_v5(path):
    """Names of the variables of ``path`` that scipy may read.

    Raises
    ------
    DataError
        Naming the file (and the variable): the MAT v5 element structure is inconsistent.
    """
    content = Path(path).read_bytes()
    prefix = where(path)
    if len(content) < 128 or content[126:128] not in (b"IM", b"MI"):
        raise DataError(f"{prefix}is not a MATLAB v5 file (no MAT-file header)")
    order = "<" if content[126:128] == b"IM" else ">"
    names = []
    for kind, payload in _elements(content[128:], order, prefix):
        if kind == _COMPRESSED:
            inner = list(_elements(_inflated(payload, prefix), order, prefix))
            if len(inner) != 1 or inner[0][0] != _MATRIX:
                raise DataError(f"{prefix}a compressed element does not hold one array "
                                "(damaged file?)")
            payload = inner[0][1]
        elif kind != _MATRIX:
            raise DataError(f"{prefix}top-level element of type {kind} is not an array "
                            "(damaged file?)")
        try:
            names.append(_check_matrix(payload, order, prefix, 0))
        except _Unsupported:
            continue
    return names
