"""Out-of-core conversion and Dask batches (imunoise.scale)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import imunoise
import numpy as np
import pytest
from imunoise import scale
from imunoise._simulation.log import still_log
from imunoise.cli import main
from imunoise.scale.convert import _Steps

FS = 40.0


def _log(hours: float, seed: int):
    return still_log(hours, FS, seed=seed)


def _same_log(a, b) -> None:
    assert a.channels == b.channels
    for ch in a.channels:  # missing samples are NaN rows in both
        assert np.array_equal(getattr(a, ch), getattr(b, ch), equal_nan=True), ch
    assert (a.time is None) == (b.time is None)
    if a.time is not None:
        assert np.array_equal(a.time, b.time)
    assert np.array_equal(a.gaps.index, b.gaps.index)
    assert np.array_equal(a.gaps.samples, b.gaps.samples)
    assert a.fs == b.fs
    assert dict(a.issues.counts) == dict(b.issues.counts)
    assert dict(a.issues.first) == dict(b.issues.first)
    assert dict(a.messages) == dict(b.messages)


def _damaged(data: bytes, every: int) -> bytes:
    """Flip one byte in every ``every``-th kilobyte (bad checksums, broken records)."""
    b = bytearray(data)
    for pos in range(500, len(b), every * 1024):
        b[pos] ^= 0x21
    return bytes(b)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("scale")
    log = _log(0.1, seed=5)  # 14400 samples
    ascii_path, bin_path = d / "a.txt", d / "b.bin"
    imunoise.write_vn_ascii(log, "VNYMR", path=ascii_path)
    imunoise.write_vn_binary(log, path=bin_path)
    bad_ascii, bad_bin = d / "a_bad.txt", d / "b_bad.bin"
    bad_ascii.write_bytes(_damaged(ascii_path.read_bytes(), 7))
    bad_bin.write_bytes(_damaged(bin_path.read_bytes(), 5))
    return {"ascii": ascii_path, "binary": bin_path, "ascii_bad": bad_ascii,
            "binary_bad": bad_bin, "dir": d}


@pytest.mark.parametrize("kind", ["ascii", "binary", "ascii_bad", "binary_bad"])
@pytest.mark.parametrize("out", ["cols", "log.npy", "log.parquet"])
def test_convert_round_trip_is_exact(logs, tmp_path, kind, out):
    src = logs[kind]
    ref = imunoise.read(src, fs=FS)
    # Small pieces: records are cut at many piece boundaries.
    done = scale.convert(src, tmp_path / out, fs=FS, chunk_bytes=4096 + 17)
    assert done.samples == len(ref)
    assert all(p.exists() for p in done.files)
    _same_log(ref, scale.load(done.out))
    if kind.endswith("bad"):
        assert ref.issues.total > 0 and len(ref.gaps) > 0
        assert done.issues.samples_missing == ref.issues.samples_missing


def test_load_memory_maps_without_copy(logs, tmp_path):
    for out in ("cols", "log.npy"):
        log = scale.load(scale.convert(logs["binary"], tmp_path / out).out)
        for ch in log.channels:
            base = getattr(log, ch)
            while base is not None and not isinstance(base, np.memmap):
                base = base.base
            assert isinstance(base, np.memmap), (out, ch)
            assert not getattr(log, ch).flags.writeable


def test_memory_mapped_analysis_equals_in_memory(logs, tmp_path):
    ref = imunoise.read(logs["ascii"], fs=FS)
    for out in ("cols", "log.npy"):
        mm = scale.load(scale.convert(logs["ascii"], tmp_path / out, fs=FS).out)
        for sensor in ("gyro", "accel"):
            a = imunoise.adev(getattr(ref, sensor), ref.fs, taus=10)
            b = imunoise.adev(getattr(mm, sensor), mm.fs, taus=10)
            for field in ("taus", "dev", "n", "edf", "ci_low", "ci_high"):
                assert np.array_equal(getattr(a, field), getattr(b, field), equal_nan=True)
            fa, fb = imunoise.fit(a), imunoise.fit(b)
            for t in "QNBKR":
                assert np.array_equal(fa.value(t), fb.value(t), equal_nan=True)
                assert np.array_equal(fa.std(t), fb.std(t), equal_nan=True)


def test_convert_replaces_and_rejects(logs, tmp_path):
    out = tmp_path / "cols"
    scale.convert(logs["binary"], out)
    done = scale.convert(logs["ascii"], out, fs=FS)  # fewer channels: no stale time.npy
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in done.files)
    assert not list(tmp_path.glob(".*"))
    with pytest.raises(ValueError, match="out must be"):
        scale.convert(logs["ascii"], tmp_path / "x.csv")
    with pytest.raises(ValueError, match="chunk_bytes"):
        scale.convert(logs["ascii"], out, chunk_bytes=10)
    empty = tmp_path / "empty.txt"
    empty.write_bytes(b"$VNYMR,garbage*00\r\n" * 3)
    with pytest.raises(ValueError, match="no usable records"):
        scale.convert(empty, tmp_path / "e.npy", format="vn-ascii", fs=FS)
    assert not (tmp_path / "e.npy").exists()
    assert not list(tmp_path.glob(".*"))


def test_cli_convert_streams(logs, tmp_path, capsys):
    out = tmp_path / "c.npy"
    assert main(["convert", str(logs["binary"]), "-o", str(out), "--chunk-mb", "0.01"]) == 0
    assert "14400 samples" in capsys.readouterr().out
    meta = json.loads((tmp_path / "c.npy.meta.json").read_text())
    assert meta["samples"] == 14400 and meta["format"] == "vn-binary"
    _same_log(imunoise.read(logs["binary"]), scale.load(out))


def test_convert_memory_is_bounded(tmp_path):
    """Converting a ~50 MB log keeps the child's peak RSS growth far below the file size."""
    src = tmp_path / "big.txt"
    one = imunoise.write_vn_ascii(_log(1 / 36, seed=9), "VNYMR")  # 4000 sentences
    reps = max(1, (50 << 20) // len(one))
    with open(src, "wb") as f:
        for _ in range(reps):
            f.write(one)
    size = src.stat().st_size
    code = textwrap.dedent(f"""
        import resource, sys
        import numpy as np
        import imunoise
        from imunoise import scale
        base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        done = scale.convert({str(src)!r}, {str(tmp_path / "out")!r}, fs=40.0,
                             chunk_bytes=4 << 20)
        log = scale.load(done.out)
        r = imunoise.adev(log.gyro, log.fs, taus=10)
        imunoise.fit(r)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(done.samples, (peak - base) * 1024)
    """)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    samples, grown = map(int, res.stdout.split())
    assert samples == reps * 4000
    # The decoded channels alone are 12 float64 per sample (~40 % of the text);
    # memory grows by a few pieces only (pages of the memory map are file-backed
    # and counted in RSS as they are read, so allow the mapped gyro array too).
    decoded = samples * 12 * 8
    assert grown < 0.5 * size, (grown, size)
    assert grown < decoded, (grown, decoded)


# --- batch ------------------------------------------------------------------


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    paths = []
    for i in range(3):
        p = d / f"imu{i}.bin"
        imunoise.write_vn_binary(_log(0.05, seed=20 + i), path=p)
        paths.append(p)
    bad = d / "imu9.bin"
    bad.write_bytes(bytes(range(256)) * 40)  # no VN record in it
    return d, paths, bad


def _check_frame(df, paths, bad) -> None:
    good = df[df["error"].isna()]
    assert len(good) == 3 * 6
    assert sorted(good["path"].unique()) == sorted(str(p) for p in paths)
    assert set(zip(good["sensor"], good["axis"], strict=True)) == {
        (s, a) for s in ("gyro", "accel") for a in "XYZ"}
    err = df[df["path"] == str(bad)]
    assert len(err) == 1 and err["error"].iloc[0] and err["sensor"].isna().all()
    assert (good["samples"] == 7200).all()
    # The simulated noise densities are recovered to within a few percent.
    n_gyro = good.loc[good["sensor"] == "gyro", "N"].to_numpy()
    want = 0.0035 * np.pi / 180
    assert np.all(np.abs(n_gyro / want - 1) < 0.1), n_gyro / want
    assert (good["N_std"] > 0).all() and good["verdict"].notna().all()


def test_batch_serial(fleet):
    d, paths, bad = fleet
    df = imunoise.batch(str(d / "*.bin"), client=False)
    _check_frame(df, paths, bad)


def test_batch_local_cluster_equals_serial(fleet):
    distributed = pytest.importorskip("distributed")
    d, paths, bad = fleet
    serial = imunoise.batch([*paths, bad], client=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        parallel = imunoise.batch([*paths, bad], client=client)
        # The same cluster by its address: used unchanged.
        by_address = imunoise.batch([*paths, bad], client=cluster.scheduler_address)
        assert len(client.scheduler_info()["workers"]) == 2
    _check_frame(parallel, paths, bad)
    import pandas as pd

    pd.testing.assert_frame_equal(parallel, serial)
    pd.testing.assert_frame_equal(by_address, serial)


def test_cli_batch_writes_table(fleet, tmp_path, capsys):
    pd = pytest.importorskip("pandas")
    d, paths, bad = fleet
    out = tmp_path / "r.csv"
    assert main(["batch", str(d / "*.bin"), "-o", str(out), "--serial"]) == 0
    text = capsys.readouterr().out
    assert "for 4 logs" in text and "1 failed" in text and str(bad) in text
    assert len(pd.read_csv(out)) == 3 * 6 + 1
    assert main(["batch", str(d / "nothing*.bin"), "-o", str(out), "--serial"]) == 2
    assert "matches no file" in capsys.readouterr().err


@pytest.mark.parametrize("n", [2, 9, 10, 1001])
def test_streamed_step_median_equals_numpy(n):
    rng = np.random.default_rng(n)
    t = np.cumsum(rng.choice([0.0, 0.00125, 0.00125, 0.0012501, -0.5, 0.0025], size=n))
    steps = _Steps()
    for piece in np.array_split(t, 4):
        steps.add(piece)
    d = np.diff(t)
    d = d[d > 0]
    assert steps.median() == (np.median(d) if len(d) else None)


def test_convert_csv_is_read_whole_and_equal(logs, tmp_path, capsys):
    csv = tmp_path / "log.csv"
    assert main(["convert", str(logs["binary"]), "-o", str(csv)]) == 0
    capsys.readouterr()
    ref = imunoise.read(csv)
    done = scale.convert(csv, tmp_path / "c.npy", chunk_bytes=8192)
    _same_log(ref, scale.load(done.out))


def test_parquet_metadata(logs, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "p.parquet"
    done = scale.convert(logs["binary"], out)
    table = pq.read_table(out)
    assert table.column_names[:4] == ["time", "gyro_x", "gyro_y", "gyro_z"]
    # Written after the rows: the file's key-value metadata.
    assert float(pq.read_metadata(out).metadata[b"fs"]) == done.fs
