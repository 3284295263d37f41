"""read_rosbag on real lab-driver bags and on bags written here with rosbags' writer."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from helpers import vn_sentences as vn_helpers
from helpers.vn_sentences import ymr, ymr_fields
from imunoise.errors import ParseError
from imunoise.readers import rosbag_reader
from imunoise.readers.rosbag_reader import read_rosbag
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

DATA = Path(__file__).parents[1] / "data"
MCAP = DATA / "vn100-ros" / "11sec_motion_0.mcap"
SHARED = Path("/work/shared/data/vn100-ros")
ROS1 = SHARED / "ros1_stationary.bag"
DB3 = SHARED / "ros2_circle_0.db3"
VN_RTOL = vn_helpers.VN_RTOL

# The lab driver's message in ros2_circle_0.db3, read off its serialized bytes (the
# bag carries no definitions): a header, a sensor_msgs Imu, a MagneticField, the sentence.
IMUMSG = (
    "std_msgs/Header header\nsensor_msgs/Imu imu\n"
    "sensor_msgs/MagneticField mag_field\nstring raw_imu_string\n"
)


def _oracle(path, topic, field, **kw):
    """(header stamps in s, receive times in s, sentences) read with rosbags alone."""
    stamps, times, sentences = [], [], []
    with AnyReader([path], **kw) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, t, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            stamps.append(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9)
            times.append(t * 1e-9)
            sentences.append(getattr(msg, field))
    return np.array(stamps), np.array(times), sentences


def _check_ends(log, sentences, times):
    for i in (0, -1):
        v = ymr_fields(sentences[i])
        np.testing.assert_allclose(log.ypr[i], v[0:3], rtol=VN_RTOL)
        np.testing.assert_allclose(log.mag[i], v[3:6], rtol=VN_RTOL)
        np.testing.assert_allclose(log.accel[i], v[6:9], rtol=VN_RTOL)
        np.testing.assert_allclose(log.gyro[i], v[9:12], rtol=VN_RTOL)
        assert log.time[i] == pytest.approx(times[i], abs=1e-6)


# -- real bags -------------------------------------------------------------------------


def test_mcap_lab_driver_schema_from_bag():
    stamps, _t, sentences = _oracle(MCAP, "/imu", "raw")
    log = read_rosbag(MCAP)
    # 414 messages in the bag's metadata.yaml; the custom type came from the MCAP schema
    assert len(log) == 414 == len(sentences)
    assert log.format == "rosbag" and log.issues.total == 0
    assert dict(log.messages) == {"VNYMR": 414}
    assert set(log.channels) == {"gyro", "accel", "mag", "ypr"}
    _check_ends(log, sentences, stamps)
    assert log.time[-1] - log.time[0] == pytest.approx(10.3, abs=0.05)
    # the driver's own parsed Imu fields disagree with the sentence: the sentence wins
    assert log.gyro[0, 0] == pytest.approx(-0.355773, rel=VN_RTOL)
    assert read_rosbag(MCAP.read_bytes()).source == "<bytes>"


@pytest.mark.skipif(not ROS1.exists(), reason="../shared/data (unlicensed ROS 1 bag) absent")
def test_ros1_bag_custom_type_from_connection_header():
    stamps, _t, sentences = _oracle(ROS1, "/imu", "VNYMR")
    log = read_rosbag(ROS1)
    assert len(log) == 2732 == len(sentences)
    assert log.issues.total == 0
    assert log.messages["VNYMR"] == 2732
    assert log.messages["ignored /gnss [sensor_stack/msg/gnss_msg]"] == 69
    assert log.messages["ignored /rosout [rosgraph_msgs/msg/Log]"] == 2735
    _check_ends(log, sentences, stamps)


@pytest.mark.skipif(not DB3.exists(), reason="../shared/data (unlicensed ROS 2 bag) absent")
def test_ros2_db3_without_definitions():
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(IMUMSG, "imu_msg/msg/IMUmsg"))
    stamps, times, sentences = _oracle(DB3, "/imu", "raw_imu_string", default_typestore=store)
    with pytest.warns(UserWarning, match="no definition in the bag"):
        log = read_rosbag(DB3)
    assert len(log) == 2617 == len(sentences)
    assert log.messages["ignored /gps [gps_msg/msg/GPSmsg]"] == 65
    _check_ends(log, sentences, times)  # receive times: the header is not known
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = read_rosbag(DB3, msg_defs={"imu_msg/msg/IMUmsg": IMUMSG})
    assert len(log) == 2617 and log.issues.total == 0
    _check_ends(log, sentences, stamps)  # header stamps once the type is known
    with pytest.raises(ValueError, match="definition is not in the bag"):
        read_rosbag(DB3, topic="/gps")


# -- bags written here -------------------------------------------------------------------


def _store():
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg("std_msgs/Header header\nstring raw\n", "lab/msg/Raw"))
    return store


def _header(store, ns):
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="imu")


def _imu(store, ns, w, a, q, qcov0=0.0):
    t = store.types
    V, Q = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]
    cov = np.zeros(9)
    return t["sensor_msgs/msg/Imu"](
        header=_header(store, ns),
        orientation=Q(x=q[0], y=q[1], z=q[2], w=q[3]),
        orientation_covariance=np.r_[qcov0, np.zeros(8)],
        angular_velocity=V(x=w[0], y=w[1], z=w[2]),
        angular_velocity_covariance=cov,
        linear_acceleration=V(x=a[0], y=a[1], z=a[2]),
        linear_acceleration_covariance=cov,
    )


def _write(path, store, topics, plugin=StoragePlugin.SQLITE3):
    """topics: {name: (msgtype, [(ns, msg), ...])}"""
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        for name, (msgtype, items) in topics.items():
            conn = writer.add_connection(name, msgtype, typestore=store)
            for ns, msg in items:
                writer.write(conn, ns + 1000, store.serialize_cdr(msg, msgtype))


@pytest.mark.parametrize("plugin", [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
def test_imu_bag_round_trip(tmp_path, plugin):
    rng = np.random.default_rng(7)
    n = 200
    ns = 1_700_000_000_000_000_000 + np.arange(n) * 2_500_000 + rng.integers(0, 1000, n)
    gyro, accel = rng.normal(0, 0.01, (n, 3)), rng.normal(0, 0.1, (n, 3)) + [0, 0, 9.81]
    quat = rng.normal(size=(n, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    mag_t = rng.normal(0, 3e-5, (n, 3))
    store = get_typestore(Stores.ROS2_HUMBLE)
    V = store.types["geometry_msgs/msg/Vector3"]
    Mag = store.types["sensor_msgs/msg/MagneticField"]
    Fix = store.types["sensor_msgs/msg/NavSatFix"]
    imu = [
        (int(t), _imu(store, int(t), g, a, q))
        for t, g, a, q in zip(ns, gyro, accel, quat, strict=True)
    ]
    mags = [
        (
            int(t),
            Mag(
                header=_header(store, int(t)),
                magnetic_field=V(*m),
                magnetic_field_covariance=np.zeros(9),
            ),
        )
        for t, m in zip(ns, mag_t, strict=True)
    ]
    fix = Fix(
        header=_header(store, 5),
        status=store.types["sensor_msgs/msg/NavSatStatus"](status=0, service=1),
        latitude=1.0,
        longitude=2.0,
        altitude=3.0,
        position_covariance=np.zeros(9),
        position_covariance_type=0,
    )
    _write(
        tmp_path / "bag",
        store,
        {
            "/imu/data": ("sensor_msgs/msg/Imu", imu),
            "/imu/mag": ("sensor_msgs/msg/MagneticField", mags),
            "/gps": ("sensor_msgs/msg/NavSatFix", [(5, fix)] * 3),
        },
        plugin,
    )
    calls = []
    log = read_rosbag(tmp_path / "bag", progress=lambda d, t: calls.append((d, t)))
    assert calls[-1][0] == calls[-1][1] > 0
    assert len(log) == n and log.issues.total == 0
    np.testing.assert_array_equal(log.gyro, gyro)
    np.testing.assert_array_equal(log.accel, accel)
    np.testing.assert_array_equal(log.quaternion, quat)
    np.testing.assert_array_equal(log.mag, mag_t * 1e4)  # Tesla -> Gauss
    np.testing.assert_allclose(log.time, ns * 1e-9, rtol=0, atol=5e-7)
    np.testing.assert_array_equal(np.diff(log.time) > 0, True)
    assert log.messages["ignored /gps [sensor_msgs/msg/NavSatFix]"] == 3
    assert log.fs == pytest.approx(400.0, rel=1e-3)

    alone = read_rosbag(tmp_path / "bag", topic="/imu/mag")
    np.testing.assert_array_equal(alone.mag, mag_t * 1e4)
    assert alone.channels == ("mag",)


def test_imu_without_orientation_and_topic_errors(tmp_path):
    store = get_typestore(Stores.ROS2_HUMBLE)
    items = [
        (
            k * 10**7 + 1,
            _imu(store, k * 10**7 + 1, [k, 0, 0], [0, 0, 9.8], [0, 0, 0, 1], qcov0=-1.0),
        )
        for k in range(5)
    ]
    _write(
        tmp_path / "a",
        store,
        {"/a": ("sensor_msgs/msg/Imu", items), "/b": ("sensor_msgs/msg/Imu", items)},
    )
    with pytest.raises(ValueError, match=r"several IMU topics \['/a', '/b'\]"):
        read_rosbag(tmp_path / "a")
    log = read_rosbag(tmp_path / "a", topic="/b")
    assert log.quaternion is None and log.gyro[:, 0].tolist() == [0, 1, 2, 3, 4]
    assert log.fs == pytest.approx(100.0)
    with pytest.raises(ValueError, match="not in the bag"):
        read_rosbag(tmp_path / "a", topic="/c")
    with pytest.raises(ValueError, match="not a ROS 1 bag"):
        read_rosbag(b"hello")
    with pytest.raises(FileNotFoundError):
        read_rosbag(tmp_path / "missing.bag")


@pytest.mark.parametrize("batch", [20_000, 7])
def test_custom_vn_message_bad_sentences(tmp_path, batch, monkeypatch):
    monkeypatch.setattr(rosbag_reader, "_BATCH", batch)
    store = _store()
    Raw = store.types["lab/msg/Raw"]
    rng = np.random.default_rng(1)
    values = rng.normal(size=(30, 12)).round(6)
    sentences = [ymr(v, bad_checksum=k in (4, 17)) for k, v in enumerate(values)]
    sentences[9] = "no sentence here"
    ns = [10**18 + k * 25_000_000 for k in range(30)]
    _write(
        tmp_path / "vn",
        store,
        {
            "/vn": (
                "lab/msg/Raw",
                [
                    (t, Raw(header=_header(store, t), raw=s))
                    for t, s in zip(ns, sentences, strict=True)
                ],
            ),
        },
    )
    log = read_rosbag(tmp_path / "vn")
    keep = [k for k in range(30) if k not in (4, 9, 17)]
    assert len(log) == 30  # the damaged messages are missing samples on the stamp grid
    assert list(log.gaps.index) == [4, 9, 17] and log.issues.samples_missing == 3
    assert log.issues.location == "message"
    assert log.issues.counts["bad_checksum"] == 2
    assert log.issues.first["bad_checksum"] == (5, 18)
    assert log.issues.counts["malformed_field"] == 1
    assert log.issues.first["malformed_field"] == (10,)
    np.testing.assert_allclose(log.gyro[keep], values[keep, 9:12], rtol=VN_RTOL)
    np.testing.assert_allclose(log.time, np.array(ns) * 1e-9, atol=5e-7, rtol=0)
    with pytest.raises(ValueError, match=r"message 5\b"):
        read_rosbag(tmp_path / "vn", strict=True)


def test_strict_error_names_the_message(tmp_path):
    store = get_typestore(Stores.ROS2_HUMBLE)
    ns = [10**18 + k * 10**7 for k in range(6)]
    gyro = [[k, 0.0, 0.0] for k in range(6)]
    gyro[2][1] = np.nan  # message 3 is damaged
    items = [
        (t, _imu(store, t, w, [0, 0, 9.8], [0, 0, 0, 1])) for t, w in zip(ns, gyro, strict=True)
    ]
    _write(tmp_path / "bag", store, {"/imu": ("sensor_msgs/msg/Imu", items)}, StoragePlugin.MCAP)
    log = read_rosbag(tmp_path / "bag")
    assert log.issues.first["malformed_field"] == (3,) and list(log.gaps.index) == [2]
    with pytest.raises(ParseError) as info:
        read_rosbag(tmp_path / "bag", strict=True)
    error = info.value
    assert (error.kind, error.line, error.reason) == ("malformed_field", 3, "non-finite value")
    assert error.source == str(tmp_path / "bag")
    (mcap,) = (tmp_path / "bag").glob("*.mcap")
    with pytest.raises(ParseError) as info:
        read_rosbag(mcap.read_bytes(), strict=True)
    assert (info.value.line, info.value.source) == (3, None)  # bytes in memory


def test_temperature_topic_is_merged_onto_the_imu_stamps(tmp_path):
    """A sensor_msgs Temperature topic at 1 Hz next to a 100 Hz Imu topic: the log's
    temperature is the linear interpolation on the IMU stamps (held at the ends)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    Temp = store.types["sensor_msgs/msg/Temperature"]
    t0 = 1_700_000_000_000_000_000
    n = 500
    ns = t0 + np.arange(n) * 10_000_000
    imu = [(int(t), _imu(store, int(t), (0.0, 0.0, 0.0), (0.0, 0.0, 9.81), (0, 0, 0, 1)))
           for t in ns]
    temp_ns = t0 + 500_000_000 + np.arange(4) * 1_000_000_000
    temp_c = np.array([30.0, 30.5, 31.5, 31.0])
    temps = [(int(t), Temp(header=_header(store, int(t)), temperature=float(c), variance=0.0))
             for t, c in zip(temp_ns, temp_c, strict=True)]
    _write(tmp_path / "bag", store, {"/imu/data": ("sensor_msgs/msg/Imu", imu),
                                     "/imu/temperature": ("sensor_msgs/msg/Temperature", temps)})
    log = read_rosbag(tmp_path / "bag")
    assert "temperature" in log.channels
    assert log.messages["sensor_msgs/msg/Temperature"] == 4
    expected = np.interp(ns - t0, temp_ns - t0, temp_c)
    np.testing.assert_allclose(log.temperature, expected)
    assert log.temperature[0] == 30.0 and log.temperature[-1] == 31.0
    assert log.temperature[100] == pytest.approx(30.25)  # 1.0 s: halfway 0.5 s -> 1.5 s
    with pytest.raises(ValueError, match="is a Temperature topic; choose the Imu topic"):
        read_rosbag(tmp_path / "bag", topic="/imu/temperature")
