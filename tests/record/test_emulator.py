"""The emulator answers like a VN-100: checked replies, $VNERR codes for bad input."""

from __future__ import annotations

import pytest
from imunoise.recording.protocol import crc16, error_name, parse_reply, sentence
from imunoise.recording.session import Session, open_port


def test_checksums_match_the_protocol_vectors():
    assert crc16(b"123456789") == 0x31C3
    assert sentence("VNRRG,30,0,0,0,0,1,0,1") == b"$VNRRG,30,0,0,0,0,1,0,1*6C\r\n"
    assert sentence("VNERR,03") == b"$VNERR,03*72\r\n"
    assert parse_reply(b"$VNYPR,+010.071,+000.278,-002.026*60\r\n").fields[0] == "+010.071"
    assert parse_reply(b"$VNYPR,+010.071,+000.278,-002.026*61\r\n") is None
    assert parse_reply(sentence("VNRRG,15", crc=True)).header == "VNRRG"


@pytest.mark.parametrize("raw, code", [
    (b"$VNRRG,01*00\r\n", 0x03),                 # bad checksum
    (b"$VNFOO*XX\r\n", 0x04),                    # unknown command
    (b"$VNRRG,99*XX\r\n", 0x08),                 # no such register
    (b"$VNWRG,01,VN-200*XX\r\n", 0x09),          # identity is read-only
    (b"$VNWRG,07,33*XX\r\n", 0x07),              # not a rate register 7 takes
    (b"$VNWRG,30,0,0,0*XX\r\n", 0x05),           # register 30 has 7 fields
])
def test_bad_input_gets_its_vnerr(emulator, raw, code):
    emu = emulator(seed=9)
    port = open_port(emu.path, 115200)
    try:
        session = Session(port)
        session.command("VNASY,0")
        port.write(raw)
        received = bytearray()
        errors: list[int] = []
        for _ in range(500):  # until the reply is in (give up after 10 s)
            received += port.read(4096)
            replies = [parse_reply(line) for line in bytes(received).split(b"\n")[:-1]]
            errors = [r.error for r in replies if r is not None and r.error is not None]
            if errors:
                break
        assert errors == [code], (error_name(code), bytes(received[-300:]))
    finally:
        port.close()


def _emitted(seconds: float, **registers):
    """What the emulated sensor sends in ``seconds`` of sensor time with the
    register values given (no port: the encoder itself), read back."""
    from imunoise.emulate.outputs import SampleSource, encode
    from imunoise.emulate.registers import Registers
    from imunoise.readers.vn import read_vn

    regs = Registers()
    for reg, value in registers.items():
        regs.values[int(reg[1:])] = value
    records = encode(regs, SampleSource(3), 0, round(seconds * 800))
    return read_vn(b"".join(records), fs=float(regs.values[7][0]))


@pytest.mark.parametrize("rate", [40, 200])
def test_emitted_white_noise_has_the_datasheets_density_at_the_output_rate(rate):
    # 800 Hz samples decimated without averaging made the density sqrt(800/rate) too
    # high (4.5x at 40 Hz); averaged to the output rate it is the datasheet's. At
    # tau = 0.25 s the white noise dominates (bias instability adds ~3 %).
    import imunoise
    import numpy as np

    log = _emitted(300, r7=(rate,))
    for sensor, density in (("gyro", np.radians(0.0035)), ("accel", 0.14e-3 * 9.80665)):
        dev = imunoise.adev(getattr(log, sensor), log.fs, taus=np.array([0.25])).dev[0]
        measured = dev * np.sqrt(0.25)
        np.testing.assert_allclose(measured, density, rtol=0.12, err_msg=sensor)


def test_attitude_and_field_move_like_a_still_sensors():
    # constant before; now small noise and slow wander around the constant, no jumps
    import numpy as np

    log = _emitted(200, r7=(40,))
    ypr, mag = np.asarray(log.ypr), np.asarray(log.mag)
    assert np.all(ypr.std(axis=0) > 0.002) and np.all(ypr.std(axis=0) < 0.1)  # deg
    assert np.all(np.ptp(ypr, axis=0) < 0.5)
    np.testing.assert_allclose(ypr.mean(axis=0), (-77.7, -1.3, 0.15), atol=0.05)
    assert np.all(mag.std(axis=0) > 1e-4) and np.all(mag.std(axis=0) < 5e-3)  # Gauss
    np.testing.assert_allclose(mag.mean(axis=0), (0.045, 0.247, -0.338), atol=1e-3)
    # wander: the 10 s means move more than white noise alone would move them
    tens = ypr[: len(ypr) // 400 * 400].reshape(-1, 400, 3).mean(axis=1)
    assert np.all(tens.std(axis=0) > ypr.std(axis=0) / np.sqrt(400))


@pytest.mark.parametrize("speed", [0, -1, float("nan"), float("inf"), 1e300, 1001])
def test_speed_outside_its_bounds_is_refused_before_the_port_appears(tmp_path, speed):
    from imunoise.emulate import Emulator

    with pytest.raises(ValueError, match=r"speed must be .* in \(0, 1000\]"):
        Emulator(tmp_path / "port", speed=speed)
    assert not (tmp_path / "port").exists()


def test_a_sensor_thread_that_dies_is_an_error_not_a_quiet_exit(tmp_path, monkeypatch, capsys):
    # --speed 1e300 once overflowed the clock inside the thread: the command waited on
    # and exited 0 with a port that no longer answered
    from imunoise.cli import main
    from imunoise.emulate import device

    def overflow(self) -> None:
        raise OverflowError("cannot convert float infinity to integer")

    monkeypatch.setattr(device.Emulator, "_step", overflow)
    assert main(["emulate", str(tmp_path / "port"), "--seconds", "10"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("imunoise: error: the emulated sensor on ") and "\n" not in err
    assert "stopped: cannot convert float infinity to integer" in err
    assert not (tmp_path / "port").exists()  # the port is removed on the way out


def test_the_quaternion_is_the_attitude_of_the_yaw_pitch_roll_beside_it():
    import numpy as np
    from imunoise.emulate.outputs import SampleSource
    from scipy.spatial.transform import Rotation

    out = SampleSource(4).take(np.arange(19, 800 * 60, 20), 20)
    expected = Rotation.from_euler("ZYX", out["ypr"], degrees=True).as_quat()  # x, y, z, w
    np.testing.assert_allclose(out["quaternion"], expected, atol=1e-12)
    assert np.ptp(out["quaternion"], axis=0).max() > 1e-5  # moves with them
