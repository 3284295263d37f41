"""End-to-end benchmark of ``imunoise report`` on a generated 5 h, 40 Hz ``$VNYMR`` log.

Writes the log (still VN-100: gravity on -Z, Earth field, white + random-walk
noise at datasheet level, values printed with the VN-100's decimals and valid
checksums), then runs ``imunoise report LOG -o DIR`` in a child process and
prints its wall time and peak RSS (``resource.getrusage(RUSAGE_CHILDREN)``).

    python benches/bench_report.py [--hours 5] [--fs 40] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from imunoise._support import cpu as _cpu


def write_vnymr(path: Path, hours: float, fs: float, seed: int = 0) -> int:
    n = int(round(hours * 3600 * fs))
    rng = np.random.default_rng(seed)
    ypr = np.array([-77.7, -1.3, 0.15]) + rng.normal(0, 1e-3, (n, 3))
    mag = np.array([0.045, 0.247, -0.338]) + rng.normal(0, 5e-4, (n, 3))
    acc = np.array([-0.2, -0.03, -9.85]) + rng.normal(0, 0.0137, (n, 3))
    acc += np.cumsum(rng.normal(0, 3e-5 / np.sqrt(fs), (n, 3)), axis=0)
    gyr = rng.normal(0, 6.1e-5 * np.sqrt(fs), (n, 3))
    gyr += np.cumsum(rng.normal(0, 2e-6 / np.sqrt(fs), (n, 3)), axis=0)
    cols = np.hstack([ypr, mag, acc, gyr])
    fmt = ",".join(["%+08.3f"] * 3 + ["%+08.4f"] * 3 + ["%+07.3f"] * 3 + ["%+010.6f"] * 3)
    bodies = [("VNYMR," + fmt % tuple(row)).encode() for row in cols.tolist()]
    width = len(bodies[0])
    assert all(len(b) == width for b in bodies), "fixed-width fields overflowed"
    arr = np.frombuffer(b"".join(bodies), dtype=np.uint8).reshape(n, width)
    checks = np.bitwise_xor.reduce(arr, axis=1)
    with open(path, "wb") as f:
        for b, c in zip(bodies, checks.tolist(), strict=True):
            f.write(b"$" + b + b"*%02X\n" % c)
    return n


def main() -> None:
    print(f"machine: {_cpu.describe()}", flush=True)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=5.0)
    ap.add_argument("--fs", type=float, default=40.0)
    ap.add_argument("--keep", type=Path, default=None, help="keep log and report here")
    args = ap.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="imunoise-bench-"))
    work.mkdir(parents=True, exist_ok=True)
    log = work / "vnymr_5h.txt"
    t0 = time.perf_counter()
    n = write_vnymr(log, args.hours, args.fs)
    print(f"generated {n} sentences, {log.stat().st_size / 1e6:.1f} MB "
          f"in {time.perf_counter() - t0:.1f} s")
    cmd = [sys.executable, "-c", "import sys; from imunoise.cli import main; sys.exit(main())",
           "report", str(log), "-o", str(work / "report"), "--no-progress"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    if proc.returncode != 0:
        sys.exit(f"report failed ({proc.returncode}): {proc.stderr.strip()}")
    print(proc.stdout.strip())
    print(f"imunoise report: {wall:.2f} s wall, peak RSS {max(peak, before) / 1024:.0f} MiB "
          f"(target < 10 s, < 1024 MiB), {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
