"""Phase input (data_type="phase") for the Allan family, and the phase statistics
PDEV, MTIE and TIE rms: equal to allantools to 1e-9 at common taus."""

import warnings

import allantools as at
import imunoise
import numpy as np
import pytest
from helpers.signals import noise

#: imunoise name -> allantools function of the same definition (overlapping forms)
FAMILY = {"adev": at.oadev, "mdev": at.mdev, "tdev": at.tdev, "hdev": at.ohdev,
          "ohdev": at.ohdev, "totdev": at.totdev, "mtotdev": at.mtotdev,
          "ttotdev": at.ttotdev, "htotdev": at.htotdev, "theo1": at.theo1}
PHASE_STATS = {"pdev": at.pdev, "mtie": at.mtie, "tierms": at.tierms}
NOISES = ["white", "flicker", "walk"]


def reference(function, x, fs, taus, data_type):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(x, rate=fs, data_type=data_type, taus=taus)


def phase(kind, n, seed):
    """Phase of a power-law kind: white PM, flicker PM, white FM (walk of phase)."""
    return noise(kind, n, seed=seed) * 1e-9


def assert_same(ours, ref):
    t, dev, _err, n = ref
    np.testing.assert_allclose(ours.taus, t, rtol=1e-12)
    np.testing.assert_array_equal(ours.n, n)
    np.testing.assert_allclose(ours.dev, dev, rtol=1e-9, atol=0)


@pytest.mark.parametrize("name", sorted(FAMILY))
@pytest.mark.parametrize("kind", NOISES)
def test_the_family_with_phase_input_equals_allantools(name, kind):
    # allantools' total family loops in Python: short records keep it quick
    slow = name in ("theo1", "mtotdev", "ttotdev", "htotdev")
    x = phase(kind, 301 if slow else 4001, seed=7)
    ours = getattr(imunoise, name)(x, 10.0, data_type="phase")
    assert ours.data_type == "phase" and ours.n_samples == len(x) - 1
    assert_same(ours, reference(FAMILY[name], x, 10.0, ours.taus, "phase"))


@pytest.mark.parametrize("name", ["adev", "totdev", "theobr"])
def test_phase_input_is_the_rate_it_integrates(name):
    y = noise("flicker", 3000, seed=2)
    x = np.concatenate([[5.0], 5.0 + np.cumsum(y) / 50.0])  # an offset changes nothing
    f = getattr(imunoise, name)
    rate, ph = f(y, 50.0), f(x, 50.0, data_type="phase")
    np.testing.assert_allclose(ph.dev, rate.dev, rtol=1e-9)
    np.testing.assert_array_equal(ph.edf, rate.edf)
    assert ph.n_samples == rate.n_samples and rate.data_type == "freq"


def test_a_missing_phase_point_leaves_out_the_terms_around_it():
    x = phase("walk", 1001, seed=4)
    gapped = x.copy()
    gapped[500] = np.nan
    r = imunoise.adev(gapped, 1.0, data_type="phase", taus=np.array([1.0, 4.0]))
    # the two intervals beside point 500 are missing: terms k..k+2m that hold it go
    assert r.missing == 1
    np.testing.assert_array_equal(r.n, [999 - 3, 993 - 9])
    full = imunoise.adev(x, 1.0, data_type="phase", taus=np.array([1.0, 4.0]))
    np.testing.assert_allclose(r.dev, full.dev, rtol=0.05)


def test_data_type_errors_name_the_argument():
    with pytest.raises(ValueError, match="data_type must be one of 'freq', 'phase'; got 'rate'"):
        imunoise.adev(np.ones(10), 1.0, data_type="rate")
    with pytest.raises(ValueError, match="x as phase must have at least 2 points.*got 1"):
        imunoise.adev(np.ones(1), 1.0, data_type="phase")
    with pytest.raises(ValueError, match="sample 3 is inf"):
        imunoise.mdev(np.r_[np.zeros(3), np.inf, np.zeros(5)], 1.0, data_type="phase")
    for f in (imunoise.pdev, imunoise.mtie, imunoise.tierms):
        with pytest.raises(ValueError, match="data_type must be one of"):
            f(np.ones(10), 1.0, data_type="Phase")
    with pytest.raises(ValueError, match=r"x has 2 phase points .* \(at least 3: "):
        imunoise.mtie(np.ones(2), 1.0, data_type="phase")
    with pytest.raises(ValueError, match=r"x has 3 phase points, too few for pdev \(at least 4"):
        imunoise.pdev(np.ones(2), 1.0)


