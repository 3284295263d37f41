"""ROS bags: ROS 1 ``.bag``, ROS 2 sqlite3 ``.db3`` and MCAP, through ``rosbags``.

:func:`read_rosbag` reads one IMU topic into an :class:`~imunoise.readers.log.ImuLog`:

* ``sensor_msgs/msg/Imu``: gyro (rad/s), accel (m/s²), orientation quaternion
  (x, y, z, w; left out when the driver marks it absent with covariance[0] = -1 or
  sends zeros), time from ``header.stamp``. A single ``sensor_msgs/msg/MagneticField``
  topic with the same stamps is merged in as ``mag`` (Tesla -> Gauss), and a single
  ``sensor_msgs/msg/Temperature`` topic as ``temperature`` (°C; usually published
  slower than the IMU, so interpolated linearly onto the IMU stamps and held
  constant before its first and after its last message).
* ``sensor_msgs/msg/MagneticField`` alone (``topic=`` it, or when it is the only one).
* Any message type with a string field carrying a raw VN-100 sentence (the usual
  lab-driver format, e.g. ``vn_driver/msg/Vectornav`` with ``string raw``): the
  sentence is decoded by the VN parser and wins over any parsed fields of the same
  message; time from the message's ``header.stamp``, else the bag's receive time.

Custom message types are registered from the definitions stored in the bag (MCAP
schemas, ROS 1 connection headers, ROS 2 ``message_definitions`` where the bag has
them), so the original message packages are not needed. A ROS 2 ``.db3`` written
before Iron carries no definitions: pass ``msg_defs={"pkg/msg/Type": "<.msg text>"}``
(or a ready ``typestore``). Without either, a topic of unknown type is still read when
its serialized messages contain ``$VN`` sentences: the sentence is cut out of the
message bytes and the bag's receive time is used (with a warning).

Issue locations are 1-based message numbers on the topic (``issues.location ==
"message"``).
"""

from __future__ import annotations

import errno
import os
import re
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from imunoise._support import warn as _warn
from imunoise.errors import AssumptionWarning, ImunoiseTypeError, ImunoiseValueError, ParseError
from imunoise.readers._sentences import IssueTally, sentence_rows
from imunoise.readers.log import ImuLog, log_on_grid
from imunoise.readers.probe import Confidence, Probe

__all__ = ["SIGNATURES", "read_rosbag", "sniff"]

IMU = "sensor_msgs/msg/Imu"
MAG = "sensor_msgs/msg/MagneticField"
TEMPERATURE = "sensor_msgs/msg/Temperature"
TESLA_TO_GAUSS = 1e4
_BATCH = 20_000  # messages per call of the VN parser
_PREALLOC = 1 << 16  # rows allocated before the first message of a sensor topic

#: What a topic is (see _classify_topics) and, for a VN message, the attribute
#: path of its sentence field.
_Kind = tuple[str, tuple[str, ...] | None]

#: First bytes of each bag file format -> the extension rosbags reads it by.
SIGNATURES = {b"#ROSBAG V2.0": ".bag", b"\x89MCAP": ".mcap", b"SQLite format 3\x00": ".db3"}


def sniff(probe: Probe) -> Confidence:
    """A bag by magic number or extension, or a ROS 2 bag directory."""
    if probe.is_dir:
        path = probe.path
        is_bag = (
            (path / "metadata.yaml").exists() or any(path.glob("*.db3")) or any(path.glob("*.mcap"))
        )
        return Confidence.SIGNATURE if is_bag else Confidence.NO
    if probe.suffix in SIGNATURES.values() or probe.head.startswith(tuple(SIGNATURES)):
        return Confidence.SIGNATURE
    return Confidence.NO


def _typestore(typestore, msg_defs: Mapping[str, str] | None):
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = typestore if typestore is not None else get_typestore(Stores.LATEST)
    if msg_defs:
        types = {}
        for name, text in msg_defs.items():
            if not isinstance(text, str):
                raise ImunoiseTypeError(
                    f"msg_defs[{name!r}] must be .msg text; got {type(text).__name__}")
            types.update(get_types_from_msg(text, name))
        store.register(types)
    return store


