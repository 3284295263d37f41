"""imunoise record under sensor faults: one line naming the port, exit 2, no
traceback; the sensor left as it was found (its settings back, its output on);
every second lost kept in the metadata and LOG.gaps."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import imunoise
import numpy as np
import pytest
from helpers.fake_sensor import FACTORY
from imunoise.cli import main
from imunoise.readers.recording import outages


def run(argv, capsys) -> tuple[int, list[str]]:
    """Exit status and stderr lines of ``imunoise argv``."""
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err.splitlines()


def the_error(lines: list[str], *names: str) -> str:
    """The one error line (warnings may precede it), which names every one of
    ``names``; no traceback, nothing but imunoise's own lines."""
    assert not any("Traceback" in line for line in lines), lines
    assert all(line.startswith(("imunoise: error: ", "imunoise: warning: ")) for line in lines), \
        lines
    errors = [line for line in lines if line.startswith("imunoise: error: ")]
    assert len(errors) == 1, lines
    for name in names:
        assert name in errors[0], (name, errors[0])
    return errors[0]


def settled(fake) -> None:
    """Wait until the fake has taken in every command sent (none new for 0.2 s)."""
    seen, since = -1, time.monotonic()
    while time.monotonic() - since < 0.2:
        if len(fake.received) != seen:
            seen, since = len(fake.received), time.monotonic()
        time.sleep(0.01)


def left_as_found(fake) -> None:
    """Every register as the factory set it, and the output resumed last."""
    settled(fake)
    assert fake.registers == FACTORY
    assert fake.received and fake.received[-1] == "VNASY,1" and fake.streaming


def test_old_firmware_without_binary_outputs_records_ascii_with_a_note(fake_sensor, tmp_path,
                                                                       capsys):
    fake = fake_sensor(refuse={75, 76, 77})
    out = tmp_path / "old.txt"
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 1, "--rate", 20], capsys)
    assert code == 0, lines
    assert len(lines) == 1 and lines[0].startswith("imunoise: warning: registers 75, 76, 77")
    assert "invalid register (0x08)" in lines[0]
    meta = json.loads((tmp_path / "old.txt.meta.json").read_text())
    assert len(meta["notes"]) == 1 and "75, 76, 77" in meta["notes"][0]
    assert set(meta["previous"]) == {"30", "7", "6"} and meta["fs"] == 20
    assert fake.writes() == ["VNWRG,07,20", "VNWRG,07,40"]  # set, then set back
    left_as_found(fake)
    log = imunoise.read(out)
    assert log.fs == 20 and 10 <= len(log) <= 30 and log.messages["VNYMR"] == len(log)


def test_old_firmware_refuses_binary_before_anything_is_written(fake_sensor, tmp_path, capsys):
    fake = fake_sensor(refuse={75, 76, 77})
    out = tmp_path / "old.bin"
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 1,
                       "--binary", "200:common=TimeStartup+AngularRate"], capsys)
    assert code == 2
    the_error(lines, fake.path, "no binary outputs", "without --binary")
    assert len(lines) == 1  # the note is not said when nothing is recorded
    assert fake.writes() == []
    left_as_found(fake)
    assert list(tmp_path.glob("old.bin*")) == []


def _read_only_folder(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    return folder / "x.txt"


def _beside_a_side_file(tmp_path):
    (tmp_path / "x.txt.gaps").write_text("")  # left by another record
    return tmp_path / "x.txt"


def _inside_a_file(tmp_path):
    (tmp_path / "file").write_text("")
    return tmp_path / "file" / "x.txt"


@pytest.mark.parametrize("make, says", [
    (lambda t: t / "no" / "such" / "x.txt", "does not exist"),
    (lambda t: t, "is a folder"),
    (_beside_a_side_file, "never overwritten"),
    (_inside_a_file, "is not a folder"),
    pytest.param(_read_only_folder, "cannot create files", marks=pytest.mark.skipif(
        os.geteuid() == 0, reason="root writes in a read-only folder")),
    (lambda t: Path("/proc/x.txt"), "cannot create files"),  # a folder that takes none, root too
])
def test_an_output_that_cannot_be_written_leaves_the_sensor_untouched(fake_sensor, tmp_path,
                                                                      capsys, monkeypatch,
                                                                      make, says):
    monkeypatch.chdir(tmp_path)
    fake = fake_sensor()
    out = make(tmp_path)
    assert isinstance(out, os.PathLike)
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 1, "--rate", 20], capsys)
    assert code == 2
    the_error(lines, str(out), says)
    settled(fake)
    assert fake.received == []  # not one byte went to the sensor
    assert fake.registers == FACTORY


