"""Errors raised by the file readers.

Every reader raises :class:`MotionFormatError` (a ``ValueError``) for malformed
input, with the file and, where it is known, the 1-based line number in the
message, so that a user can open the file at the offending line.
"""

from __future__ import annotations

import os


class MotionFormatError(ValueError):
    """Malformed motion, skeleton, mesh or landmark file.

    Parameters
    ----------
    path : str or os.PathLike
        The file being read.
    line : int or None
        1-based line number of the offending line, if known.
    message : str
        What is wrong.
    """

    def __init__(self, path, line: int | None, message: str):
        self.path = os.fspath(path) if path is not None else "<memory>"
        self.line = line
        self.message = message
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


def parse_float(token: str, path, line: int, what: str = "value") -> float:
    """Parse one float, raising :class:`MotionFormatError` on junk or NaN/inf."""
    try:
        value = float(token)
    except ValueError:
        raise MotionFormatError(path, line, f"non-numeric {what} {token!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise MotionFormatError(path, line, f"non-finite {what} {token!r}")
    return value
