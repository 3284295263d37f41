"""A data file and its metadata change together.

Each output has its own metadata (``X.npy.meta.json``, ``X.csv.meta.json``), which
carries the data's fingerprint; the pair is published data first, metadata second,
under a lock on the directory. A writer killed (SIGKILL) before, between or after
the two renames leaves the old pair, a pair the reader refuses naming the file, or
the new pair; two converts to one output leave one of the two whole pairs.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import imunoise
import pytest
from helpers.data import DATA
from imunoise.cli import main
from imunoise.errors import ParseError

ROOT = Path(__file__).resolve().parents[2]


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "python") + os.pathsep + str(ROOT / "tests")
    env.pop("PYTHONWARNINGS", None)
    return env


def _source(tmp_path: Path, lines: int) -> Path:
    """The first ``lines`` lines of a VN ASCII log without timestamps (fs matters)."""
    path = tmp_path / f"src{lines}.txt"
    raw = (DATA / "rugged_0513test.txt").read_bytes().splitlines(keepends=True)
    path.write_bytes(b"".join(raw[1:lines + 1]))
    return path


@pytest.mark.parametrize("suffix", [".npy", ".csv"])
def test_outputs_of_one_stem_keep_their_own_rate(suffix, tmp_path, capsys):
    src = _source(tmp_path, 300)
    other = ".csv" if suffix == ".npy" else ".npy"
    assert main(["convert", str(src), "-o", str(tmp_path / f"log{suffix}"), "--fs", "40"]) == 0
    assert main(["convert", str(src), "-o", str(tmp_path / f"log{other}"), "--fs", "100"]) == 0
    assert imunoise.read(tmp_path / f"log{suffix}").fs == 40
    assert imunoise.read(tmp_path / f"log{other}").fs == 100
    assert (tmp_path / f"log{suffix}.meta.json").is_file()
    assert not (tmp_path / "log.meta.json").exists()


def test_convert_leaves_a_recordings_metadata_alone(tmp_path, capsys):
    run = tmp_path / "run"  # a recording: raw log `run`, its metadata `run.meta.json`
    run.write_bytes(_source(tmp_path, 200).read_bytes())
    recorded = json.dumps({"fs": 40, "port": "/dev/ttyUSB0", "identity": {"model": "VN-100"}})
    (tmp_path / "run.meta.json").write_text(recorded)
    assert main(["convert", str(run), "-o", str(tmp_path / "run.csv"), "--fs", "100"]) == 0
    assert (tmp_path / "run.meta.json").read_text() == recorded
    assert imunoise.read(run).fs == 40
    assert imunoise.read(tmp_path / "run.csv").fs == 100


def test_the_old_shared_name_is_not_read_for_a_npy(tmp_path, capsys):
    src = _source(tmp_path, 200)
    out = tmp_path / "log.npy"
    assert main(["convert", str(src), "-o", str(out), "--fs", "40"]) == 0
    (tmp_path / "log.npy.meta.json").rename(tmp_path / "log.meta.json")  # as written before
    with pytest.raises(ParseError, match=r"log\.npy.*log\.meta\.json is the name earlier "
                       r"versions gave.*rename it to log\.npy\.meta\.json"):
        imunoise.read(out)
    (tmp_path / "log.meta.json").rename(tmp_path / "log.npy.meta.json")
    assert imunoise.read(out).fs == 40


_KILLER = textwrap.dedent("""
    import os, signal, sys
    from imunoise.cli import main
    calls, kill_at = [0], int(sys.argv[1])
    real = os.replace
    def replace(src, dst):
        calls[0] += 1
        if calls[0] == kill_at and str(dst).endswith(("log.npy", "log.csv", "meta.json")):
            os.kill(os.getpid(), signal.SIGKILL)  # kill -9 instead of this rename
        return real(src, dst)
    os.replace = replace
    sys.exit(main(["convert", sys.argv[2], "-o", sys.argv[3], "--fs", sys.argv[4],
                   "--no-progress"]))
""")


def _killed_convert(kill_at: int, src: Path, out: Path, fs: float) -> int:
    return subprocess.run([sys.executable, "-c", _KILLER, str(kill_at), str(src), str(out),
                           str(fs)], env=_env(), capture_output=True).returncode


def _read(out: Path):
    """(samples, fs) of ``out``, or the error reading it (warnings are errors)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        try:
            log = imunoise.read(out)
        except (ParseError, UserWarning) as exc:
            return exc
    return len(log), log.fs


@pytest.mark.parametrize("suffix", [".npy", ".csv"])
def test_kill_9_before_between_and_after_the_renames(suffix, tmp_path, capsys):
    old_src, new_src = _source(tmp_path, 300), _source(tmp_path, 500)
    out = tmp_path / f"log{suffix}"
    assert main(["convert", str(old_src), "-o", str(out), "--fs", "40"]) == 0
    old = _read(out)
    assert old == (300, 40.0)
    # the first rename is the data's: killed instead of it, the old pair stays
    assert _killed_convert(1, new_src, out, 100) == -signal.SIGKILL
    assert _read(out) == old
    # killed between the data's rename and the metadata's: the new data beside the
    # old metadata, refused (the .npy) or read without it (the CSV), naming the file
    assert _killed_convert(2, new_src, out, 100) == -signal.SIGKILL
    mixed = _read(out)
    assert isinstance(mixed, ParseError if suffix == ".npy" else UserWarning), mixed
    assert f"log{suffix}.meta.json describes" in str(mixed) and "other data" in str(mixed)
    # the next write removes the killed runs' temporaries (saying so) and publishes
    done = subprocess.run([sys.executable, "-m", "imunoise.cli", "convert", str(new_src), "-o",
                           str(out), "--fs", "100", "--no-progress"], env=_env(),
                          capture_output=True, text=True)
    assert done.returncode == 0 and "interrupted imunoise run" in done.stderr, done.stderr
    assert _read(out) == (500, 100.0)
    assert not [p for p in tmp_path.iterdir() if ".imunoise-tmp" in p.name]


def test_concurrent_converts_leave_one_whole_pair(tmp_path):
    small, large = _source(tmp_path, 300), _source(tmp_path, 500)
    out = tmp_path / "log.npy"
    command = [sys.executable, "-m", "imunoise.cli", "convert"]
    for _ in range(3):
        runs = [subprocess.Popen([*command, str(src), "-o", str(out), "--fs", fs,
                                  "--no-progress"], env=_env(), stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
                for src, fs in ((small, "40"), (large, "100"))]
        assert [r.wait() for r in runs] == [0, 0]
        assert _read(out) in ((300, 40.0), (500, 100.0))


def test_a_copied_pair_still_reads(tmp_path, capsys):
    src = _source(tmp_path, 200)
    out = tmp_path / "log.npy"
    assert main(["convert", str(src), "-o", str(out), "--fs", "40"]) == 0
    copy = tmp_path / "copy"
    copy.mkdir()
    for name in ("log.npy", "log.npy.meta.json"):  # a copy gets a new mtime: the digest decides
        (copy / name).write_bytes((tmp_path / name).read_bytes())
    assert _read(copy / "log.npy") == (200, 40.0)
    data = bytearray((copy / "log.npy").read_bytes())
    data[-1] ^= 1  # one bit of the last sample: same size, other content
    (copy / "log.npy").write_bytes(bytes(data))
    with pytest.raises(ParseError, match=r"log\.npy\.meta\.json describes .* other data"):
        imunoise.read(copy / "log.npy")
