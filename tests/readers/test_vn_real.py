"""Real VN-100 recordings: exact record counts and values against a plain-Python oracle."""

import imunoise
import numpy as np
import pytest
from helpers.data import DATA, shared_file
from helpers.vn_oracle import good_sentences
from imunoise.readers.vn import read_vn_tables


def test_rugged_ascii_counts_and_values():
    path = DATA / "rugged_0513test.txt"
    raw = path.read_bytes()
    expected = np.array(good_sentences(raw))
    assert len(expected) == 3902  # SOURCES.md: 3,902 sentences, first/last line truncated
    log = imunoise.read(path, fs=40)
    assert log.format == "vn-ascii" and log.source == str(path)
    assert log.messages == {"VNYMR": 3902}
    np.testing.assert_array_equal(log.ypr, expected[:, 0:3])
    np.testing.assert_array_equal(log.mag, expected[:, 3:6])
    np.testing.assert_array_equal(log.accel, expected[:, 6:9])
    np.testing.assert_array_equal(log.gyro, expected[:, 9:12])
    # The first line is a fragment without '$' (skipped bytes); the last is cut short.
    assert log.issues.counts["truncated_record"] == 1
    assert log.issues.first["truncated_record"] == (3904,)
    first_line = raw.split(b"\n", 1)[0]
    assert log.issues.counts["bytes_skipped"] == len(first_line) + 1
    assert log.issues.location == "line"
    with pytest.raises(ValueError, match=r"line 3904 .*truncated_record"):
        imunoise.read(path, strict=True, fs=40)


def test_rugged_fs_default_warns():
    with pytest.warns(UserWarning, match="no timestamps"):
        log = imunoise.read(DATA / "rugged_0513test.txt")
    assert log.fs == 40.0


def test_waves_binary_packets():
    path = DATA / "waves_F00294.bin"
    t = read_vn_tables(path)
    assert t.format == "vn-binary"
    assert t.binary_records == 99  # spec §7.3 B3: 99 packets, all CRC-valid
    assert t.issues.counts["bad_checksum"] == 0
    (name,) = [n for n in t.tables if n.startswith("binary_")]
    assert name == "binary_143e003a00"
    c = t.tables[name]
    # First packet (spec §7.3 B3), float32 values printed to 6-7 digits.
    np.testing.assert_allclose(
        [c["imu.uncomp_mag_x"][0], c["imu.uncomp_accel_z"][0], c["imu.uncomp_gyro_z"][0]],
        [-0.0880193, -9.384514, -0.00367320],
        rtol=2e-6,
    )
    np.testing.assert_allclose(
        [c["imu.temperature"][0], c["imu.pressure"][0], c["attitude.yaw"][0]],
        [19.455679, 102.088005, 135.927414],
        rtol=1e-7,
    )
    np.testing.assert_allclose(c["attitude.dcm_0"][0], -0.712983, atol=1e-6)
    np.testing.assert_allclose(c["attitude.accel_d"][0], -9.756364, atol=1e-6)
    log = imunoise.read(path, fs=10)
    assert log.format == "vn-binary" and len(log) == 99
    assert log.issues.location == "byte"
    # Uncompensated IMU values fill the channels (the packet has no compensated ones).
    np.testing.assert_array_equal(log.gyro[:, 2], c["imu.uncomp_gyro_z"])
    np.testing.assert_array_equal(log.temperature, c["imu.temperature"])
    # Each packet is 124 bytes; the rest is the logger's text (NMEA + markers).
    assert t.bytes_parsed >= 99 * 124
    assert t.bytes_parsed + t.bytes_in_bad_records + t.bytes_skipped == len(path.read_bytes())


def test_live_capture_shared():
    path = shared_file("data/vn100-ascii/live_capture.txt")
    log = imunoise.read(path, fs=40)
    assert log.messages == {"VNYMR": 30178} and log.issues.total == 0
    expected = np.array(good_sentences(path.read_bytes()))
    np.testing.assert_array_equal(log.gyro, expected[:, 9:12])


def test_both_streams_shared():
    path = shared_file("data/vn100-binary/serial_both_streams.bin")
    t = read_vn_tables(path)
    assert t.messages["VNYMR"] == len(good_sentences(path.read_bytes())) == 40
    assert t.binary_records == 199
    (name,) = [n for n in t.tables if n.startswith("binary_")]
    c = t.tables[name]
    dt = np.diff(c["common.time_startup"])
    assert np.median(dt) == pytest.approx(1 / 200, rel=1e-3)
    log = imunoise.read(path)
    assert log.fs == pytest.approx(200, rel=1e-3)
    assert len(log.time) == 199


def test_waves_f00379_shared():
    t = read_vn_tables(shared_file("data/vn100-binary/waves_F00379.bin"))
    # spec §7.3: 8,897 candidates, 8,895 CRC-valid.
    assert t.binary_records == 8895
    assert t.issues.counts["bad_checksum"] == 2


def test_csv_raw_column_shared():
    path = shared_file("data/vn100-csv/stationary_data_5min_0.csv")
    t = read_vn_tables(path)
    assert t.messages == {"VNYMR": len(good_sentences(path.read_bytes()))}
