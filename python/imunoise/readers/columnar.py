"""What ``imunoise convert`` writes, read back: ``.npy`` + meta, a directory of
``.npy``, ``.npz``, ``.parquet`` (CSV is read by :mod:`imunoise.readers.csv_reader`).

Every output of ``convert`` carries the same metadata (:func:`log_meta`): the
rate, the source and its format, the samples, the parse issues with their first
locations, the message counts and the gaps. :func:`read_columnar` restores the
:class:`~imunoise.readers.log.ImuLog` from the arrays and that metadata, so a
log read back is the log that was written: same samples, time, fs, channels,
gaps and issues. Metadata that contradicts itself (negative counts, gaps outside
the samples ...) is refused by :func:`check_meta`, naming the field.

Arrays without that metadata (an ``.npz`` or ``.npy`` from elsewhere) are not
guessed at: the error says to build the log with
:meth:`~imunoise.readers.log.ImuLog.from_arrays`.
"""

from __future__ import annotations

import io
import os
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from imunoise._support.schema import CHANNELS, column_names
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError, ParseError
from imunoise.readers import metafile
from imunoise.readers.grid import Gaps
from imunoise.readers.log import ISSUE_KINDS, ImuLog, ParseIssues
from imunoise.readers.probe import Confidence, Probe

__all__ = ["META_VERSION", "REQUIRED", "check_meta", "log_meta", "read_columnar", "sniff"]

#: Version of the metadata written with every output of ``convert``.
META_VERSION = 1
#: Key of the metadata: in the ``.npz``, in the Parquet key-value metadata, and the
#: first word of the CSV comment line that holds it.
META_KEY = "imunoise"

_NPY_MAGIC = b"\x93NUMPY"
_ZIP_MAGIC = b"PK\x03\x04"
_PARQUET_MAGIC = b"PAR1"

_FROM_ARRAYS = ("build the log with imunoise.ImuLog.from_arrays(fs, gyro=..., accel=..., "
                "time=...)")


def sniff(probe: Probe) -> Confidence:
    """``.npy``/``.npz``/Parquet by their magic number, or a directory with ``meta.json``."""
    if probe.is_dir:
        return Confidence.SIGNATURE if (probe.path / "meta.json").is_file() else Confidence.NO
    head = probe.head
    if head.startswith((_NPY_MAGIC, _PARQUET_MAGIC)):
        return Confidence.SIGNATURE
    if head.startswith(_ZIP_MAGIC) and (probe.suffix == ".npz" or probe.path is None):
        return Confidence.SIGNATURE
    return Confidence.NO


def log_meta(*, fs: float, source: str, fmt: str, issues: ParseIssues,
             messages: Mapping[str, int], samples: int, channels, table, gaps: Gaps) -> dict:
    """The metadata every output of ``convert`` carries (JSON-able)."""
    return {
        "imunoise_columnar": META_VERSION,
        "fs": float(fs),
        "source": source,
        "format": fmt,
        "samples": int(samples),
        "channels": list(channels),
        "table": table,
        "messages": {k: int(v) for k, v in messages.items()},
        "issues": {
            "counts": {k: int(v) for k, v in issues.counts.items()},
            "first": {k: [int(x) for x in v] for k, v in issues.first.items()},
            "location": issues.location,
        },
        "gaps": {"index": gaps.index.tolist(), "samples": gaps.samples.tolist()},
    }


#: Fields every metadata of ``convert`` has (:func:`log_meta`); a missing one is an
#: error. Other keys are ignored: a newer imunoise may add some, none changes what
#: the arrays mean.
REQUIRED = ("imunoise_columnar", "fs", "source", "format", "samples", "channels", "table",
            "messages", "issues", "gaps")
#: Issue kinds every version of the metadata counts (later kinds, e.g.
#: ``time_reset``, are zero where missing): a count that is gone is not zero.
V1_KINDS = ("bad_checksum", "malformed_field", "unknown_message", "truncated_record",
            "bytes_skipped", "device_error", "duplicate_time", "time_reversed")
#: Where the issue locations of ``issues.first`` count from.
_LOCATIONS = ("line", "byte", "message")
#: Longest text field (source, format, table) accepted, characters.
_MAX_TEXT = 1 << 16


def _text(meta: dict, key: str, where, *, optional: bool = False) -> None:
    value = meta[key]
    if optional and value is None:
        return
    if not isinstance(value, str) or len(value) > _MAX_TEXT:
        raise metafile.bad_field(where, key, f"must be a text of at most {_MAX_TEXT} "
                                 f"characters{' or null' if optional else ''}; got "
                                 f"{metafile.shown(value)}")


