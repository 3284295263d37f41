"""Streams are first-class: stdin, pipes and FIFOs are read once, start to end, with
the same result as the file; ``-`` is stdin in every command (issue #24 item 1)."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import threading
from pathlib import Path

import imunoise
import pytest
from helpers.data import DATA
from helpers.same_log import assert_same_log
from imunoise import scale
from imunoise.cli import main

VN_LOG = Path(imunoise.__file__).parent / "data" / "vn100_stationary_5min.txt"
CSV_LOG = DATA / "vn100-csv" / "stationary_data_5min_0.csv"
PYTHON = Path(imunoise.__file__).parents[1]


def _stdin(monkeypatch, data: bytes) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(data)))


@pytest.mark.parametrize(("log", "fs"), [(VN_LOG, 40.0), (CSV_LOG, None),
                                         (DATA / "waves_F00294.bin", 40.0),
                                         (DATA / "rugged_0513test.txt", 40.0)])
def test_a_stream_reads_as_the_file(log, fs):
    with open(log, "rb") as f:
        from_stream = imunoise.read(f, fs=fs)
    assert from_stream.source == str(log)  # named by the file object's name
    assert_same_log(from_stream, imunoise.read(log, fs=fs))
    anonymous = imunoise.read(io.BytesIO(log.read_bytes()), fs=fs)
    assert anonymous.source == "<stream>"
    assert_same_log(anonymous, imunoise.read(log, fs=fs))


def test_a_csv_through_a_pipe_keeps_its_header():
    log = imunoise.read(io.BytesIO(CSV_LOG.read_bytes()))
    assert log.format == "csv" and log.time is not None
    assert len(log) == 13223 and round(log.fs, 4) == 39.9994


def test_dash_is_stdin_in_every_command(monkeypatch, capsys, tmp_path):
    data = VN_LOG.read_bytes()
    for command in (["stats"], ["adev", "--taus", "decade"], ["psd"], ["fit"], ["events"],
                    ["dadev"]):
        _stdin(monkeypatch, data)
        assert main([command[0], "-", "--fs", "40", *command[1:]]) == 0, command
        assert "error" not in capsys.readouterr().err
    _stdin(monkeypatch, data)
    assert main(["stats", "-", "--fs", "40"]) == 0
    assert "13223 samples at 40 Hz" in capsys.readouterr().out
    for suffix in ("", ".npy", ".csv", ".npz", ".parquet"):
        out = tmp_path / f"from-stdin{suffix}"
        _stdin(monkeypatch, data)
        assert main(["convert", "-", "-o", str(out), "--fs", "40"]) == 0, suffix
        assert_same_log(imunoise.read(out), imunoise.read(VN_LOG, fs=40.0))
    _stdin(monkeypatch, data)
    assert main(["report", "-", "-o", str(tmp_path / "rep"), "--fs", "40", "--spec", "none",
                 "--no-progress"]) == 0


def test_a_pipe_into_the_cli_gives_every_sample():
    env = {**os.environ, "PYTHONPATH": str(PYTHON)}
    for source in ("-", "/dev/stdin"):
        done = subprocess.run(
            [sys.executable, "-c", "import sys; from imunoise.cli import main; sys.exit(main())",
             "stats", source, "--fs", "40"],
            input=VN_LOG.read_bytes(), capture_output=True, env=env, timeout=120, check=False)
        assert done.returncode == 0, done.stderr
        assert b"13223 samples at 40 Hz, parse issues: no issues" in done.stdout, source


def test_a_stream_is_converted_piece_by_piece_as_the_file(tmp_path):
    """Larger than one piece: streamed from the pipe, the format probed from the
    first piece, nothing read twice."""
    chunk = 1 << 16
    with open(VN_LOG, "rb") as f:
        from_stream = scale.convert(f, tmp_path / "s.npy", fs=40, chunk_bytes=chunk)
    from_file = scale.convert(VN_LOG, tmp_path / "f.npy", fs=40, chunk_bytes=chunk)
    assert from_stream.samples == from_file.samples == 13223
    assert from_stream.bytes_read == from_file.bytes_read == VN_LOG.stat().st_size
    assert_same_log(scale.load(from_stream), scale.load(from_file), source=True)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_a_fifo_is_read_once_without_hanging(tmp_path):
    fifo = tmp_path / "live"
    os.mkfifo(fifo)
    data = CSV_LOG.read_bytes()

    def writer():
        with open(fifo, "wb") as f:  # one writer, one pass: a second open would block
            f.write(data)

    result: dict = {}

    def reader():
        result["log"] = imunoise.read(fifo)

    threads = [threading.Thread(target=writer, daemon=True),
               threading.Thread(target=reader, daemon=True)]
    for t in threads:
        t.start()
    threads[1].join(timeout=60)
    assert "log" in result, "reading the FIFO hung (opened twice?)"
    assert_same_log(result["log"], imunoise.read(CSV_LOG))
    assert result["log"].source == str(fifo)
