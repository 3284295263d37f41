"""imunoise.record against the emulated VN-100: lossless, faults in place, config."""

from __future__ import annotations

import io

import imunoise
import numpy as np
import pytest
from helpers.emulator import FULL, record_slice, stop_after
from imunoise.emulate import Fault
from imunoise.readers.recording import host_times, outages
from imunoise.recording import DeviceError, binary_output, record

IMU_RATE = 800


def test_ten_minutes_recorded_byte_identical_and_settings_restored(emulator, tmp_path):
    """10 min of 800 Hz binary + 200 Hz ASCII, time-compressed."""
    emu = emulator(speed=200, seed=1)
    before = emu.registers
    out = tmp_path / "still.vn"
    rec = record(emu.path, out, stop=stop_after(emu, 600), ascii="VNYMR", rate=200,
                 binary=[binary_output(800, FULL)], live=True, live_stream=io.StringIO())
    raw = out.read_bytes()
    assert raw == record_slice(emu)  # everything sent while recording, nothing else
    assert rec.bytes == len(raw) > 40_000_000
    assert rec.identity["model"] == "VN-100T-CR" and rec.restored
    # every register written was verified (else record raises); the old ones are back
    assert rec.settings[75][:2] == ("1", "1") and rec.settings[7] == ("200",)
    assert emu.registers == before
    log = imunoise.read(out)
    assert log.messages["VNYMR"] > 0 and log.time is not None
    assert log.issues.total == 0 and len(log.gaps) == 0
    assert log.messages["VNYMR"] * 4 == pytest.approx(len(log), abs=8)  # 200 Hz beside 800 Hz
    assert log.duration >= 600
    # the live view parsed a copy of the same stream: same samples, same ADEV (its
    # AllanStream, fed a second at a time, against the whole record's)
    snap = rec.snapshot
    np.testing.assert_array_equal(snap.gyro, log.gyro)
    _same_adev(snap.adev, imunoise.adev(log.gyro, log.fs))
    assert snap.dropped == 0
    # the host receive times: one line per chunk, offsets increasing from 0 within the log
    offsets, seconds = host_times(out)
    assert offsets[0] == 0 and np.all(np.diff(offsets) > 0) and offsets[-1] < len(raw)
    assert np.all(np.diff(seconds) >= 0) and len(seconds) == len(offsets)