def _find_vn_field(msg, path=()) -> tuple[str, ...] | None:
    """Attribute path of the first string field holding ``$VN`` in a decoded message."""
    fields = getattr(msg, "__dataclass_fields__", None)
    if fields is None:
        return None
    for name in fields:
        value = getattr(msg, name, None)
        if isinstance(value, str) and "$VN" in value:
            return (*path, name)
        if hasattr(value, "__msgtype__"):
            found = _find_vn_field(value, (*path, name))
            if found:
                return found
    return None


def _cut_sentence(raw: bytes) -> bytes:
    """The printable run starting at ``$VN`` in serialized message bytes (b"" if none)."""
    start = raw.find(b"$VN")
    if start < 0:
        return b""
    end = start
    while end < len(raw) and 0x20 <= raw[end] < 0x7F:
        end += 1
    return raw[start:end]


def _stamp(msg) -> int:
    header = getattr(msg, "header", None) or getattr(msg, "Header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return 0
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def read_rosbag(
    source,
    *,
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    topic: str | None = None,
    msg_defs: Mapping[str, str] | None = None,
    typestore=None,
) -> ImuLog:
    """Read the IMU topic of a ROS 1, ROS 2 (sqlite3) or MCAP bag.

    Parameters
    ----------
    source : str, os.PathLike or bytes
        A ``.bag``, ``.mcap`` or ``.db3`` file, or a ROS 2 bag directory (with its
        ``metadata.yaml``); bytes are written to a temporary file first.
    strict : bool
        Raise :class:`~imunoise.errors.ParseError` at the first message that does
        not decode (``.line`` is its 1-based number on the topic), instead of
        counting it.
    fs : float, optional
        Sample rate used when the topic carries no usable timestamps.
    progress : callable, optional
        Called as ``progress(done, total)`` in bytes (estimated from messages read).
    topic : str, optional
        The topic to read. Default: the one topic carrying VN sentences, else the
        one ``sensor_msgs/msg/Imu`` topic, else the one ``MagneticField`` topic.
    msg_defs : mapping, optional
        Message type -> ``.msg`` definition text, for bags that do not embed their
        definitions (ROS 2 ``.db3`` before Iron). Nested types must be given too
        unless they are standard ROS types.
    typestore : rosbags.typesys.store.Typestore, optional
        A typestore that already knows the bag's types (used as the default).

    Returns
    -------
    ImuLog
        ``format="rosbag"``; ``messages`` counts the decoded records by type and
        lists the topics that were not read as ``"ignored <topic> [<type>]"``.
        Rows are on the grid of the header stamps (the receive time where a
        message has none): dropped messages are NaN rows and ``log.gaps``.

    Raises
    ------
    FileNotFoundError
        When ``source`` is a path that does not exist.
    """
    if isinstance(source, bytes | bytearray | memoryview):
        data = bytes(source)
        suffix = next((s for m, s in SIGNATURES.items() if data.startswith(m)), None)
        if suffix is None:
            raise ImunoiseValueError(
                "source: bytes are not a ROS 1 bag, an MCAP file or a sqlite3 bag")
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / f"bag{suffix}"
            path.write_bytes(data)
            return _read_bag(path, _BYTES, strict, fs, progress, topic, msg_defs, typestore)
    if not isinstance(source, str | os.PathLike):
        raise ImunoiseTypeError(f"source must be a path or bytes; got {type(source).__name__}")
    path = Path(source)
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such bag", str(path))
    return _read_bag(path, str(path), strict, fs, progress, topic, msg_defs, typestore)


_BYTES = "<bytes>"  # the name of a bag given as bytes


def _read_bag(path, name, strict, fs, progress, topic, msg_defs, typestore) -> ImuLog:
    """Open the bag at ``path`` (a file or a ROS 2 bag directory) and read it."""
    from rosbags.highlevel import AnyReader, AnyReaderError

    total = (
        sum(p.stat().st_size for p in path.iterdir() if p.is_file())
        if path.is_dir()
        else path.stat().st_size
    )
    default = _typestore(typestore, msg_defs) if (typestore or msg_defs) else None
    try:
        try:
            reader = AnyReader([path], default_typestore=default)
            reader.open()
        except AnyReaderError as exc:
            if default is not None or "type definitions" not in str(exc):
                raise ImunoiseValueError(f"{name}: cannot open bag: {exc}") from exc
            reader = AnyReader([path], default_typestore=_typestore(None, None))
            reader.open()
        try:
            return _read(reader, name, total, strict, fs, progress, topic)
        finally:
            reader.close()
    except Exception as exc:
        if _ours(exc):
            raise
        raise _damaged(exc, name) from exc


def _ours(exc: BaseException) -> bool:
    """True for the errors this module raises on purpose (they name the bag, the
    topic or the argument); False for what a damaged bag makes a library (rosbags,
    apsw/sqlite, struct, the codecs ...) or a builtin raise."""
    if isinstance(exc, ParseError | FileNotFoundError):
        return True
    if type(exc) not in (ValueError, TypeError):
        return False
    tb = exc.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    return tb is not None and tb.tb_frame.f_globals.get("__name__") == __name__


def _damaged(exc: Exception, name: str) -> ParseError:
    """A library's exception on a damaged bag as a :class:`ParseError` naming the
    file, the byte offset when the library said it, and the cause."""
    text = " ".join(str(exc).split()) or "no detail"
    if isinstance(exc, MemoryError):  # rosbags reads a record of the size it claims
        text = "a record's size field asks for more memory than there is"
    found = re.search(r"offset (\d+)", text)
    truncated = re.search(r"truncat|unexpected end|eof|short read|not enough", text, re.I)
    return ParseError(
        f"damaged bag: {type(exc).__name__}: {text[:300]}",
        kind="truncated_record" if truncated else "malformed_field",
        offset=int(found.group(1)) if found else None,
        source=None if name == _BYTES else name,
    )


def _read(reader, name, total, strict, fs, progress, topic) -> ImuLog:
    """Read the chosen topic of an open bag: the steps below, in order."""
    topics, kinds = _classify_topics(reader)
    chosen = _choose_topic(topics, kinds, topic, reader.typestore.fielddefs, name)
    count_all = sum(c.msgcount for conns in topics.values() for c in conns) or 1
    tick = _ticker(progress, total, count_all)
    tally = IssueTally()
    kind, field = kinds[chosen]
    if kind in ("imu", "mag"):
        # a lone MagneticField topic is merged only when the user did not pick a topic
        data = _read_sensor_topic(
            reader, topics, kinds, chosen, topic is None, tally, strict, name, tick
        )
    else:
        data = _read_vn_topic(reader, topics[chosen], kind, field, tally, strict, name, tick)
    if progress is not None:
        progress(total, total)
    return _assemble(data, topics, tally, fs, name)


@dataclass
class _TopicData:
    """What was read from the chosen topic (and a merged magnetometer topic)."""

    channels: dict[str, np.ndarray]
    messages: dict[str, int]  # records decoded per message type
    time_ns: np.ndarray  # int64 stamps, 0 where a message had none
    topics: tuple[str, ...]  # the topics read


def _classify_topics(reader) -> tuple[dict[str, list], dict[str, _Kind]]:
    """Connections per topic, and what each topic is: ``imu``, ``mag``, ``vn`` (a
    decodable message with a ``$VN`` string field, whose attribute path is kept),
    ``vn-bytes`` (an unknown type whose bytes hold ``$VN``) or ``other``."""
    known = reader.typestore.fielddefs
    topics: dict[str, list] = {}
    for conn in reader.connections:
        topics.setdefault(conn.topic, []).append(conn)
    kinds: dict[str, _Kind] = {}
    for tp, conns in topics.items():
        msgtype = conns[0].msgtype
        if msgtype == IMU:
            kinds[tp] = ("imu", None)
        elif msgtype == MAG:
            kinds[tp] = ("mag", None)
        elif msgtype == TEMPERATURE:
            kinds[tp] = ("temperature", None)
        else:
            raw = next((raw for _c, _t, raw in reader.messages(connections=conns)), None)
            if raw is None:
                kinds[tp] = ("other", None)
            elif msgtype in known:
                try:
                    field = _find_vn_field(reader.deserialize(raw, msgtype))
                except Exception:  # a message that does not decode is not a VN topic
                    field = None
                kinds[tp] = ("vn", field) if field else ("other", None)
            else:
                kinds[tp] = ("vn-bytes", None) if b"$VN" in raw else ("other", None)
    return topics, kinds


def _choose_topic(topics, kinds, topic, known, name) -> str:
    """The topic to read: ``topic`` if given, else the one VN topic, else the one
    Imu topic, else the one MagneticField topic; an error if it cannot be read."""
    if topic is not None:
        if topic not in topics:
            raise ImunoiseValueError(
                f"topic: {topic!r} is not in the bag; topics are {sorted(topics)}")
        chosen = topic
    else:
        for group in (("vn", "vn-bytes"), ("imu",), ("mag",)):
            cands = sorted(tp for tp, (k, _f) in kinds.items() if k in group)
            if len(cands) > 1:
                raise ImunoiseValueError(
                    f"{name}: several IMU topics {cands}; choose one with topic=")
            if cands:
                chosen = cands[0]
                break
        else:
            listing = {tp: conns[0].msgtype for tp, conns in topics.items()}
            raise ImunoiseValueError(
                f"{name}: no IMU topic (sensor_msgs/msg/Imu, MagneticField or a message "
                f"with a $VN sentence); topics are {listing}"
            )
    if kinds[chosen][0] == "temperature":
        raise ImunoiseValueError(f"{name}: topic {chosen!r} is a Temperature topic; choose the Imu "
                         "topic (the temperature is merged into it)")
    if kinds[chosen][0] == "other":
        msgtype = topics[chosen][0].msgtype
        if msgtype not in known:
            raise ImunoiseValueError(
                f"{name}: topic {chosen!r} has type {msgtype!r}, whose definition is not "
                "in the bag; pass msg_defs={type: '.msg text'}"
            )
        raise ImunoiseValueError(
            f"{name}: topic {chosen!r} ({msgtype}) is neither sensor_msgs Imu/MagneticField "
            "nor a message with a $VN sentence"
        )
    return chosen


def _ticker(progress, total: int, count_all: int) -> Callable[[], None]:
    """A function to call per message read; reports progress every 1000 messages."""
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if progress is not None and done % 1000 == 0:
            progress(int(total * done / count_all), total)

    return tick


def _read_sensor_topic(
    reader, topics, kinds, chosen, merge_mag, tally, strict, name, tick
) -> _TopicData:
    """An Imu topic (with the bag's one MagneticField topic merged in when it has
    the same stamps and ``merge_mag``) or a MagneticField topic."""
    kind = kinds[chosen][0]
    stamps, values = _sensor_arrays(reader, topics[chosen], kind, tally, strict, name, tick)
    channels: dict[str, np.ndarray] = {}
    messages = {topics[chosen][0].msgtype: len(stamps)}
    read = [chosen]
    if kind == "mag":
        channels["mag"] = values[0]
        return _TopicData(channels, messages, stamps, tuple(read))
    gyro, accel, quat, has_quat = values
    channels.update(gyro=gyro, accel=accel)
    if has_quat:
        channels["quaternion"] = quat
    mags = [tp for tp, (k, _f) in kinds.items() if k == "mag"]
    if merge_mag and len(mags) == 1:
        mstamps, (mag,) = _sensor_arrays(
            reader, topics[mags[0]], "mag", IssueTally(), False, name, lambda: None
        )
        if len(mstamps) == len(stamps) and np.array_equal(mstamps, stamps):
            channels["mag"] = mag
            messages[MAG] = len(stamps)
            read.append(mags[0])
    temps = [tp for tp, (k, _f) in kinds.items() if k == "temperature"]
    if len(temps) == 1 and len(stamps):
        tstamps, values = _temperature_arrays(reader, topics[temps[0]])
        if len(tstamps):
            # interpolate on stamps relative to the first IMU stamp (float64 keeps ns)
            order = np.argsort(tstamps, kind="stable")
            channels["temperature"] = np.interp(
                (stamps - stamps[0]).astype(np.float64),
                (tstamps[order] - stamps[0]).astype(np.float64), values[order])
            messages[TEMPERATURE] = len(tstamps)
            read.append(temps[0])
    return _TopicData(channels, messages, stamps, tuple(read))


def _temperature_arrays(reader, conns) -> tuple[np.ndarray, np.ndarray]:
    """Stamps (ns) and temperatures (°C) of a sensor_msgs Temperature topic; messages
    that do not decode or are not finite are left out (the IMU rows stay)."""
    stamps, values = [], []
    for _conn, t, raw in reader.messages(connections=conns):
        try:
            msg = reader.deserialize(raw, TEMPERATURE)
            value = float(msg.temperature)
        except Exception:  # a damaged temperature message only costs its own value
            continue
        if np.isfinite(value):
            stamps.append(_stamp(msg) or t)
            values.append(value)
    return np.asarray(stamps, dtype=np.int64), np.asarray(values, dtype=np.float64)


def _read_vn_topic(reader, conns, kind, field, tally, strict, name, tick) -> _TopicData:
    """A topic whose messages carry one VN sentence each: in the string field at
    attribute path ``field`` (``kind == "vn"``), or cut out of the raw message
    bytes (``"vn-bytes"``, an unknown type: then the receive time is the stamp)."""
    items, stamps, locs = [], [], []
    parts: list[dict[str, np.ndarray]] = []
    kept_ns: list[np.ndarray] = []
    messages: dict[str, int] = {}

    def flush() -> None:
        # sentences are decoded in batches so that no Python object per message
        # outlives its batch
        rows = sentence_rows(items, locs, tally, strict=strict, source=name, where="message")
        if rows.channels:
            parts.append(rows.channels)
            kept_ns.append(np.asarray(stamps, dtype=np.int64)[rows.kept])
        for key, count in rows.messages.items():
            messages[key] = messages.get(key, 0) + count
        items.clear()
        stamps.clear()
        locs.clear()

    msgtype = conns[0].msgtype
    for number, (_conn, t, raw) in enumerate(reader.messages(connections=conns), start=1):
        tick()
        if kind == "vn-bytes":
            items.append(_cut_sentence(raw))
            stamps.append(t)
        else:
            try:
                msg = reader.deserialize(raw, msgtype)
            except Exception as exc:
                if strict:
                    flush()  # a bad sentence in an earlier message is reported first
                    raise _parse_error(f"does not decode: {exc}", number, name) from exc
                tally.add("malformed_field", number)
                continue
            value = msg
            for attr in field:
                value = getattr(value, attr, "")
            items.append(value.encode("latin-1", "replace") if isinstance(value, str) else b"")
            stamps.append(_stamp(msg) or t)
        locs.append(number)
        if len(items) >= _BATCH:
            flush()
    flush()
    if kind == "vn-bytes":
        _warn.warn(
            f"{name}: topic {conns[0].topic!r} has type {msgtype!r} with no definition in the "
            "bag; VN sentences were cut out of the message bytes and the bag receive time is "
            "used (pass msg_defs= to use the message header stamps)", AssumptionWarning
        )
    channels = {ch: np.concatenate([p[ch] for p in parts]) for ch in (parts[0] if parts else ())}
    time_ns = np.concatenate(kept_ns) if kept_ns else np.zeros(0, dtype=np.int64)
    return _TopicData(channels, messages, time_ns, (conns[0].topic,))


def _assemble(data: _TopicData, topics, tally, fs, name) -> ImuLog:
    """The log of what was read, on the grid of its stamps; topics not read are
    listed in ``messages`` as ignored."""
    messages = dict(data.messages)
    for tp, conns in topics.items():
        if tp not in data.topics:
            messages[f"ignored {tp} [{conns[0].msgtype}]"] = sum(c.msgcount for c in conns)
    time_ns = data.time_ns
    time = None
    if len(time_ns) and np.all(time_ns > 0):
        sec0 = int(time_ns[0]) // 1_000_000_000
        time = sec0 + (time_ns - sec0 * 1_000_000_000) * 1e-9
    return log_on_grid(
        fs=fs,
        source=name,
        format="rosbag",
        issues=tally.issues("message"),
        channels=data.channels,
        time=time,
        messages=messages,
    )


def _parse_error(reason: str, number: int, name: str) -> ParseError:
    """The strict-mode error for message ``number`` of the topic."""
    return ParseError(
        reason, kind="malformed_field", line=number, source=None if name == _BYTES else name
    )


def _sensor_arrays(reader, conns, kind, tally, strict, name, tick):
    """Stamps (ns) and arrays of an Imu or MagneticField topic."""
    # the bag's message count may be damaged: start from at most _PREALLOC rows and grow
    n = min(sum(c.msgcount for c in conns), _PREALLOC)
    stamps = np.zeros(n, dtype=np.int64)
    width = 10 if kind == "imu" else 3
    out = np.zeros((n, width), dtype=np.float64)
    quat_flag = np.zeros(n, dtype=bool)
    k = 0
    msgtype = conns[0].msgtype
    for number, (_conn, t, raw) in enumerate(reader.messages(connections=conns), start=1):
        tick()
        try:
            msg = reader.deserialize(raw, msgtype)
            if kind == "imu":
                w, a, q = msg.angular_velocity, msg.linear_acceleration, msg.orientation
                row = (w.x, w.y, w.z, a.x, a.y, a.z, q.x, q.y, q.z, q.w)
                has_q = float(msg.orientation_covariance[0]) != -1.0 and any(
                    v != 0 for v in row[6:]
                )
            else:
                m = msg.magnetic_field
                row = (m.x * TESLA_TO_GAUSS, m.y * TESLA_TO_GAUSS, m.z * TESLA_TO_GAUSS)
                has_q = False
            values = np.asarray(row, dtype=np.float64)
        except Exception as exc:
            if strict:
                raise _parse_error(f"does not decode: {exc}", number, name) from exc
            tally.add("malformed_field", number)
            continue
        used = values[:6] if kind == "imu" else values
        if not np.isfinite(used).all():
            if strict:
                raise _parse_error("non-finite value", number, name)
            tally.add("malformed_field", number)
            continue
        if k >= len(stamps):  # more messages than allocated (or than msgcount said): grow
            extra = max(len(stamps), 1024)
            stamps = np.concatenate([stamps, np.zeros(extra, dtype=np.int64)])
            out = np.concatenate([out, np.zeros((extra, width))])
            quat_flag = np.concatenate([quat_flag, np.zeros(extra, dtype=bool)])
        out[k] = values
        stamps[k] = _stamp(msg) or t
        quat_flag[k] = has_q
        k += 1
    stamps, out, quat_flag = stamps[:k], out[:k], quat_flag[:k]
    if kind == "mag":
        return stamps, (out,)
    has_quat = bool(k) and bool(quat_flag.all())
    return stamps, (out[:, 0:3], out[:, 3:6], out[:, 6:10], has_quat)
