"""The total family and Theo1: NBS14 published values, allantools to 1e-10,
properties and bad input."""

import contextlib
import csv
import io
import warnings

import allantools as at
import imunoise
import numpy as np
import pytest
from allantools import ci as at_ci
from helpers.signals import noise

OURS = {
    "mtotdev": imunoise.mtotdev,
    "ttotdev": imunoise.ttotdev,
    "htotdev": imunoise.htotdev,
    "theo1": imunoise.theo1,
}
PEERS = {"mtotdev": at.mtotdev, "ttotdev": at.ttotdev, "htotdev": at.htotdev, "theo1": at.theo1}


def read_table(path):
    rows = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    return {row["statistic"]: row for row in csv.DictReader(rows)}


def nbs14_10(data_dir):
    lines = [
        ln
        for ln in (data_dir / "nbs14_10point.txt").read_text().splitlines()
        if ln and not ln.startswith("#")
    ]
    return np.array(lines[1].split(), dtype=float)


# --- published values -------------------------------------------------------------


@pytest.mark.parametrize(
    "name, row",
    [("mtotdev", "mtotdev_nobias"), ("ttotdev", "ttotdev_nobias")],
)
def test_nbs14_10_point_without_bias_correction(data_dir, name, row):
    expected = read_table(data_dir / "nbs14_10point_expected.csv")[row]
    r = OURS[name](nbs14_10(data_dir), 1.0, taus=np.array([1.0, 2.0]))
    want = [float(expected["dev_tau1"]), float(expected["dev_tau2"])]
    np.testing.assert_allclose(r.dev, want, rtol=1e-4)


def test_nbs14_10_point_htotdev(data_dir):
    # The published table is bias corrected (white FM, 0.995) except at m = 1,
    # where HTOT is the overlapping Hadamard deviation.
    expected = read_table(data_dir / "nbs14_10point_expected.csv")["htotdev_published"]
    y = nbs14_10(data_dir)
    want = np.array([float(expected["dev_tau1"]), float(expected["dev_tau2"])])
    corrected = imunoise.htotdev(y, 1.0, taus=np.array([1.0, 2.0]), bias_correction=True)
    np.testing.assert_allclose(corrected.dev, want, rtol=1e-4)
    plain = imunoise.htotdev(y, 1.0, taus=np.array([1.0, 2.0]))
    np.testing.assert_allclose(plain.dev, want * [1.0, np.sqrt(0.995)], rtol=1e-4)


def test_nbs14_10_point_published_with_bias_correction(data_dir):
    # SP 1065 / Stable32 table with bias correction (quoted in the csv header).
    y = nbs14_10(data_dir)
    taus = np.array([1.0, 2.0])
    r = imunoise.mtotdev(y, 1.0, taus=taus, bias_correction=True)
    np.testing.assert_allclose(r.dev, [75.50203, 75.83606], rtol=1e-4)
    r = imunoise.ttotdev(y, 1.0, taus=taus, bias_correction=True)
    np.testing.assert_allclose(r.dev, [43.59112, 87.56794], rtol=1e-4)


@pytest.mark.parametrize(
    "name, row, bias",
    [
        ("mtotdev", "mtotdev_nobias", False),
        ("ttotdev", "ttotdev_nobias", False),
        ("theo1", "theo1_nobias", False),
        # Stable32's 1000-point HTOTDEV values are bias corrected (white FM).
        ("htotdev", "htotdev", True),
    ],
)
def test_nbs14_1000_point(data_dir, name, row, bias):
    y = np.loadtxt(data_dir / "nbs14_1000_frequency.txt")
    expected = read_table(data_dir / "nbs14_1000point_expected.csv")[row]
    taus = np.array([float(expected[k]) for k in ("tau_a", "tau_b", "tau_c")])
    want = [float(expected[k]) for k in ("dev_a", "dev_b", "dev_c")]
    r = OURS[name](y, 1.0, taus=taus, bias_correction=bias)
    np.testing.assert_array_equal(r.taus, taus)
    np.testing.assert_allclose(r.dev, want, rtol=1e-4)


