# rust/bindings/records.rs: the record file convert writes its .npy data through.

import numpy as np
from numpy.typing import NDArray

class RecordFile:
    """Appends records of `width` float64 values to the existing file `path`."""

    def __init__(self, path: str, width: int) -> None: ...
    def append(self, arrays: list[NDArray[np.float64]]) -> None:
        """Append one record per row: row r of every array, in order."""
    @property
    def rows(self) -> int:
        """Rows appended so far."""
    def close(self) -> None:
        """Close the file."""
