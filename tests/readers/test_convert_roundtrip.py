"""Everything ``imunoise convert`` writes reads back through ``imunoise.read`` and the
CLI: same samples (bit for bit), time, fs, channels, gaps and issues (issue #24)."""

from __future__ import annotations

import json
from pathlib import Path

import imunoise
import numpy as np
import pytest
from helpers.same_log import assert_same_log
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from imunoise import scale
from imunoise.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"
CSV_LOG = DATA / "vn100-csv" / "stationary_data_5min_0.csv"
WRITERS = ("dir", "npy", "parquet", "csv", "npz")
READERS = ("vn-binary", "vn-ascii", "csv")


def _source(kind: str, n: int, fs: float, drops: list[int], seed: int, folder: Path) -> Path:
    rng = np.random.default_rng(seed)
    keep = np.setdiff1d(np.arange(n), drops)
    gyro = rng.normal(0, 0.01, (n, 3))[keep]
    accel = rng.normal([0, 0, -9.8], 0.02, (n, 3))[keep]
    mag = rng.normal(0.3, 0.01, (n, 3))[keep]
    # a clock in whole nanoseconds, as the VN-100 and a ROS stamp give it
    t = (1_700_000_000.0 if kind == "csv" else 12.5) + np.round(np.arange(n) / fs * 1e9)[keep] / 1e9
    path = folder / f"src-{kind}"
    if kind == "vn-binary":
        imunoise.write_vn_binary({"gyro": gyro, "accel": accel, "mag": mag, "time": t},
                                 path=path.with_suffix(".bin"))
        return path.with_suffix(".bin")
    if kind == "vn-ascii":
        ypr = rng.uniform(-10, 10, (len(keep), 3))
        imunoise.write_vn_ascii({"ypr": ypr, "mag": mag, "accel": accel, "gyro": gyro},
                                path=path.with_suffix(".txt"))
        return path.with_suffix(".txt")
    rows = ["time,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z"]
    rows += [",".join(repr(float(v)) for v in (t[i], *gyro[i], *accel[i])) for i in range(len(t))]
    path = path.with_suffix(".csv")
    path.write_text("\n".join(rows) + "\n")
    return path


def _convert(src: Path, out: Path, fs: float) -> None:
    assert main(["convert", str(src), "-o", str(out), "--fs", str(fs), "--no-progress"]) == 0


@pytest.mark.parametrize("writer", WRITERS)
@pytest.mark.parametrize("reader", READERS)
@settings(max_examples=8, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    n=st.integers(4, 200),
    fs=st.sampled_from([40.0, 100.0, 200.0, 800.0]),
    drops=st.lists(st.integers(1, 190), max_size=6, unique=True),
    seed=st.integers(0, 2**16),
)
def test_every_reader_times_every_writer_round_trips(reader, writer, n, fs, drops, seed,
                                                     tmp_path_factory, capsys):
    folder = tmp_path_factory.mktemp("rt")
    drops = [d for d in drops if d < n - 1]
    src = _source(reader, n, fs, drops, seed, folder)
    log = imunoise.read(src, fs=fs)
    out = folder / {"dir": "out", "npy": "out.npy", "parquet": "out.parquet", "csv": "out.csv",
                    "npz": "out.npz"}[writer]
    _convert(src, out, fs)
    capsys.readouterr()
    assert_same_log(imunoise.read(out), log)
    if writer in ("dir", "npy", "parquet"):
        assert_same_log(scale.load(out), log)


@pytest.mark.parametrize("suffix", ["", ".npy", ".parquet", ".csv", ".npz"])
def test_every_cli_command_reads_what_convert_wrote(suffix, tmp_path, capsys):
    src = DATA.parent.parent / "python" / "imunoise" / "data" / "vn100_stationary_5min.txt"
    out = tmp_path / f"live{suffix}"
    _convert(src, out, 40.0)
    capsys.readouterr()
    for command in (["stats"], ["adev", "--taus", "decade"], ["psd"], ["fit", "--sensor", "gyro"]):
        assert main([*command, str(out)]) == 0, command
        printed = capsys.readouterr()
        assert "error" not in printed.err
    assert main(["stats", str(out)]) == 0
    assert "13223 samples at 40 Hz" in capsys.readouterr().out