def _object(value, where, field: str) -> dict:
    if not isinstance(value, dict):
        raise metafile.bad_field(where, field, f"must be a JSON object; got "
                                 f"{metafile.shown(value)}")
    return value


def check_meta(meta, where, *, tied: bool = False) -> dict:
    """``meta`` if it describes a log consistently, else a
    :class:`~imunoise.errors.ParseError` naming the file ``where`` and the field.

    Checks every field :func:`log_meta` writes, by type and range: the version,
    a rate in (0, :data:`~imunoise.readers.metafile.MAX_FS`] Hz (``true`` is not
    one), counts that are integers in [0, 2**63) (samples, messages, issues,
    locations), known channels (each once) and issue kinds, a known location
    unit, and gaps that are sorted, non-overlapping and inside the samples.
    ``tied``: the metadata of a file beside it must carry the file's fingerprint
    (``data``, see :mod:`imunoise.readers.metafile`).
    """
    bad = metafile.bad_field
    if not isinstance(meta, dict):
        raise ParseError(f"the metadata is not a JSON object; got {metafile.shown(meta)}",
                         kind="malformed_field", source=str(where))
    version = meta.get("imunoise_columnar")
    if isinstance(version, bool) or version != META_VERSION:
        raise bad(where, "imunoise_columnar", f"must be {META_VERSION}; got "
                  f"{metafile.shown(version)}")
    for key in (*REQUIRED, *(("data",) if tied else ())):
        if key not in meta:
            raise bad(where, key, "is missing")
    metafile.rate(meta["fs"], where)
    for key in ("source", "format"):
        _text(meta, key, where)
    _text(meta, "table", where, optional=True)
    samples = metafile.count(meta["samples"], where, "samples")
    channels = meta["channels"]
    known = ("time", *CHANNELS)
    if (not isinstance(channels, list) or not channels
            or any(not isinstance(c, str) or c not in known for c in channels)
            or len(set(channels)) != len(channels)):
        raise bad(where, "channels", f"must list channels of {known}, each once; got "
                  f"{metafile.shown(channels)}")
    for name, n in _object(meta["messages"], where, "messages").items():
        metafile.count(n, where, f"messages.{name}")
    issues = _object(meta["issues"], where, "issues")
    for key in ("counts", "first", "location"):
        if key not in issues:
            raise bad(where, f"issues.{key}", "is missing")
    counts = _object(issues["counts"], where, "issues.counts")
    missing = [k for k in V1_KINDS if k not in counts]
    if missing:
        raise bad(where, "issues.counts", f"lacks the kinds {missing} (every version "
                  "writes them)")
    for kind, n in counts.items():
        if kind not in ISSUE_KINDS:
            raise bad(where, "issues.counts", f"has unknown kind {metafile.shown(kind)}")
        metafile.count(n, where, f"issues.counts.{kind}")
    for kind, locations in _object(issues["first"], where, "issues.first").items():
        if kind not in ISSUE_KINDS or not isinstance(locations, list):
            raise bad(where, f"issues.first.{kind}", "is not a list of locations of a known "
                      "kind")
        for i, loc in enumerate(locations):
            metafile.count(loc, where, f"issues.first.{kind}[{i}]")
    if issues["location"] not in _LOCATIONS:
        raise bad(where, "issues.location", f"must be one of {_LOCATIONS}; got "
                  f"{metafile.shown(issues['location'])}")
    gaps = _object(meta["gaps"], where, "gaps")
    index, lengths = gaps.get("index"), gaps.get("samples")
    if not isinstance(index, list) or not isinstance(lengths, list) or len(index) != len(
            lengths):
        raise bad(where, "gaps", "must hold lists 'index' and 'samples' of equal length")
    end = 0
    for i, (start, k) in enumerate(zip(index, lengths, strict=True)):
        metafile.count(start, where, f"gaps.index[{i}]")
        if metafile.count(k, where, f"gaps.samples[{i}]") == 0 or start < end or (
                start + k > samples):
            raise bad(where, f"gaps[{i}]", f"({start}, {k}) is not a run of missing samples "
                      f"inside the {samples} samples, after the one before")
        end = start + k
    if tied:
        metafile.tie_fields(meta["data"], where)
    return meta


def _issues(meta: dict) -> ParseIssues:
    iss = meta["issues"]
    return ParseIssues(counts=iss["counts"], first={k: tuple(v) for k, v in iss["first"].items()},
                       location=iss["location"])


