"""Every check of the project, in the order CI runs them; the README's test command.

    python3 tools/check.py            # rust, lint, test, docs
    python3 tools/check.py test       # one step (or several: rust lint)
    python3 tools/check.py wheel      # a step outside the default run
    python3 tools/check.py --list

Steps:
  rust  cargo fmt --check, clippy (all targets and features, warnings are errors),
        the pure core's unit tests (cargo test --no-default-features)
  lint  ruff check; mypy.stubtest of the extension against python/imunoise/_core/*.pyi
  test  pytest (Python tests; extra arguments after -- go to pytest)
  docs  the documentation site, warnings as errors, gallery run, a page for every
        public name and CLI subcommand checked (tools/check_docs.py; the docs extra);
        about a minute, so part of the default run: a docstring that breaks the site
        fails the check where it is written
  wheel not in the default run (a release build, minutes): build the abi3 wheel
        (manylinux2014 with Zig where installed, its tag asserted), install it into a
        fresh venv with no Rust on PATH, smoke import, versions, `imunoise demo`
        (tools/check_wheel.py)

Each step prints what it runs; the first failing command ends the run with its exit code.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

STEPS: dict[str, list[list[str]]] = {
    "rust": [
        ["cargo", "fmt", "--all", "--check"],
        ["cargo", "clippy", "--all-targets", "--all-features", "--quiet", "--", "-D", "warnings"],
        ["cargo", "test", "--no-default-features", "--quiet"],
    ],
    "lint": [
        ["ruff", "check", "python", "tests", "benches", "tools", "docs"],
        [PY, "-m", "mypy.stubtest", "imunoise._core", "--allowlist",
         "tools/stubtest-allowlist.txt"],
    ],
    "test": [[PY, "-m", "pytest"]],
    "docs": [[PY, "tools/check_docs.py"]],
    "wheel": [[PY, "tools/check_wheel.py"]],
}
#: The steps of a plain `python3 tools/check.py` (CI's run).
DEFAULT = ["rust", "lint", "test", "docs"]


def run(command: list[str]) -> int:
    exe = command[0]
    if exe != PY and shutil.which(exe) is None:
        print(f"check: {exe} not found on PATH", file=sys.stderr)
        return 127
    print(f"$ {' '.join(command)}", flush=True)
    start = time.monotonic()
    code = subprocess.call(command, cwd=ROOT, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    print(f"  ({time.monotonic() - start:.0f} s, exit {code})", flush=True)
    return code


def main(argv: list[str]) -> int:
    pytest_args: list[str] = []
    if "--" in argv:
        cut = argv.index("--")
        argv, pytest_args = argv[:cut], argv[cut + 1:]
    if "--list" in argv:
        print("\n".join(s if s in DEFAULT else f"{s}  (run only when named)" for s in STEPS))
        return 0
    steps = argv or DEFAULT
    unknown = [s for s in steps if s not in STEPS]
    if unknown:
        print(f"check: steps must be among {', '.join(STEPS)}; got {', '.join(unknown)}",
              file=sys.stderr)
        return 2
    for step in steps:
        print(f"== {step}", flush=True)
        for command in STEPS[step]:
            code = run(command + pytest_args if step == "test" else command)
            if code:
                return code
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
