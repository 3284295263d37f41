"""read_csv on real exported logs, unit handling, bad rows, random text."""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from helpers import vn_sentences as vn_helpers
from helpers.vn_sentences import ymr, ymr_fields
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from imunoise.errors import ParseError
from imunoise.readers import csv_reader
from imunoise.readers.csv_reader import read_csv

DATA = Path(__file__).parents[1] / "data"
VN_CSV = DATA / "vn100-csv" / "stationary_data_5min_0.csv"
SHARED = Path("/work/shared/data")
IG500N = SHARED / "other-imu" / "ig500n_static.txt"
G = 9.80665
VN_RTOL = vn_helpers.VN_RTOL


def _csv_rows(path):
    with open(path, newline="") as fh:
        return list(csv.reader(fh))


# -- the real VN-100 CSV (ROS 2 bag export with a raw sentence column) ------------------


def test_vn_csv_raw_column_wins():
    rows = _csv_rows(VN_CSV)
    header, first, last = rows[0], rows[1], rows[-1]
    log = read_csv(VN_CSV)
    # 13,223 messages in the bag's metadata.yaml, one data line each
    assert len(log) == 13223 == len(rows) - 1
    assert log.format == "csv" and log.issues.total == 0
    assert log.messages["VNYMR"] == 13223
    assert set(log.channels) == {"gyro", "accel", "mag", "ypr"}
    raw = header.index("raw")
    for row, i in ((first, 0), (last, -1)):
        v = ymr_fields(row[raw])
        np.testing.assert_allclose(log.ypr[i], v[0:3], rtol=VN_RTOL)
        np.testing.assert_allclose(log.mag[i], v[3:6], rtol=VN_RTOL)
        np.testing.assert_allclose(log.accel[i], v[6:9], rtol=VN_RTOL)
        np.testing.assert_allclose(log.gyro[i], v[9:12], rtol=VN_RTOL)
        assert log.time[i] == pytest.approx(float(row[header.index("ros_t")]), abs=1e-6)
    # the recording driver's own columns are mis-scaled and axis-swapped: not used
    assert log.gyro[0, 0] != float(first[header.index("gyro_x")])
    assert log.fs == pytest.approx(40.0, abs=0.05)


def test_vn_csv_bad_sentences_counted_at_their_lines():
    text = VN_CSV.read_text().splitlines()
    # line numbers are 1-based file lines; line 1 is the header
    text[4] = text[4].replace("*6", "*0", 1) if "*6" in text[4] else text[4][:-3] + '00"'
    text[9] = text[9].split(',"$VN')[0] + ',""'  # a row whose raw field is empty
    text[20] = text[20].split(",")[0] + ",oops"  # wrong number of fields
    data = ("\n".join(text) + "\n").encode()
    log = read_csv(data)
    # the damaged rows are missing samples at their place on the time grid
    assert len(log) == 13223 and list(log.gaps.index) == [3, 8, 19]
    assert log.issues.counts["bad_checksum"] == 1
    assert log.issues.first["bad_checksum"] == (5,)
    assert log.issues.counts["malformed_field"] == 2
    assert log.issues.first["malformed_field"] == (10, 21)
    # samples stay with their own row's timestamp after the dropped ones
    row = list(csv.reader([text[5]]))[0]
    assert log.time[4] == pytest.approx(float(row[1]), abs=1e-6)
    np.testing.assert_allclose(log.gyro[4], ymr_fields(row[-1])[9:12], rtol=VN_RTOL)
    with pytest.raises(ValueError, match=r"line 5\b"):
        read_csv(data, strict=True)


def test_vn_csv_numeric_columns_on_request():
    rows = _csv_rows(VN_CSV)
    log = read_csv(
        VN_CSV,
        columns={"gyro": ["gyro_x", "gyro_y", "gyro_z"], "accel": [5, 6, 7]},
        time_column="bag_t",
    )
    assert len(log) == 13223 and log.messages == {"csv": 13223}
    np.testing.assert_array_equal(log.gyro[-1], [float(v) for v in rows[-1][2:5]])
    np.testing.assert_array_equal(log.accel[0], [float(v) for v in rows[1][5:8]])
    assert log.time[0] == float(rows[1][0])


def test_progress_reaches_total():
    calls = []
    read_csv(VN_CSV, columns={"gyro": [2, 3, 4]}, progress=lambda d, t: calls.append((d, t)))
    size = VN_CSV.stat().st_size
    assert calls and calls[-1] == (size, size)
    assert all(a <= b for (a, _), (b, _) in zip(calls, calls[1:], strict=False))


