"""What format detection looks at: a source's path and its first bytes.

Every format's ``sniff(probe)`` answers with a :class:`Confidence`;
:func:`imunoise.readers.read.detect_format` takes the most confident answer, so
that a magic number beats a file extension, which beats a look at the content.
"""

from __future__ import annotations

import enum
import os
from functools import cached_property
from pathlib import Path

#: Bytes of the source a sniffer sees.
SNIFF_BYTES = 1 << 16


class Confidence(enum.IntEnum):
    """How sure a sniffer is that a source is in its format (higher wins)."""

    NO = 0
    GUESS = 1  # plausible content, e.g. delimited text
    CONTENT = 2  # the format's own records seen in the first bytes
    NAME = 3  # the file extension names the format
    # Records whose checksum (CRC-16) verifies: surer than a name or a header-like
    # first line, since text between binary packets can look like a CSV header.
    CHECKED = 4
    SIGNATURE = 5  # a magic number or a container's layout


class Probe:
    """A source (path or bytes) seen by the sniffers; the file is read once, on demand."""

    def __init__(self, source: str | os.PathLike | bytes | bytearray | memoryview) -> None:
        self._source = source
        self.path = None if isinstance(source, bytes | bytearray | memoryview) else Path(source)

    @property
    def suffix(self) -> str:
        """The file extension in lower case (``""`` for bytes)."""
        return "" if self.path is None else self.path.suffix.lower()

    @cached_property
    def is_dir(self) -> bool:
        return self.path is not None and self.path.is_dir()

    @cached_property
    def head(self) -> bytes:
        """The first :data:`SNIFF_BYTES` bytes (``b""`` for a directory)."""
        if self.path is None:
            return bytes(self._source[:SNIFF_BYTES])
        if self.is_dir:
            return b""
        with open(self.path, "rb") as f:
            return f.read(SNIFF_BYTES)
