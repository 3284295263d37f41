"""Whole-log tables: the CSV and ``.npz`` outputs of ``imunoise convert``.

Both carry the metadata of :func:`imunoise.readers.columnar.log_meta` (rate,
source, format, issues, messages, gaps), so that :func:`imunoise.read` gives
back the log that was written: the ``.npz`` as an entry ``imunoise`` (a JSON
string), the CSV in ``OUT.csv.meta.json`` beside it (the CSV itself stays a plain
header and rows for any other tool), with the CSV's fingerprint so that a reader
never pairs it with another CSV (:func:`imunoise._support.atomic.publish_pair`). Every
value is written with the shortest text that parses back to the same float64
(numpy's round-trip repr): epoch times keep their nanoseconds, samples are
bit-identical.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from imunoise._support import atomic as _atomic
from imunoise._support.schema import column_names
from imunoise.readers import metafile
from imunoise.readers.columnar import META_KEY, log_meta
from imunoise.readers.log import ImuLog

__all__ = ["log_columns", "write_csv", "write_npz"]

#: Rows formatted at a time by :func:`write_csv` (bounds the text held in memory).
_CSV_ROWS = 1 << 16


def log_columns(log: ImuLog) -> tuple[list[str], list[np.ndarray]]:
    """Flat column names and 1-D arrays: ``time`` first when present, then each
    channel's columns (``gyro_x`` ...), then ``valid`` (1/0) when the log has gaps."""
    names, cols = [], []
    if log.time is not None:
        names.append("time")
        cols.append(np.asarray(log.time, dtype=np.float64))
    for ch in log.channels:
        arr = np.asarray(getattr(log, ch), dtype=np.float64)
        names.extend(column_names(ch))
        cols.extend([arr] if arr.ndim == 1 else [arr[:, j] for j in range(arr.shape[1])])
    if len(log.gaps):
        names.append("valid")
        cols.append(log.valid.astype(np.float64))
    return names, cols


def _meta(log: ImuLog) -> dict:
    channels = (["time"] if log.time is not None else []) + list(log.channels)
    return log_meta(fs=log.fs, source=log.source, fmt=log.format, issues=log.issues,
                    messages=log.messages, samples=len(log), channels=channels, table=None,
                    gaps=log.gaps)


def write_csv(log: ImuLog, out, *, inputs: Iterable = ()) -> list[Path]:
    """Write ``log`` as CSV (a header, one row per grid row, NaN in missing rows) and
    its metadata as ``OUT.csv.meta.json``, published together (``inputs`` are
    refused as outputs); returns both paths."""
    out = Path(os.fspath(out))
    names, cols = log_columns(log)
    meta_file = metafile.meta_path(out)
    _atomic.refuse_input(meta_file, inputs)
    meta = _meta(log)
    with _atomic.staged(out, inputs=inputs) as (fh, tmp):
        fh.write((",".join(names) + "\n").encode())
        for start in range(0, len(log), _CSV_ROWS):
            text = [c[start:start + _CSV_ROWS].astype(str) for c in cols]  # round-trip repr
            fh.write("".join(",".join(row) + "\n" for row in zip(*text, strict=True)).encode())
    _atomic.publish_pair(tmp, out, lambda tie: json.dumps({**meta, "data": tie}, indent=1),
                         meta_file)
    return [out, meta_file]


def write_npz(log: ImuLog, out, *, inputs: Iterable = ()) -> list[Path]:
    """Write ``log`` as ``.npz`` atomically: ``fs``, the flat columns and the
    metadata; returns ``[path]``."""
    out = Path(os.fspath(out))
    names, cols = log_columns(log)
    with _atomic.replacing(out, inputs=inputs) as fh:
        np.savez(fh, fs=np.float64(log.fs), **dict(zip(names, cols, strict=True)),
                 **{META_KEY: np.array(json.dumps(_meta(log)))})
    return [out]
