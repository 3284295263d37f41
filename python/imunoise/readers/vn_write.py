"""Deprecated home of the VN-100 writers: use :mod:`imunoise.writers.vn`.

Kept for one release so that old imports keep working.
"""

import warnings

from imunoise.errors import ImunoiseDeprecationWarning
from imunoise.writers.vn import binary_columns, write_vn_ascii, write_vn_binary

__all__ = ["binary_columns", "write_vn_ascii", "write_vn_binary"]

warnings.warn(
    "imunoise.readers.vn_write is deprecated; import from imunoise.writers.vn "
    "(or use imunoise.write_vn_ascii / imunoise.write_vn_binary)",
    ImunoiseDeprecationWarning,
    stacklevel=2,
)
