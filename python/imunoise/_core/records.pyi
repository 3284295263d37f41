# rust/bindings/records.rs: the record file convert writes its .npy data through.

import os
from typing import final

import numpy as np
import numpy.typing as npt

@final
class RecordFile:
    """Appends records of ``width`` float64 values to the existing file ``path``
    (its header written by the caller)."""

    def __new__(cls, path: str | os.PathLike[str], width: int) -> RecordFile: ...
    def append(self, arrays: list[npt.NDArray[np.float64]]) -> None:
        """Append one record per row: row r of every array in ``arrays``, in order."""
    def digest(self, head: bytes) -> str:
        """The file's BLAKE3 digest (64 hex digits) with ``head`` as its first bytes
        (the header, as long as when the file was opened), then the records."""
    @property
    def rows(self) -> int:
        """Rows appended so far."""
    def close(self) -> None:
        """Close the file (every append is already written to it)."""
