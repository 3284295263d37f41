"""Write -> read round trips for VN ASCII (every message type) and VN binary."""

import imunoise
import numpy as np
import pytest
from imunoise._core import vn as _core_vn
from imunoise.readers.vn import read_vn_tables
from imunoise.writers.vn import binary_columns

FIELDS = _core_vn.vn_message_fields()
NANOS = ("time_startup", "time_gps", "time_syncin", "time_pps", "gps_tow")


def printed(values: np.ndarray, decimals: int) -> np.ndarray:
    """What a reader must return for values printed with `decimals` (Python's formatting)."""
    return np.array([float(f"{v:+.{decimals}f}") for v in values])


@pytest.mark.parametrize("message", sorted(FIELDS))
@pytest.mark.parametrize("crc", [False, True])
def test_ascii_every_message(message, crc):
    rng = np.random.default_rng(abs(hash(message)) % 2**32)
    names = FIELDS[message]
    n = 50
    data = {name: rng.uniform(-50, 50, n) for name in names}
    decimals = [int(d) for d in rng.integers(0, 7, len(names))]
    out = imunoise.write_vn_ascii(
        data, message, crc=crc, line_ending="\n", decimals=decimals
    )
    assert out.count(b"\n") == n and b"\r" not in out
    t = read_vn_tables(out, strict=True)
    assert t.messages == {message: n}
    for name, d in zip(names, decimals, strict=True):
        np.testing.assert_array_equal(t.tables[message][name], printed(data[name], d))


def test_ascii_appended_fields():
    n = 20
    ypr = np.linspace(-170, 170, n * 3).reshape(n, 3)
    count = np.arange(n, dtype=float) * 1000
    status = np.arange(n, dtype=float) % 4
    out = imunoise.write_vn_ascii({"ypr": ypr}, "VNYPR", count=count, status=status)
    assert out.startswith(b"$VNYPR,-170.000,") and b",S0000,T0000000000*" in out
    cols = read_vn_tables(out, strict=True).tables["VNYPR"]
    np.testing.assert_array_equal(cols["serial_count"], count)
    np.testing.assert_array_equal(cols["status"], status)


def test_log_roundtrip_ascii_and_binary():
    rng = np.random.default_rng(0)
    n = 400
    log = imunoise.ImuLog.from_arrays(
        40.0,
        gyro=rng.normal(0, 0.01, (n, 3)),
        accel=rng.normal(0, 0.1, (n, 3)) + [0, 0, -9.81],
        mag=rng.normal(0, 0.3, (n, 3)),
        ypr=rng.uniform(-90, 90, (n, 3)),
    )
    back = imunoise.read(imunoise.write_vn_ascii(log), fs=40)
    assert back.messages == {"VNYMR": n} and back.issues.total == 0
    np.testing.assert_allclose(back.gyro, log.gyro, atol=5e-7 + 1e-15)
    np.testing.assert_allclose(back.ypr, log.ypr, atol=5e-4 + 1e-12)
    raw = imunoise.write_vn_binary(log)
    back = imunoise.read(raw)
    assert back.format == "vn-binary" and len(back) == n
    assert back.fs == pytest.approx(40.0)
    for ch in ("gyro", "accel", "mag", "ypr"):
        np.testing.assert_array_equal(
            getattr(back, ch), getattr(log, ch).astype(np.float32).astype(np.float64)
        )
    np.testing.assert_allclose(back.time, np.arange(n) / 40.0, atol=1e-9)


def test_binary_every_field():
    groups = _core_vn.vn_binary_fields()
    rng = np.random.default_rng(1)
    for group, (_, fields) in groups.items():
        selection = {group: sorted(fields)}
        names = binary_columns(selection)
        n = 7
        cols = {}
        for name in names:
            if "utc_year" in name:
                cols[name] = rng.integers(2000, 2100, n).astype(float)
            elif name.startswith(("time.utc", "time.time_status")):
                cols[name] = rng.integers(0, 60, n).astype(float)
            elif name.split(".")[1] in NANOS:
                cols[name] = rng.integers(0, 10**9, n) / 1e3
            elif name.endswith(("status", "count", "week", "sat", "_ms")):
                cols[name] = rng.integers(0, 65535, n).astype(float)
            else:
                cols[name] = rng.normal(0, 100, n)
        raw = imunoise.write_vn_binary(cols, selection)
        t = read_vn_tables(raw, strict=True)
        assert t.binary_records == n and t.bytes_parsed == len(raw)
        (table,) = t.tables.values()
        for name in names:
            want = cols[name]
            if name.split(".")[1] in ("lat", "lon", "alt", *NANOS):
                np.testing.assert_allclose(table[name], want, rtol=1e-15, atol=1e-9)
            else:
                np.testing.assert_array_equal(table[name], want.astype(np.float32), err_msg=name)


def test_writer_errors_name_the_problem():
    with pytest.raises(ValueError, match="message must be one of"):
        imunoise.write_vn_ascii({"ypr": np.zeros((2, 3))}, "VNXXX")
    with pytest.raises(ValueError, match="lacks"):
        imunoise.write_vn_ascii({"ypr": np.zeros((2, 3))}, "VNYMR")
    with pytest.raises(ValueError, match="not finite"):
        imunoise.write_vn_ascii({"ypr": np.full((2, 3), np.nan)}, "VNYPR")
    with pytest.raises(ValueError, match="unknown field"):
        imunoise.write_vn_binary({}, {"common": ["Nope"]})


def test_old_writer_module_still_imports_with_a_warning(monkeypatch):
    import importlib
    import sys

    monkeypatch.delitem(sys.modules, "imunoise.readers.vn_write", raising=False)
    with pytest.warns(DeprecationWarning, match="imunoise.writers.vn"):
        old = importlib.import_module("imunoise.readers.vn_write")
    assert old.write_vn_ascii is imunoise.write_vn_ascii
    assert old.write_vn_binary is imunoise.write_vn_binary
