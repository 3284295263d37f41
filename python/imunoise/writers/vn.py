"""Writers for VN-100 ASCII sentences and binary packets.

Used by the simulator, the benchmarks and the round-trip tests: what these write,
:func:`imunoise.read` reads back (ASCII values to the printed decimals, binary
values to float32).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from imunoise._core import vn as _core_vn
from imunoise._support import atomic as _atomic
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import ImuLog

# column base name -> (channel, column index or None for 1-D channels)
_FROM_CHANNEL: dict[str, tuple[str, int | None]] = {}
for _ch, _names in {
    "gyro": ("gyro_x", "gyro_y", "gyro_z"),
    "accel": ("accel_x", "accel_y", "accel_z"),
    "mag": ("mag_x", "mag_y", "mag_z"),
    "ypr": ("yaw", "pitch", "roll"),
    "quaternion": ("qx", "qy", "qz", "qw"),
    "delta_theta": ("delta_theta_x", "delta_theta_y", "delta_theta_z"),
    "delta_velocity": ("delta_vel_x", "delta_vel_y", "delta_vel_z"),
}.items():
    for _i, _n in enumerate(_names):
        _FROM_CHANNEL[_n] = (_ch, _i)
        if _ch in ("gyro", "accel", "mag"):
            _FROM_CHANNEL["uncomp_" + _n] = (_ch, _i)
_FROM_CHANNEL["temperature"] = ("temperature", None)
_FROM_CHANNEL["pressure"] = ("pressure", None)

#: Common-group field -> channels it needs; the default selection takes every field
#: whose channels the data has (plus TimeStartup).
_COMMON_DEFAULT = (
    ("YawPitchRoll", ("ypr",)),
    ("Quaternion", ("quaternion",)),
    ("AngularRate", ("gyro",)),
    ("Accel", ("accel",)),
    ("MagPres", ("mag", "temperature", "pressure")),
)


def _default_fields(data) -> dict[str, list[str]]:
    def has(ch: str) -> bool:
        if isinstance(data, Mapping):
            return ch in data
        return getattr(data, ch, None) is not None

    fields = ["TimeStartup"] + [f for f, chans in _COMMON_DEFAULT if all(map(has, chans))]
    out = {"common": fields}
    if has("mag") and not has("pressure"):
        out["imu"] = ["Mag"]
    return out

#: Binary fields that default to zero when not given (status words, counters).
_ZERO_DEFAULT = ("vpe_status", "imu_status", "sens_sat", "syncin_count", "syncout_count")


def _column(data, name: str) -> np.ndarray | None:
    """Column ``name`` (bare or group-qualified) from an ImuLog or a mapping."""
    base = name.split(".", 1)[-1]
    if isinstance(data, Mapping):
        for key in (name, base):
            if key in data:
                return np.ascontiguousarray(data[key], dtype=np.float64).reshape(-1)
    source = _FROM_CHANNEL.get(base)
    if source is not None:
        channel, idx = source
        arr = getattr(data, channel, None) if not isinstance(data, Mapping) else data.get(channel)
        if arr is not None:
            arr = np.asarray(arr, dtype=np.float64)
            return np.ascontiguousarray(arr if idx is None else arr[:, idx])
    return None


def _length(data) -> int:
    if isinstance(data, ImuLog):
        return len(data)
    for v in data.values():
        return len(np.asarray(v))
    return 0


def _finish(out: bytes, path) -> bytes:
    if path is not None:
        _atomic.write_bytes(path, out)
    return out


def write_vn_ascii(
    data: ImuLog | Mapping[str, np.ndarray],
    message: str = "VNYMR",
    *,
    path: str | os.PathLike | None = None,
    crc: bool = False,
    line_ending: str = "\r\n",
    decimals: Sequence[int] | None = None,
    count: np.ndarray | None = None,
    status: np.ndarray | None = None,
) -> bytes:
    """Write ``$VN<message>`` sentences, one per sample.

    Parameters
    ----------
    data : ImuLog or mapping
        Channels (``log.gyro`` ...) or a mapping of channel names (``"gyro"``:
        (n, 3)) and/or field names (``"yaw"``, ``"lin_accel_x"`` ...).
    message : str
        Any type of the spec's tables 3.1 and 3.2 (``"VNYMR"``, ``"VNIMU"`` ...).
    crc : bool
        Append a 4-digit CRC-16 instead of the 2-digit XOR-8 checksum.
    line_ending : str
        ``"\\r\\n"`` as the sensor sends, or ``"\\n"``.
    decimals : sequence of int, optional
        Printed decimals per field (default: as a VN-100 prints them).
    count, status : array, optional
        Appended ``T`` (counter) and ``S`` (status word) fields.
    path : path, optional
        Also write the bytes to this file.

    Returns
    -------
    bytes
    """
    fields = _core_vn.vn_message_fields()
    if message not in fields:
        raise ImunoiseValueError(f"message must be one of {sorted(fields)}; got {message!r}")
    columns, missing = [], []
    for name in fields[message]:
        col = _column(data, name)
        if col is None:
            missing.append(name)
        columns.append(col)
    if missing:
        raise ImunoiseValueError(f"data lacks {missing} needed for {message}")
    opt = [
        None if a is None else np.ascontiguousarray(a, dtype=np.float64) for a in (count, status)
    ]
    # all positional: the binding's last keyword is being renamed from eol to line_ending
    out = _core_vn.write_vn_ascii(
        message, columns, list(decimals) if decimals is not None else None, opt[0], opt[1], crc,
        line_ending.encode(),
    )
    return _finish(out, path)


def _selection(fields) -> list[tuple[int, int]]:
    table = _core_vn.vn_binary_fields()
    if isinstance(fields, Mapping):
        out = []
        for group, names in fields.items():
            if group not in table:
                raise ImunoiseValueError(
                    f"fields group must be one of {sorted(table)}; got {group!r}")
            index, known = table[group]
            mask = 0
            for name in [names] if isinstance(names, str) else names:
                if name not in known:
                    raise ImunoiseValueError(
                        f"fields[{group!r}] has unknown field {name!r}; known: {sorted(known)}"
                    )
                mask |= 1 << known[name]
            out.append((index, mask))
        return out
    return [(int(g), int(m)) for g, m in fields]


def binary_columns(fields) -> list[str]:
    """Column names (group-qualified, payload order) of packets for ``fields``."""
    return list(_core_vn.vn_binary_columns(_selection(fields))[0])


def write_vn_binary(
    data: ImuLog | Mapping[str, np.ndarray],
    fields: Mapping[str, Sequence[str]] | Sequence[tuple[int, int]] | None = None,
    *,
    path: str | os.PathLike | None = None,
) -> bytes:
    """Write VN binary output packets (``0xFA`` ... CRC-16), one per sample.

    Parameters
    ----------
    data : ImuLog or mapping
        Channels, and/or columns by (qualified) name, e.g. ``"common.yaw"``.
        ``TimeStartup`` comes from ``time`` or else ``i / fs``; status words and
        counters default to 0; any other field must be given.
    fields : mapping or sequence
        Selection as ``{"common": ["TimeStartup", "AngularRate"], "imu": [...]}``
        (default: Common TimeStartup plus YawPitchRoll, Quaternion, AngularRate,
        Accel, MagPres for the channels present; IMU Mag if mag has no pressure)
        (field names of the spec's §5.3 tables) or ``[(group index, field mask)]``.
    path : path, optional
        Also write the bytes to this file.

    Returns
    -------
    bytes
    """
    if fields is None:
        fields = _default_fields(data)
    selection = _selection(fields)
    names, _ = _core_vn.vn_binary_columns(selection)
    n = _length(data)
    columns, missing = {}, []
    for name in names:
        col = _column(data, name)
        base = name.split(".", 1)[-1]
        if col is None and base == "time_startup":
            t = getattr(data, "time", None) if isinstance(data, ImuLog) else data.get("time")
            if t is not None:
                col = np.ascontiguousarray(t, dtype=np.float64)
            elif isinstance(data, ImuLog):
                col = np.arange(n, dtype=np.float64) / data.fs
        if col is None and base in _ZERO_DEFAULT:
            col = np.zeros(n)
        if col is None:
            missing.append(name)
        columns[name] = col
    if missing:
        raise ImunoiseValueError(f"data lacks {missing} needed for fields {fields!r}")
    return _finish(_core_vn.write_vn_binary(selection, columns), path)
