"""imunoise record / emulate / plan on the command line: errors are one line, exit 2."""

from __future__ import annotations

import pytest
from imunoise.cli import main


@pytest.mark.parametrize("argv, message", [
    (["record", "/nonexistent/port", "-o", "x.vn", "--seconds", "1"], "/nonexistent/port"),
    (["record", "p", "-o", "x.vn", "--binary", "800"], "--binary must be HZ:FIELDS"),
    (["record", "p", "-o", "x.vn", "--binary", "300:common=TimeStartup"],
     "800 Hz divided by a whole number"),
    (["record", "p", "-o", "x.vn", "--binary", "800:common=Bogus"], "'Bogus' is not in group"),
    (["record", "p", "-o", "x.vn", "--baud", "fast"], "--baud must be a number or 'auto'"),
    (["record", "p", "-o", "x.vn", "--rate", "33"], "rate must be one of"),
    (["plan", "--target", "2"], "argument --target: must be in (0, 1); got '2'"),
    (["emulate", "p", "--fault", "melt@1"], "fault kind must be one of"),
    # bounds said before anything is written to a sensor or a port made
    (["record", "p", "-o", "x.vn", "--binary", "1e-300:common=TimeStartup"],
     "binary rate must be 800 Hz divided by a whole number from 1 to 65535"),
    (["record", "p", "-o", "x.vn", "--binary", "800:common=0x10029"],
     "mask of group common must be within 0x0001 ... 0xFFFF (16 bits); got 0x10029"),
    (["record", "p", "-o", "x.vn", "--binary", "nan:common=TimeStartup"], "got nan"),
    (["record", "p", "-o", "x.vn", "--outage-timeout", "0"], "--outage-timeout"),
    (["emulate", "p", "--speed", "1e300"], "--speed must be at most 1000"),
    (["emulate", "p", "--speed", "inf"], "--speed: expected a positive number"),
    (["emulate", "p", "--speed", "0"], "--speed: expected a positive number"),
    (["emulate", "p", "--fault", "vanish@1:1e300"], "seconds within (0, 3.1536e+07]"),
    (["emulate", "p", "--fault", "corrupt@inf"], "fault time must be within 0"),
    (["record", "p", "-o", "x.vn", "--hours", "1e306"], "--hours is too large"),
])
def test_errors_are_one_line_with_status_2(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("imunoise: error: ") and "\n" not in err and message in err
    assert list(tmp_path.iterdir()) == []  # no log begun for a port that is not there


def test_record_from_the_emulator_and_plan(emulator, tmp_path, capsys):
    emu = emulator(speed=10, seed=8)
    out = tmp_path / "cli.vn"
    assert main(["record", emu.path, "-o", str(out), "--seconds", "1", "--ascii", "VNYMR",
                 "--rate", "100"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("recorded ") and "restored" in text and "\x1b[" not in text
    assert out.stat().st_size > 0 and emu.registers[7] == (40,)
    assert main(["plan", "--spec", "vn100", "--sensor", "gyro"]) == 0
    assert "needs N" in capsys.readouterr().out


def test_a_wrong_baud_rate_is_one_line_naming_the_port(emulator, tmp_path, capsys):
    # the emulator at 57600 Bd sends what a 115200 Bd reader sees: garbage, no reply
    emu = emulator(speed=5, seed=12, baud=57600)
    before = emu.registers
    out = tmp_path / "x.vn"
    assert main(["record", emu.path, "-o", str(out), "--seconds", "1", "--rate", "20"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("imunoise: error: ") and "\n" not in err and "Traceback" not in err
    assert emu.path in err and "no reply to $VNASY,0" in err and "wrong baud rate?" in err
    assert emu.registers == before and list(tmp_path.glob("x.vn*")) == []
