"""Wall time of ``imunoise fleet`` on 100 simulated units, 1 h at 40 Hz each.

Writes the logs (VN-100 binary, datasheet-level noise, one unit in ten with three
times the white noise) once into ``--dir`` (kept for the next run), then runs
``imunoise fleet LOG... -o DIR`` in a child process — the default local Dask
cluster of 2 worker processes, or ``--serial`` — and prints the CPU line, the
wall and CPU time (``RUSAGE_CHILDREN``: the command and its Dask processes) and
the outliers found; the load average says how much of the machine others used.

    python benches/bench_fleet.py [--units 100] [--hours 1] [--fs 40] [--serial]
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

from imunoise._simulation.log import noise_of_spec, simulate_log
from imunoise._support import cpu as _cpu


def write_logs(folder: Path, units: int, hours: float, fs: float) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in range(units):
        path = folder / f"unit{i + 1:03d}.bin"
        if not path.exists():
            noise = noise_of_spec("vn100")
            if i % 10 == 3:
                for terms in noise.values():
                    terms["N"] *= 3.0
            simulate_log(path, hours, fs, format="vn-binary", spec=noise, seed=1000 + i)
        paths.append(path)
    return paths


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--units", type=int, default=100)
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--fs", type=float, default=40.0)
    ap.add_argument("--dir", type=Path,
                    default=Path(tempfile.gettempdir()) / "imunoise-bench-fleet")
    ap.add_argument("--serial", action="store_true", help="no Dask (one process)")
    args = ap.parse_args()
    print(f"cpu: {_cpu.describe()}")
    logs = args.dir / f"{args.units}x{args.hours:g}h_{args.fs:g}Hz"
    t0 = time.perf_counter()
    paths = write_logs(logs, args.units, args.hours, args.fs)
    size = sum(p.stat().st_size for p in paths)
    print(f"{len(paths)} logs, {size / 1e9:.2f} GB, ready in {time.perf_counter() - t0:.1f} s")
    out = args.dir / "report"
    cmd = [sys.executable, "-m", "imunoise.cli", "fleet", *map(str, paths), "-o", str(out),
           "--force", "--no-progress", *(["--serial"] if args.serial else [])]
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, env=os.environ)
    wall = time.perf_counter() - t0
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = usage.ru_utime + usage.ru_stime  # the CLI and its Dask processes, once reaped
    sys.stdout.write(done.stdout)
    sys.stderr.write(done.stderr[-2000:])
    mode = "serial" if args.serial else "local Dask cluster, 2 workers"
    print(f"imunoise fleet: {len(paths)} units of {args.hours:g} h at {args.fs:g} Hz ({mode}): "
          f"{wall:.1f} s wall, {cpu:.1f} s CPU, load average before "
          f"{load:.1f}, exit {done.returncode}")
    sys.exit(done.returncode)


if __name__ == "__main__":
    main()
