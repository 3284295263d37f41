"""The Rust side of the suite: unit tests of the pure core, formatting and lints.

They run through pytest so that one command runs every test. Set
IMUNOISE_SKIP_RUST=1 to skip them on a machine without a Rust toolchain (a
wheel install, say); CI never sets it.
"""

import os
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(
    os.environ.get("IMUNOISE_SKIP_RUST") == "1", reason="IMUNOISE_SKIP_RUST=1"
)


def run(*command: str) -> None:
    if shutil.which(command[0]) is None:
        pytest.fail(f"{command[0]} not found on PATH (set IMUNOISE_SKIP_RUST=1 to skip)")
    proc = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(command)} failed:\n{proc.stdout}\n{proc.stderr}"


def test_cargo_fmt():
    run("cargo", "fmt", "--all", "--check")


def test_cargo_test_pure_core():
    run("cargo", "test", "--no-default-features", "--quiet")


def test_cargo_clippy():
    run("cargo", "clippy", "--all-targets", "--all-features", "--quiet", "--", "-D", "warnings")


def test_ruff():
    run("ruff", "check", str(ROOT))
