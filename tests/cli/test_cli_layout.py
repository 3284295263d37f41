"""Headerless text logs: the layout options of read() and of the CLI, and the error
that shows the first row with a columns= example built from it."""

import imunoise
import numpy as np
import pytest
from imunoise.cli import main

FS = 50.0


@pytest.fixture(scope="module")
def headerless(tmp_path_factory):
    """Whitespace columns, no header, no time: attitude, accel (m/s²), gyro (deg/s),
    temperature, like the IG-500N log of the issue."""
    rng = np.random.default_rng(4)
    n = 6000
    ypr = rng.normal([10.0, 1.0, -2.0], 0.01, (n, 3))
    accel = rng.normal([0.0, 0.0, -9.8], 0.01, (n, 3))
    gyro_deg = rng.normal(0.0, 0.05, (n, 3))
    temp = 35.0 + np.arange(n) / n
    path = tmp_path_factory.mktemp("layout") / "still.txt"
    np.savetxt(path, np.column_stack([ypr, accel, gyro_deg, temp]), fmt="%.6f",
               delimiter="\t")
    return path, gyro_deg, temp


def test_read_takes_the_layout(headerless):
    path, gyro_deg, temp = headerless
    log = imunoise.read(path, fs=FS, columns={"gyro": [6, 7, 8], "accel": [3, 4, 5],
                                              "temperature": 9}, units={"gyro": "deg/s"})
    np.testing.assert_allclose(log.gyro, np.radians(np.round(gyro_deg, 6)), rtol=1e-12)
    np.testing.assert_allclose(log.temperature, np.round(temp, 6))
    assert log.format == "csv" and log.fs == FS


def test_layout_with_another_format_is_an_error(headerless):
    path, _, _ = headerless
    with pytest.raises(ValueError, match="format must be 'auto' or 'csv'.*'vn-ascii'"):
        imunoise.read(path, format="vn-ascii", columns={"gyro": [6, 7, 8]})


def test_unrecognised_columns_show_the_first_row_and_an_example(headerless):
    path, _, _ = headerless
    with pytest.raises(ValueError) as err:
        imunoise.read(path, fs=FS)
    text = str(err.value)
    assert "no IMU columns recognised in 10 unnamed columns" in text
    assert "first data row: [0] " in text and "[9] 35.000000" in text
    assert "columns={'gyro': [0, 1, 2], 'accel': [3, 4, 5]}" in text
    assert "--columns gyro=0,1,2 --columns accel=3,4,5" in text


def test_cli_commands_take_the_layout(headerless, capsys):
    path, _, _ = headerless
    layout = ["--fs", str(FS), "--columns", "gyro=6,7,8", "--columns", "accel=3,4,5",
              "--units", "gyro=deg/s"]
    assert main(["stats", str(path), *layout]) == 0
    out = capsys.readouterr().out
    assert "gyro X" in out and "accel Z" in out
    assert main(["fit", str(path), "--sensor", "gyro", *layout]) == 0
    assert "angle random walk" in capsys.readouterr().out
    assert main(["adev", str(path), *layout]) == 0


def test_cli_report_takes_the_layout(headerless, tmp_path, capsys):
    path, _, _ = headerless
    out = tmp_path / "rep"
    code = main(["report", str(path), "-o", str(out), "--fs", str(FS), "--no-progress",
                 "--columns", "gyro=6,7,8", "--columns", "accel=3,4,5", "--columns",
                 "ypr=0,1,2", "--units", "gyro=deg/s", "--spec", "none"])
    assert code == 0
    md = (out / "report.md").read_text()
    assert "Attitude (yaw, pitch, roll)" in md and "Allan deviation of gyro" in md


@pytest.mark.parametrize("bad", ["gyro", "gyr=1,2,3", "gyro="])
def test_cli_rejects_a_bad_assignment_in_one_line(bad, headerless, capsys):
    path, _, _ = headerless
    assert main(["stats", str(path), "--columns", bad]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--columns" in err[0]
