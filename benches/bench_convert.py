"""`imunoise convert` against the parser alone and against the floor, same log, same run.

    python benches/bench_convert.py [--gb 1] [--log PATH] [--repeats 3] [--dir DIR] [--keep]
                                    [--layout npy|dir] [--against PYTHONPATH]

Generates a still-VN-100 ``$VNYMR`` log of ``--gb`` gigabytes (800 Hz blocks, as
``scale_bench.py``) unless ``--log`` names one, then, alternating, each in a fresh
subprocess: the parser alone (``imunoise._core.vn.parse_vn(path)``: read, every checksum,
decode into columns) and ``imunoise.scale.convert(path, OUT)`` (the same parse streamed
in 64 MiB pieces, the rows placed on the time grid and written, with the metadata and the
data's fingerprint: ``OUT.npy`` + ``OUT.npy.meta.json`` by default, a directory of
``.npy`` with ``--layout dir``) and the floor: the parse, then the parser's table
(``OUT.npy``'s bytes: as many rows of as many float64 values, in the parser's column
order) written to ``OUT`` in one ``write`` and flushed with ``fsync``, with no hash: what
any writer of these rows must pay. Each of convert and the floor first removes the
output the one before it left. Before each timed process an untimed one fills 2.5 times
the log's size of memory and exits: on a virtual machine, memory the guest has not used
for a while can cost about 2 s of system time per GB at its first touch (the host backs
it then), which would otherwise fall on whichever variant needs the most fresh memory
(the floor: the parser's table and the output's page cache at once). Prints wall time,
CPU time, throughput (MB/s of log) and peak RSS of each, and the ratios convert/parser
and convert/floor (of throughput) per round, with the load average, as a Markdown table,
then the medians of the run.

``--against DIR`` runs every round a second time with ``PYTHONPATH=DIR`` (another build's
``python/`` folder with its ``_core`` extension), alternating with this one, and labels
the rows ``this`` and ``against``.
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

#: The output of a timed run removed first (a file, a directory, its metadata).
CLEAR = """
import os, shutil, sys
out = sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
for stale in (out, out + ".meta.json"):
    try:
        os.unlink(stale)
    except (FileNotFoundError, IsADirectoryError):
        pass
"""

CONVERT = CLEAR + """
import json, resource, time, warnings
from imunoise import scale
warnings.simplefilter("ignore")
c, t = time.process_time(), time.perf_counter()
done = scale.convert(sys.argv[1], sys.argv[2], fs=800.0)
wall, cpu = time.perf_counter() - t, time.process_time() - c
size = os.stat(out).st_size if os.path.isfile(out) else None
print(json.dumps({"wall": wall, "cpu": cpu, "rows": done.samples, "bytes": size,
                  "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""


FLOOR = CLEAR + """
import json, resource, time
from imunoise._core import vn
c, t = time.process_time(), time.perf_counter()
r = vn.parse_vn(sys.argv[1])
table = max((cols for cols in r.tables.values()), key=lambda cols: len(next(iter(cols.values()))))
first = next(iter(table.values()))
rows = len(first)
data = memoryview(first.base).cast("B")  # the parser's row-major table under its columns
fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
try:
    os.write(fd, b"\\x93NUMPY" + bytes(186))  # as long as convert's .npy header (12 fields)
    while data:  # one write; the loop only for a system that writes less at once
        data = data[os.write(fd, data):]
    os.fsync(fd)
finally:
    os.close(fd)
wall, cpu = time.perf_counter() - t, time.process_time() - c
print(json.dumps({"wall": wall, "cpu": cpu, "rows": rows, "bytes": os.stat(out).st_size,
                  "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""


WARM = """
import sys
import numpy as np
np.empty(int(float(sys.argv[1])) // 8).fill(1.0)
print("{}")
"""


def run(code: str, *args: str, path: str | None = None) -> dict:
    env = dict(os.environ)
    if path is not None:
        env["PYTHONPATH"] = path
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args],
                         capture_output=True, text=True, check=True, env=env)
    return json.loads(res.stdout.strip().splitlines()[-1])


def timed(code: str, *args: str, path: str | None, warm: float) -> dict:
    """``run`` after an untimed process that filled ``warm`` bytes of memory."""
    run(WARM, str(warm))
    return run(code, *args, path=path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gb", type=float, default=1.0)
    ap.add_argument("--log", help="an existing $VNYMR log instead of a generated one")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/imunoise-bench-convert")
    ap.add_argument("--keep", action="store_true", help="keep the generated log")
    ap.add_argument("--layout", choices=("npy", "dir"), default="npy",
                    help="convert to OUT.npy (default) or a directory of .npy")
    ap.add_argument("--against", metavar="PYTHONPATH",
                    help="another build's python/ folder, run alternating with this one")
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
    builds = {"this": None, **({"against": args.against} if args.against else {})}
    print(f"machine: {_cpu.describe()}; "
          f"log {src} ({size / 1e6:.0f} MB) -> {out.name}\n")
    print("| round | build | load | parser wall / CPU (s) | parser MB/s | convert wall / CPU (s) "
          "| convert MB/s | convert RSS (MB) | floor wall / CPU (s) | floor MB/s "
          "| convert/parser | convert/floor |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    try:
        run(PARSE, str(src))  # the log into the page cache
        rounds: dict[str, list] = {name: [] for name in builds}
        for k in range(args.repeats):
            for name, path in builds.items():
                load = os.getloadavg()[0]
                p = timed(PARSE, str(src), path=path, warm=2.5 * size)
                c = timed(CONVERT, str(src), str(out), path=path, warm=2.5 * size)
                f = timed(FLOOR, str(src), str(out), path=path, warm=2.5 * size)
                assert c["rows"] == p["rows"] == f["rows"], (c["rows"], p["rows"], f["rows"])
                assert c["bytes"] in (None, f["bytes"]), (c["bytes"], f["bytes"])
                mbs = [size / 1e6 / r["wall"] for r in (p, c, f)]
                print(f"| {k + 1} | {name} | {load:.1f} | {p['wall']:.2f} / {p['cpu']:.2f} "
                      f"| {mbs[0]:.0f} | {c['wall']:.2f} / {c['cpu']:.2f} | {mbs[1]:.0f} "
                      f"| {c['rss'] / 1e6:.0f} | {f['wall']:.2f} / {f['cpu']:.2f} | {mbs[2]:.0f} "
                      f"| {mbs[1] / mbs[0]:.2f} | {mbs[1] / mbs[2]:.2f} |", flush=True)
                rounds[name].append((*mbs, p["cpu"], c["cpu"], f["cpu"],
                                     mbs[1] / mbs[0], mbs[1] / mbs[2]))
        print()
        for name, rs in rounds.items():
            med = [statistics.median(r[i] for r in rs) for i in range(8)]
            print(f"median {name}: parser {med[0]:.0f} MB/s ({med[3]:.2f} s CPU), convert "
                  f"{med[1]:.0f} MB/s ({med[4]:.2f} s CPU), floor {med[2]:.0f} MB/s "
                  f"({med[5]:.2f} s CPU); convert/parser {med[6]:.2f} (rounds "
                  f"{', '.join(f'{r[6]:.2f}' for r in rs)}), convert/floor {med[7]:.2f} "
                  f"(rounds {', '.join(f'{r[7]:.2f}' for r in rs)})")
        print(f"load {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(out, ignore_errors=True)
        for stale in (out, Path(f"{out}.meta.json")):
            if stale.is_file():
                stale.unlink()
        if not args.log and not args.keep:
            shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
