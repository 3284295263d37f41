"""Outputs fixed before a refactor must not move: a set of results on real data,
compared to the last bit (Rust kernels) or to 1e-12 (scipy-based statistics), on
every instruction-set level of the Rust kernels that this CPU can run.

Regenerate only when a change is meant to alter results, and say why in the commit:
``python tests/test_golden.py --write``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import imunoise
import numpy as np
import pytest
from imunoise._support import cpu as _cpu

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

GOLDEN = Path(__file__).parent / "data" / "golden.npz"
DATA = Path(imunoise.__file__).parent / "data" / "vn100_stationary_5min.txt"
RUGGED = Path(__file__).parent / "data" / "rugged_0513test.txt"
WAVES = Path(__file__).parent / "data" / "waves_F00294.bin"

STATISTICS = ("adev", "mdev", "hdev", "tdev", "totdev", "mtotdev", "htotdev", "ttotdev",
              "theo1", "theobr", "theoh")
#: Keys computed through scipy or numpy reductions whose last bits may follow the
#: installed version; the rest come from the Rust core and must match exactly.
_LOOSE_PREFIXES = ("describe.", "distribution.")
#: Keys that go through Theo1's FFT sliding sums (m ≥ 256): the FFT library's SSE
#: kernels, which the scalar level uses, round differently from its AVX ones.
_FFT_PREFIXES = ("theo1.", "theobr.", "theoh.")
#: Relative agreement of those keys at the scalar level (measured: 1.2e-15).
_FFT_RTOL = 1e-14


def outputs() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    log = imunoise.read(DATA)
    out["log.gyro"] = log.gyro
    out["log.accel"] = log.accel
    out["log.issues"] = np.array([log.issues.counts[k] for k in sorted(log.issues.counts)])
    for name in STATISTICS:
        x = log.gyro if name not in ("theo1", "theobr", "theoh") else log.gyro[:2000]
        r = getattr(imunoise, name)(x, log.fs)
        out[f"{name}.taus"] = r.taus
        out[f"{name}.dev"] = r.dev
        out[f"{name}.edf"] = r.edf
        out[f"{name}.ci"] = np.stack([r.ci_low, r.ci_high])
    r = imunoise.adev(log.gyro, log.fs, overlapping=False, taus="all")
    out["adev_nonoverlapping.dev"] = r.dev
    gapped = log.accel.copy()
    gapped[1000:1040] = np.nan
    gapped[5000:5003, 1] = np.nan
    for gaps in ("skip", "longest", "splice"):
        r = imunoise.adev(gapped, log.fs, gaps=gaps)
        out[f"gaps.{gaps}.dev"] = r.dev
        out[f"gaps.{gaps}.edf"] = r.edf
    model = imunoise.fit(imunoise.adev(log.gyro, log.fs, taus="decade"))
    parts = model.components  # the fit's own parameters (the golden set predates 0.2's split)
    out["fit.ieee"] = np.array([[getattr(parts, t)[i] for t in "QNBKR"]
                                for i in range(model.channels)])
    out["fit.gm_sigma"] = np.asarray(parts.gm_sigma, dtype=float)
    out["fit.gm_tau"] = np.asarray(parts.gm_tau, dtype=float)
    out["fit.cov"] = np.asarray(parts.cov, dtype=float)
    d = imunoise.describe(log)
    out["describe.rows"] = np.array([[row[k] for k in ("mean", "std", "var")]
                                     for row in d.rows()], dtype=float)
    dist = imunoise.distribution(log.gyro[:, 0])
    out["distribution.edges"] = dist.edges
    out["distribution.counts"] = dist.counts
    rugged = imunoise.read(RUGGED)
    out["rugged.accel"] = rugged.accel
    out["rugged.time_valid"] = np.asarray(rugged.valid, dtype=bool)
    waves = imunoise.read(WAVES)
    out["waves.gyro"] = waves.gyro
    out["waves.issues"] = np.array([waves.issues.counts[k] for k in sorted(waves.issues.counts)])
    return out


def _compare(got: dict[str, np.ndarray], fft_rtol: float | None) -> None:
    if not GOLDEN.exists():
        pytest.fail(f"{GOLDEN} is missing; run python tests/test_golden.py --write")
    expected = dict(np.load(GOLDEN))
    assert sorted(got) == sorted(expected)
    for key, want in expected.items():
        have = np.asarray(got[key])
        assert have.shape == want.shape, key
        if key.startswith(_LOOSE_PREFIXES):
            np.testing.assert_allclose(have, want, rtol=1e-12, atol=0, err_msg=key)
        elif fft_rtol is not None and key.startswith(_FFT_PREFIXES):
            np.testing.assert_allclose(have, want, rtol=fft_rtol, atol=0, err_msg=key)
        else:
            assert np.array_equal(have, want, equal_nan=True), f"{key} moved"


def test_outputs_match_the_golden_set():
    _compare(outputs(), fft_rtol=_FFT_RTOL if _cpu.level() == "scalar" else None)


@pytest.mark.parametrize("level", ["scalar", "avx2", "avx512", "ifma"])
def test_every_cpu_path_gives_the_golden_digits(level):
    """The kernels forced to each level give the same digits (the golden set was
    written at the avx2 level or above): CI on any x86-64 runs every path its CPU has."""
    if level not in _cpu.available_levels():
        pytest.skip(f"this CPU runs up to {_cpu.available_levels()[-1]}, not {level}")
    with _cpu.forced(level):
        assert _cpu.level() == level
        got = outputs()
    _compare(got, fft_rtol=_FFT_RTOL if level == "scalar" else None)


if __name__ == "__main__":
    if "--write" in sys.argv:
        if _cpu.level() == "scalar":
            sys.exit("write the golden set at the avx2 level or above (see _FFT_PREFIXES)")
        np.savez_compressed(GOLDEN, **outputs())
        print(f"wrote {GOLDEN}")
