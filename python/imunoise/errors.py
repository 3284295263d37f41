"""Exceptions of imunoise.

Every reader raises :class:`ParseError` for a record it cannot decode in strict
mode, with the location as attributes, so callers need not parse the message.
Files that do not exist raise the built-in :class:`FileNotFoundError`.
"""

from __future__ import annotations

__all__ = ["ParseError"]


class ParseError(ValueError):
    """A record of a log could not be decoded (strict mode).

    Attributes
    ----------
    kind : str
        The issue kind, one of :data:`imunoise.readers.log.ISSUE_KINDS`
        (``"bad_checksum"``, ``"malformed_field"`` ...).
    reason : str
        What was wrong with the record, in words.
    line : int or None
        1-based line of the record (text formats), or message number (bags).
    offset : int or None
        0-based byte offset of the record's first byte, when known.
    source : str or None
        The file the record came from (``None`` for bytes in memory).
    """

    def __init__(
        self,
        reason: str,
        *,
        kind: str,
        line: int | None = None,
        offset: int | None = None,
        source: str | None = None,
    ) -> None:
        self.reason = reason
        self.kind = kind
        self.line = line
        self.offset = offset
        self.source = source
        super().__init__(self._message())

    def _message(self) -> str:
        where = []
        if self.source is not None:
            where.append(str(self.source))
        if self.line is not None:
            where.append(f"line {self.line}")
        if self.offset is not None:
            where.append(f"byte offset {self.offset}")
        prefix = ", ".join(where)
        return f"{prefix}: {self.kind}: {self.reason}" if prefix else f"{self.kind}: {self.reason}"

    def __reduce__(self):  # keep the attributes through pickling (multiprocessing, Dask)
        return (_rebuild, (self.reason, self.kind, self.line, self.offset, self.source))


def _rebuild(reason, kind, line, offset, source):
    return ParseError(reason, kind=kind, line=line, offset=offset, source=source)