def test_injected_faults_appear_in_issues_and_gaps_at_their_place(emulator, tmp_path):
    faults = [Fault("corrupt", 1.0), Fault("pause", 2.0, 0.5), Fault("reset", 3.0)]
    emu = emulator(speed=20, seed=2, faults=faults)
    out = tmp_path / "faults.vn"
    record(emu.path, out, seconds=2.5, ascii="off", binary=[binary_output(400, FULL)])
    start = [e.offset for e in emu.events if e.kind == "asy1"][0]
    events = {e.kind: e for e in emu.events}
    assert set(events) >= {"corrupt", "pause", "reset"}, "record too short for the faults"
    with pytest.warns(UserWarning, match="time_reset"):
        log = imunoise.read(out)
    issues = log.issues
    assert issues.counts["bad_checksum"] == 1
    assert issues.first["bad_checksum"] == (events["corrupt"].offset - start,)  # byte offset
    assert issues.counts["time_reset"] == 1
    step = IMU_RATE // 400
    first_tick = round(log.time[0] * IMU_RATE)
    reset_tick = -(-events["reset"].tick // step) * step
    decoded_before = (reset_tick - first_tick) // step - 1 - 200  # less the damaged and paused
    assert issues.first["time_reset"] == (decoded_before + 1,)
    # on the grid: the damaged packet is one missing sample, the pause 0.5 s of them
    rows = log.gaps.rows()
    assert [g[2] for g in rows] == [1, 200]
    for (start_s, _, _), kind in zip(rows, ("corrupt", "pause"), strict=True):
        tick = -(-events[kind].tick // step) * step  # the first packet the fault touches
        assert start_s == pytest.approx(tick / IMU_RATE, abs=1e-6)


def test_vanishing_port_is_one_gap_of_its_length(emulator, tmp_path):
    emu = emulator(speed=10, seed=3, faults=[Fault("vanish", 1.0, 2.0)])
    out = tmp_path / "vanish.vn"
    rec = record(emu.path, out, seconds=2.5, ascii="off", binary=[binary_output(200, FULL)],
                 live=True, live_stream=io.StringIO())
    assert len(rec.outages) == 1 and outages(out) == list(rec.outages)
    assert rec.outages[0].offset > 0
    log = imunoise.read(out)
    assert len(log.gaps) == 1 and log.issues.total <= 1  # a packet cut by the hang-up
    # the truth: the ticks the recorder never got = the vanish (2 s) plus the pause
    # while it set the sensor up again (ASY,0 ... ASY,1 after reconnecting)
    gone = next(e.tick for e in emu.events if e.kind == "vanish")
    back = [e.tick for e in emu.events if e.kind == "asy1"][1]
    step = IMU_RATE // 200
    expected = (-(-back // step) - -(-gone // step))  # samples of ticks [gone, back)
    assert log.gaps.samples[0] == pytest.approx(expected, abs=1)
    assert log.gaps.samples[0] >= 2 * 200
    assert rec.snapshot.outages == 1 and rec.snapshot.dropped == log.gaps.total
    # the dropped samples are a gap of the live ADEV, skipped as adev skips the log's
    assert rec.snapshot.adev.missing[0] == log.gaps.total
    _same_adev(rec.snapshot.adev, imunoise.adev(log.gyro, log.fs, gaps="skip"))


def _same_adev(live, whole):
    """The live view's curve is the whole record's, at every tau it has (the stream
    keeps octave taus with two terms: it may lack the last)."""
    k = len(live.taus)
    assert k >= len(whole.taus) - 1
    np.testing.assert_array_equal(live.m, whole.m[:k])
    np.testing.assert_array_equal(live.n, whole.n[:k])
    np.testing.assert_allclose(live.dev, whole.dev[:k], rtol=1e-9)
    np.testing.assert_allclose(live.taus, whole.taus[:k], rtol=1e-6)


def test_outage_of_an_ascii_log_without_timestamps_comes_from_the_side_file(tmp_path):
    sentences = imunoise.write_vn_ascii({"gyro": np.zeros((100, 3)), "accel": np.zeros((100, 3)),
                                         "mag": np.zeros((100, 3)), "ypr": np.zeros((100, 3))})
    cut = sentences.index(b"$VN", len(sentences) // 2)
    out = tmp_path / "ascii.vn"
    out.write_bytes(sentences)
    (tmp_path / "ascii.vn.meta.json").write_text('{"fs": 40}')
    assert len(imunoise.read(out).gaps) == 0
    (tmp_path / "ascii.vn.gaps").write_text(f"{cut} 1000.0 1002.0\n")
    log = imunoise.read(out)
    assert log.fs == 40 and len(log) == 100 + 79
    assert log.gaps.rows() == [(50 / 40, 79 / 40, 79)]


def test_errors_of_the_sensor_are_named_and_nothing_is_left_changed(emulator, tmp_path):
    emu = emulator(speed=5, seed=4)
    before = emu.registers
    with pytest.raises(DeviceError, match=r"invalid parameter \(0x07\)"):
        record(emu.path, tmp_path / "x.vn", seconds=1, rate=200,
               binary=[binary_output(100, "common=TimeStartup+Position")])
    assert emu.registers == before


def test_settings_that_silence_the_sensor_are_refused_and_it_streams_on(emulator, tmp_path):
    emu = emulator(speed=5, seed=11)
    before = emu.registers
    with pytest.raises(ValueError, match="nothing to record"):
        record(emu.path, tmp_path / "silent.vn", seconds=1, ascii="off")
    assert emu.registers == before and emu.events[-1].kind == "asy1"  # resumed
    assert not (tmp_path / "silent.vn").exists()


def test_keep_config_leaves_the_settings_and_baud_auto_finds_the_rate(emulator, tmp_path):
    emu = emulator(speed=5, seed=5, baud=57600)
    rec = record(emu.path, tmp_path / "k.vn", seconds=0.5, baud="auto", ascii="VNIMU",
                 rate=100, crc=True, keep_config=True, live_stream=io.StringIO())
    regs = emu.registers
    assert regs[6] == (19,) and regs[7] == (100,) and regs[30][4] == 3 and not rec.restored
    log = imunoise.read(rec.path)
    assert log.messages.get("VNIMU", 0) > 10 and log.issues.total == 0
    assert log.fs == 100  # from the recording's metadata


def test_live_view_is_quiet_when_not_a_terminal(emulator, tmp_path):
    emu = emulator(speed=5, seed=6)
    stream = io.StringIO()
    rec = record(emu.path, tmp_path / "q.vn", seconds=1.2, live_stream=stream)
    assert stream.getvalue() == "" and rec.snapshot is None
    shown = io.StringIO()
    record(emu.path, tmp_path / "s.vn", seconds=1.2, live=True, live_stream=shown)
    assert "samples" in shown.getvalue()


def test_an_existing_output_is_refused(emulator, tmp_path):
    emu = emulator()
    out = tmp_path / "there.vn"
    out.write_bytes(b"keep me")
    with pytest.raises(FileExistsError):
        record(emu.path, out, seconds=1)
    assert out.read_bytes() == b"keep me"


def test_ctrl_c_ends_the_record_cleanly_without_losing_a_byte(emulator, tmp_path):
    import os
    import signal
    import threading

    emu = emulator(speed=20, seed=10)
    out = tmp_path / "interrupted.vn"

    def interrupt() -> None:
        while not out.exists() or out.stat().st_size < 50_000:
            threading.Event().wait(0.02)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt, daemon=True).start()
    rec = record(emu.path, out, binary=[binary_output(800, FULL)])
    assert rec.restored and out.read_bytes() == record_slice(emu)
