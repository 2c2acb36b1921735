"""Arrow columns as numpy arrays without importing pandas (``pyarrow``'s own ``to_numpy`` does,
which costs a third of a second at start-up — issue #17).

Fixed-width numbers and booleans are read from the column's buffers (floats with nulls get
NaN); anything else (strings, numbers with nulls) goes through Python objects.
"""

from __future__ import annotations

import numpy as np


def column_to_numpy(col) -> np.ndarray:
    """A pyarrow ``Array`` or ``ChunkedArray`` as a numpy array (a copy, writable)."""
    import pyarrow as pa

    a = col.combine_chunks() if isinstance(col, pa.ChunkedArray) else col
    t, n = a.type, len(a)
    if pa.types.is_boolean(t) and not a.null_count:
        bits = np.frombuffer(a.buffers()[1], np.uint8)
        return np.unpackbits(bits, bitorder="little")[a.offset : a.offset + n].astype(bool)
    kind = "f" if pa.types.is_floating(t) else "i" if pa.types.is_signed_integer(t) else (
        "u" if pa.types.is_unsigned_integer(t) else None)  # fmt: skip
    if kind is None or (a.null_count and kind != "f"):
        return np.array(a.to_pylist(), dtype=object if kind is None else float)
    width = t.bit_width // 8
    v = np.frombuffer(a.buffers()[1], np.dtype(f"<{kind}{width}"), n, a.offset * width).copy()
    if a.null_count:
        valid = np.frombuffer(a.buffers()[0], np.uint8)
        ok = np.unpackbits(valid, bitorder="little")[a.offset : a.offset + n].astype(bool)
        v[~ok] = np.nan
    return v