def test_bytes_and_path_agree(tmp_path):
    text = "t,gx,gy,gz\n0.0,1,2,3\n0.5,4,5,6\n"
    path = tmp_path / "x.csv"
    path.write_text(text)
    a, b = read_csv(path), read_csv(text.encode())
    np.testing.assert_array_equal(a.gyro, b.gyro)
    assert a.source == str(path) and b.source == "<bytes>" and a.fs == 2.0


# -- other sensors: whitespace columns without a header ---------------------------------


@pytest.mark.skipif(not IG500N.exists(), reason="../shared/data (unlicensed IG-500N log) absent")
def test_ig500n_whitespace_columns():
    lines = IG500N.read_text().splitlines()
    cols = {"ypr": [0, 1, 2], "accel": [3, 4, 5], "gyro": [6, 7, 8], "mag": [9, 10, 11]}
    log = read_csv(IG500N, columns={**cols, "temperature": 12}, units={"gyro": "deg/s"}, fs=100)
    assert len(log) == 36572 == len(lines)
    assert log.issues.total == 0 and log.fs == 100
    for i in (0, -1):
        v = [float(x) for x in lines[i].split()]
        np.testing.assert_array_equal(log.accel[i], v[3:6])
        np.testing.assert_allclose(log.gyro[i], np.radians(v[6:9]), rtol=1e-15)
        assert log.temperature[i] == v[12]
    with pytest.raises(ValueError, match="no IMU columns"):
        read_csv(IG500N, fs=100)
    with pytest.raises(ValueError, match="no header"):
        read_csv(IG500N, columns={"gyro": ["gx", "gy", "gz"]})


# -- names, units ---------------------------------------------------------------------


