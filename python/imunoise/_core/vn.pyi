# rust/bindings/vn.rs: VectorNav parsing and writing.

import os
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

def parse_vn(
    source: bytes | str | os.PathLike[str],
    strict: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """Decode a VN byte stream (bytes, or a path read in chunks) with the GIL released.

    Keys: ``tables`` {message: {column: float64 array}}, ``messages`` {message: count},
    ``issues`` {kind: count}, ``first`` {kind: [(byte_offset, line), ...]},
    ``bytes_total``, ``bytes_parsed``, ``bytes_in_bad_records``, ``bytes_skipped``,
    ``ascii_records``, ``binary_records``, ``missing`` {message: uint64 array of the
    good rows before each damaged record of that type}. ``progress(done, total)``
    after every chunk.
    """

def parse_vn_chunk(data: bytes, strict: bool = False, fin: bool = False) -> dict[str, Any]:
    """Decode the complete records at the start of ``data`` (all of it when ``fin``).

    Same keys as :func:`parse_vn` plus ``bytes_consumed``: the bytes decoded; the rest
    (a record cut by the end of ``data``) starts the next piece. Locations are relative
    to ``data``.
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
    eol: bytes = ...,
) -> bytes:
    """Sentences of ``message`` from columns in field order (XOR-8 or CRC-16)."""

def write_vn_binary(
    selection: list[tuple[int, int]], columns: dict[str, npt.NDArray[np.float64]]
) -> bytes:
    """Binary packets for ``selection`` from columns named as in vn_binary_columns."""
