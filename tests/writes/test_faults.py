"""kill -9 and Ctrl-C at random moments of `imunoise convert` and `imunoise report`: a
few runs of benches/faults.py (which runs >= 50 of each): every output file is the
old one or the complete new one, SIGINT exits 130 and leaves no temporary, and what
kill -9 leaves is removed, with a warning, by the next run.

Each run starts Python (about 1.5 s); the report runs (three reports, 15-20 s) run
only with IMUNOISE_FAULTS=1."""

import importlib.util
import os
import signal
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


@pytest.fixture(scope="module")
def faults():
    spec = importlib.util.spec_from_file_location("faults", ROOT / "benches" / "faults.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["faults"] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


#: An outcome of the output, not of the process: a run killed between the data's and
#: its metadata's renames also has its process outcome ("SIGKILL: killed").
OUTPUT_STATES = ("new data, old metadata: refused by the reader",)


def _check(summary, runs):
    assert summary.runs == runs
    assert not summary.failures, summary.text()
    assert sum(v for k, v in summary.outcomes.items() if k not in OUTPUT_STATES) == runs


def test_signals_during_convert(faults, tmp_path):
    sources = [(DATA / "waves_F00294.bin", []), (DATA / "rugged_0513test.txt", ["--fs", "40"])]
    # the two outputs with metadata beside them (compared as pairs)
    summary = faults.convert_faults(4, 1, tmp_path, quiet=True, sources=sources,
                                    outputs=(".csv", ".npy"))
    _check(summary, 4)


@pytest.mark.skipif(not os.environ.get("IMUNOISE_FAULTS"), reason="slow: IMUNOISE_FAULTS=1")
def test_signals_during_report(faults, tmp_path):
    summary = faults.report_faults(2, 2, tmp_path, quiet=True,
                                   inputs=(DATA / "waves_F00294.bin", DATA / "rugged_0513test.txt"))
    _check(summary, 2)


def test_an_interrupted_start_is_told_apart_from_a_failure(faults):
    assert faults._outcome(signal.SIGINT, 130) == "SIGINT: exit 130"
    assert "UNEXPECTED" in faults._outcome(signal.SIGINT, 1, "Traceback ... ValueError")
    assert "UNEXPECTED" in faults._outcome(signal.SIGKILL, 2)