def test_nbs14_1000_point_published_with_bias_correction(data_dir):
    y = np.loadtxt(data_dir / "nbs14_1000_frequency.txt")
    taus = np.array([1.0, 10.0, 100.0])
    r = imunoise.mtotdev(y, 1.0, taus=taus, bias_correction=True)
    np.testing.assert_allclose(r.dev, [2.418528e-01, 6.499161e-02, 2.287774e-02], rtol=1e-4)
    r = imunoise.ttotdev(y, 1.0, taus=taus, bias_correction=True)
    np.testing.assert_allclose(r.dev, [1.396338e-01, 3.752293e-01, 1.320847e00], rtol=1e-4)


# --- allantools -------------------------------------------------------------------


def reference(name, y, fs, taus):
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        return PEERS[name](y, rate=fs, data_type="freq", taus=taus)


def assert_same(name, y, fs, taus, rtol=1e-10):
    ours = OURS[name](y, fs, taus=taus)
    t, dev, _err, n = reference(name, y, fs, taus)
    np.testing.assert_allclose(ours.taus, t, rtol=1e-12)
    np.testing.assert_array_equal(ours.n, n)
    np.testing.assert_allclose(ours.dev, dev, rtol=rtol, atol=0)
    return ours


# allantools' TTOTDEV is its MTOTDEV scaled; it is covered by the short series below.
@pytest.mark.parametrize("name", ["mtotdev", "htotdev", "theo1"])
@pytest.mark.parametrize("kind", ["white", "flicker", "walk"])
def test_matches_allantools_on_power_law_noise(name, kind):
    y = noise(kind, 800, seed=len(name) + len(kind))
    assert_same(name, y, 10.0, "octave")


@pytest.mark.parametrize("name", sorted(OURS))
def test_matches_allantools_all_taus_short_series(name):
    y = noise("walk", 40, seed=4)
    assert_same(name, y, 1.0, "all")


@pytest.mark.parametrize("name", ["mtotdev", "htotdev", "theo1"])
def test_matches_allantools_on_ten_thousand_points_with_offset(name):
    # 9.81 offset (an accelerometer z axis); a few taus keep allantools fast.
    y = noise("flicker", 10_000, seed=8) * 1e-3 + 9.81
    taus = np.array([2.0, 6.0, 20.0]) if name == "theo1" else np.array([1.0, 3.0, 16.0])
    assert_same(name, y, 1.0, taus)


@pytest.mark.parametrize("name", ["mtotdev", "htotdev", "theo1"])
def test_two_dimensional_input_matches_per_channel(name):
    y = noise("white", 600, seed=5, channels=2)
    y[:, 1] = noise("walk", 600, seed=6) + 5.0
    ours = OURS[name](y, 4.0)
    assert ours.dev.shape == (len(ours.taus), 2)
    for c in range(2):
        _t, dev, _e, n = reference(name, y[:, c], 4.0, "octave")
        np.testing.assert_allclose(ours.dev[:, c], dev, rtol=1e-10)
        np.testing.assert_array_equal(ours.n, n)
    again = OURS[name](np.asfortranarray(y), 4.0)
    np.testing.assert_array_equal(again.dev, ours.dev)


def test_mtotdev_edf_is_sp1065_table_8():
    y = noise("walk", 3000, seed=12)
    r = imunoise.mtotdev(y, 1.0)
    for i, m in enumerate(r.m):
        with contextlib.redirect_stdout(io.StringIO()):  # allantools prints here
            want = at_ci.edf_mtotdev(len(y), int(m), int(np.clip(r.alpha[i], -2, 2)))
        assert r.edf[i] == pytest.approx(max(want, 1.0), rel=1e-12)


# --- properties -------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(OURS))
def test_scale_and_offset(name):
    y = noise("flicker", 900, seed=21)
    base = OURS[name](y, 5.0)
    scaled = OURS[name](-3.0 * y + 1e3, 5.0)
    np.testing.assert_allclose(scaled.dev, 3.0 * base.dev, rtol=1e-9)
    np.testing.assert_array_equal(scaled.alpha, base.alpha)


