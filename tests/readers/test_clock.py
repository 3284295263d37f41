"""A clock that one bad value cannot steer (issue #24 items 4, 5 and 9)."""

from __future__ import annotations

import warnings

import imunoise
import numpy as np
import pytest
from imunoise.readers.vn import read_vn_tables

N, FS = 2000, 100.0


def _csv(t, header: str = "time") -> bytes:
    gyro = np.random.default_rng(3).normal(0, 0.01, (len(t), 3))
    rows = [f"{header},gx,gy,gz"]
    rows += [",".join(repr(float(v)) for v in (t[i], *gyro[i])) for i in range(len(t))]
    return ("\n".join(rows) + "\n").encode()


def _read(data, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = imunoise.read(data, **kwargs)
    return log, " ".join(str(w.message) for w in caught)


def _binary(t: np.ndarray) -> bytes:
    rng = np.random.default_rng(5)
    n = len(t)
    return imunoise.write_vn_binary({"gyro": rng.normal(0, 0.01, (n, 3)),
                                     "accel": rng.normal(0, 0.01, (n, 3)), "time": t})


def test_one_absurd_timestamp_is_an_outlier_not_the_clock():
    t = 5 + np.arange(N) / FS
    t[700] = 1e308
    log, said = _read(_csv(t))
    assert len(log) == N and log.fs == pytest.approx(FS, rel=1e-9)
    assert log.issues.counts["time_outlier"] == 1
    assert log.issues.first["time_outlier"] == (701,)
    assert log.issues.counts["duplicate_time"] == 0 and not len(log.gaps)
    assert log.time[700] == pytest.approx(12.0)  # placed and timed by its neighbours
    assert "time_outlier" in said


def test_one_absurd_time_startup_in_a_crc_valid_packet_keeps_the_clock():
    t = 1.0 + np.arange(N) / FS
    t[1234] = 1.5e9  # a valid packet (CRC fine) carrying a wild TimeStartup
    log, _ = _read(_binary(t))
    assert log.issues.counts["bad_checksum"] == 0
    assert len(log) == N and log.fs == pytest.approx(FS, rel=1e-9)
    assert log.issues.counts["time_outlier"] == 1 and not len(log.gaps)


def test_a_device_reset_splits_the_log_into_segments_in_file_order():
    half = N // 2
    t = np.concatenate([30.0 + np.arange(half) / FS, np.arange(half) / FS])
    data = _binary(t)
    log, said = _read(data)
    gyro = read_vn_tables(data).tables
    rows = next(iter(gyro.values()))
    assert len(log) == N and not np.isnan(log.gyro).any()  # was 101 % rows, 98 % NaN
    np.testing.assert_array_equal(log.gyro[:, 0], rows["common.gyro_x"])  # order kept
    assert log.issues.counts["time_reset"] == 1
    assert log.issues.first["time_reset"] == (half + 1,)
    assert log.fs == pytest.approx(FS, rel=1e-9)
    assert "segments" in said


def test_time_that_only_decreases_is_reported_as_such():
    t = (5 + np.arange(N) / FS)[::-1]
    log, said = _read(_csv(t))
    assert log.fs == pytest.approx(FS, rel=1e-9)
    assert log.issues.counts["time_reversed"] == N - 1
    assert "decreases" in said and "no timestamps" not in said


@pytest.mark.parametrize(("step", "fs", "unit"), [
    (20_000.0, 50.0, "us"),   # µs at 50 Hz (was 50,000 Hz)
    (10.0, 100.0, "ms"),      # ms at 100 Hz (was 0.1 Hz)
    (2.5e6, 400.0, "ns"),
])
def test_the_time_unit_is_inferred_from_the_rate_with_a_warning(step, fs, unit):
    log, said = _read(_csv(np.arange(500) * step))
    assert log.fs == pytest.approx(fs, rel=1e-9)
    assert f"taken as {unit}" in said


@pytest.mark.parametrize(("t", "header"), [
    (1.7e18 + np.arange(500) * 2.5e7, "time"),   # epoch ns: the magnitude says it
    (np.arange(500) * 2.5e7, "stamp_ns"),        # the name says it
    (1.7e9 + np.arange(500) * 0.025, "time"),    # epoch seconds
])
def test_a_time_unit_that_is_not_a_guess_needs_no_warning(t, header):
    log, said = _read(_csv(t, header))
    assert log.fs == pytest.approx(40.0, rel=1e-6)
    assert "taken as" not in said


def test_first_says_where_duplicate_and_reversed_time_happened():
    t = 5 + np.arange(N) / FS
    t[300] = t[299]           # a duplicate stamp
    t[900], t[901] = t[901], t[900]  # two samples swapped: one step back
    log, _ = _read(_csv(t))
    assert log.issues.counts["duplicate_time"] >= 1 and log.issues.first["duplicate_time"]
    assert log.issues.first["time_reversed"] == (902,)
    assert "sample 902" in repr(log.issues)


def test_describe_of_an_empty_log_is_clear():
    empty = imunoise.ImuLog.from_arrays(40.0, gyro=np.zeros((0, 3)))
    with pytest.raises(ValueError, match="has no samples; describe needs at least 2"):
        imunoise.describe(empty)


def test_csv_digit_separators_are_bad_rows():
    data = b"time,gx,gy,gz\n0,1,2,3\n0.025,1_000,2,3\n0.05,1,2,3\n"
    log, _ = _read(data)
    assert log.issues.counts["malformed_field"] == 1
    assert log.issues.first["malformed_field"] == (3,)
    assert np.nanmax(log.gyro) < 1000
