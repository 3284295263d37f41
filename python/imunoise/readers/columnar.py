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
import json
import math
import os
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from imunoise._schema import CHANNELS, column_names
from imunoise.readers.grid import Gaps
from imunoise.readers.log import ISSUE_KINDS, ImuLog, ParseIssues
from imunoise.readers.probe import Confidence, Probe

__all__ = ["META_VERSION", "check_meta", "log_meta", "meta_path", "read_columnar", "sniff"]

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


def meta_path(out: Path) -> Path:
    """The metadata file of a ``.npy`` output: ``OUT.meta.json`` beside it."""
    return out.with_name(out.stem + ".meta.json")


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


def _count(value, where: str, field: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{where}: metadata field {field!r} must be a count >= 0; got {value!r}")
    return value


def check_meta(meta, where: str) -> dict:
    """``meta`` if it describes a log consistently, else ``ValueError`` naming the field.

    Checks the version, a positive finite ``fs``, counts that are integers >= 0
    (samples, messages, issues), known channels and issue kinds, and gaps that
    are sorted, non-overlapping and inside the samples.
    """
    if not isinstance(meta, dict):
        raise ValueError(f"{where}: the metadata is not a JSON object")
    if meta.get("imunoise_columnar") != META_VERSION:
        raise ValueError(f"{where}: metadata field 'imunoise_columnar' must be {META_VERSION}; "
                         f"got {meta.get('imunoise_columnar')!r}")
    for key in ("fs", "source", "format", "samples", "channels", "issues"):
        if key not in meta:
            raise ValueError(f"{where}: metadata field {key!r} is missing")
    fs = meta["fs"]
    if isinstance(fs, bool) or not isinstance(fs, int | float) or not (
            math.isfinite(fs) and fs > 0):
        raise ValueError(f"{where}: metadata field 'fs' must be a positive finite rate in Hz; "
                         f"got {fs!r}")
    samples = _count(meta["samples"], where, "samples")
    channels = meta["channels"]
    if not isinstance(channels, list) or any(c not in ("time", *CHANNELS) for c in channels):
        raise ValueError(f"{where}: metadata field 'channels' must list channels of "
                         f"{('time', *CHANNELS)}; got {channels!r}")
    for name, count in (meta.get("messages") or {}).items():
        _count(count, where, f"messages.{name}")
    issues = meta["issues"]
    if not isinstance(issues, dict) or not isinstance(issues.get("counts"), dict):
        raise ValueError(f"{where}: metadata field 'issues.counts' is missing")
    for kind, count in issues["counts"].items():
        if kind not in ISSUE_KINDS:
            raise ValueError(f"{where}: metadata field 'issues.counts' has unknown kind {kind!r}")
        _count(count, where, f"issues.counts.{kind}")
    for kind, where_first in (issues.get("first") or {}).items():
        if kind not in ISSUE_KINDS or not isinstance(where_first, list):
            raise ValueError(f"{where}: metadata field 'issues.first.{kind}' is not a list of "
                             "locations of a known kind")
        for i, loc in enumerate(where_first):
            _count(loc, where, f"issues.first.{kind}[{i}]")
    gaps = meta.get("gaps")
    if gaps is not None:
        index, lengths = gaps.get("index"), gaps.get("samples")
        if not isinstance(index, list) or not isinstance(lengths, list) or len(index) != len(
                lengths):
            raise ValueError(f"{where}: metadata fields 'gaps.index' and 'gaps.samples' must be "
                             "lists of equal length")
        end = 0
        for i, (start, k) in enumerate(zip(index, lengths, strict=True)):
            _count(start, where, f"gaps.index[{i}]")
            if _count(k, where, f"gaps.samples[{i}]") == 0 or start < end or start + k > samples:
                raise ValueError(f"{where}: metadata field 'gaps' row {i} ({start}, {k}) is not "
                                 f"a run of missing samples inside the {samples} samples, after "
                                 "the one before")
            end = start + k
    return meta


def _issues(meta: dict) -> ParseIssues:
    iss = meta["issues"]
    return ParseIssues(counts=iss["counts"],
                       first={k: tuple(v) for k, v in (iss.get("first") or {}).items()},
                       location=iss.get("location", "line"))


def log_from_meta(meta: dict, arrays: Mapping[str, np.ndarray], where: str) -> ImuLog:
    """The :class:`ImuLog` of checked metadata and its channel arrays."""
    lengths = {ch: len(a) for ch, a in arrays.items()}
    if any(n != meta["samples"] for n in lengths.values()):
        raise ValueError(f"{where}: the metadata says {meta['samples']} samples but the arrays "
                         f"hold {lengths}")
    fs = float(meta["fs"])
    gaps = meta.get("gaps")
    # the gaps as convert found them: no pass over memory-mapped channels for NaN
    gaps = None if gaps is None else Gaps(gaps["index"], gaps["samples"], fs)
    return ImuLog(fs=fs, source=meta["source"], format=meta["format"], issues=_issues(meta),
                  messages=meta.get("messages") or {}, gaps=gaps, **arrays)


def _json(text, where: str) -> dict:
    try:
        return json.loads(text)
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"{where}: the imunoise metadata is not valid JSON ({exc})") from None


