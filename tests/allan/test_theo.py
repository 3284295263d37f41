"""ThêoBR and ThêoH: direct transcriptions of the definitions (NIST SP 1065 §5.2.15-16,
Howe 2006), the same definitions assembled from allantools' oadev and theo1, the
published Theo1 bias by noise type, properties and bad input."""

import contextlib
import io
import os
import pathlib
import signal
import subprocess
import sys
import time
import warnings

import allantools as at
import imunoise
import numpy as np
import pytest
from helpers.signals import noise
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from imunoise.cli import main

# --- direct transcription of the definitions (plain loops, phase in samples) ------------


def phase(y):
    """x_0 = 0, x_k = Σ_{i<k} (y_i − ȳ): N = n + 1 points, in units of τ0."""
    y = np.asarray(y, dtype=float)
    return np.concatenate([[0.0], np.cumsum(y - y.mean())])


def naive_avar(x, m):
    n = len(x)
    total = sum((x[i + 2 * m] - 2 * x[i + m] + x[i]) ** 2 for i in range(n - 2 * m))
    return total / (2 * m * m * (n - 2 * m))


def naive_theo1(x, m):
    # SP 1065 eq. 30 with τ0 = 1: the inner sum over δ written out, vectorised over i.
    n = len(x)
    h = m // 2
    i = np.arange(n - m)
    total = 0.0
    for d in range(h):
        a = x[i] - x[i - d + h] + x[i + m] - x[i + d + h]
        total += np.sum(a * a) / (h - d)
    return total / (0.75 * (n - m) * m * m)


def naive_kappa(x):
    n = int(np.floor(0.1 * len(x) / 3 - 3))
    ratios = [naive_avar(x, 9 + 3 * i) / naive_theo1(x, 12 + 4 * i) for i in range(n + 1)]
    return sum(ratios) / (n + 1)


