"""A recording's side files as the reader sees them: a malformed line or field is a
ParseError naming the file (and the line or field), nothing blocks, nothing
overflows."""

import json
import os
import threading

import imunoise
import numpy as np
import pytest
from imunoise.errors import ParseError
from imunoise.readers import metafile
from imunoise.readers.recording import MAX_OUTAGE, SPAN_SLACK, host_times, outages


@pytest.fixture
def log(tmp_path):
    """A 100-sentence VN ASCII log (no timestamps) with a recording's metadata."""
    sentences = imunoise.write_vn_ascii({ch: np.zeros((100, 3))
                                         for ch in ("gyro", "accel", "mag", "ypr")})
    path = tmp_path / "run.vn"
    path.write_bytes(sentences)
    (tmp_path / "run.vn.meta.json").write_text(json.dumps({"fs": 40, "seconds": 60.0}))
    return path


@pytest.mark.parametrize("line", ["100 0 inf", "100 0 nan", "100 -inf 0", "100 0 1e12",
                                  "100 5 4", "-1 0 1", "1e3 0 1", "100 0", "100 0 1 2",
                                  "x 0 1", "100 0 0x10", "99999999 0 1", "9" * 40 + " 0 1"])
def test_bad_gaps_lines_name_the_file_and_line(log, line):
    side = log.with_name("run.vn.gaps")
    side.write_text(f"50 1000.0 1001.0\n{line}\n")
    with pytest.raises(ParseError) as info:
        imunoise.read(log)
    assert info.value.source == str(side) and info.value.line == 2, str(info.value)


def test_an_outage_is_bounded_by_the_recording(log):
    side = log.with_name("run.vn.gaps")
    side.write_text(f"50 0 {60 + SPAN_SLACK}\n")  # the metadata's 60 s, plus the slack
    assert len(outages(log)) == 1
    side.write_text(f"50 0 {60 + SPAN_SLACK + 0.01}\n")
    with pytest.raises(ParseError, match=r"from 0 to 61 s"):
        outages(log)
    log.with_name("run.vn.meta.json").write_text('{"fs": 40}')  # span unknown: the fixed bound
    side.write_text(f"50 0 {MAX_OUTAGE}\n")
    assert len(outages(log)) == 1
    side.write_text(f"50 0 {MAX_OUTAGE * 1.01}\n")
    with pytest.raises(ParseError, match="outage must last"):
        outages(log)


def test_a_line_cut_by_a_kill_is_left_out(log):
    log.with_name("run.vn.gaps").write_text("50 1000.0 1001.0\n60 1002.0 10")
    assert [o.offset for o in outages(log)] == [50]
    log.with_name("run.vn.times").write_text("0 1000000000\n100 2000000000\n200 30")
    offsets, seconds = host_times(log)
    assert offsets.tolist() == [0, 100] and seconds.tolist() == [1.0, 2.0]


@pytest.mark.parametrize("line", ["0 -5", "0 1.5", "0", "a b", "0 " + "9" * 30])
def test_bad_times_lines_name_the_file_and_line(log, line):
    side = log.with_name("run.vn.times")
    side.write_text(f"0 1000000000\n{line}\n")
    with pytest.raises(ParseError) as info:
        host_times(log)
    assert info.value.source == str(side) and info.value.line == 2


@pytest.mark.parametrize(("text", "field"), [
    ('{"fs": true}', "fs"), ('{"fs": 1e308}', "fs"), ('{"fs": -40}', "fs"),
    ('{"fs": "40"}', "fs"), ('{"fs": 0}', "fs"), ('{"fs": NaN}', None),
    ('{"fs": Infinity}', None), ('{"fs": 40, "seconds": -1}', "seconds"),
    ('{"fs": 40, "bytes": 1.5}', "bytes"), ('{"fs": 40, "outages": "3"}', "outages"),
    ('{"fs": 40, "identity": ["VN-100"]}', "identity"),
    ('{"fs": 40, "previous": {"6": "14"}}', "previous"),
    ('{"fs": 40, "port": 3}', "port"), ('[40]', None), ('"fs"', None),
    ('{"fs": ' + "[" * 100_000 + "]" * 100_000 + "}", None),
    ('{"fs": 4' + "0" * 5000 + "}", None),
])
def test_bad_recording_metadata_is_a_parse_error(log, text, field):
    meta = log.with_name("run.vn.meta.json")
    meta.write_text(text)
    with pytest.raises(ParseError) as info:
        imunoise.read(log)
    assert info.value.source == str(meta)
    if field is not None:
        assert f"metadata field {field!r}" in str(info.value)


def test_an_unknown_field_of_a_newer_recorder_is_ignored(log):
    log.with_name("run.vn.meta.json").write_text('{"fs": 40, "lost": [[1.0, 2.0]]}')
    assert imunoise.read(log).fs == 40


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
@pytest.mark.parametrize("side", [".meta.json", ".gaps", ".times"])
def test_a_fifo_as_a_side_file_does_not_hang(log, side):
    fifo = log.with_name("run.vn" + side)
    fifo.unlink(missing_ok=True)
    os.mkfifo(fifo)
    outcome = []

    def read():
        try:
            imunoise.read(log) if side != ".times" else host_times(log)
        except ParseError as exc:
            outcome.append(exc)

    thread = threading.Thread(target=read, daemon=True)
    thread.start()
    thread.join(10)
    if thread.is_alive():  # unblock the reader so the test run can end
        with open(fifo, "wb"):
            pass
        pytest.fail(f"reading beside a FIFO {side} hung")
    assert outcome and outcome[0].source == str(fifo) and "not a regular file" in str(outcome[0])


def test_metadata_files_are_bounded(tmp_path, monkeypatch):
    big = tmp_path / "x.meta.json"
    big.write_text('{"fs": 40}' + " " * 100)
    monkeypatch.setattr(metafile, "MAX_BYTES", 50)
    with pytest.raises(ParseError, match="more than the 50"):
        metafile.load(big)


def test_outages_cannot_ask_for_more_rows_than_the_grid_bound(log):
    # 100 records at 40 Hz: 99 x 100 missing rows at most (MAX_GRID_RATIO), i.e. 247 s
    log.with_name("run.vn.meta.json").write_text('{"fs": 40, "seconds": 100000}')
    side = log.with_name("run.vn.gaps")
    middle = log.stat().st_size // 2  # an outage before the first record is no gap
    side.write_text(f"{middle} 0 100\n{middle + 10} 200 300\n")
    assert imunoise.read(log).gaps.total == 2 * 3999
    side.write_text(f"{middle} 0 100\n{middle + 10} 200 400\n")
    with pytest.raises(ParseError) as info:
        imunoise.read(log)
    assert info.value.source == str(side) and info.value.line == 2
    assert "more than 99x the 100 records" in str(info.value)


def test_an_old_convert_metadata_under_the_shared_name_is_not_the_recordings(log, tmp_path):
    # `convert run.vn -o run.csv` once wrote run.meta.json, the name of the metadata
    # of a recording `run`; it describes run.csv, so the recording `run` does not use it
    run = tmp_path / "run"
    run.write_bytes(log.read_bytes())
    (tmp_path / "run.meta.json").write_text(json.dumps({"imunoise_columnar": 1, "fs": 100}))
    with pytest.warns(UserWarning) as caught:
        got = imunoise.read(run)
    assert got.fs == 40  # the reader's default, said in a warning; not the 100 Hz of run.csv
    assert any("earlier imunoise convert wrote for run.csv" in str(w.message) for w in caught)
