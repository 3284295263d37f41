"""The names and constants every module shares: channels, their columns and axis
labels, the sensor groups each analysis covers, and standard gravity.

One place on purpose: copies of these drifted before (the quaternion columns were
labelled w, x, y, z by two writers while every reader stores x, y, z, w). Rust owns
what Rust computes (statistic names, issue kinds, fit limits; see ``imunoise._core``);
this module owns what only Python uses.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType

from imunoise.errors import ImunoiseValueError

#: Standard gravity (CGPM), m/s².
G = 9.80665

#: Channel name -> (columns, unit). Every channel is float64 (n, columns) in an
#: ``ImuLog``; ``temperature`` and ``pressure`` are (n,).
CHANNELS: Mapping[str, tuple[int, str]] = MappingProxyType(
    {
        "gyro": (3, "rad/s"),
        "accel": (3, "m/s^2"),
        "mag": (3, "Gauss"),
        "ypr": (3, "deg"),
        "quaternion": (4, "1"),
        "temperature": (1, "degC"),
        "pressure": (1, "kPa"),
        "delta_theta": (3, "deg"),
        "delta_velocity": (3, "m/s"),
    }
)

#: Column suffixes of the multi-column channels. The quaternion is stored as the
#: readers decode it (VN-100 and ROS order): vector part first, scalar ``w`` last.
COLUMN_SUFFIXES: Mapping[int, tuple[str, ...]] = MappingProxyType(
    {3: ("x", "y", "z"), 4: ("x", "y", "z", "w")}
)

#: Sensors whose noise the Allan analysis and the noise model describe.
ALLAN_SENSORS = ("gyro", "accel")
#: Sensors whose sample statistics and histograms the report shows.
SAMPLE_SENSORS = ("gyro", "accel", "mag")
#: Names of the three columns of the ``ypr`` channel (the VN-100's attitude
#: filter output, degrees).
ATTITUDE_NAMES = ("yaw", "pitch", "roll")
#: Log-spaced averaging times per decade of the report's and the batch analysis's
#: Allan deviation (``adev(x, fs, taus=TAUS_PER_DECADE)``).
TAUS_PER_DECADE = 10
#: Channels :func:`imunoise.describe` summarises when given a log.
STATISTICS_CHANNELS = ("gyro", "accel", "mag", "ypr", "temperature", "pressure")


def column_names(channel: str) -> list[str]:
    """Flat column names of a channel, as every writer (``imunoise convert`` to
    CSV/NPZ/Parquet, :mod:`imunoise.scale`) names them: ``gyro_x`` ...,
    ``quaternion_x, quaternion_y, quaternion_z, quaternion_w``; one-column channels
    (and ``"time"``, ``"valid"``) keep their name."""
    cols = CHANNELS[channel][0] if channel in CHANNELS else 1
    return [channel] if cols == 1 else [f"{channel}_{a}" for a in COLUMN_SUFFIXES[cols]]


def axis_names(channels: int, axes: Sequence[str] | None = None) -> list[str]:
    """Display labels of ``channels`` axes: ``X, Y, Z`` (``W`` fourth), ``value``
    for one channel, ``ch0 …`` beyond four; ``axes`` overrides and must match."""
    if axes is None:
        if channels == 1:
            return ["value"]
        if channels <= 4:
            return [a.upper() for a in COLUMN_SUFFIXES[4][:channels]]
        return [f"ch{i}" for i in range(channels)]
    axes = list(axes)
    if len(axes) != channels:
        raise ImunoiseValueError(f"axes must name {channels} channels; got {axes!r}")
    return axes


def sensor_label(sensor: str, axis: int, channels: int) -> str:
    """``"gyro X"``-style label of one axis of a sensor (the bare name for one channel)."""
    return sensor if channels == 1 else f"{sensor} {axis_names(channels)[axis]}"
