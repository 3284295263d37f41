"""Ctrl-C's watchdog ends a process that has not unwound within its deadline (a long
fsync, a kernel that does not look at the flag): the temporaries of the files being
written must go with it, as they go when the unwinding reaches its clean-up."""

from __future__ import annotations

import subprocess
import sys


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)


def test_a_hard_exit_while_writing_leaves_no_temporary(tmp_path):
    target = tmp_path / "out.bin"
    done = _run(f"""
import imunoise._support.atomic as atomic, imunoise._support.interrupt as interrupt
with atomic.staged({str(target)!r}) as (fh, tmp):
    fh.write(b"partial")
    interrupt._end(2)  # what the watchdog does at its deadline
""")
    assert done.returncode == 130, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_hard_exit_while_publishing_leaves_neither_temporary(tmp_path):
    target = tmp_path / "out.npy"
    meta = tmp_path / "out.npy.meta.json"
    done = _run(f"""
import imunoise._support.atomic as atomic, imunoise._support.interrupt as interrupt
with atomic.staged({str(target)!r}) as (fh, tmp):
    fh.write(b"data")

def meta_of(mark):
    interrupt._end(2)  # the watchdog ends the process while the pair is published

atomic.publish_pair(tmp, {str(target)!r}, meta_of, {str(meta)!r})
""")
    assert done.returncode == 130, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []
