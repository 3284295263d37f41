# ruff: noqa: E501  (protocol test vectors are quoted verbatim)
"""The VN-100 protocol spec's test vectors (vn100-protocol.md §7)."""

import imunoise
import numpy as np
import pytest
from imunoise.readers.vn import read_vn_tables

A = {
    "A1": b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69",
    "A6": b"$VNQMR,+0.021375,-0.049923,+0.797361,-0.601055,-0.2354,+0.8029,+1.8875,+00.795,-00.412,-09.709,-00.0201,-00.0055,-00.0149*76",
    "A7": b"$VNQMR,+0.004183,+0.001149,+0.089285,+0.995997,+00.0113,-00.2384,+00.1800,+00.020,-00.092,-09.683,-00.000272,+00.000824,+00.000073,T0000000543*3D",
    "A8": b"$VNIMU,-00.0350,+00.4222,-00.6643,-00.015,+00.019,+09.948,+00.002066,-00.008442,-00.044656,+20.7,+084.322*66",
    "A9": b"$VNYBA,+059.745,+003.857,-004.949,+00.001,-00.008,+00.150,+00.000478,-00.000896,-00.001366*5B",
    "A10": b"$VNYPR,+010.071,+000.278,-002.026*60",
    "A13": b"$VNRRG,9,-0.017386,-0.000303,+0.055490,+0.998308*4F",
    "A16": b"$VNRRG,80,+0.665016,-000.119,-000.409,-000.025,+000.011,-000.084,-006.702*6A",
}

MUST_REJECT = [
    b"$VNQMR,-0.017057,-0.000767,+0.056534,+0.998255,+1.0670,-0.2568,+3.0696,-00.019,+00.320,-09.802,-0.002801,-0.001186,-0.001582*65",
    b"$VNRRG,20,+1.0684,-0.2578,+3.0649,-00.005,+00.341,-09.780,-0.0.000840,-0.000466*64",
    b"$VNERR,12*72",
]


def hexbytes(s: str) -> bytes:
    return bytes.fromhex(s.replace("|", " "))


B1 = hexbytes(
    "FA 01 09 00 | 70 05 00 03 0A 00 00 00 | 48 0E 2C 42 08 4C 37 C1 10 38 8B C2 | D4 CB"
)
B2 = hexbytes(
    "FA 01 28 05 A8 02 C3 3F E7 89 B0 42 3D A9 6A C1 D0 83 54 3A 92 3E 0B BB 1C 25 30 BA"
    " 04 7D 1C 41 3B B2 83 3D 4E EA 9C BE F1 BD 93 BE A4 55 8C BD 26 C7 77 3E F4 28 E6 41"
    " 57 CE C1 42 C0 E9"
)
C = hexbytes(
    "fa 01 00 3e cd cc 4c 3d 8f c2 f5 bc cd cc 1c c1 52 49 9d 3a 17 b7 d1 b9 34 80 37 3a"
    " 3d 0a 57 3e 0a d7 a3 3c 66 66 e6 3e 00 00 cc 41 66 a6 ca 42"
    " cd cc cc 3c 89 d2 de 3a 52 49 1d ba 6f 12 83 3a 52 49 9d 3a 17 b7 51 ba 48 e1 7a be"
    " 02 00 2a 00 00 00 8c bd"
)


def test_a1_decoded_values():
    log = imunoise.read(A["A1"] + b"\r\n", fs=40)
    assert log.format == "vn-ascii"
    assert log.messages == {"VNYMR": 1}
    np.testing.assert_array_equal(log.ypr[0], [100.949, -7.330, 0.715])
    np.testing.assert_array_equal(log.mag[0], [-0.0049, -0.2449, 0.5397])
    np.testing.assert_array_equal(log.accel[0], [-1.258, -0.100, -9.701])
    np.testing.assert_array_equal(log.gyro[0], [-0.000018, 0.001122, -0.000551])
    assert log.issues.total == 0


