"""Exceptions and warnings of imunoise.

Every error imunoise raises is an :class:`ImunoiseError` (``except
imunoise.ImunoiseError`` catches them all), and still the built-in class it always
was: a bad argument is an :class:`ImunoiseValueError` (a :class:`ValueError`) or an
:class:`ImunoiseTypeError` (a :class:`TypeError`); a record a reader cannot decode in
strict mode a :class:`ParseError` (a :class:`ValueError`), with its location as
attributes, so callers need not parse the message. Files that do not exist raise the
built-in :class:`FileNotFoundError`, and Ctrl-C :class:`KeyboardInterrupt`.

Every warning is an :class:`ImunoiseWarning` (``warnings.filterwarnings("ignore",
category=imunoise.ImunoiseWarning)`` silences them all and nothing else), of one of
these kinds:

=========================  ==============================================================
:class:`GapWarning`        missing samples, gaps and what they cost (dropped taus, splices)
:class:`AssumptionWarning` a value imunoise assumed for you (a sample rate, a unit, a
                           format) — pass it to silence the warning
:class:`DataWarning`       what a log holds: damaged or left-out records, metadata set aside
:class:`CoverageWarning`   a result to read with care: a model that follows its curve
                           poorly, a grid too sparse, a computation that fell back
                           (also a :class:`RuntimeWarning`)
:class:`ImunoiseDeprecationWarning`  an old spelling (also a :class:`DeprecationWarning`)
=========================  ==============================================================
"""

from __future__ import annotations

__all__ = [
    "AssumptionWarning",
    "CoverageWarning",
    "DataWarning",
    "GapWarning",
    "ImunoiseDeprecationWarning",
    "ImunoiseError",
    "ImunoiseTypeError",
    "ImunoiseValueError",
    "ImunoiseWarning",
    "ParseError",
]


class ImunoiseError(Exception):
    """Base of every error imunoise raises."""


class ImunoiseValueError(ImunoiseError, ValueError):
    """An argument's value is out of its bounds; the message names the argument, the
    bound and the value received."""


class ImunoiseTypeError(ImunoiseError, TypeError):
    """An argument is of the wrong type; the message names it and the type received."""


class ImunoiseWarning(UserWarning):
    """Base of every warning imunoise gives."""


class GapWarning(ImunoiseWarning):
    """Missing samples, gaps and what they cost."""


class AssumptionWarning(ImunoiseWarning):
    """A value imunoise assumed because none was given."""


class DataWarning(ImunoiseWarning):
    """What a log holds: damaged or left-out records, metadata set aside."""


class CoverageWarning(ImunoiseWarning, RuntimeWarning):
    """A result to read with care: a poor fit, a sparse grid, a fallback."""


class ImunoiseDeprecationWarning(ImunoiseWarning, DeprecationWarning):
    """An old spelling that still works for one release."""


class ParseError(ImunoiseError, ValueError):
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
