"""Writers that turn :class:`~imunoise.readers.log.ImuLog` data into a sensor's own format."""

from imunoise.writers.vn import binary_columns, write_vn_ascii, write_vn_binary

__all__ = ["binary_columns", "write_vn_ascii", "write_vn_binary"]
