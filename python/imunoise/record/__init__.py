"""Record a VN-100 on a serial port (``imunoise record``): lossless raw log, side
files, live view. See :mod:`imunoise.record.recorder`."""

from imunoise.record.config import binary_output
from imunoise.record.protocol import DeviceError
from imunoise.record.recorder import Recording, record

__all__ = ["DeviceError", "Recording", "binary_output", "record"]
