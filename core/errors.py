"""Typed errors of the TruOrtho core.

Every error raised on purpose by ``core`` derives from :class:`TruOrthoError`;
subclasses also inherit the matching builtin (as rasterio's errors do) so that
generic ``except ValueError`` code keeps working. The Processing layer turns
any :class:`TruOrthoError` into a ``QgsProcessingException`` in one place
(``truortho.processing.feedback``).
"""

from __future__ import annotations


class TruOrthoError(Exception):
    """Root of all TruOrtho errors."""


class InputError(TruOrthoError, ValueError):
    """Bad user input: a value, parameter or combination that cannot be used."""


class FormatError(InputError):
    """A file could not be parsed.

    Parameters
    ----------
    path : str
        The file (or a description of the source) that was being read.
    message : str
        What was wrong and what was expected.
    line : int, optional
        1-based line number when the error is tied to one line.
    """

    def __init__(self, path: object, message: str, line: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        self.reason = message
        where = f"{self.path}, line {line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class MissingFileError(InputError, FileNotFoundError):
    """A file the input refers to does not exist."""

    def __init__(self, path: object, message: str = "file not found") -> None:
        self.path = str(path)
        super().__init__(f"{self.path}: {message}")


class CRSError(InputError):
    """A coordinate reference system is missing, invalid or not usable."""


class GeometryError(TruOrthoError, ArithmeticError):
    """A geometric computation is impossible (degenerate configuration)."""


class ConvergenceError(TruOrthoError, RuntimeError):
    """An iterative estimation did not converge."""


class CancelledError(TruOrthoError):
    """The user cancelled the operation (raised through the progress protocol)."""
