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


#: Legacy encodings a text file not in UTF-8 is tried in, to say which one it reads as: (codec, name, test of the
#: bad line's text). Windows-1252 first when every non-ASCII character it gives is an accented Latin letter (an
#: East Asian codec would read "Tête" as a kanji and a "t"), then the East Asian ones when the line then holds
#: their script (they decode most byte pairs), then Windows-1252 for anything else it decodes.
_LEGACY_ENCODINGS = (
    ("cp1252", "Windows-1252 (Western European)", r"^(?:[\x00-\x7f]|[\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u00ff])*$"),
    ("cp932", "Shift-JIS (Japanese; Windows code page 932)", r"[\u3040-\u30ff\u4e00-\u9fff\uff66-\uff9f]"),
    ("gb18030", "GB18030 (Chinese)", r"[\u4e00-\u9fff]"),
    ("euc_kr", "EUC-KR (Korean)", r"[\uac00-\ud7af]"),
    ("cp1252", "Windows-1252 (Western European)", r"."),
)


def _encoding_hint(data: bytes, at: int) -> str:
    """``"; it reads as <encoding>: ..."`` for text that one legacy encoding decodes whole, naming it and how to
    convert the file to UTF-8 (``iconv``); ``""`` when none does."""
    import re

    start, end = data.rfind(b"\n", 0, at) + 1, data.find(b"\n", at)
    for codec, name, script in _LEGACY_ENCODINGS:
        try:
            data.decode(codec)
            line = data[start:end if end >= 0 else len(data)].decode(codec).strip()
        except UnicodeDecodeError:
            continue
        if re.search(script, line):
            return (f"; it reads as {name}, e.g. {line[:60]!r}: convert it to UTF-8 first, e.g. iconv -f "
                    f"{codec.upper()} -t UTF-8 < IN > OUT")
    return ""


def read_text_lines(path) -> list[str]:
    """The lines of a UTF-8 text file, with errors that name file and line.

    A leading UTF-8 byte-order mark (written by some Windows editors) is an
    encoding signature, not content, and is dropped. Bytes that are not UTF-8
    raise :class:`MotionFormatError` naming the first bad line (the built-in
    decoder would only give a byte offset).

    Raises
    ------
    MotionFormatError
        The file cannot be opened or is not UTF-8 text.
    """
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise MotionFormatError(path, None, f"cannot open: {exc.strerror or exc}") from None
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    # universal newlines (LF, CRLF, CR), as open(..., newline=None) reads them
    data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise MotionFormatError(
            path, line, f"not UTF-8 text (byte {data[exc.start:exc.start + 1]!r}){_encoding_hint(data, exc.start)}"
        ) from None
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    return lines
