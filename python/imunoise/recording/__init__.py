"""Record a VN-100 on a serial port (``imunoise record``): lossless raw log, side
files, live view. See :mod:`imunoise.recording.recorder`."""

from imunoise.recording.config import binary_output
from imunoise.recording.protocol import DeviceError
from imunoise.recording.recorder import Recording, SensorLost, record

__all__ = ["DeviceError", "Recording", "SensorLost", "binary_output", "record"]