def _flat(table: Mapping[str, np.ndarray], channels, where: str) -> dict[str, np.ndarray]:
    """Channels from flat columns (``gyro_x`` ...)."""
    arrays = {}
    for ch in channels:
        names = column_names(ch)
        missing = [n for n in names if n not in table]
        if missing:
            raise ValueError(f"{where}: the metadata lists channel {ch!r} but columns "
                             f"{missing} are missing")
        cols = [np.asarray(table[n], dtype=np.float64) for n in names]
        arrays[ch] = cols[0] if len(cols) == 1 else np.column_stack(cols)
    return arrays


def _read_dir(path: Path) -> ImuLog:
    where = str(path)
    meta = check_meta(_json((path / "meta.json").read_bytes(), where), where)
    missing = [ch for ch in meta["channels"] if not (path / f"{ch}.npy").is_file()]
    if missing:
        raise ValueError(f"{where}: the metadata lists channels {missing} but their .npy files "
                         "are missing")
    arrays = {ch: np.load(path / f"{ch}.npy", mmap_mode="r") for ch in meta["channels"]}
    return log_from_meta(meta, arrays, where)


def _read_npy(source, path: Path | None) -> ImuLog:
    where = "<bytes>" if path is None else str(path)
    meta_file = None if path is None else meta_path(path)
    if meta_file is None or not meta_file.is_file():
        beside = "" if meta_file is None else f" ({meta_file.name} beside it)"
        raise ValueError(f"{where}: a .npy without the metadata imunoise convert writes"
                         f"{beside}; {_FROM_ARRAYS}")
    meta = check_meta(_json(meta_file.read_bytes(), str(meta_file)), str(meta_file))
    rec = np.load(path, mmap_mode="r")
    if rec.dtype.names is None or set(meta["channels"]) - set(rec.dtype.names):
        raise ValueError(f"{where}: not the structured array of {meta['channels']} its "
                         f"metadata describes")
    return log_from_meta(meta, {ch: rec[ch] for ch in meta["channels"]}, where)


def _read_npz(source, path: Path | None) -> ImuLog:
    where = "<bytes>" if path is None else str(path)
    try:
        with np.load(path if path is not None else io.BytesIO(bytes(source)),
                     allow_pickle=False) as z:
            table = {k: z[k] for k in z.files}
    except Exception as exc:  # noqa: BLE001 - zipfile/zlib/numpy raise many kinds
        raise ValueError(f"{where}: not a readable .npz ({exc})") from None
    if META_KEY not in table and "fs" in table:
        return _legacy_npz(table, where)
    if META_KEY not in table:
        raise ValueError(f"{where}: an .npz of arrays {sorted(table)} without the metadata "
                         f"imunoise convert writes; {_FROM_ARRAYS}")
    meta = check_meta(_json(str(table[META_KEY]), where), where)
    return log_from_meta(meta, _flat(table, meta["channels"], where), where)


def _legacy_npz(table: Mapping[str, np.ndarray], where: str) -> ImuLog:
    """An ``.npz`` of an earlier ``convert``: ``fs`` and flat columns, no metadata."""
    channels = [ch for ch in ("time", *CHANNELS) if all(n in table for n in column_names(ch))]
    if not [ch for ch in channels if ch != "time"]:
        raise ValueError(f"{where}: an .npz of arrays {sorted(table)} with no imunoise "
                         f"channel columns; {_FROM_ARRAYS}")
    fs = float(np.asarray(table["fs"]).reshape(-1)[0])
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
        raise ValueError(f"{where}: not a readable Parquet file ({exc})") from None
    raw = kv.get(META_KEY.encode())
    if raw is None:
        raise ValueError(f"{where}: a Parquet file without the metadata imunoise convert "
                         f"writes (key {META_KEY!r}); {_FROM_ARRAYS}")
    meta = check_meta(_json(raw, where), where)
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
        raise TypeError(f"source must be a path or bytes; got {type(source).__name__}")
    if head.startswith(_NPY_MAGIC):
        log = _read_npy(source, path)
    elif head.startswith(_ZIP_MAGIC):
        log = _read_npz(source, path)
    elif head.startswith(_PARQUET_MAGIC):
        log = _read_parquet(source, path)
    else:
        raise ValueError(f"{path or '<bytes>'}: not a .npy, .npz or Parquet file")
    if progress is not None:
        size = len(source) if path is None else os.path.getsize(path)
        progress(size, size)
    return log