def test_csv_export_keeps_every_digit_of_epoch_time(tmp_path, capsys):
    out = tmp_path / "rt.csv"
    assert main(["convert", str(CSV_LOG), "-o", str(out)]) == 0
    log = imunoise.read(CSV_LOG)
    back = imunoise.read(out)
    assert len(back) == 13223 and round(back.fs, 4) == 39.9994
    assert_same_log(back, log)
    # a plain CSV for other tools (header, rows); without the metadata beside it the
    # time column alone gives the same grid and rate
    assert out.read_text().startswith("time,gyro_x,")
    assert (tmp_path / "rt.csv.meta.json").is_file()
    bare = tmp_path / "bare.csv"
    bare.write_text(out.read_text())
    plain = imunoise.read(bare)
    assert len(plain) == 13223 and plain.fs == log.fs
    np.testing.assert_array_equal(plain.time, log.time)
    capsys.readouterr()
    assert main(["stats", str(out)]) == 0
    assert "13223 samples at 39.9994 Hz" in capsys.readouterr().out


def test_npz_of_arbitrary_arrays_is_refused_with_what_to_do(tmp_path):
    path = tmp_path / "mine.npz"
    np.savez(path, a=np.zeros(10), b=np.ones((10, 3)))
    with pytest.raises(ValueError, match=r"mine\.npz.*from_arrays"):
        imunoise.read(path)
    assert main(["stats", str(path)]) == 2


def test_npy_without_metadata_is_refused_with_what_to_do(tmp_path):
    path = tmp_path / "mine.npy"
    np.save(path, np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r"mine\.npy.*mine\.npy\.meta\.json.*from_arrays"):
        imunoise.read(path)


def test_convert_names_the_formats_it_writes(tmp_path, capsys):
    assert main(["convert", str(CSV_LOG), "-o", str(tmp_path / "x.txt")]) == 2
    err = capsys.readouterr().err
    assert "x.txt" in err and ".npz" in err and ".parquet" in err


@pytest.mark.parametrize(("field", "value"), [
    ("gaps.samples[0]", -3),
    ("issues.counts.bad_checksum", -1),
    ("samples", -5),
    ("fs", 0),
    ("messages.VNYMR", -2),
])
def test_load_refuses_inconsistent_metadata_naming_the_field(field, value, tmp_path):
    src = DATA.parent.parent / "python" / "imunoise" / "data" / "vn100_stationary_5min.txt"
    raw = src.read_bytes().splitlines(keepends=True)
    damaged = tmp_path / "d.txt"
    damaged.write_bytes(b"".join(raw[:100] + [b"$VNYMR,garbage*00\r\n"] + raw[101:200]))
    out = tmp_path / "o.npy"
    scale.convert(damaged, out, fs=40)
    meta_file = tmp_path / "o.npy.meta.json"
    meta = json.loads(meta_file.read_text())
    assert meta["gaps"]["samples"]
    target, key = meta, field
    for part in field.split(".")[:-1]:
        target = target[part]
    key = field.split(".")[-1]
    if key.endswith("]"):
        key, index = key[:-3], int(key[-2])
        target[key][index] = value
    else:
        target[key] = value
    meta_file.write_text(json.dumps(meta))
    with pytest.raises(ValueError, match=rf"'{__import__('re').escape(field)}'"):
        scale.load(out)
    with pytest.raises(ValueError, match=rf"'{__import__('re').escape(field)}'"):
        imunoise.read(out)


def _both_streams(n: int = 400, fs: float = 200.0) -> bytes:
    """Binary packets with a jittered nanosecond TimeStartup, ASCII sentences between
    them (as serial_both_streams.bin: the binary stream is the richest table)."""
    rng = np.random.default_rng(11)
    t = np.round((1.0 + np.arange(n) / fs + rng.normal(0, 2e-5, n)) * 1e9) / 1e9
    gyro, accel = rng.normal(0, 0.01, (n, 3)), rng.normal(0, 0.01, (n, 3))
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    packets = imunoise.write_vn_binary({"gyro": gyro, "accel": accel, "mag": accel, "ypr": gyro,
                                        "quaternion": quat, "time": t})
    size = len(packets) // n
    lines = imunoise.write_vn_ascii({"ypr": gyro, "mag": accel, "accel": accel, "gyro": gyro},
                                    ).splitlines(keepends=True)
    return b"".join(packets[i * size:(i + 1) * size] + lines[i] for i in range(n))


@pytest.mark.parametrize("suffix", ["", ".npy", ".parquet"])
def test_read_and_convert_then_load_agree(suffix, tmp_path):
    src = tmp_path / "both.bin"
    src.write_bytes(_both_streams())
    log = imunoise.read(src)
    assert log.time is not None and log.issues.counts["bad_checksum"] == 0
    back = scale.load(scale.convert(src, tmp_path / f"out{suffix}"))
    assert_same_log(back, log, source=True)