def test_htotdev_ignores_a_linear_rate_drift():
    y = noise("white", 1000, seed=3)
    drift = y + 0.05 * np.arange(y.size)
    a = imunoise.htotdev(y, 1.0)
    b = imunoise.htotdev(drift, 1.0)
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-8)


def test_ttotdev_is_mtotdev_times_tau_over_root_three():
    y = noise("walk", 800, seed=2)
    md = imunoise.mtotdev(y, 4.0)
    td = imunoise.ttotdev(y, 4.0)
    scale = md.taus / np.sqrt(3)
    np.testing.assert_allclose(td.dev, md.dev * scale, rtol=1e-13)
    np.testing.assert_allclose(td.ci_high, md.ci_high * scale, rtol=1e-13)
    np.testing.assert_array_equal(td.edf, md.edf)


def test_total_deviations_of_white_fm_are_near_adev():
    # For white FM, MTOT ≈ MDEV, HTOT ≈ HDEV ≈ ADEV and Theo1(m) ≈ ADEV(0.75 m).
    y = noise("white", 20_000, seed=17)
    adev = imunoise.adev(y, 1.0, taus=np.array([6.0, 12.0, 24.0])).dev
    theo = imunoise.theo1(y, 1.0, taus=np.array([8.0, 16.0, 32.0])).dev
    np.testing.assert_allclose(theo, adev, rtol=0.05)
    h = imunoise.htotdev(y, 1.0, taus=np.array([8.0, 16.0]))
    np.testing.assert_allclose(h.dev, 1 / np.sqrt(h.taus), rtol=0.05)


def test_results_are_frozen_and_labelled():
    r = imunoise.theo1(noise("white", 200, seed=1), 2.0)
    assert r.kind == "theo1"
    assert np.all(r.m % 2 == 0)
    assert np.all(r.ci_low < r.dev) and np.all(r.dev < r.ci_high)
    with pytest.raises(ValueError):
        r.dev[0] = 1.0


# --- bad input --------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(OURS))
def test_bias_correction_must_be_a_bool(name):
    with pytest.raises(TypeError, match="bias_correction"):
        OURS[name](np.ones(100), 1.0, bias_correction="yes")


@pytest.mark.parametrize("name", sorted(OURS))
def test_too_short_and_non_finite(name):
    with pytest.raises(ValueError, match="too few"):
        OURS[name](np.array([1.0, 2.0]), 1.0)
    y = noise("white", 50, seed=1)
    y[7] = np.nan
    with pytest.raises(ValueError, match="1 missing samples.*cannot skip gaps"):
        OURS[name](y, 1.0)


def test_taus_out_of_range_are_dropped_with_a_warning():
    y = noise("white", 90, seed=1)
    with pytest.warns(UserWarning, match="dropped"):
        r = imunoise.mtotdev(y, 1.0, taus=np.array([1.0, 31.0, 40.0]))
    np.testing.assert_array_equal(r.m, [1])
    with pytest.warns(UserWarning, match="dropped"):
        r = imunoise.theo1(y, 1.0, taus=np.array([3.0, 4.0]))
    np.testing.assert_array_equal(r.m, [4])


@pytest.mark.parametrize("name", ["mtotdev", "htotdev", "theo1"])
def test_matches_allantools_at_long_taus_of_a_random_walk(name):
    # Long taus go through the block expansions (rust/allan/reflected.rs for
    # m ≥ 16, rust/allan/theo1.rs for m ≥ 256); a random walk on a 9.81 offset is
    # where an expansion in prefix sums would lose digits.
    y = np.cumsum(noise("white", 1500, seed=21)) * 1e-3 + 9.81
    taus = [256.0, 600.0, 1000.0, 1498.0] if name == "theo1" else [16.0, 64.0, 250.0, 499.0]
    assert_same(name, y, 1.0, np.array(taus), rtol=1e-10)
