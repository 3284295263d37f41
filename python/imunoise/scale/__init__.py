"""Scale: logs larger than memory, and fleets of logs.

Two features, one module each:

* :mod:`imunoise.scale.convert` — :func:`convert` streams a log into a columnar
  file (a directory of ``.npy``, one structured ``.npy`` or Parquet) with memory
  bounded by the piece size, and :func:`load` memory-maps it back as an
  :class:`~imunoise.readers.log.ImuLog`;
* :mod:`imunoise.scale.batch` — :func:`batch` analyses many logs with
  dask.distributed (or one after another), one result row per log, sensor and axis.
"""

from imunoise.scale.batch import BATCH_SENSORS, BATCH_TAUS, analyse_log, batch
from imunoise.scale.convert import CHUNK_BYTES, Conversion, convert, load

__all__ = [
    "BATCH_SENSORS",
    "BATCH_TAUS",
    "CHUNK_BYTES",
    "Conversion",
    "analyse_log",
    "batch",
    "convert",
    "load",
]
