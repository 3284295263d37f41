"""The log formats :func:`imunoise.read` knows: one :class:`Format` entry each.

Adding a format is a reader module (``read_x(source, *, strict, fs, progress)``
plus a ``sniff(probe)``, see :mod:`imunoise.readers.probe`) and one entry in
:data:`FORMATS`; detection, dispatch and the list of ``format=`` values follow.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from imunoise._core import vn as _core_vn
from imunoise.errors import ImunoiseValueError
from imunoise.readers import columnar, csv_reader, rosbag_reader
from imunoise.readers.log import ImuLog
from imunoise.readers.probe import Confidence, Probe
from imunoise.readers.vn import read_vn

__all__ = ["FORMATS", "Format", "get", "names"]


@dataclass(frozen=True)
class Format:
    """One log format.

    Attributes
    ----------
    name : str
        The ``format=`` value and ``ImuLog.format``.
    sniff : callable
        ``sniff(probe) -> Confidence``: how sure it is that a source is in this format.
    read : callable
        ``read(source, *, strict, fs, progress) -> ImuLog``.
    streamable : bool
        The Rust VN stream parser reads it piece by piece, so
        :func:`imunoise.scale.convert` converts it in bounded memory; other formats
        are read whole.
    """

    name: str
    sniff: Callable[[Probe], Confidence]
    read: Callable[..., ImuLog]
    streamable: bool = False


def _vn_counts(probe: Probe) -> tuple[int, int]:
    """``$VN`` sentence starts and ``0xFA`` binary sync bytes in the first bytes."""
    return probe.head.count(b"$VN"), probe.head.count(b"\xfa")


def _sniff_vn_ascii(probe: Probe) -> Confidence:
    """VN sentences, at least as many as binary sync bytes."""
    n_ascii, n_sync = _vn_counts(probe)
    return Confidence.CONTENT if n_ascii and n_sync <= n_ascii else Confidence.NO


#: Binary packets whose CRC-16 verifies in the first bytes that make a source
#: VN binary whatever its name or first lines (two, so that one chance match of
#: a CRC in other binary data is not enough: about 1 in 65,536 per try).
CHECKED_PACKETS = 2


def _checked_packets(probe: Probe) -> int:
    """Binary packets in the first bytes whose CRC-16 verifies (decoded by the
    reader's own Rust parser; a packet cut by the end of the head is not counted)."""
    if probe.is_dir or b"\xfa" not in probe.head:
        return 0
    rows = _core_vn.VnStream(False).feed(probe.head)
    return sum(len(next(iter(cols.values()), ())) for name, cols in rows.tables.items()
               if name.startswith("binary_"))


def _sniff_vn_binary(probe: Probe) -> Confidence:
    """Binary packets that pass their CRC (a logger's text markers between them,
    e.g. ``S,Booting from beginning!``, must not make the log a CSV); else more
    binary sync bytes than VN sentences (both framings may be interleaved)."""
    n_ascii, n_sync = _vn_counts(probe)
    if n_sync > n_ascii and _checked_packets(probe) >= CHECKED_PACKETS:
        return Confidence.CHECKED
    return Confidence.CONTENT if n_sync > n_ascii else Confidence.NO


#: Every format, in the order ties of confidence are broken.
FORMATS: tuple[Format, ...] = (
    # one reader for both VN framings: it accepts them interleaved in one stream
    Format("vn-ascii", _sniff_vn_ascii, read_vn, streamable=True),
    Format("vn-binary", _sniff_vn_binary, read_vn, streamable=True),
    Format("csv", csv_reader.sniff, csv_reader.read_csv),
    Format("rosbag", rosbag_reader.sniff, rosbag_reader.read_rosbag),
    # what `imunoise convert` writes: .npy + meta, a directory of .npy, .npz, .parquet
    Format("columnar", columnar.sniff, columnar.read_columnar),
)


def names() -> tuple[str, ...]:
    """The format names, in registry order."""
    return tuple(fmt.name for fmt in FORMATS)


def get(name: str) -> Format:
    """The entry of format ``name``."""
    for fmt in FORMATS:
        if fmt.name == name:
            return fmt
    raise ImunoiseValueError(f"format must be one of {names()}; got {name!r}")