def test_read_and_convert_then_load_agree_on_serial_both_streams(tmp_path):
    from helpers.data import shared_file

    src = shared_file("data/vn100-binary/serial_both_streams.bin")
    log = imunoise.read(src)
    back = scale.load(scale.convert(src, tmp_path / "out.npy"))
    assert back.fs == log.fs  # was 200.00000003 vs 200.00141
    assert_same_log(back, log, source=True)


def test_a_streamed_conversion_keeps_reads_clock(tmp_path):
    """Larger than one piece: the streamed grid finds the same rate (least-squares
    line, not the median step), gaps, outlier stamp and reset as ``read``."""
    rng = np.random.default_rng(2)
    n, fs = 3000, 200.0
    t = np.round((1 + np.arange(n) / fs * (1 + 3e-5) + rng.normal(0, 2e-5, n)) * 1e9) / 1e9
    t = np.delete(t, [500, 501, 502, 1700])
    t[900] = 1.5e9  # one absurd stamp in a CRC-valid packet
    t[2000:] -= t[2000] - 0.5  # the device restarted: TimeStartup from 0.5 s again
    gyro = rng.normal(0, 0.01, (len(t), 3))
    src = tmp_path / "big.bin"
    imunoise.write_vn_binary({"gyro": gyro, "accel": gyro, "time": t}, path=src)
    with pytest.warns(UserWarning, match="time_outlier"):
        log = imunoise.read(src)
    back = scale.load(scale.convert(src, tmp_path / "big.npy", chunk_bytes=4096))
    assert back.fs == pytest.approx(log.fs, rel=1e-8)  # the median step is 30 ppm off
    assert abs(1 / np.median(np.diff(t[:900])) - log.fs) > 1e-3
    assert len(back) == len(log)
    np.testing.assert_array_equal(back.gaps.index, log.gaps.index)
    np.testing.assert_array_equal(np.isnan(back.gyro), np.isnan(log.gyro))
    for kind in ("time_outlier", "time_reset", "duplicate_time"):
        assert back.issues.counts[kind] == log.issues.counts[kind], kind
        assert back.issues.first[kind] == log.issues.first[kind], kind
    assert log.issues.counts["time_reset"] == 1 and log.issues.counts["time_outlier"] == 1


def test_an_unknown_format_is_named_with_what_to_do(tmp_path):
    path = tmp_path / "blob.xyz"
    path.write_bytes(bytes(range(0x80, 0xF0)) * 8)  # no VN sync byte, no delimiter
    with pytest.raises(ValueError, match=r"blob\.xyz.*format=.*from_arrays"):
        imunoise.read(path)


def test_metadata_beside_a_csv_is_used_only_when_it_is_imunoise_and_fits(tmp_path, capsys):
    out = tmp_path / "rt.csv"
    assert main(["convert", str(CSV_LOG), "-o", str(out)]) == 0
    log = imunoise.read(CSV_LOG)
    lines = out.read_text().splitlines(keepends=True)
    cut = tmp_path / "cut.csv"  # rows removed by hand: the metadata no longer fits
    cut.write_text("".join(lines[:1000] + lines[1100:]))
    (tmp_path / "cut.csv.meta.json").write_text((tmp_path / "rt.csv.meta.json").read_text())
    with pytest.warns(UserWarning, match=r"cut\.csv\.meta\.json describes .* other data"):
        plain = imunoise.read(cut)
    assert len(plain.gaps) == 1 and plain.gaps.samples[0] == 100
    assert plain.fs == pytest.approx(log.fs, rel=1e-6)
    mine = tmp_path / "mine.csv"  # mine.meta.json is not read for mine.csv, whosever it is
    mine.write_text(out.read_text())
    (tmp_path / "mine.meta.json").write_text('{"author": "me"}')
    assert len(imunoise.read(mine)) == 13223


@pytest.mark.parametrize("suffix", ["", ".npy", ".parquet", ".csv", ".npz"])
def test_a_ros_bag_round_trips_through_every_writer(suffix, tmp_path, capsys):
    bag = DATA / "vn100-ros" / "11sec_motion_0.mcap"
    log = imunoise.read(bag)
    out = tmp_path / f"bag{suffix}"
    assert main(["convert", str(bag), "-o", str(out)]) == 0
    assert_same_log(imunoise.read(out), log, source=True)
