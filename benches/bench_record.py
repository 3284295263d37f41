"""Recorder throughput and CPU at 921,600-baud-equivalent binary output.

    python benches/bench_record.py [--seconds 30]

The VN-100 emulator (this process, real time) streams 800 Hz binary packets of
Common TimeStartup, YawPitchRoll, Quaternion, AngularRate, Accel, MagPres, Imu
(110 bytes: 88,000 B/s = 880,000 baud of 8N1 framing, 95.5 % of 921,600) on a
pseudo-terminal; ``imunoise.record`` runs in a child process, once without and
once with the live view (drawn to /dev/null), and reports its own CPU time
(``resource.getrusage``, user + system, the setup excluded) per wall second of
recording. Also checked: every byte the emulator sent while recording is in the
file (sizes equal), and the stream kept its rate (the emulator never waited).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from imunoise._support import cpu as _cpu
from imunoise.emulate import Emulator

FIELDS = "common=TimeStartup+YawPitchRoll+Quaternion+AngularRate+Accel+MagPres+Imu"
PACKET = 1 + 1 + 2 + 8 + 12 + 16 + 12 + 12 + 20 + 24 + 2
CHILD = """
import json, os, resource, sys, time
from imunoise.recording import binary_output, record
port, out, seconds, live = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4] == "1"
done = {}
import imunoise.recording.recorder as rr
original = rr._Recorder.connect
def connect(self, first, **options):
    data = original(self, first, **options)
    if first:
        done["t0"], done["r0"] = time.monotonic(), resource.getrusage(resource.RUSAGE_SELF)
    return data
rr._Recorder.connect = connect
rec = record(port, out, seconds=seconds, ascii="off", binary=[binary_output(800, sys.argv[5])],
             live=live, live_stream=open(os.devnull, "w"))
r1, t1 = resource.getrusage(resource.RUSAGE_SELF), time.monotonic()
r0 = done["r0"]
cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
print(json.dumps({"bytes": rec.bytes, "wall": t1 - done["t0"], "cpu": cpu}))
"""


def run(seconds: float, live: bool, tmp: Path, index: int) -> dict:
    port = tmp / f"port{index}"
    with Emulator(port, speed=1.0, seed=index, keep_sent=False) as emu:
        out = subprocess.run(
            [sys.executable, "-c", CHILD, str(port), str(tmp / f"rec{index}.vn"), str(seconds),
             "1" if live else "0", FIELDS],
            check=True, capture_output=True, text=True)
        result = json.loads(out.stdout.strip().splitlines()[-1])
        asy = [e.offset for e in emu.events if e.kind in ("asy1", "asy0")]
    start = [e for e in asy][1]  # after setup: ASY,0 (setup), ASY,1 (start), ASY,0 (end)
    result["sent"] = asy[2] - start
    return result


def main() -> None:
    print(f"machine: {_cpu.describe()}", flush=True)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=30.0)
    args = parser.parse_args()
    print(f"# recorder at {PACKET * 800:,} B/s ({PACKET} B x 800 Hz), {args.seconds:g} s each; "
          f"load average {os.getloadavg()[0]:.2f}")
    print("| live view | bytes/s recorded | CPU of one core | all bytes kept |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for index, live in enumerate((False, True)):
            r = run(args.seconds, live, Path(tmp), index)
            print(f"| {'on' if live else 'off'} | {r['bytes'] / r['wall']:,.0f} | "
                  f"{100 * r['cpu'] / r['wall']:.1f} % | {r['bytes'] == r['sent']} |")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