def test_units_and_nanoseconds():
    text = (
        "timestamp,gx [deg/s],gy [deg/s],gz [deg/s],ax,ay,az,mag_x,mag_y,mag_z,temp\n"
        "1700000000000000000,90,0,-180,1,0,-1,50,0,-25,300\n"
        "1700000000010000000,0,45,0,0.5,0,0,0,0,0,310\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = read_csv(text.encode(), units={"accel": "g", "mag": "uT", "temperature": "K"})
    np.testing.assert_allclose(log.gyro[0], [math.pi / 2, 0, -math.pi])
    np.testing.assert_allclose(log.accel[0], [G, 0, -G])
    np.testing.assert_allclose(log.mag[0], [0.5, 0, -0.25])  # 100 uT = 1 Gauss
    np.testing.assert_allclose(log.temperature, [300 - 273.15, 310 - 273.15])
    assert log.time[0] == pytest.approx(1.7e9)
    assert log.fs == pytest.approx(100.0)


@pytest.mark.parametrize(
    "names",
    [
        ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"),
        ("gx", "gy", "gz", "ax", "ay", "az"),
        ("wx", "wy", "wz", "accel.x", "accel.y", "accel.z"),
        (
            "field.angular_velocity.x",
            "field.angular_velocity.y",
            "field.angular_velocity.z",
            "field.linear_acceleration.x",
            "field.linear_acceleration.y",
            "field.linear_acceleration.z",
        ),
    ],
)
def test_header_names_recognised(names):
    text = "time," + ",".join(names) + "\n0,1,2,3,4,5,6\n0.01,7,8,9,10,11,12\n"
    log = read_csv(text.encode())
    np.testing.assert_array_equal(log.gyro, [[1, 2, 3], [7, 8, 9]])
    np.testing.assert_array_equal(log.accel, [[4, 5, 6], [10, 11, 12]])
    assert log.fs == pytest.approx(100.0)


def test_bad_arguments():
    text = b"t,gx,gy,gz\n0,1,2,3\n"
    with pytest.raises(ValueError, match="unknown unit"):
        read_csv(text, units={"gyro": "furlong/s"})
    with pytest.raises(ValueError, match="not of angular_rate"):
        read_csv(text, units={"gyro": "g"})
    with pytest.raises(ValueError, match="unknown channel"):
        read_csv(text, columns={"gyroscope": [1, 2, 3]})
    with pytest.raises(ValueError, match="no column named"):
        read_csv(text, columns={"gyro": ["a", "b", "c"]})
    with pytest.raises(ValueError, match="needs 3"):
        read_csv(text, columns={"gyro": [1, 2]})
    with pytest.raises(TypeError, match="path or bytes"):
        read_csv(12)


# -- bad rows ---------------------------------------------------------------------------


def test_malformed_rows_counted_with_line_numbers(tmp_path):
    text = (
        "# exported by a logger\n"
        "t;gx;gy;gz\n"  # line 2
        "0.00;1;2;3\n"
        "0.01;1;2\n"  # 4: a field short
        "\n"
        "0.02;1;x;3\n"  # 6: not a number
        "0.03;4;5;6\r\n"
        "0.04;inf;5;6\n"  # 8: not finite
        "0.05;7;8;9;10\n"  # 9: a field too many
        "0.06;1;1;1"  # no final newline
    )
    log = read_csv(text.encode())
    assert len(log) == 3
    assert log.issues.counts["malformed_field"] == 4
    assert log.issues.first["malformed_field"] == (4, 6, 8, 9)
    np.testing.assert_array_equal(log.gyro, [[1, 2, 3], [4, 5, 6], [1, 1, 1]])
    with pytest.raises(ParseError) as info:
        read_csv(text.encode(), strict=True)
    error = info.value
    assert (error.kind, error.line, error.offset, error.source) == (
        "malformed_field",
        4,
        None,
        None,  # bytes in memory
    )
    assert error.reason == "3 fields, expected 4"
    with pytest.raises(ParseError) as info:
        read_csv(text.replace("0.01;1;2\n", "").encode(), strict=True)
    assert (info.value.line, info.value.reason) == (5, "column 3 is not a number: 'x'")
    path = tmp_path / "log.csv"
    path.write_text(text)
    with pytest.raises(ParseError) as info:
        read_csv(path, strict=True)
    assert (info.value.line, info.value.source) == (4, str(path))


@pytest.mark.parametrize("chunk", [1 << 22, 997])
def test_corrupted_real_csv_every_line_accounted(chunk, monkeypatch):
    monkeypatch.setattr(csv_reader, "_CHUNK_BYTES", chunk)  # lines cut across chunks
    lines = VN_CSV.read_text().splitlines()
    rng = np.random.default_rng(3)
    bad = sorted(rng.choice(np.arange(1, len(lines)), size=25, replace=False))
    for i in bad:
        cut = rng.integers(1, 60)
        lines[i] = lines[i][:cut]  # truncated line
    data = ("\n".join(lines) + "\n").encode()
    log = read_csv(data, columns={"gyro": [2, 3, 4]}, time_column="ros_t")
    # every truncated line is a missing sample (NaN row) at its place on the grid
    assert len(log) == len(lines) - 1
    assert list(log.gaps.index) == [int(i) - 1 for i in bad]
    assert log.issues.counts["malformed_field"] == 25
    assert log.issues.first["malformed_field"] == tuple(int(i) + 1 for i in bad[:10])
    good = [ln.split(",") for k, ln in enumerate(lines) if k and k not in set(bad)]
    np.testing.assert_array_equal(
        log.gyro[log.valid], [[float(v) for v in g[2:5]] for g in good]
    )
    np.testing.assert_array_equal(log.time[log.valid], [float(g[1]) for g in good])


_token = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**20), 10**20).map(str),
    st.text(alphabet=' ,;"\t$*0123456789.eE+-xyzVNAN', max_size=8),
)
_row = st.lists(_token, min_size=0, max_size=6).map(",".join)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rows=st.lists(_row, max_size=30), crlf=st.booleans())
def test_random_rows_are_all_accounted_for(rows, crlf):
    """Every data line is a sample or a counted malformed line (no time column: the
    time grid's own accounting is tested in test_gaps.py). A NaN field is a missing
    value, so its row is a missing sample; an infinite one is malformed."""
    end = "\r\n" if crlf else "\n"
    text = "gx,gy,gz" + end + end.join(rows) + end
    data_lines = [r for r in rows if r.strip()]
    log = read_csv(text.encode(), fs=10.0)
    assert len(log) + log.issues.counts["malformed_field"] == len(data_lines)
    assert log.issues.total == log.issues.counts["malformed_field"]
    assert not np.isinf(log.gyro).any()
    try:
        strict = read_csv(text.encode(), fs=10.0, strict=True)
    except ParseError as exc:
        assert exc.line == log.issues.first["malformed_field"][0]
    else:
        assert len(strict) == len(log) and log.issues.total == 0


def test_strict_error_located_when_parser_names_no_line(monkeypatch):
    import imunoise.readers._sentences as sentences

    real = sentences.parse_sentences

    def terse(data, *, strict, source):
        if strict and b"*00" in data:
            raise ValueError("checksum mismatch")  # names no line
        return real(data, strict=False, source=source)

    monkeypatch.setattr(sentences, "parse_sentences", terse)
    good = [ymr([k] * 12) for k in range(4)]
    bad = good[2].rsplit("*", 1)[0] + "*00"
    rows = [f'{k * 0.025},"{s}"' for k, s in enumerate([good[0], good[1], bad, good[3]])]
    data = ("t,raw\n" + "\n".join(rows) + "\n").encode()
    with pytest.raises(ValueError, match=r"line 4: checksum mismatch"):
        read_csv(data, strict=True)