@pytest.mark.parametrize("name", sorted(PHASE_STATS))
@pytest.mark.parametrize("kind", NOISES)
@pytest.mark.parametrize("data_type", ["phase", "freq"])
def test_phase_statistics_equal_allantools(name, kind, data_type):
    x = phase(kind, 1501, seed=11) if data_type == "phase" else noise(kind, 1500, seed=12)
    ours = getattr(imunoise, name)(x, 4.0, data_type=data_type)
    assert ours.kind == name
    assert_same(ours, reference(PHASE_STATS[name], x, 4.0, "octave", data_type))


@pytest.mark.parametrize("name", sorted(PHASE_STATS))
def test_phase_statistics_every_tau_and_a_rate_offset(name):
    # phase input keeps its rate offset, as allantools: MTIE and TIE see it
    x = phase("white", 400, seed=5) + 3e-9 * np.arange(400)
    ours = getattr(imunoise, name)(x, 1.0, taus="all", data_type="phase")
    assert_same(ours, reference(PHASE_STATS[name], x, 1.0, "all", "phase"))


def test_pdev_long_m_and_channels():
    y = noise("white", 4000, seed=8, channels=2)
    taus = np.array([0.1, 0.3, 2.5, 40.0, 199.0])
    ours = imunoise.pdev(y, 10.0, taus=taus)
    for c in range(2):
        t, dev, _e, n = reference(at.pdev, y[:, c], 10.0, taus, "freq")
        np.testing.assert_allclose(ours.dev[:, c], dev, rtol=1e-9)
    assert np.all(np.isfinite(ours.ci_low)) and np.all(ours.ci_low < ours.dev)
    assert np.all(ours.dev < ours.ci_high)


def test_mtie_and_tierms_say_there_is_no_interval():
    y = noise("walk", 500, seed=1)
    for f in (imunoise.mtie, imunoise.tierms):
        r = f(y, 1.0)
        assert np.all(np.isnan(r.ci_low)) and np.all(np.isnan(r.ci_high))
        assert np.all(np.isnan(r.edf)) and not r.alpha_identified.any()


def test_phase_statistics_skip_gaps():
    x = phase("walk", 2001, seed=3)
    gapped = x.copy()
    gapped[1000] = np.nan
    taus = np.array([1.0, 8.0])
    for f in (imunoise.pdev, imunoise.mtie, imunoise.tierms):
        full = f(x, 1.0, taus=taus, data_type="phase")
        r = f(gapped, 1.0, taus=taus, data_type="phase")
        assert r.missing == 1 and np.all(r.n < full.n)
        np.testing.assert_allclose(r.dev, full.dev, rtol=0.1)
    # the windows left out are exactly those holding point 1000: m + 1 of them (TIE)
    r = imunoise.tierms(gapped, 1.0, taus=taus, data_type="phase")
    np.testing.assert_array_equal(r.n, [2000 - 2, 1993 - 9])
    with pytest.warns(UserWarning, match="longest gap-free segment, points 0 to 999"):
        imunoise.mtie(gapped, 1.0, taus=taus, data_type="phase", gaps="longest")
    with pytest.warns(UserWarning, match="splices over"):
        imunoise.pdev(gapped, 1.0, taus=taus, data_type="phase", gaps="splice")


def test_mtie_grows_with_tau_and_bounds_tie():
    y = noise("white", 5000, seed=9)
    r, t = imunoise.mtie(y, 1.0, taus="all"), imunoise.tierms(y, 1.0, taus="all")
    assert np.all(np.diff(r.dev) >= 0)
    assert np.all(r.dev >= t.dev)


def test_a_curve_without_interval_plots_on_its_own_scale():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    r = imunoise.mtie(noise("white", 2000, seed=1), 10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        low, high = r.plot().axes[0].get_ylim()
    assert low < np.nanmin(r.dev) and np.nanmax(r.dev) < high
