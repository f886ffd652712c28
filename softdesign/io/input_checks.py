"""Checks on an input file before a reader opens it: a readable regular file, and headers that match its size.

A reader handed a FIFO waits forever, one handed ``/dev/zero`` reads without
end, and numpy allocates what an ``.npy`` header claims before it reads a
byte (a 128-byte header can claim 10^11 x 3 float64).  These checks look at
the file's metadata and header only, and raise
:class:`~softdesign.errors.InputDataError` naming the file, what it is, what
was expected and the fix.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from softdesign.errors import InputDataError
from softdesign.io.case_yaml import file_kind
from softdesign.limits import MEMORY_BUDGET_BYTES, MEMORY_BUDGET_TEXT

#: Number kinds an array input may hold: float, signed and unsigned integer (numpy dtype.kind).
NUMBER_KINDS = "fiu"
#: Largest input file, bytes: every reader holds its whole file in memory, so a file over the build's memory budget
#: cannot be read (a 300 GB sparse surface was hashed for 200 s before ingest refused it).
MAX_INPUT_BYTES = MEMORY_BUDGET_BYTES
#: Size of one binary STL triangle record, bytes (normal, 3 corners, attribute count).
STL_RECORD_BYTES = 50
#: Size of a binary STL's header and triangle count, bytes.
STL_HEADER_BYTES = 84


def check_input_file(path: Path, key: str) -> None:
    """Raise InputDataError unless ``path`` is a regular file this user can read.

    Parameters
    ----------
    path : the input file
    key : the case file's key naming it (``final.surface``), for the message
    """
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise InputDataError(
            f"{key}: file not found: {path}; check the path (relative paths start at the case file's folder)"
        ) from None
    except OSError as err:
        raise InputDataError(f"{key}: cannot reach {path} ({err.strerror}); check the path and its folders") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputDataError(
            f"{key}: {path} is {file_kind(info.st_mode)}, not a regular file; expected a centerline or surface "
            "file (e.g. a VMTK .vtp): give the file's path"
        )
    if not os.access(path, os.R_OK):
        raise InputDataError(f"{key}: {path} cannot be read (permission denied); make it readable for this user")
    if info.st_size > MAX_INPUT_BYTES:
        raise InputDataError(
            f"{key}: {path} is {info.st_size:,} bytes, above the bound of {MAX_INPUT_BYTES:,} bytes "
            f"({MEMORY_BUDGET_TEXT}, the build's memory budget: a reader holds its whole file); a vessel's surface or "
            "centerline takes a few MB: check the file, or decimate the surface (e.g. vmtksurfacedecimation)"
        )


@contextmanager
def input_os_errors(inputs: list[Path]) -> Iterator[None]:
    """Turn an OSError on one of ``inputs`` (e.g. EIO, or permission lost mid-run) into an InputDataError naming it."""
    try:
        yield
    except OSError as err:
        names = {os.path.realpath(p) for p in inputs}
        path = next(
            (os.fsdecode(n) for n in (err.filename, err.filename2) if n is not None and os.path.realpath(n) in names),
            None,
        )
        if path is None:
            raise
        raise InputDataError(
            f"{path}: cannot read this input file ({err.strerror or err}); check that it is readable and complete"
        ) from err


def check_npy_header(path: Path) -> tuple[int, ...]:
    """The array's shape; InputDataError unless the ``.npy`` header names a number array the file's size holds.

    Reads the header only (numpy.lib.format), so nothing is allocated for what the header claims.
    """
    import numpy as np

    size = path.stat().st_size
    try:
        with path.open("rb") as handle:
            version = np.lib.format.read_magic(handle)
            fmt = np.lib.format
            read_header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
            shape, _, dtype = read_header(handle)
            offset = handle.tell()
    except (OSError, ValueError) as err:
        raise InputDataError(f"{path}: not a readable .npy array ({err}); save it with numpy.save") from None
    if dtype.kind not in NUMBER_KINDS or dtype.hasobject:
        raise InputDataError(
            f"{path}: holds {dtype} values, expected real numbers (float or integer); "
            "save the points as float64 (complex, string and object arrays are refused)"
        )
    needed = int(np.prod(shape, dtype=object)) * dtype.itemsize + offset
    if needed > size:
        raise InputDataError(
            f"{path}: the header claims a {shape} array ({needed} bytes), but the file has {size} bytes; "
            "the file is truncated or corrupt: save it again with numpy.save"
        )
    return tuple(int(n) for n in shape)


def stl_problem(path: Path) -> str | None:
    """Why ``path`` is neither a binary nor an ASCII STL, or None when it may be one (from its size and first bytes)."""
    size = path.stat().st_size
    with path.open("rb") as handle:
        head = handle.read(STL_HEADER_BYTES)
    if len(head) == STL_HEADER_BYTES:
        count = int.from_bytes(head[80:84], "little")
        if size == STL_HEADER_BYTES + STL_RECORD_BYTES * count:
            return None
    if head.lstrip().lower().startswith(b"solid") and head.isascii():
        return None
    return (
        f"neither a binary STL (84 + 50 x triangles bytes; {size} bytes here) nor an ASCII STL "
        "(text starting with 'solid')"
    )
