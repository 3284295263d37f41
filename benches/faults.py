"""Fault injection: kill -9 and Ctrl-C at random moments of ``imunoise convert`` and
``imunoise report``, and damaged bags.

    python benches/faults.py convert --runs 100   # half kill -9, half SIGINT
    python benches/faults.py report --runs 100
    python benches/faults.py bags --per-bag 10000

convert / report: every run converts (or reports) another real log onto the output
the previous run left, and signals the process at a uniformly random moment of its
measured duration, from 0.8 x its start-up (interpreter, imports, argument checks:
the time it takes to fail on a missing log) to 1.1 x the whole run. After each run:

* every output file is byte for byte the old one or the complete new one (the
  reference run's; a report's time stamp and SVG ids normalised, SVGs parsed);
* after SIGINT the exit status is 130 (or death by SIGINT while the interpreter
  was still starting, which a shell also shows as 130) and no temporary is left;
* after kill -9 a temporary may be left (nothing can clean up after SIGKILL): the
  next run into the folder must remove it and say so on stderr;
* a run that finished leaves exactly the new output (a report: no stale figure).

bags: bit flips, truncations and zeroed blocks of a ROS 1 bag, a ROS 2 db3 and an
MCAP (tests/helpers/bags.py; with --shared also the real bags of
../shared/data/vn100-ros):
``imunoise.read`` must raise nothing but ParseError or a ValueError/OSError naming
the file.

Logs: tests/data, and ../shared/data when present. Prints one summary per command.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from imunoise._support import cpu as _cpu

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DATA = ROOT / "tests" / "data"
SHARED = ROOT.parent / "shared" / "data"
if not SHARED.exists():
    SHARED = Path("/work/shared/data")
TEMP_TAG = ".imunoise-tmp"

#: (log, extra arguments) converted and reported on.
LOGS = [
    (DATA / "rugged_0513test.txt", ["--fs", "40"]),
    (DATA / "waves_F00294.bin", []),
    (DATA / "vn100-csv" / "stationary_data_5min_0.csv", []),
]
SHARED_LOGS = [
    ("vn100-ascii/live_capture.txt", ["--fs", "40"]),
    ("vn100-binary/waves_F00379.bin", []),
]
CONVERT_OUTPUTS = (".csv", ".npz", ".npy", ".parquet", "")
REPORT_LOGS = (DATA / "rugged_0513test.txt", DATA / "vn100-csv" / "stationary_data_5min_0.csv")


def logs() -> list[tuple[Path, list[str]]]:
    found = list(LOGS)
    for rel, extra in SHARED_LOGS:
        if (SHARED / rel).exists():
            found.append((SHARED / rel, extra))
    return found


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "python") + os.pathsep + env.get("PYTHONPATH", "")
    env.pop("PYTHONWARNINGS", None)
    return env


def _command(*args) -> list[str]:
    return [sys.executable, "-m", "imunoise.cli", *map(str, args)]


def _run(args) -> subprocess.CompletedProcess:
    return subprocess.run(_command(*args), env=_env(), capture_output=True, text=True,
                          check=False)


def _signalled(args, delay: float, sig: int) -> tuple[int, str]:
    """Start the command, send ``sig`` after ``delay`` s; (exit status, stderr)."""
    with tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(_command(*args), env=_env(), stdout=subprocess.DEVNULL,
                                stderr=err, text=True)
        try:
            proc.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            proc.send_signal(sig)
        rc = proc.wait()
        err.seek(0)
        return rc, err.read()


# -- what a file holds -----------------------------------------------------------------

_STAMP = re.compile(rb"on \d{4}-\d\d-\d\d \d\d:\d\d UTC")
_MTIME = re.compile(rb'"mtime_ns": \d+')


def _digest(path: Path) -> str:
    """Hash of what a file means: the report's time stamp left out; an SVG (whose
    ids and date matplotlib randomises) is "svg" when it parses, else its bytes."""
    data = path.read_bytes()
    if path.suffix == ".svg":
        try:
            ET.fromstring(data)
        except ET.ParseError:
            return "broken " + hashlib.sha256(data).hexdigest()
        return "svg"
    if path.suffix == ".npz":
        import numpy as np

        try:
            with np.load(path) as z:
                data = b"".join(k.encode() + z[k].tobytes() for k in sorted(z.files))
        except Exception:  # noqa: BLE001 - a damaged archive is a finding, not a crash
            return "broken " + hashlib.sha256(data).hexdigest()
    if path.suffix in (".md", ".html"):
        data = _STAMP.sub(b"on <stamp>", data)
    if path.name.endswith("meta.json"):  # the data's mtime differs run to run
        data = _MTIME.sub(b'"mtime_ns": <t>', data)
    return hashlib.sha256(data).hexdigest()


def _state(out: Path, names: list[str] | None = None) -> dict[str, str]:
    """{relative path: digest} of an output (a file, a file and its meta, or a folder)."""
    if out.is_dir():
        return {p.relative_to(out).as_posix(): _digest(p) for p in sorted(out.rglob("*"))
                if p.is_file() and TEMP_TAG not in p.name}
    found = {}
    for name in names or [out.name]:
        p = out.parent / name
        if p.exists():
            found[name] = _digest(p)
    return found


def _temporaries(directory: Path) -> list[Path]:
    return [p for p in directory.rglob("*") if TEMP_TAG in p.name or p.name.startswith(".")]


@dataclass
class Summary:
    command: str
    runs: int = 0
    outcomes: Counter = field(default_factory=Counter)
    failures: list[str] = field(default_factory=list)
    left_by_kill: int = 0
    swept_and_said: int = 0
    seconds: float = 0.0

    def fail(self, message: str) -> None:
        self.failures.append(message)

    def text(self) -> str:
        lines = [f"{self.command}: {self.runs} runs in {self.seconds:.0f} s; outcomes "
                 + ", ".join(f"{k} {v}" for k, v in sorted(self.outcomes.items())),
                 f"  kill -9 left a temporary in {self.left_by_kill} runs; a later run "
                 f"removed them and said so {self.swept_and_said} times",
                 f"  failures: {len(self.failures)}"]
        lines += [f"    {f}" for f in self.failures[:20]]
        return "\n".join(lines)


def startup_seconds(command: str, work: Path) -> float:
    """Seconds until ``command`` does its work (interpreter, imports, argument
    checks): the time it takes to fail on a log that does not exist."""
    t0 = time.perf_counter()
    _run([command, work / "no-such-log.txt", "-o", work / "never.csv"])
    return time.perf_counter() - t0


def _outcome(sig: int, rc: int, err: str = "") -> str:
    name = "SIGINT" if sig == signal.SIGINT else "SIGKILL"
    if rc == 0:
        return f"{name}: finished first"
    if sig == signal.SIGINT and rc == 130:
        return "SIGINT: exit 130"
    if sig == signal.SIGINT and rc == -signal.SIGINT:
        # Python's own status for a Ctrl-C before the CLI's main() runs (imports) or
        # after it returned; a shell shows it as 130 too
        return "SIGINT: before main() (killed by SIGINT, shell 130)"
    if sig == signal.SIGINT and rc == 1 and err.rstrip().endswith("KeyboardInterrupt") \
            and "imunoise" not in err:
        return "SIGINT: interpreter start-up (Python exits 1)"
    if sig == signal.SIGKILL and rc == -signal.SIGKILL:
        return "SIGKILL: killed"
    return f"{name}: UNEXPECTED exit {rc}"


def _check_run(summary: Summary, tag: str, sig: int, rc: int, err: str, directory: Path,
               pending: list[Path]) -> list[Path]:
    """Checks common to both commands; returns the temporaries this run left."""
    outcome = _outcome(sig, rc, err)
    summary.outcomes[outcome] += 1
    if "UNEXPECTED" in outcome:
        summary.fail(f"{tag}: {outcome}: {err.strip()[-300:]}")
    said = "interrupted imunoise run" in err
    remaining = [p for p in pending if p.exists()]
    if pending and not remaining:
        if said:
            summary.swept_and_said += 1
        else:
            summary.fail(f"{tag}: removed a killed run's temporaries without saying so")
    elif remaining and rc == 0:
        summary.fail(f"{tag}: finished, but a killed run's temporaries remain: {remaining}")
    left = [p for p in _temporaries(directory) if p not in remaining]
    if left and sig == signal.SIGINT:
        summary.fail(f"{tag}: SIGINT left {[p.name for p in left]}")
    if left and sig == signal.SIGKILL:
        summary.left_by_kill += 1
    # a killed run's temporaries wait for the next run that gets to write
    return remaining + (left if sig == signal.SIGKILL else [])


# -- convert ---------------------------------------------------------------------------


def _convert_names(out: Path) -> list[str] | None:
    return [out.name, out.name + ".meta.json"] if out.suffix in (".npy", ".csv") else None


def _refused_pair(out: Path, after: dict, old: dict, new: dict) -> bool:
    """True when ``out`` holds the new data and the old metadata and reading it is an
    error (a warning for a CSV) naming the file, in a fresh interpreter."""
    meta = out.name + ".meta.json"
    if not (after.get(out.name) == new.get(out.name) and after.get(meta) == old.get(meta)):
        return False
    # a CSV is then read as a plain CSV with a warning naming its metadata
    code = ("import sys, warnings, imunoise\nfrom imunoise.errors import ParseError\n"
            "warnings.simplefilter('error', UserWarning)\n"
            "try:\n    imunoise.read(sys.argv[1])\nexcept (ParseError, UserWarning) as e:\n"
            "    sys.exit(0 if sys.argv[1] in str(e) else 3)\nsys.exit(4)")
    return subprocess.run([sys.executable, "-c", code, str(out)], env=_env(),
                          capture_output=True).returncode == 0


def convert_faults(runs: int, seed: int, work: Path, *, quiet: bool = False,
                   sources: list | None = None, outputs=CONVERT_OUTPUTS) -> Summary:
    """``runs`` signalled converts spread over the ``outputs`` layouts, each onto the
    output the previous one left, from another of ``sources`` (default :func:`logs`)."""
    rng = random.Random(seed)
    summary = Summary("convert")
    start = time.perf_counter()
    boot = startup_seconds("convert", work)
    sources = sources or logs()
    ref: dict[tuple[int, str], tuple[dict, float]] = {}

    def reference(i: int, fmt: str) -> tuple[dict, float]:
        if (i, fmt) not in ref:
            out = work / "ref" / f"{i}" / f"out{fmt}"
            out.parent.mkdir(parents=True, exist_ok=True)
            t0 = time.perf_counter()
            done = _run(["convert", sources[i][0], "-o", out, *sources[i][1], "--no-progress"])
            if done.returncode:
                raise RuntimeError(f"reference convert failed: {done.stderr}")
            ref[(i, fmt)] = (_state(out, _convert_names(out)), time.perf_counter() - t0)
        return ref[(i, fmt)]

    for k, fmt in enumerate(outputs):
        folder = work / f"fmt{k}"
        folder.mkdir(parents=True)
        out = folder / f"out{fmt}"
        current = rng.randrange(len(sources))
        done = _run(["convert", sources[current][0], "-o", out, *sources[current][1],
                     "--no-progress"])
        if done.returncode:
            raise RuntimeError(done.stderr)
        state = _state(out, _convert_names(out))
        pending: list[Path] = []
        for r in range(runs // len(outputs) + (k < runs % len(outputs))):
            new = rng.choice([i for i in range(len(sources)) if i != current])
            expect_new, seconds = reference(new, fmt)
            sig = signal.SIGKILL if r % 2 else signal.SIGINT
            delay = rng.uniform(0.8 * boot, 1.1 * seconds)
            rc, err = _signalled(["convert", sources[new][0], "-o", out, *sources[new][1],
                                  "--no-progress"], delay, sig)
            tag = f"convert {sources[new][0].name} -> out{fmt or '/'} {sig.name} at {delay:.2f} s"
            summary.runs += 1
            pending = _check_run(summary, tag, sig, rc, err, folder, pending)
            after = _state(out, _convert_names(out))
            if after == expect_new:
                current, state = new, after
            elif after != state and _refused_pair(out, after, state, expect_new):
                # killed between the data's rename and its metadata's: the new data
                # beside the old metadata, which the reader must refuse
                summary.outcomes["new data, old metadata: refused by the reader"] += 1
                state = after
            elif after != state:
                summary.fail(f"{tag}: output is neither the old nor the new one")
                state = after
            if rc == 0 and after != expect_new:
                summary.fail(f"{tag}: finished but the output is not the new one")
            if not quiet:
                print(f"  {tag}: exit {rc}, {'new' if after == expect_new else 'old'}",
                      flush=True)
    summary.seconds = time.perf_counter() - start
    return summary


# -- report ----------------------------------------------------------------------------


def report_faults(runs: int, seed: int, work: Path, *, quiet: bool = False,
                  inputs=REPORT_LOGS) -> Summary:
    """``runs`` signalled reports into one folder, alternating the two ``inputs``."""
    rng = random.Random(seed)
    summary = Summary("report")
    start = time.perf_counter()
    boot = startup_seconds("report", work)
    refs, seconds = [], []
    for i, log in enumerate(inputs):
        out = work / f"ref{i}"
        t0 = time.perf_counter()
        done = _run(["report", log, "-o", out, "--fs", "40", "--no-progress"])
        if done.returncode:
            raise RuntimeError(done.stderr)
        seconds.append(time.perf_counter() - t0)
        refs.append(_state(out))
    out = work / "report"
    current = 0
    shutil.copytree(work / "ref0", out)
    pending: list[Path] = []
    for r in range(runs):
        new = 1 - current
        sig = signal.SIGKILL if r % 2 else signal.SIGINT
        delay = rng.uniform(0.8 * boot, 1.1 * seconds[new])
        rc, err = _signalled(["report", inputs[new], "-o", out, "--fs", "40",
                              "--no-progress"], delay, sig)
        tag = f"report {inputs[new].name} {sig.name} at {delay:.2f} s"
        summary.runs += 1
        pending = _check_run(summary, tag, sig, rc, err, out, pending)
        after = _state(out)
        for rel, digest in after.items():
            if digest not in (refs[0].get(rel), refs[1].get(rel)):
                summary.fail(f"{tag}: {rel} is neither an old nor a complete new file")
        if rc == 0:
            if after != refs[new]:
                extra = sorted(set(after) - set(refs[new]))
                summary.fail(f"{tag}: finished but the folder differs from the new report "
                             f"(extra: {extra[:5]})")
            current = new
        if not quiet:
            print(f"  {tag}: exit {rc}, {len(after)} files", flush=True)
    summary.seconds = time.perf_counter() - start
    return summary


# -- bags ------------------------------------------------------------------------------


def bag_faults(per_bag: int, seed: int, work: Path, shared: bool = False) -> dict[str, Counter]:
    sys.path.insert(0, str(ROOT / "tests"))
    sys.path.insert(0, str(ROOT / "python"))
    from helpers.bags import mutate, outcome, small_bags

    bags = dict(small_bags(work / "bags"))
    for rel in ("vn100-ros/ros1_stationary.bag", "vn100-ros/ros2_circle_0.db3"):
        if shared and (SHARED / rel).exists():
            bags["shared " + Path(rel).name] = SHARED / rel
    results: dict[str, Counter] = {}
    for name, path in bags.items():
        rng = random.Random(f"{seed}-{name}")
        data = path.read_bytes()
        damaged = work / f"damaged{path.suffix}"
        counts: Counter = Counter()
        t0 = time.perf_counter()
        for _ in range(per_bag):
            kind, body = mutate(data, rng)
            damaged.write_bytes(body)
            result = outcome(damaged)
            counts["LEAK" if result.startswith("LEAK") else result] += 1
            if result.startswith("LEAK") and counts["LEAK"] <= 3:
                print(f"  {name} {kind}: {result[:200]}")
            if sum(counts.values()) % 1000 == 0:
                print(f"  {name}: {sum(counts.values())} done", flush=True)
        results[name] = counts
        print(f"{name}: {per_bag} mutations in {time.perf_counter() - t0:.0f} s: "
              + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())), flush=True)
    return results


def main(argv=None) -> int:
    print(f"machine: {_cpu.describe()}", flush=True)
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=("convert", "report", "bags"))
    p.add_argument("--runs", type=int, default=100, help="runs (half kill -9, half SIGINT)")
    p.add_argument("--per-bag", type=int, default=10_000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--shared", action="store_true",
                   help="bags: also the real (MB-sized, slower) bags of ../shared/data")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="imunoise-faults-") as tmp:
        work = Path(tmp)
        if args.what == "bags":
            results = bag_faults(args.per_bag, args.seed, work, args.shared)
            return 1 if any(c["LEAK"] for c in results.values()) else 0
        run = convert_faults if args.what == "convert" else report_faults
        summary = run(args.runs, args.seed, work, quiet=args.quiet)
        print(summary.text())
        return 1 if summary.failures else 0


if __name__ == "__main__":
    sys.exit(main())
