"""Out-of-core benchmark: generate a large $VNYMR log, convert it, analyse the memory map.

    python benches/scale_bench.py --gb 5 --dir /tmp/imunoise-scale [--keep]

Generation writes simulated still-VN-100 blocks (0.05 h at 800 Hz each, a new seed per
block) until the file reaches the size asked. Conversion and analysis each run in a fresh
subprocess that reports its wall time and peak RSS (ru_maxrss). The generated files are
deleted at the end unless --keep.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from imunoise._support import cpu as _cpu

FS = 800.0

CONVERT = """
import json, resource, sys, time
from imunoise import scale
t = time.perf_counter()
done = scale.convert(sys.argv[1], sys.argv[2], fs={fs})
wall = time.perf_counter() - t
print(json.dumps({{"wall_s": wall, "peak_rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                  * 1024, "samples": done.samples}}))
"""

ANALYSE = """
import json, resource, sys, time
import imunoise
from imunoise._support import cpu as _cpu
from imunoise import scale
t = time.perf_counter()
log = scale.load(sys.argv[1])
out = {}
for sensor in ("gyro", "accel"):
    r = imunoise.adev(getattr(log, sensor), log.fs, taus=10)
    m = imunoise.fit(r)
    out[sensor + "_N"] = [float(v) for v in m.N]
wall = time.perf_counter() - t
out.update(wall_s=wall, peak_rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
print(json.dumps(out))
"""


def generate(path: Path, size: int) -> tuple[int, float]:
    import imunoise
    from imunoise._simulation.log import still_log

    t = time.perf_counter()
    seed = 0
    with open(path, "wb") as f:
        while f.tell() < size:
            log = still_log(0.05, FS, seed=1000 + seed)
            f.write(imunoise.write_vn_ascii(log, "VNYMR"))
            seed += 1
    return path.stat().st_size, time.perf_counter() - t


def run(code: str, *args: str) -> dict:
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args],
                         capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--gb", type=float, default=5.0)
    ap.add_argument("--dir", default="/tmp/imunoise-scale")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    d = Path(args.dir)
    d.mkdir(parents=True, exist_ok=True)
    src, out = d / "big.txt", d / "big-cols"
    try:
        size, gen_s = generate(src, int(args.gb * 1e9))
        conv = run(CONVERT.format(fs=FS), str(src), str(out))
        npy = sum(p.stat().st_size for p in out.iterdir())
        ana = run(ANALYSE, str(out))
        print(json.dumps({
            "machine": f"{_cpu.describe()}, "
                       f"{os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES') / 2**30:.0f}"
                       " GiB RAM",
            "text_bytes": size, "generate_s": gen_s, "npy_bytes": npy,
            "convert": conv, "analyse": ana,
        }, indent=1))
    finally:
        if not args.keep:
            shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