def log_from_meta(meta: dict, arrays: Mapping[str, np.ndarray], where: str) -> ImuLog:
    """The :class:`ImuLog` of checked metadata and its channel arrays."""
    lengths = {ch: len(a) for ch, a in arrays.items()}
    if any(n != meta["samples"] for n in lengths.values()):
        raise ParseError(f"the metadata says {meta['samples']} samples but the arrays hold "
                         f"{lengths}", kind="malformed_field", source=str(where))
    fs = float(meta["fs"])
    gaps = meta["gaps"]
    # the gaps as convert found them: no pass over memory-mapped channels for NaN
    gaps = Gaps(gaps["index"], gaps["samples"], fs)
    try:
        return ImuLog(fs=fs, source=meta["source"], format=meta["format"],
                      issues=_issues(meta), messages=meta["messages"], gaps=gaps, **arrays)
    except ValueError as exc:  # the arrays' shapes: name the file they came from
        raise ParseError(str(exc), kind="malformed_field", source=str(where)) from None


def _flat(table: Mapping[str, np.ndarray], channels, where: str) -> dict[str, np.ndarray]:
    """Channels from flat columns (``gyro_x`` ...)."""
    arrays = {}
    for ch in channels:
        names = column_names(ch)
        missing = [n for n in names if n not in table]
        if missing:
            raise ParseError(f"the metadata lists channel {ch!r} but columns {missing} are "
                             "missing", kind="malformed_field", source=str(where))
        try:
            cols = [np.asarray(table[n], dtype=np.float64).reshape(-1) for n in names]
            arrays[ch] = cols[0] if len(cols) == 1 else np.column_stack(cols)
        except ValueError as exc:  # columns of other lengths or of text
            raise ParseError(f"the columns of channel {ch!r} do not make one array ({exc})",
                             kind="malformed_field", source=str(where)) from None
    return arrays


def _load_npy(path: Path, where) -> np.ndarray:
    """``np.load(path, mmap_mode="r")``, its errors naming the file."""
    try:
        return np.load(path, mmap_mode="r", allow_pickle=False)
    # a cut or damaged header: numpy raises ValueError, OSError, EOFError, TokenError
    except Exception as exc:  # noqa: BLE001
        raise ParseError(f"not a readable .npy ({exc})", kind="malformed_field",
                         source=str(where)) from None


def _read_dir(path: Path) -> ImuLog:
    where = path / "meta.json"
    meta = check_meta(metafile.load(where), where)
    ties = _object(meta.get("data"), where, "data") if "data" in meta else None
    if ties is None:
        raise metafile.bad_field(where, "data", "is missing (a directory written by an earlier "
                                 "imunoise: convert the log again)")
    missing = [ch for ch in meta["channels"] if not (path / f"{ch}.npy").is_file()]
    if missing:
        raise ParseError(f"the metadata lists channels {missing} but their .npy files are "
                         "missing", kind="malformed_field", source=str(where))
    for ch in meta["channels"]:
        metafile.check_tie(ties.get(f"{ch}.npy"), path / f"{ch}.npy", where)
    arrays = {ch: _load_npy(path / f"{ch}.npy", path / f"{ch}.npy") for ch in meta["channels"]}
    return log_from_meta(meta, arrays, path)


def _read_npy(source, path: Path | None) -> ImuLog:
    where = "<bytes>" if path is None else str(path)
    meta_file = None if path is None else metafile.meta_path(path)
    meta = None if meta_file is None else metafile.load(meta_file)
    if meta is None:
        beside = "" if meta_file is None else f" ({meta_file.name} beside it)"
        legacy = None if path is None else metafile.legacy_path(path)
        if legacy is not None and legacy.is_file():
            beside += (f"; {legacy.name} is the name earlier versions gave the metadata of "
                       f"{path.stem}.npy and {path.stem}.csv alike, so it cannot say which "
                       f"it describes: convert the log again, or rename it to "
                       f"{meta_file.name} if it is this file's")
        raise ParseError(f"a .npy without the metadata imunoise convert writes{beside}; "
                         f"{_FROM_ARRAYS}", kind="malformed_field", source=where)
    meta = check_meta(meta, meta_file, tied=True)
    metafile.check_tie(meta["data"], path, meta_file)
    rec = _load_npy(path, where)
    if rec.dtype.names is None or set(meta["channels"]) - set(rec.dtype.names) or rec.ndim != 1:
        raise ParseError(f"not the structured array of {meta['channels']} its metadata "
                         "describes", kind="malformed_field", source=where)
    return log_from_meta(meta, {ch: rec[ch] for ch in meta["channels"]}, where)


