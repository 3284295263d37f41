"""VN-100 parsing: imunoise vs pandas.read_csv and a plain-Python parser, same run.

    python benches/bench_parse.py [--quick]

ASCII: a generated 5 h, 40 Hz ``$VNYMR`` file (~88 MB, CRLF, every checksum
valid) in a temporary directory, read by
  * imunoise.read (every checksum verified, all cores),
  * pandas.read_csv, no checksum, two ways: the fastest setup we found
    (``comment="*"`` drops the checksum, all columns parse in C) and the usual
    recipe (default read, then split the checksum off the last column),
  * a plain-Python line parser that verifies every checksum.
Binary: a generated 1 h, 800 Hz capture (Common TimeStartup, YawPitchRoll,
AngularRate, Accel, MagPres: 80-byte packets), read by imunoise; reported in GB/s.
Prints medians and ratios as Markdown. ``--quick`` uses 30 min / 10 min.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import tempfile
import time
from functools import reduce
from pathlib import Path

import imunoise
import numpy as np
import pandas as pd
from imunoise._support import cpu as _cpu


def median_time(fn, repeats: int) -> tuple[float, float]:
    """Median wall-clock and median CPU seconds (all threads of this process)."""
    times, cpu = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(times), statistics.median(cpu)


def still_log(n: int, fs: float, seed: int = 0) -> imunoise.ImuLog:
    rng = np.random.default_rng(seed)
    return imunoise.ImuLog.from_arrays(
        fs,
        ypr=rng.normal([100.0, -7.3, 0.7], 0.01, (n, 3)),
        mag=rng.normal([-0.005, -0.245, 0.54], 0.001, (n, 3)),
        accel=rng.normal([0.0, 0.0, -9.81], 0.01, (n, 3)),
        gyro=rng.normal(0.0, 0.0005, (n, 3)),
        temperature=rng.normal(25.0, 0.1, n),
        pressure=rng.normal(101.3, 0.01, n),
    )


def python_parser(path: Path) -> np.ndarray:
    rows = []
    with open(path, "rb") as f:
        for line in f:
            line = line.rstrip(b"\r\n")
            if not line.startswith(b"$VN"):
                continue
            body, _, check = line[1:].partition(b"*")
            if reduce(lambda a, c: a ^ c, body, 0) != int(check, 16):
                continue
            rows.append([float(v) for v in body.split(b",")[1:]])
    return np.array(rows)


def pandas_plain(path: Path) -> np.ndarray:
    # The usual recipe: read_csv, then split the checksum off the last column.
    df = pd.read_csv(path, header=None)
    last = df[12].str.split("*", n=1).str[0].astype(np.float64)
    return np.column_stack([df.iloc[:, 1:12].to_numpy(dtype=np.float64), last.to_numpy()])


def pandas_parser(path: Path) -> np.ndarray:
    # Fastest pandas setup we found: the C engine, "*" as comment character so the
    # checksum is dropped and all 12 numeric columns parse as float64 in C.
    df = pd.read_csv(path, header=None, usecols=range(1, 13), comment="*", engine="c")
    return df.to_numpy(dtype=np.float64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="30 min ASCII, 10 min binary")
    args = parser.parse_args()
    hours_ascii = 0.5 if args.quick else 5.0
    minutes_bin = 10 if args.quick else 60
    repeats = 3 if args.quick else 5
    print(f"machine: {_cpu.describe()}, python "
          f"{platform.python_version()}, pandas {pd.__version__}, numpy {np.__version__}")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        n = int(hours_ascii * 3600 * 40)
        path = tmp / "ymr.txt"
        imunoise.write_vn_ascii(still_log(n, 40.0), "VNYMR", path=path)
        size = path.stat().st_size
        print(f"\nASCII: {n} $VNYMR sentences, {size / 1e6:.1f} MB\n")
        log = imunoise.read(path, fs=40)
        assert len(log) == n and log.issues.total == 0
        ref = pandas_parser(path)
        np.testing.assert_allclose(ref[:, 9:12], log.gyro, rtol=1e-15, atol=0)
        print(f"load average before: {os.getloadavg()[0]:.2f}")
        t_imu = median_time(lambda: imunoise.read(path, fs=40), repeats)
        t_pd = median_time(lambda: pandas_parser(path), repeats)
        t_pd_plain = median_time(lambda: pandas_plain(path), max(1, repeats - 2))
        t_py = median_time(lambda: python_parser(path), 1)
        print(f"load average after: {os.getloadavg()[0]:.2f}\n")
        print("| reader | checksums | median s | MB/s | CPU s | imunoise speed-up |")
        print("|---|---|---:|---:|---:|---:|")
        for name, chk, (t, c) in (
            ("imunoise.read", "all verified", t_imu),
            ('pandas.read_csv(comment="*")', "none", t_pd),
            ("pandas.read_csv + split '*'", "none", t_pd_plain),
            ("plain Python", "all verified", t_py),
        ):
            ratio = t / t_imu[0]
            print(f"| {name} | {chk} | {t:.3f} | {size / 1e6 / t:.0f} | {c:.3f} | {ratio:.1f}x |")

        m = int(minutes_bin * 60 * 800)
        bpath = tmp / "capture.bin"
        imunoise.write_vn_binary(still_log(m, 800.0, seed=1), path=bpath)
        bsize = bpath.stat().st_size
        blog = imunoise.read(bpath)
        assert len(blog) == m and blog.issues.total == 0
        data = bpath.read_bytes()
        print(f"\nBinary: {m} packets of {bsize // m} bytes, {bsize / 1e6:.1f} MB")
        print(f"load average before: {os.getloadavg()[0]:.2f}")
        t_file = median_time(lambda: imunoise.read(bpath), repeats)
        t_mem = median_time(lambda: imunoise.read(data, fs=800), repeats)
        print(f"load average after: {os.getloadavg()[0]:.2f}\n")
        print("| source | median s | GB/s | CPU s |")
        print("|---|---:|---:|---:|")
        for name, (t, c) in (("file", t_file), ("bytes in memory", t_mem)):
            print(f"| {name} | {t:.3f} | {bsize / 1e9 / t:.2f} | {c:.3f} |")


if __name__ == "__main__":
    main()
