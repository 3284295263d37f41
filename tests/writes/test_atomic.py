"""Every write is atomic: unique temporary, fsync, rename; the mode kept; inputs refused."""

import os
import subprocess
import sys

import numpy as np
import pytest
from imunoise._support import atomic as _atomic
from imunoise.cli import main


def _hidden(directory):
    return [p.name for p in directory.iterdir() if p.name.startswith(".")]


def test_an_exception_keeps_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old\n")
    with pytest.raises(KeyboardInterrupt), _atomic.replacing(target) as fh:
        fh.write(b"half of the new")
        raise KeyboardInterrupt
    assert target.read_text() == "old\n"
    assert _hidden(tmp_path) == []


def test_two_writers_of_one_target_use_their_own_temporaries(tmp_path):
    target = tmp_path / "t.yaml"
    with _atomic.replacing(target) as a, _atomic.replacing(target) as b:
        assert a.name != b.name
        a.write(b"first")
        b.write(b"second")
    assert target.read_bytes() == b"first"  # the last to finish wins, whole
    assert _hidden(tmp_path) == []


def test_a_replaced_file_keeps_its_mode_and_a_new_one_gets_the_umasks(tmp_path):
    kept = tmp_path / "kept.yaml"
    kept.write_text("x")
    kept.chmod(0o640)
    _atomic.write_text(kept, "y")
    assert kept.stat().st_mode & 0o777 == 0o640
    old = os.umask(0o022)
    try:
        fresh = _atomic.write_text(tmp_path / "imu.yaml", "z")
    finally:
        os.umask(old)
    assert fresh.stat().st_mode & 0o777 == 0o644  # was 0600 (mkstemp)


def test_an_output_that_is_an_input_is_refused(tmp_path):
    src = tmp_path / "in.csv"
    src.write_text("time,gx\n0,1\n")
    link = tmp_path / "link.csv"
    link.hardlink_to(src)
    with pytest.raises(ValueError, match="is the input"):
        _atomic.write_text(link, "gone", inputs=[src])
    assert src.read_text() == "time,gx\n0,1\n"


def test_convert_onto_its_input_exits_2_and_keeps_it(tmp_path, capsys):
    src = tmp_path / "in.csv"
    n = 200
    rows = np.column_stack([np.arange(n) / 100.0, np.ones((n, 3))])
    np.savetxt(src, rows, delimiter=",", header="time,gx,gy,gz", comments="")
    before = src.read_bytes()
    assert main(["convert", str(src), "-o", str(tmp_path / "." / "in.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is the input" in err[0]
    assert src.read_bytes() == before


def test_temporaries_of_killed_runs_are_removed_next_time_and_said(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    pid = int(dead.stdout)
    stale = tmp_path / f".out.csv.{pid}-0123abcd{_atomic.TEMP_TAG}.csv"
    stale.write_text("partial")
    stale_dir = tmp_path / f".cols.{pid}-89abcdef{_atomic.TEMP_TAG}"
    stale_dir.mkdir()
    (stale_dir / "gyro.npy").write_bytes(b"partial")
    live = tmp_path / f".other.{os.getpid()}-00000000{_atomic.TEMP_TAG}"
    live.write_text("being written")
    _atomic._cleaned.discard(os.path.abspath(tmp_path))
    with pytest.warns(UserWarning, match="removed 2 temporary file.*interrupted"):
        _atomic.write_text(tmp_path / "out.csv", "new")
    assert sorted(_hidden(tmp_path)) == [live.name]
    assert (tmp_path / "out.csv").read_text() == "new"


def test_sigterm_unwinds_like_ctrl_c(tmp_path, capsys):
    """The CLI turns SIGTERM into an exit (143) that removes the temporary being written."""
    import signal
    import time

    from imunoise import cli

    old = cli._exit_on_sigterm()
    try:
        with pytest.raises(SystemExit) as info, _atomic.replacing(tmp_path / "o.csv") as fh:
            fh.write(b"half")
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the handler interrupts this
    finally:
        signal.signal(signal.SIGTERM, old)
    assert info.value.code == 143
    assert list(tmp_path.iterdir()) == []
    assert "terminated" in capsys.readouterr().err