@pytest.mark.parametrize("behaviour, says", [
    ({"mute": True}, "nothing came"),
    ({"bad_checksums": True}, "none a valid reply"),
])
def test_no_reply_is_one_line_and_the_output_is_resumed(fake_sensor, tmp_path, capsys,
                                                        behaviour, says):
    fake = fake_sensor(**behaviour)
    out = tmp_path / "x.txt"
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 1, "--rate", 20], capsys)
    assert code == 2
    the_error(lines, fake.path, "no reply to $VNASY,0 within 2 s", says)
    settled(fake)
    assert fake.writes() == []
    assert fake.received[-1] == "VNASY,1"  # sent even to a sensor that never answered
    assert list(tmp_path.glob("x.txt*")) == []


def test_baud_auto_against_a_silent_sensor(fake_sensor, tmp_path, capsys):
    fake = fake_sensor(mute=True)
    code, lines = run(["record", fake.path, "-o", tmp_path / "x.txt", "--seconds", 1,
                       "--baud", "auto"], capsys)
    assert code == 2
    the_error(lines, fake.path, "no VN-100 answered at any baud rate tried", "115200", "9600")
    assert fake.writes() == []


def test_a_write_echoed_wrong_is_one_line_and_everything_is_restored(fake_sensor, tmp_path,
                                                                     capsys):
    # the sensor stores what it is sent but echoes another value, every time: the
    # setting fails, the restore cannot be confirmed (a warning), the resume is sent
    fake = fake_sensor(echo_wrong={7})
    code, lines = run(["record", fake.path, "-o", tmp_path / "x.txt", "--seconds", 1,
                       "--ascii", "VNIMU", "--rate", 20], capsys)
    assert code == 2
    the_error(lines, fake.path, "register 7: wrote 20 but the sensor echoed 21")
    warned = [line for line in lines if line.startswith("imunoise: warning: ")]
    assert len(warned) == 1 and "register 7" in warned[0] and "40" in warned[0]
    assert fake.writes() == ["VNWRG,07,20", "VNWRG,07,40"]  # 6 never written
    left_as_found(fake)


def test_an_error_after_a_write_restores_what_was_written(fake_sensor, tmp_path, capsys):
    # register 7 is written (20 Hz), then register 6 is refused: 7 must go back to 40
    fake = fake_sensor(error_on_write={6})
    code, lines = run(["record", fake.path, "-o", tmp_path / "x.txt", "--seconds", 1,
                       "--ascii", "VNIMU", "--rate", 20], capsys)
    assert code == 2 and len(lines) == 1
    the_error(lines, fake.path, "$VNWRG,06,19", "invalid parameter (0x07)")
    assert fake.writes()[:2] == ["VNWRG,07,20", "VNWRG,06,19"]
    assert "VNWRG,07,40" in fake.writes()[2:]
    left_as_found(fake)
    assert list(tmp_path.glob("x.txt*")) == []


@pytest.mark.parametrize("gone", ["silent", "hangup"])
def test_a_sensor_gone_for_good_ends_the_record_with_its_loss_kept(fake_sensor, tmp_path,
                                                                   capsys, gone):
    fake = fake_sensor(gone_after=1.0, gone=gone)
    out = tmp_path / "gone.txt"
    began = time.monotonic()
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 3,
                       "--outage-timeout", 0.5], capsys)
    took = time.monotonic() - began
    assert code == 2 and len(lines) == 1
    the_error(lines, fake.path, "went silent", "lost", "gone.txt.gaps")
    assert took < 3 + 2.5  # ended with --seconds (and one reconnection attempt)
    assert fake.gone
    meta = json.loads((tmp_path / "gone.txt.meta.json").read_text())
    assert meta["outages"] == 1 and meta["ended_in_outage"] is True
    (loss,) = meta["outage_list"]
    # the loss starts with the last byte before the sensor went and lasts to the end
    assert fake.gone_at - 0.2 <= loss["start"] <= fake.gone_at + 0.1  # bytes in flight
    end = meta["started"] + meta["seconds"]
    assert loss["end"] == pytest.approx(end, abs=0.3)
    assert loss["seconds"] == pytest.approx(loss["end"] - loss["start"], abs=1e-5)
    assert loss["seconds"] > 1.5
    assert loss["offset"] == meta["bytes"] == out.stat().st_size
    # the same outage in .gaps, as one that ended would be
    (kept,) = outages(out)
    assert (kept.offset, kept.start, kept.end) == (loss["offset"], loss["start"], loss["end"])
    # every second accounted for: what was recorded plus what was lost is the record
    log = imunoise.read(out)
    received = int(np.isfinite(log.gyro[:, 0]).sum())
    assert received / 40 + loss["seconds"] == pytest.approx(meta["seconds"], abs=0.3)


def _plain_file(tmp_path):
    (tmp_path / "plain").write_text("")
    return tmp_path / "plain"


@pytest.mark.parametrize("make, says", [
    (_plain_file, "not a serial port (a regular file)"),
    (lambda t: t, "not a serial port (a folder)"),
    (lambda t: "/dev/null", "not a serial port (a device that is not a terminal)"),
    (lambda t: t / "nothing", "no such port"),
])
def test_a_port_that_is_no_serial_port_is_named(tmp_path, capsys, make, says):
    port = make(tmp_path)
    code, lines = run(["record", port, "-o", tmp_path / "x.txt", "--seconds", 1], capsys)
    assert code == 2
    the_error(lines, str(port), says)
    assert not (tmp_path / "x.txt").exists()


def test_a_sensor_gone_for_good_with_settings_changed_says_they_stay(fake_sensor, tmp_path,
                                                                     capsys):
    fake = fake_sensor(gone_after=1.0, gone="hangup")
    out = tmp_path / "gone.txt"
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 2.5, "--rate", 20,
                       "--outage-timeout", 0.5], capsys)
    assert code == 2 and len(lines) == 1
    the_error(lines, fake.path, "lost", "its settings were not restored")
    meta = json.loads((tmp_path / "gone.txt.meta.json").read_text())
    assert meta["restored"] is False and meta["ended_in_outage"] is True
    assert any("not restored" in note for note in meta["notes"])


def test_a_sensor_silent_for_a_while_is_one_outage_and_the_record_goes_on(fake_sensor,
                                                                          tmp_path, capsys):
    # silent 1.2 s, then back: set up again, the silence one outage (not one per
    # reconnection), the record complete and the settings restored
    fake = fake_sensor(gone_after=1.0, back_after=1.2)
    out = tmp_path / "back.txt"
    code, lines = run(["record", fake.path, "-o", out, "--seconds", 4, "--rate", 20,
                       "--outage-timeout", 0.4], capsys)
    assert code == 0 and lines == []
    left_as_found(fake)
    meta = json.loads((tmp_path / "back.txt.meta.json").read_text())
    assert meta["outages"] == 1 and meta["ended_in_outage"] is False and meta["restored"]
    (loss,) = meta["outage_list"]
    assert fake.gone_at - 0.2 <= loss["start"] <= fake.gone_at + 0.1
    assert fake.back_at <= loss["end"] <= fake.back_at + 1.0  # the first byte after
    assert [(o.offset, o.start, o.end) for o in outages(out)] == [
        (loss["offset"], loss["start"], loss["end"])]
    log = imunoise.read(out)
    (gap,) = log.gaps.rows()
    assert gap[1] == pytest.approx(loss["seconds"], abs=2 / 20)
    received = int(np.isfinite(log.gyro[:, 0]).sum())  # the gap's samples are NaN rows
    assert received / 20 + loss["seconds"] == pytest.approx(meta["seconds"], abs=0.4)


def test_the_api_raises_sensor_lost_with_what_was_recorded(fake_sensor, tmp_path):
    from imunoise.recording import DeviceError, SensorLost, record

    fake = fake_sensor(gone_after=0.5, gone="hangup")
    with pytest.raises(SensorLost, match="lost") as info:
        record(fake.path, tmp_path / "api.txt", seconds=2, outage_timeout=0.3)
    assert isinstance(info.value, DeviceError)
    rec = info.value.recording
    assert rec.bytes == (tmp_path / "api.txt").stat().st_size > 0
    assert len(rec.outages) == 1 and rec.outages[0].offset == rec.bytes
    assert rec.outages[0].seconds > 1.0