def test_every_valid_sentence_decodes():
    data = b"\r\n".join(A.values()) + b"\r\n"
    t = read_vn_tables(data)
    assert t.issues.total == 0 and t.bytes_skipped == 0
    assert t.messages == {"VNYMR": 1, "VNQMR": 2, "VNIMU": 1, "VNYBA": 1, "VNYPR": 1,
                          "VNQTN": 1, "VNDTV": 1}
    np.testing.assert_array_equal(t.tables["VNQMR"]["serial_count"], [np.nan, 543.0])
    imu = t.tables["VNIMU"]
    assert imu["temperature"][0] == 20.7 and imu["pressure"][0] == 84.322
    dtv = t.tables["VNDTV"]
    assert dtv["delta_time"][0] == 0.665016 and dtv["delta_vel_z"][0] == -6.702
    assert t.tables["VNQTN"]["qw"][0] == 0.998308


@pytest.mark.parametrize("line", MUST_REJECT)
def test_must_reject(line):
    t = read_vn_tables(line + b"\r\n")
    assert t.ascii_records == 0
    assert t.issues.total == 1
    with pytest.raises(ValueError, match="line 1"):
        read_vn_tables(line + b"\r\n", strict=True)


def test_crc16_sentences():
    text = (
        b"$VNRRG,15*92EA\r\n$VNRRG,54*4E0F\r\n$VNRRG,01*E15F\r\n$VNWRG,06,14*1CB5\r\n"
        b"$VNWRG,07,40*D570\r\n$VNWRG,06,14*59\r\n"
        + A["A1"][:-3]
        + b"*C251\r\n"
    )
    t = read_vn_tables(text, strict=True)
    assert t.messages == {"VNRRG": 3, "VNWRG": 3, "VNYMR": 1}
    bad = text.replace(b"*C251", b"*C252")
    assert read_vn_tables(bad).issues.counts["bad_checksum"] == 1


def test_appended_status_and_count():
    text = (
        b"$VNYPR,+010.071,+000.278,-002.026*60\r\n"
        b"$VNYPR,+010.071,+000.278,-002.026,T1162704*2F\r\n"
        b"$VNYPR,+010.071,+000.278,-002.026,S0000*1F\r\n"
    )
    t = read_vn_tables(text, strict=True)
    ypr = t.tables["VNYPR"]
    np.testing.assert_array_equal(ypr["serial_count"], [np.nan, 1162704, np.nan])
    np.testing.assert_array_equal(ypr["status"], [np.nan, np.nan, 0])


def test_device_error_recorded():
    t = read_vn_tables(b"$VNERR,03*72\r\n$VNWNV*57\r\n$VNRFS*5F\r\n$VNRST*4D\r\n")
    assert t.issues.counts["device_error"] == 1
    assert t.tables["VNERR"]["code"][0] == 3
    assert t.messages == {"VNWNV": 1, "VNRFS": 1, "VNRST": 1}


def test_binary_b1_b2_c():
    log = imunoise.read(B1, fs=40)
    assert log.format == "vn-binary"
    assert log.time[0] == pytest.approx(43.000006, abs=1e-12)
    np.testing.assert_allclose(log.ypr[0], [43.013947, -11.456062, -69.609497], atol=2e-6)
    t = read_vn_tables(B2)
    (cols,) = t.tables.values()
    np.testing.assert_allclose(
        [cols["common.gyro_x"][0], cols["common.accel_x"][0], cols["common.mag_z"][0]],
        [0.00081068, 9.780521, 0.241971],
        atol=5e-7,
    )
    assert cols["common.temperature"][0] == pytest.approx(28.769997, abs=1e-5)
    assert cols["common.pressure"][0] == pytest.approx(96.903008, abs=1e-5)
    t = read_vn_tables(C)
    (cols,) = t.tables.values()
    assert cols["common.vpe_status"][0] == 2 and cols["common.syncin_count"][0] == 42
    assert cols["common.delta_time"][0] == pytest.approx(0.025)
    assert cols["common.delta_vel_z"][0] == pytest.approx(-0.245)


def test_manual_b4_is_rejected_and_corrected_accepted():
    b4 = hexbytes("FA 05 08 00 01 00 A4 15 02 42 4D DF EB 3F F6 1A 36 BE BF 2D A4 41 A8 3A")
    assert read_vn_tables(b4).binary_records == 0
    fixed = hexbytes("FA 05 08 00 10 00 A4 15 02 42 4D DF EB 3F F6 1A 36 BE BF 2D A4 41 AF 1A")
    (cols,) = read_vn_tables(fixed).tables.values()
    assert cols["imu.temperature"][0] == pytest.approx(20.522337, abs=1e-5)
