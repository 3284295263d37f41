"""`imunoise convert` against the parser alone, same log, same run.

    python benches/bench_convert.py [--gb 1] [--log PATH] [--repeats 3] [--dir DIR] [--keep]
                                    [--layout npy|dir]

Generates a still-VN-100 ``$VNYMR`` log of ``--gb`` gigabytes (800 Hz blocks, as
``scale_bench.py``) unless ``--log`` names one, then, alternating, each in a fresh
subprocess: the parser alone (``imunoise._core.vn.parse_vn(path)``: read, every checksum,
decode into columns) and ``imunoise.scale.convert(path, OUT)`` (the same parse streamed
in 64 MiB pieces, the rows placed on the time grid and written, with the metadata and the
data's fingerprint: ``OUT.npy`` + ``OUT.npy.meta.json`` by default, a directory of
``.npy`` with ``--layout dir``). Prints wall time, CPU time, throughput (MB/s of log),
peak RSS and convert/parser throughput ratio per round, with the load average, as a
Markdown table, then the medians and the median ratio of the run.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path

from imunoise._support import cpu as _cpu

PARSE = """
import json, resource, sys, time
from imunoise._core import vn
c, t = time.process_time(), time.perf_counter()
r = vn.parse_vn(sys.argv[1])
wall, cpu = time.perf_counter() - t, time.process_time() - c
rows = max(len(next(iter(cols.values()))) for cols in r.tables.values())
print(json.dumps({"wall": wall, "cpu": cpu, "rows": rows,
                  "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""

CONVERT = """
import json, os, resource, shutil, sys, time, warnings
from imunoise import scale
warnings.simplefilter("ignore")
out = sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
for stale in (out, out + ".meta.json"):
    try:
        os.unlink(stale)
    except (FileNotFoundError, IsADirectoryError):
        pass
c, t = time.process_time(), time.perf_counter()
done = scale.convert(sys.argv[1], sys.argv[2], fs=800.0)
wall, cpu = time.perf_counter() - t, time.process_time() - c
print(json.dumps({"wall": wall, "cpu": cpu, "rows": done.samples,
                  "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""


def run(code: str, *args: str) -> dict:
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args],
                         capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gb", type=float, default=1.0)
    ap.add_argument("--log", help="an existing $VNYMR log instead of a generated one")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/imunoise-bench-convert")
    ap.add_argument("--keep", action="store_true", help="keep the generated log")
    ap.add_argument("--layout", choices=("npy", "dir"), default="npy",
                    help="convert to OUT.npy (default) or a directory of .npy")
    args = ap.parse_args()
    d = Path(args.dir)
    d.mkdir(parents=True, exist_ok=True)
    out = d / ("cols.npy" if args.layout == "npy" else "cols")
    if args.log:
        src = Path(args.log)
    else:
        sys.path.insert(0, str(Path(__file__).parent))
        from scale_bench import generate

        src = d / "big.txt"
        if not src.exists():
            generate(src, int(args.gb * 1e9))
    size = src.stat().st_size
    print(f"machine: {_cpu.describe()}; "
          f"log {src} ({size / 1e6:.0f} MB) -> {out.name}\n")
    print("| round | load | parser wall / CPU (s) | parser MB/s | parser RSS (MB) "
          "| convert wall / CPU (s) | convert MB/s | convert RSS (MB) | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    try:
        run(PARSE, str(src))  # the log into the page cache
        rounds = []
        for k in range(args.repeats):
            load = os.getloadavg()[0]
            p = run(PARSE, str(src))
            c = run(CONVERT, str(src), str(out))
            assert c["rows"] == p["rows"], (c["rows"], p["rows"])
            mbs = [size / 1e6 / r["wall"] for r in (p, c)]
            print(f"| {k + 1} | {load:.1f} | {p['wall']:.2f} / {p['cpu']:.2f} | {mbs[0]:.0f} "
                  f"| {p['rss'] / 1e6:.0f} | {c['wall']:.2f} / {c['cpu']:.2f} | {mbs[1]:.0f} "
                  f"| {c['rss'] / 1e6:.0f} | {mbs[1] / mbs[0]:.2f} |", flush=True)
            rounds.append((*mbs, p["cpu"], c["cpu"]))
        med = [statistics.median(r[i] for r in rounds) for i in range(4)]
        ratios = sorted(r[1] / r[0] for r in rounds)
        print(f"\nmedian: parser {med[0]:.0f} MB/s ({med[2]:.2f} s CPU), convert {med[1]:.0f} "
              f"MB/s ({med[3]:.2f} s CPU); convert/parser {statistics.median(ratios):.2f} "
              f"(rounds {', '.join(f'{x:.2f}' for x in ratios)}), CPU parser/convert "
              f"{med[2] / med[3]:.2f}; load {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(out, ignore_errors=True)
        for stale in (out, Path(f"{out}.meta.json")):
            if stale.is_file():
                stale.unlink()
        if not args.log and not args.keep:
            shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
