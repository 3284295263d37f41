"""Small bags of the three formats (ROS 1, ROS 2 sqlite3, MCAP) and the damage done to
them by the mutation tests and ``benches/faults.py``."""

from __future__ import annotations

import random
import shutil
from pathlib import Path

import numpy as np

from helpers.data import DATA
from helpers.vn_sentences import ymr

MCAP = DATA / "vn100-ros" / "11sec_motion_0.mcap"
_RAW = "std_msgs/Header header\nstring raw\n"


def _header(store, ns):
    t = store.types
    stamp = t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
    header = t["std_msgs/msg/Header"]
    seq = {"seq": 0} if "seq" in header.__dataclass_fields__ else {}  # ROS 1 only
    return header(stamp=stamp, frame_id="imu", **seq)


def _ros1_bag(path: Path, n: int) -> Path:
    """A ROS 1 bag of a lab driver's raw VN sentences (custom type from the bag)."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(_RAW, "lab/msg/Raw"))
    raw = store.types["lab/msg/Raw"]
    rng = np.random.default_rng(1)
    with Writer(path) as writer:
        conn = writer.add_connection("/imu/raw", "lab/msg/Raw", typestore=store)
        for i in range(n):
            ns = 1_700_000_000_000_000_000 + i * 25_000_000
            values = np.r_[rng.normal(0, 1, 3), rng.normal(0, 0.3, 3), 0, 0, -9.8,
                           rng.normal(0, 0.01, 3)]
            msg = raw(header=_header(store, ns), raw=ymr(values))
            writer.write(conn, ns, store.serialize_ros1(msg, "lab/msg/Raw"))
    return path


def _db3_bag(directory: Path, n: int) -> Path:
    """A ROS 2 sqlite3 bag of sensor_msgs Imu; returns its .db3 file."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    t = store.types
    V, Q = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]
    rng = np.random.default_rng(2)
    with Writer(directory, version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        conn = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=store)
        for i in range(n):
            ns = 1_700_000_000_000_000_000 + i * 10_000_000
            w, a = rng.normal(0, 0.01, 3), rng.normal(0, 0.1, 3) + [0, 0, 9.81]
            msg = t["sensor_msgs/msg/Imu"](
                header=_header(store, ns), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.zeros(9), angular_velocity=V(x=w[0], y=w[1], z=w[2]),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=V(x=a[0], y=a[1], z=a[2]),
                linear_acceleration_covariance=np.zeros(9))
            writer.write(conn, ns, store.serialize_cdr(msg, "sensor_msgs/msg/Imu"))
    return next(directory.glob("*.db3"))


def small_bags(directory: Path, n: int = 80) -> dict[str, Path]:
    """{"ros1": .bag, "db3": .db3, "mcap": the bundled .mcap} in ``directory``."""
    directory.mkdir(parents=True, exist_ok=True)
    mcap = directory / MCAP.name
    shutil.copyfile(MCAP, mcap)
    return {
        "ros1": _ros1_bag(directory / "raw.bag", n),
        "db3": _db3_bag(directory / "imu_db3", n),
        "mcap": mcap,
    }


KINDS = ("flip", "truncate", "zero")


def mutate(data: bytes, rng: random.Random, kind: str | None = None) -> tuple[str, bytes]:
    """``data`` damaged one way: 1-8 bit flips, a truncation, or a zeroed block of
    16-4096 bytes. Returns (kind, damaged bytes)."""
    kind = kind or rng.choice(KINDS)
    b = bytearray(data)
    if kind == "flip":
        for _ in range(rng.randint(1, 8)):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
    elif kind == "truncate":
        del b[rng.randrange(len(b)):]
    else:
        at, size = rng.randrange(len(b)), rng.choice((16, 256, 4096))
        b[at:at + size] = bytes(len(b[at:at + size]))
    return kind, bytes(b)


def outcome(path: Path) -> str:
    """How ``imunoise.read`` took the file: "ok", "ParseError", "named <Error>" (a
    ValueError/OSError naming the file) or "LEAK <module.Error>: message"."""
    import warnings

    import imunoise
    from imunoise.errors import ParseError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            imunoise.read(path)
    except ParseError:
        return "ParseError"
    except (ValueError, OSError) as exc:
        if path.name in str(exc):
            return f"named {type(exc).__name__}"
        return f"LEAK {type(exc).__module__}.{type(exc).__name__}: {exc}"
    except Exception as exc:  # noqa: BLE001 - what leaks is what is measured
        return f"LEAK {type(exc).__module__}.{type(exc).__name__}: {exc}"
    return "ok"
