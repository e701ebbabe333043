"""Shared helpers of the exchange-format readers and writers.

Every reader goes through :func:`read_text` (size limit, UTF-8, typed errors)
and parses numbers with :func:`parse_float` / :func:`parse_int` (finite,
``|v| <= 1e15``) or, for decoded JSON/YAML values, :class:`ValueReader`.
Errors are :class:`~truortho.core.errors.FormatError` naming the file and,
where there is one, the 1-based line.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator
from pathlib import Path

from ..errors import FormatError, InputError, MissingFileError
from ..orientation import check_relative_path

MAX_FILE_BYTES = 512 * 1024**2
MAX_ABS_VALUE = 1e15


def read_text(path: str | os.PathLike, what: str = "file", max_bytes: int = MAX_FILE_BYTES) -> str:
    """The content of a UTF-8 text file (a leading BOM is dropped).

    Raises
    ------
    MissingFileError
        The file does not exist.
    FormatError
        The file is larger than ``max_bytes``, unreadable or not UTF-8.
    """
    p = Path(path)
    if not p.is_file():
        raise MissingFileError(p, f"{what} not found")
    try:
        size = p.stat().st_size
        if size > max_bytes:
            raise FormatError(
                p, f"{what} is too large ({size / 1024**2:.0f} MB; the limit is {max_bytes / 1024**2:.0f} MB)"
            )
        data = p.read_bytes()
    except OSError as err:
        raise FormatError(p, f"cannot read the {what}: {err.strerror or err}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise FormatError(
            p, f"not UTF-8 text (invalid byte 0x{data[err.start]:02x}); save the {what} as UTF-8", line=line
        ) from None
    return text[1:] if text.startswith("\ufeff") else text


def numbered_lines(text: str) -> Iterator[tuple[int, str]]:
    """``(line_number, line)`` for every line (1-based, line ends removed)."""
    yield from enumerate(text.splitlines(), start=1)


def data_lines(text: str, comment: str = "#") -> Iterator[tuple[int, str]]:
    """``(line_number, stripped_line)`` of non-empty, non-comment lines."""
    for i, line in numbered_lines(text):
        s = line.strip()
        if s and not s.startswith(comment):
            yield i, s


def parse_float(token: str, path: object, line: int | None, what: str) -> float:
    """A finite float of reasonable size from a text token, else :class:`FormatError`."""
    try:
        v = float(token)
    except (TypeError, ValueError):
        raise FormatError(path, f"{what}: expected a number, got {_show(token)}", line=line) from None
    if not math.isfinite(v) or abs(v) > MAX_ABS_VALUE:
        raise FormatError(
            path, f"{what}: expected a finite number of reasonable size, got {_show(token)}", line=line
        )
    return v


def parse_int(token: str, path: object, line: int | None, what: str) -> int:
    """An integer (``|v| <= 1e15``) from a text token, else :class:`FormatError`."""
    t = token.strip() if isinstance(token, str) else token
    if not isinstance(t, str) or not t.lstrip("+-").isdigit() or len(t) > 17:
        raise FormatError(path, f"{what}: expected an integer, got {_show(token)}", line=line)
    return int(t)


def check_name(name: str, path: object, line: int | None, what: str = "image name") -> str:
    """A relative image path without ``..`` (normalised to ``/``), else :class:`FormatError`."""
    try:
        return check_relative_path(name, what)
    except InputError as err:
        raise FormatError(path, str(err), line=line) from None


def fmt(v: float) -> str:
    """Shortest text that reads back as exactly the same float."""
    return repr(float(v))


def load_json(path: str | os.PathLike, what: str = "JSON file") -> object:
    """Decoded JSON (NaN/Infinity rejected); errors carry the line number."""
    text = read_text(path, what)
    return parse_json(text, path)


def parse_json(text: str, path: object) -> object:
    try:
        return json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as err:
        raise FormatError(path, f"invalid JSON: {err.msg}", line=err.lineno) from None
    except (ValueError, RecursionError) as err:
        raise FormatError(path, f"invalid JSON: {err}") from None


def _reject_constant(name: str):
    raise ValueError(f"{name} is not allowed")


def _show(token: object) -> str:
    s = repr(token)
    return s if len(s) <= 60 else s[:57] + "..."


class ValueReader:
    """Typed access to decoded JSON/YAML values; failures name the file and field."""

    def __init__(self, path: object) -> None:
        self.path = path

    def fail(self, field: str, msg: str):
        raise FormatError(self.path, f"{field}: {msg}")

    def num(self, v: object, field: str) -> float:
        if isinstance(v, bool) or not isinstance(v, int | float):
            self.fail(field, f"expected a number, got {_show(v)}")
        if isinstance(v, int) and abs(v) > MAX_ABS_VALUE:
            self.fail(field, f"number too large: {_show(v)}")
        f = float(v)  # type: ignore[arg-type]
        if not math.isfinite(f) or abs(f) > MAX_ABS_VALUE:
            self.fail(field, f"expected a finite number of reasonable size, got {_show(v)}")
        return f

    def size(self, v: object, field: str) -> int:
        if isinstance(v, float) and v.is_integer():
            v = int(v)
        if isinstance(v, bool) or not isinstance(v, int) or not 0 < v <= 10**6:
            self.fail(field, f"expected a positive integer (pixels), got {_show(v)}")
        return v  # type: ignore[return-value]

    def vec(self, v: object, n: int, field: str) -> list[float]:
        if not isinstance(v, list | tuple) or len(v) != n:
            self.fail(field, f"expected a list of {n} numbers, got {_show(v)}")
        seq: list | tuple = v  # type: ignore[assignment]
        return [self.num(x, f"{field}[{i}]") for i, x in enumerate(seq)]

    def obj(self, v: object, field: str) -> dict:
        if not isinstance(v, dict):
            self.fail(field, f"expected an object, got {type(v).__name__}")
        return v  # type: ignore[return-value]

    def text(self, v: object, field: str) -> str:
        if not isinstance(v, str) or not v or len(v) > 4096:
            self.fail(field, f"expected a non-empty string, got {_show(v)}")
        return v  # type: ignore[return-value]
