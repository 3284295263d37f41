"""Ctrl-C latency of the command line: SIGINT at chosen moments of a command, the
time from the signal to the exit, the exit status and whether stderr holds a
traceback.

    python benches/interrupt.py dadev /tmp/sim5h.bin --taus all -- --at 0.3 2 5
    python benches/interrupt.py fit LOG --bootstrap 200 -- --at 1 3

Everything before ``--`` is the command's arguments; ``--at`` lists the moments
(seconds after the start) at which to send SIGINT, one run each. The target:
exit 130, no traceback, stopped within 1 s of the signal.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def interrupt(argv: list[str], at: float) -> tuple[int, float, str]:
    """Runs ``imunoise argv``, sends SIGINT ``at`` s after the start; returns the exit
    status, the seconds from the signal to the exit and stderr."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
    # SIGINT back to its default in the child: a shell's background job ignores it,
    # and a process started with SIGINT ignored keeps ignoring it
    proc = subprocess.Popen([sys.executable, "-m", "imunoise.cli", *argv], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(at)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate()
    return proc.returncode, time.monotonic() - sent, err.decode(errors="replace")


def main() -> int:
    cut = sys.argv.index("--") if "--" in sys.argv else len(sys.argv)
    command = sys.argv[1:cut]
    p = argparse.ArgumentParser()
    p.add_argument("--at", type=float, nargs="+", default=[0.3, 1.0, 3.0])
    opts = p.parse_args(sys.argv[cut + 1:])
    worst = 0.0
    for at in opts.at:
        code, took, err = interrupt(command, at)
        worst = max(worst, took)
        tb = "traceback" if "Traceback" in err else "no traceback"
        print(f"SIGINT at {at:5.2f} s: exit {code}, stopped {took:.3f} s after, {tb}"
              + (f"; stderr: {err.strip().splitlines()[-1]}" if err.strip() else ""))
        if "Traceback" in err:
            print(err)
    print(f"worst: {worst:.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