@pytest.mark.parametrize("kind", ["white", "flicker", "walk"])
def test_theobr_is_the_definition(kind):
    y = noise(kind, 300, seed=len(kind))
    x = phase(y)
    kappa = naive_kappa(x)
    r = imunoise.theobr(y, 2.0, taus="all")
    np.testing.assert_array_equal(r.m, np.arange(10, 301, 2))  # even 10 <= m <= N - 1
    np.testing.assert_allclose(r.taus, 0.75 * r.m / 2.0, rtol=1e-15)
    want = [np.sqrt(kappa * naive_theo1(x, m)) for m in r.m[::7]]
    np.testing.assert_allclose(r.dev[::7], want, rtol=1e-10)
    np.testing.assert_array_equal(r.n, (301 - r.m) * (r.m // 2))


def test_theoh_is_the_definition_on_all_taus():
    y = noise("flicker", 150, seed=2)
    x = phase(y)
    kappa = naive_kappa(x)
    r = imunoise.theoh(y, 1.0, taus="all")
    k = 15  # the largest tau <= 10 % of T = 150 s
    avar = r.taus * r.fs == r.m
    np.testing.assert_array_equal(r.m[avar], np.arange(1, k + 1))
    theo_m = np.arange(22, 151, 2)  # even m with 0.75 m > k, up to N - 1
    np.testing.assert_array_equal(r.m[~avar], theo_m)
    np.testing.assert_allclose(r.taus[~avar], 0.75 * theo_m)
    want = [naive_avar(x, m) for m in range(1, k + 1)]
    want += [kappa * naive_theo1(x, m) for m in theo_m]
    np.testing.assert_allclose(r.var, want, rtol=1e-10)
    assert np.all(np.diff(r.taus) > 0)


# --- the definitions assembled from allantools' own oadev and theo1 ------------------------


def _quiet(fn, *args, **kwargs):
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        return fn(*args, **kwargs)


@pytest.mark.parametrize("kind", ["white", "walk"])
def test_theobr_from_allantools_pieces(kind):
    # allantools (2024.06) has no ThêoBR; its oadev and theo1 give the bias ratio.
    y = noise(kind, 400, seed=7) * 1e-3 + 9.81
    fs = 5.0
    n = (len(y) + 1) // 30 - 3
    i = np.arange(n + 1)
    _t, ad, _e, _n = _quiet(at.oadev, y, rate=fs, data_type="freq", taus=(9 + 3 * i) / fs)
    _t, th, _e, _n = _quiet(at.theo1, y, rate=fs, data_type="freq", taus=(12 + 4 * i) / fs)
    kappa = np.mean(ad**2 / th**2)
    ms = np.array([10.0, 16.0, 64.0, 200.0, 400.0])
    t1, dev1, _e, n1 = _quiet(at.theo1, y, rate=fs, data_type="freq", taus=ms / fs)
    r = imunoise.theobr(y, fs, taus=0.75 * t1)
    np.testing.assert_array_equal(r.m, ms)
    np.testing.assert_allclose(r.dev, np.sqrt(kappa) * dev1, rtol=1e-10)
    np.testing.assert_array_equal(r.n, n1)


# --- published Theo1 bias: what the ratio has to find -------------------------------------

#: SP 1065 / Howe 2006: AVAR/Theo1 = a + b/m^c by noise type (white FM: 1).
PUBLISHED_BIAS = {
    "white": (1.0, 0.0, 1.0),
    "flicker": (1.87, -1.05, 0.79),
    "walk": (2.70, -1.53, 0.85),
}


@pytest.mark.parametrize("kind", ["white", "flicker", "walk"])
def test_bias_ratio_finds_the_published_theo1_bias(kind):
    n_samples = 3000
    a, b, c = PUBLISHED_BIAS[kind]
    m = 12 + 4 * np.arange((n_samples + 1) // 30 - 2)
    expected = np.mean(a + b / m**c)
    kappas = []
    for seed in range(4):
        y = noise(kind, n_samples, seed=seed)
        br = imunoise.theobr(y, 1.0, taus=np.array([30.0]))
        t1 = imunoise.theo1(y, 1.0, taus=br.m.astype(float))
        kappas.append(br.var[0] / t1.var[0])
    assert np.mean(kappas) == pytest.approx(expected, rel=0.1)


def _noise_type(kind, n, seed):
    """Rate samples of white PM (differenced white phase), white FM, flicker FM or
    random-walk FM."""
    if kind == "white_pm":
        return np.diff(noise("white", n + 1, seed=seed))
    return noise({"white_fm": "white", "flicker_fm": "flicker", "rw_fm": "walk"}[kind], n,
                 seed=seed)


@pytest.mark.parametrize("kind", ["white_pm", "white_fm", "flicker_fm", "rw_fm"])
def test_theobr_equals_the_definition_at_random_factors(kind):
    # The bias ratio comes from the exact all-factor sweep (63 Theo1 factors up to
    # m = 264 here); ThêoBR is κ·Theo1 at each factor, within 1e-9 of the definition.
    y = _noise_type(kind, 2000, seed=7)
    x = phase(y)
    kappa = naive_kappa(x)
    r = imunoise.theobr(y, 1.0, taus="all")
    pick = np.random.default_rng(len(kind)).choice(len(r.m), size=24, replace=False)
    want = [kappa * naive_theo1(x, int(r.m[i])) for i in pick]
    np.testing.assert_allclose(r.var[pick], want, rtol=1e-9)


def test_the_sp1065_ladder_is_its_printed_definition():
    # n = floor(N/6) - 3 ratios (SP 1065 eq. 33 as printed), stopping at the last AVAR
    # with a term: N = 601 phase points give n = 97 (the last AVAR, m = 300, has 1).
    y = _noise_type("rw_fm", 600, seed=5)
    x = phase(y)
    n = min(len(x) // 6 - 3, ((len(x) - 1) // 2 - 9) // 3)
    assert n == 97
    kappa = np.mean([naive_avar(x, 9 + 3 * i) / naive_theo1(x, 12 + 4 * i)
                     for i in range(n + 1)])
    r = imunoise.theobr(y, 1.0, taus=[30.0, 90.0], ratio_ladder="sp1065")
    want = [kappa * naive_theo1(x, int(m)) for m in r.m]
    np.testing.assert_allclose(r.var.ravel(), want, rtol=1e-9)
    default = imunoise.theobr(y, 1.0, taus=[30.0, 90.0])
    assert not np.allclose(r.var, default.var, rtol=1e-6)


@pytest.mark.parametrize("fn", [imunoise.theobr, imunoise.theoh])
def test_a_ratio_block_takes_the_ratio_from_block_averages(fn):
    # The fast ThêoBR: kappa from every 4th phase point (the samples averaged in blocks
    # of 4), Theo1 still from every sample.
    y = _noise_type("flicker_fm", 1600, seed=9)
    x = phase(y)
    exact = fn(y, 1.0)
    fast = fn(y, 1.0, ratio_block=4)
    theo = exact.taus * 1.0 < exact.m  # ThêoBR points (all of theobr's)
    ratio = fast.var[theo] / exact.var[theo]
    np.testing.assert_allclose(ratio, naive_kappa(x[::4]) / naive_kappa(x), rtol=1e-9)
    np.testing.assert_array_equal(fast.var[~theo], exact.var[~theo])


def test_bad_ratio_options_name_the_argument():
    y = np.random.default_rng(0).normal(size=500)
    with pytest.raises(ValueError, match="ratio_ladder must be one of"):
        imunoise.theobr(y, 1.0, ratio_ladder="stable32")
    with pytest.raises(ValueError, match=r"ratio_block must be >= 1; got 0"):
        imunoise.theoh(y, 1.0, ratio_block=0)
    with pytest.raises(TypeError, match="ratio_block must be an integer"):
        imunoise.theobr(y, 1.0, ratio_block=2.0)
    with pytest.raises(ValueError, match=r"ratio_block <= 5\); got 6"):
        imunoise.theobr(y, 1.0, ratio_block=6)


_INTERRUPTED_CHILD = """
import sys, time
import numpy as np
import imunoise
y = np.random.default_rng(0).normal(size=1_000_000)
print("ready", flush=True)
t0 = time.perf_counter()
try:
    imunoise.theoh(y, 40.0)
except KeyboardInterrupt:
    print(f"interrupted after {time.perf_counter() - t0:.2f} s", flush=True)
    sys.exit(0)
print("finished", flush=True)
sys.exit(1)
"""


def _interrupt_after_ready(args, env_path):
    env = dict(os.environ, PYTHONPATH=env_path)
    # A shell's background job inherits SIGINT ignored, and Python then installs no
    # KeyboardInterrupt: the child gets Ctrl-C's default disposition back.
    proc = subprocess.Popen([sys.executable, *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(1.5)  # well inside the computation (tens of seconds on 10^6 samples)
    proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()  # no-op once it has exited; never leave a run behind
    return proc.returncode, out, err


def _python_path():
    return str(pathlib.Path(imunoise.__file__).parent.parent) + ":" + ":".join(sys.path)


def test_ctrl_c_stops_theoh():
    code, out, err = _interrupt_after_ready(["-c", _INTERRUPTED_CHILD], _python_path())
    assert code == 0, (out, err)
    assert out.startswith("interrupted after"), (out, err)


def test_ctrl_c_in_the_cli_exits_130(tmp_path):
    log = tmp_path / "big.csv"
    # Long enough to be running 1.5 s in on the fastest path (IFMA: ≈ 2 s for 400,000).
    y = np.random.default_rng(1).normal(size=(1_000_000, 3))
    np.savetxt(log, y, delimiter=",", header="gyro_x,gyro_y,gyro_z", comments="", fmt="%.6f")
    child = (
        "import sys, imunoise.allan as allan\n"
        "from imunoise.cli import main\n"
        "real = allan.theoh\n"
        "def announced(*a, **k):\n"
        "    print('ready', flush=True)\n"
        "    return real(*a, **k)\n"
        "allan.theoh = announced\n"
        f"sys.exit(main(['adev', {str(log)!r}, '--fs', '40', '--kind', 'theoh']))\n"
    )
    code, out, err = _interrupt_after_ready(["-c", child], _python_path())
    assert code == 130, (out, err)
    assert err.strip() == "imunoise: interrupted"


# --- properties ---------------------------------------------------------------------------


@pytest.mark.parametrize("fn", [imunoise.theobr, imunoise.theoh])
def test_scale_and_offset(fn):
    y = noise("flicker", 900, seed=21)
    base = fn(y, 5.0)
    scaled = fn(-3.0 * y + 1e3, 5.0)
    np.testing.assert_allclose(scaled.dev, 3.0 * base.dev, rtol=1e-9)
    np.testing.assert_array_equal(scaled.alpha, base.alpha)
    np.testing.assert_array_equal(scaled.taus, base.taus)


@settings(max_examples=25, deadline=None)
@given(
    y=hnp.arrays(
        np.float64,
        st.integers(89, 260),
        elements=st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False),
    ),
    scale=st.floats(1e-3, 1e3),
    offset=st.floats(-1e3, 1e3),
)
def test_scale_and_offset_invariance_on_any_data(y, scale, offset):
    if np.ptp(y) == 0:
        return
    for fn in (imunoise.theobr, imunoise.theoh):
        base = fn(y, 10.0)
        moved = fn(scale * y + offset, 10.0)
        # Adding the offset rounds each sample to ~eps·|offset|: that much may be lost.
        rounding = 1e-14 * (abs(offset) + scale * np.max(np.abs(y)))
        # A result carries variances: a deviation below √(smallest normal double) ≈
        # 1.5e-154 has a subnormal variance and keeps few digits (hypothesis found
        # one sample of 2.2e-160 among zeros, scaled by 0.005: a variance of 1e-324).
        subnormal = np.sqrt(np.finfo(float).tiny) * max(scale, 1.0)
        np.testing.assert_allclose(
            moved.dev, scale * base.dev, rtol=1e-7,
            atol=1e-9 * scale * np.ptp(y) + rounding + subnormal
        )


def test_white_fm_theobr_agrees_with_the_allan_deviation():
    # White FM, σ_y(τ) = 1/√τ: the 95 % intervals of ThêoBR hold the true value and
    # the Allan deviation of the same data at the same taus.
    y = noise("white", 6000, seed=17)
    taus = np.array([12.0, 24.0, 48.0, 96.0, 192.0])
    br = imunoise.theobr(y, 1.0, taus=taus, confidence=0.95)
    np.testing.assert_array_equal(br.taus, taus)
    ad = imunoise.adev(y, 1.0, taus=taus)
    assert np.all((br.ci_low < 1 / np.sqrt(taus)) & (1 / np.sqrt(taus) < br.ci_high))
    assert np.all((br.ci_low < ad.dev) & (ad.dev < br.ci_high))


def test_theobr_intervals_cover_the_true_deviation():
    # 68 % intervals over 40 white-FM records: with Theo1's EDF alone (Stable32's
    # choice) the short taus were covered in only 30-45 % of records, because every
    # tau shares the scatter of the bias ratio; ThêoBR's EDF includes it.
    taus = np.array([12.0, 48.0, 192.0])
    rng = np.random.default_rng(2024)
    covered = []
    for _ in range(40):
        r = imunoise.theobr(rng.normal(size=1000), 1.0, taus=taus)
        covered.append((r.ci_low < 1 / np.sqrt(taus)) & (1 / np.sqrt(taus) < r.ci_high))
    coverage = np.mean(covered, axis=0)
    assert np.all((coverage > 0.5) & (coverage < 0.9)), coverage
    t1 = imunoise.theo1(rng.normal(size=1000), 1.0, taus=r.m.astype(float))
    assert np.all(r.edf < t1.edf)


def test_theoh_is_oadev_below_the_switch_and_theobr_above():
    y = noise("walk", 2000, seed=9)
    h = imunoise.theoh(y, 2.0)
    k = 128 / 2.0  # largest octave tau <= 10 % of T = 1000 s
    avar = h.taus <= k
    assert h.taus[avar].max() == k
    o = imunoise.adev(y, 2.0, taus=h.taus[avar])
    np.testing.assert_allclose(h.dev[avar], o.dev, rtol=1e-12)
    np.testing.assert_array_equal(h.edf[avar], o.edf)
    np.testing.assert_array_equal(h.n[avar], o.n)
    br = imunoise.theobr(y, 2.0, taus=h.taus[~avar])
    np.testing.assert_array_equal(br.m, h.m[~avar])
    np.testing.assert_allclose(h.dev[~avar], br.dev, rtol=1e-12)
    np.testing.assert_array_equal(h.n[~avar], br.n)
    assert np.all(h.taus[~avar] > k)
    np.testing.assert_array_equal(h.m[~avar], [256, 512, 1024])


def test_theoh_explicit_taus_split_at_ten_percent():
    y = noise("white", 1000, seed=4)
    taus = np.array([1.0, 50.0, 100.0, 120.0, 300.0])  # T = 1000 s, 10 % = 100 s
    h = imunoise.theoh(y, 1.0, taus=taus)
    np.testing.assert_array_equal(h.m, [1, 50, 100, 160, 400])
    np.testing.assert_allclose(h.taus, [1, 50, 100, 120, 300])


@pytest.mark.parametrize("fn", [imunoise.theobr, imunoise.theoh])
def test_two_dimensional_input_matches_per_channel(fn):
    y = noise("white", 700, seed=5, channels=2)
    y[:, 1] = noise("walk", 700, seed=6) + 5.0
    both = fn(y, 4.0)
    assert both.dev.shape == (len(both.taus), 2)
    for c in range(2):
        one = fn(y[:, c], 4.0)
        np.testing.assert_allclose(both.dev[:, c], one.dev, rtol=1e-13)
        np.testing.assert_array_equal(both.edf[:, c], one.edf)
    again = fn(np.asfortranarray(y), 4.0)
    np.testing.assert_array_equal(again.dev, both.dev)


@pytest.mark.parametrize("fn, kind", [(imunoise.theobr, "theobr"), (imunoise.theoh, "theoh")])
def test_results_are_frozen_and_labelled(fn, kind):
    r = fn(noise("white", 500, seed=1), 2.0)
    assert r.kind == kind and r.overlapping
    assert np.all(r.ci_low < r.dev) and np.all(r.dev < r.ci_high)
    assert np.all(r.edf >= 1.0)
    with pytest.raises(ValueError):
        r.dev[0] = 1.0


@pytest.mark.parametrize("kind", ["theoh", "mtotdev", "ttotdev", "htotdev", "theo1"])
def test_cli_prints_the_long_tau_family(tmp_path, capsys, kind):
    y = noise("white", 300, seed=3, channels=3)
    log = tmp_path / "log.csv"
    np.savetxt(log, y, delimiter=",", header="gyro_x,gyro_y,gyro_z", comments="")
    assert main(["adev", str(log), "--fs", "10", "--kind", kind]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines()[2:]]
    r = getattr(imunoise, kind)(imunoise.read(log, fs=10.0).gyro, 10.0)
    np.testing.assert_allclose([float(row[0]) for row in rows], r.taus, rtol=1e-5)
    # deviation and bounds rounded together to the interval (GUM, numbers.interval_cells)
    assert [row[2:5] for row in rows] == [
        list(imunoise.display.interval_cells(r.dev[i, 0], r.ci_low[i, 0], r.ci_high[i, 0]))
        for i in range(len(r.taus))]
    np.testing.assert_allclose([float(row[2]) for row in rows], r.dev[:, 0], rtol=0.02)


# --- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize("fn", [imunoise.theobr, imunoise.theoh])
def test_too_short_non_finite_and_bad_arguments(fn):
    with pytest.raises(ValueError, match="88 samples, too few.*at least 89"):
        fn(np.ones(88), 1.0)
    fn(noise("white", 89, seed=1), 1.0)
    y = noise("white", 200, seed=1)
    y[7] = np.nan
    with pytest.raises(ValueError, match="1 missing samples.*cannot skip gaps"):
        fn(y, 1.0)
    y = noise("white", 200, seed=1)
    with pytest.raises(ValueError, match="confidence"):
        fn(y, 1.0, confidence=1.5)
    with pytest.raises(ValueError, match="fs"):
        fn(y, -1.0)
    with pytest.raises(ValueError, match="taus"):
        fn(y, 1.0, taus="weekly")
    with pytest.raises(TypeError):
        fn(y, 1.0, bias_correction=True)  # bias removal is the statistic itself


def test_theobr_drops_taus_out_of_range_with_a_warning():
    y = noise("white", 200, seed=1)
    with pytest.warns(UserWarning, match="2 of 4 taus dropped"):
        r = imunoise.theobr(y, 1.0, taus=np.array([1.5, 12.0, 100.0, 400.0]))
    np.testing.assert_array_equal(r.m, [16, 134])
    with pytest.warns(UserWarning, match="dropped"), pytest.raises(ValueError, match="none"):
        imunoise.theobr(y, 1.0, taus=np.array([1.0]))


def test_long_records_warn_before_a_slow_run(monkeypatch):
    import imunoise.allan as allan_module

    def refuse(*_args, **_kwargs):
        raise RuntimeError("kernel reached")

    monkeypatch.setattr(allan_module._core_allan, "analyse", refuse)
    monkeypatch.setattr(allan_module._core_allan, "analyse_plan", refuse)
    x = np.zeros(5_000_000)
    for fn in (imunoise.theobr, imunoise.theoh):
        with pytest.warns(UserWarning, match=r"N/30 averaging factors.*minutes.*ratio_block"):
            with pytest.raises(RuntimeError, match="kernel reached"):
                fn(x, 40.0)