def _read_npz(source, path: Path | None) -> ImuLog:
    where = "<bytes>" if path is None else str(path)
    try:
        with np.load(path if path is not None else io.BytesIO(bytes(source)),
                     allow_pickle=False) as z:
            table = {k: z[k] for k in z.files}
    except Exception as exc:  # noqa: BLE001 - zipfile/zlib/numpy raise many kinds
        raise ImunoiseValueError(f"{where}: not a readable .npz ({exc})") from None
    if META_KEY not in table and "fs" in table:
        return _legacy_npz(table, where)
    if META_KEY not in table:
        raise ImunoiseValueError(f"{where}: an .npz of arrays {sorted(table)} without the metadata "
                         f"imunoise convert writes; {_FROM_ARRAYS}")
    meta = check_meta(metafile.parse(str(table[META_KEY]), where), where)
    return log_from_meta(meta, _flat(table, meta["channels"], where), where)


def _legacy_npz(table: Mapping[str, np.ndarray], where: str) -> ImuLog:
    """An ``.npz`` of an earlier ``convert``: ``fs`` and flat columns, no metadata."""
    channels = [ch for ch in ("time", *CHANNELS) if all(n in table for n in column_names(ch))]
    if not [ch for ch in channels if ch != "time"]:
        raise ImunoiseValueError(f"{where}: an .npz of arrays {sorted(table)} with no imunoise "
                         f"channel columns; {_FROM_ARRAYS}")
    fs_value = np.asarray(table["fs"]).reshape(-1)
    if fs_value.size != 1 or fs_value.dtype.kind not in "iuf":
        raise ParseError(f"entry 'fs' must be one rate in Hz; got {fs_value[:3]!r}",
                         kind="malformed_field", source=where)
    fs = metafile.rate(fs_value[0].item(), where, "fs")
    arrays = _flat(table, channels, where)
    valid = table.get("valid")
    gaps = None if valid is None else Gaps.from_valid(np.asarray(valid) > 0.5, fs)
    return ImuLog(fs=fs, source=where, format="columnar", issues=ParseIssues.none(),
                  gaps=gaps, **arrays)


def _read_parquet(source, path: Path | None) -> ImuLog:
    where = "<bytes>" if path is None else str(path)
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise ImportError(f"{where}: reading Parquet needs pyarrow (pip install pyarrow)") from None
    handle = path if path is not None else io.BytesIO(bytes(source))
    try:
        kv = pq.read_metadata(handle).metadata or {}
        if path is None:
            handle.seek(0)
        table = pq.read_table(handle)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises its own ArrowInvalid etc.
        raise ImunoiseValueError(f"{where}: not a readable Parquet file ({exc})") from None
    raw = kv.get(META_KEY.encode())
    if raw is None:
        raise ImunoiseValueError(f"{where}: a Parquet file without the metadata imunoise convert "
                         f"writes (key {META_KEY!r}); {_FROM_ARRAYS}")
    meta = check_meta(metafile.parse(raw, where), where)
    columns = {n: table.column(n).to_numpy() for n in table.column_names}
    return log_from_meta(meta, _flat(columns, meta["channels"], where), where)


def read_columnar(
    source,
    *,
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> ImuLog:
    """Read what ``imunoise convert`` wrote (directory, ``.npy``, ``.npz``, ``.parquet``).

    ``strict``, ``fs`` and ``progress`` are accepted for the reader interface; the
    rate is the one stored (``fs`` is not needed and is ignored).

    Raises
    ------
    ValueError
        When the arrays carry no imunoise metadata, or metadata that contradicts
        itself or the arrays (naming the field).
    """
    del strict, fs  # the stored log has its rate and its issues already
    if isinstance(source, bytes | bytearray | memoryview):
        path, head = None, bytes(source[:8])
    elif isinstance(source, str | os.PathLike):
        path = Path(os.fspath(source))
        if path.is_dir():
            return _read_dir(path)
        with open(path, "rb") as f:
            head = f.read(8)
    else:
        raise ImunoiseTypeError(f"source must be a path or bytes; got {type(source).__name__}")
    if head.startswith(_NPY_MAGIC):
        log = _read_npy(source, path)
    elif head.startswith(_ZIP_MAGIC):
        log = _read_npz(source, path)
    elif head.startswith(_PARQUET_MAGIC):
        log = _read_parquet(source, path)
    else:
        raise ImunoiseValueError(f"{path or '<bytes>'}: not a .npy, .npz or Parquet file")
    if progress is not None:
        size = len(source) if path is None else os.path.getsize(path)
        progress(size, size)
    return log
