"""Every reader brings the temperature of the sources that carry it (VN sentences
$VNIMU/$VNYCM/$VNCMV, VN binary IMU group, CSV columns; ROS: tests/readers)."""

import warnings
from functools import reduce

import imunoise
import numpy as np
import pytest
from helpers.data import DATA


def sentence(body: str) -> bytes:
    checksum = reduce(lambda a, b: a ^ b, body.encode(), 0)
    return f"${body}*{checksum:02X}\r\n".encode()


@pytest.mark.parametrize(("message", "before", "after"), [
    ("VNIMU", 9, 1),   # mag, accel, gyro, temperature, pressure
    ("VNYCM", 12, 0),  # ypr, mag, accel, gyro, temperature
    ("VNCMV", 9, 0),   # mag, accel, gyro, temperature
])
def test_vn_sentences_with_temperature(message, before, after):
    temps = 25.0 + np.arange(30) * 0.1
    data = b"".join(
        sentence(",".join([message, *["0.1"] * before, f"{t:.2f}", *["101.3"] * after]))
        for t in temps)
    log = imunoise.read(data, fs=40.0)
    np.testing.assert_allclose(log.temperature, temps)


def test_vn_binary_imu_group_temperature():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = imunoise.read(DATA / "waves_F00294.bin", fs=10.0)
    assert log.temperature is not None
    assert np.all((log.temperature > -40) & (log.temperature < 85))


def test_csv_temperature_column(tmp_path):
    path = tmp_path / "log.csv"
    rows = ["time,gyro_x,gyro_y,gyro_z,temperature"]
    rows += [f"{i / 100:.2f},0.1,0.2,0.3,{20 + i / 100:.2f}" for i in range(50)]
    path.write_text("\n".join(rows) + "\n")
    log = imunoise.read(path)
    np.testing.assert_allclose(log.temperature, 20 + np.arange(50) / 100)


def test_csv_with_raw_vn_sentences_keeps_their_temperature(tmp_path):
    """A CSV exported from a ROS bag with the raw sentence in a column (the lab-driver
    layout): the sentence's temperature reaches the log (ROS VN topics share this path)."""
    temps = 25 + np.arange(30) / 10
    rows = ["t,raw"] + [
        f'{i / 40:.3f},"' + sentence(",".join(["VNIMU", *["0.1"] * 9, f"{t:.2f}", "101.3"]))
        .decode().strip() + '"'
        for i, t in enumerate(temps)]
    path = tmp_path / "raw.csv"
    path.write_text("\n".join(rows) + "\n")
    log = imunoise.read(path)
    np.testing.assert_allclose(log.temperature, temps)
