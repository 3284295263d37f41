# rust/bindings/vn.rs: VectorNav parsing and writing.

import os
from collections.abc import Callable
from typing import final

import numpy as np
import numpy.typing as npt

__all__ = [
    "FIRST_KEEP",
    "ISSUE_KINDS",
    "VnResult",
    "VnRows",
    "VnStream",
    "parse_vn",
    "vn_binary_columns",
    "vn_binary_fields",
    "vn_message_fields",
    "write_vn_ascii",
    "write_vn_binary",
]

#: The parser's issue kinds, in order.
ISSUE_KINDS: tuple[str, ...]
#: First locations kept per issue kind.
FIRST_KEEP: int

@final
class VnResult:
    """What a parse produced (``parse_vn``, ``VnStream.finish``)."""

    @property
    def tables(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]:
        """{message: {column: float64 array}}."""
    @property
    def missing(self) -> dict[str, npt.NDArray[np.uint64]]:
        """{message: good rows before each damaged record of that type}."""
    @property
    def messages(self) -> dict[str, int]:
        """{message: records}, command responses included."""
    @property
    def issues(self) -> dict[str, int]:
        """{kind: count} for every name of ISSUE_KINDS."""
    @property
    def first(self) -> dict[str, list[tuple[int, int]]]:
        """{kind: [(byte_offset, line), ...]}, at most FIRST_KEEP per kind."""
    @property
    def bytes_total(self) -> int: ...
    @property
    def bytes_parsed(self) -> int: ...
    @property
    def bytes_in_bad_records(self) -> int: ...
    @property
    def bytes_skipped(self) -> int: ...
    @property
    def ascii_records(self) -> int: ...
    @property
    def binary_records(self) -> int: ...
    @property
    def format(self) -> str:
        """"vn-binary" if binary packets outnumber sentences, else "vn-ascii"."""

@final
class VnRows:
    """The rows of one piece of a stream (``VnStream.feed``)."""

    @property
    def tables(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]: ...
    @property
    def missing(self) -> dict[str, npt.NDArray[np.uint64]]: ...

@final
class VnStream:
    """One VN parse fed piece by piece: ``feed`` returns the rows the bytes so far
    complete; ``finish`` the summary of the whole stream (its tables hold the last
    rows only). Counts, first locations and lines run on across pieces."""

    def __new__(cls, strict: bool = False) -> VnStream: ...
    def feed(self, data: bytes | bytearray | memoryview) -> VnRows:
        """The rows of the records the bytes so far complete. ``data``: bytes or any
        C-contiguous buffer of bytes, parsed in place (do not change it meanwhile)."""
    def finish(self) -> VnResult: ...

def parse_vn(
    source: bytes | str | os.PathLike[str],
    strict: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> VnResult:
    """Decode a VN byte stream (bytes, or a path read in chunks) with the GIL released.

    ``progress(done, total)`` after every chunk. Strict mode raises
    :class:`imunoise.errors.ParseError` for the first damaged record.
    """

def vn_message_fields() -> dict[str, list[str]]:
    """Field names, in order, of every decoded ASCII message type."""

def vn_binary_fields() -> dict[str, tuple[int, dict[str, int]]]:
    """Group name -> (group index, {field name: field number}) for decodable groups."""

def vn_binary_columns(selection: list[tuple[int, int]]) -> tuple[list[str], str]:
    """(column names in payload order, table name) for a (group, field mask) selection."""

def write_vn_ascii(
    message: str,
    columns: list[npt.NDArray[np.float64]],
    decimals: list[int] | None = None,
    count: npt.NDArray[np.float64] | None = None,
    status: npt.NDArray[np.float64] | None = None,
    crc: bool = False,
    line_ending: bytes = b"\r\n",
) -> bytes:
    """Sentences of ``message`` from columns in field order (XOR-8 or CRC-16)."""

def write_vn_binary(
    selection: list[tuple[int, int]], columns: dict[str, npt.NDArray[np.float64]]
) -> bytes:
    """Binary packets for ``selection`` from columns named as in vn_binary_columns."""
