"""Gaps: NaN marks a missing sample; the difference estimators leave out every term
touching one, the total family refuses, and gaps= chooses the way out."""

import warnings

import allantools
import imunoise
import numpy as np
import pytest
from helpers.signals import noise
from hypothesis import given, settings
from hypothesis import strategies as st

SKIPPING = {
    "adev": (imunoise.adev, True),
    "adev-no": (imunoise.adev, False),
    "hdev": (imunoise.hdev, True),
    "hdev-no": (imunoise.hdev, False),
    "mdev": (imunoise.mdev, None),
    "tdev": (imunoise.tdev, None),
}
REFUSING = [
    imunoise.totdev,
    imunoise.mtotdev,
    imunoise.ttotdev,
    imunoise.htotdev,
    imunoise.theo1,
    imunoise.theobr,
    imunoise.theoh,
]


def skipping_reference(y, kind, m, overlapping):
    """(variance, terms) from the SP 1065 definitions on rate samples y, leaving out
    every term whose window holds a NaN. ȳ_k is the mean of y[k:k+m]."""
    ybar = lambda k: y[k : k + m].mean()  # noqa: E731
    if kind in ("adev", "hdev"):
        order = 2 if kind == "adev" else 3
        window, stride = order * m, (1 if overlapping else m)
        divisor = 2.0 if kind == "adev" else 6.0

        def term(k):
            if kind == "adev":
                return ybar(k + m) - ybar(k)  # eq. 7
            return ybar(k + 2 * m) - 2 * ybar(k + m) + ybar(k)  # eq. 18

    else:  # modified Allan, eq. 14: the mean of m overlapping first differences
        window, stride, divisor = 3 * m - 1, 1, 2.0

        def term(k):
            return np.mean([ybar(i + m) - ybar(i) for i in range(k, k + m)])

    total, terms = 0.0, 0
    for k in range(0, len(y) - window + 1, stride):
        if np.isnan(y[k : k + window]).any():
            continue
        total += term(k) ** 2
        terms += 1
    return total / (divisor * terms) if terms else np.nan, terms


def with_gaps(y, gaps):
    y = y.copy()
    for start, length in gaps:
        y[start : start + length] = np.nan
    return y


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(40, 260),
    gaps=st.lists(st.tuples(st.integers(0, 259), st.integers(1, 12)), max_size=6),
    seed=st.integers(0, 2**16),
    name=st.sampled_from(sorted(SKIPPING)),
)
def test_skipping_equals_the_definition(n, gaps, seed, name):
    func, overlapping = SKIPPING[name]
    kind = name.split("-")[0].replace("tdev", "mdev")
    y = with_gaps(np.random.default_rng(seed).normal(size=n) + 5.0, gaps)
    if np.isnan(y).all():
        return
    kwargs = {} if overlapping is None else {"overlapping": overlapping}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            r = func(y, 1.0, taus=[1, 2, 3, 5], **kwargs)
        except ValueError as exc:
            assert "fewer than 2 terms at every tau" in str(exc)
            return
    for i, m in enumerate(r.m):
        var, terms = skipping_reference(y, kind, int(m), overlapping is not False)
        assert r.n[i] == terms
        if name == "tdev":
            var *= r.taus[i] ** 2 / 3.0
        assert r.var[i] == pytest.approx(var, rel=1e-9)
        assert r.edf[i] > 0
    assert r.missing == np.isnan(y).sum()


def test_gap_free_results_do_not_depend_on_gaps():
    y = noise("white", 5000, seed=2)
    for func in (imunoise.adev, imunoise.mdev, imunoise.hdev, imunoise.totdev):
        base = func(y, 10.0)
        assert base.missing == 0 and base.gaps == "skip"
        for gaps in ("longest", "splice"):
            other = func(y, 10.0, gaps=gaps)
            for field in ("var", "n", "edf", "ci_low", "alpha"):
                np.testing.assert_array_equal(getattr(other, field), getattr(base, field))


def test_gapped_channels_are_each_their_own_record():
    rng = np.random.default_rng(4)
    x = rng.normal(size=(3000, 2))
    x[100:130, 0] = np.nan
    x[2000, 1] = np.nan
    r = imunoise.adev(x, 1.0, taus=[1, 8, 64])
    assert r.n.shape == (3, 2)
    np.testing.assert_array_equal(r.missing, [30, 1])
    for c in range(2):
        alone = imunoise.adev(x[:, c], 1.0, taus=[1, 8, 64])
        np.testing.assert_array_equal(r.var[:, c], alone.var)
        np.testing.assert_array_equal(r.n[:, c], alone.n)
    # The same gaps in every channel: one n per tau.
    x[2000, 1] = 0.0
    x[:, 1] = np.where(np.isnan(x[:, 0]), np.nan, x[:, 1])
    assert imunoise.adev(x, 1.0).n.ndim == 1


def test_gradev_agrees_at_one_sample_and_uses_more_terms_beyond():
    # allantools.gradev takes phase with missing *readings*: the phase across a gap
    # is known, so a term needs only its three phase points x_k, x_k+m, x_k+2m. Rate
    # samples y_k = (x_k+1 − x_k)·fs lose the phase across a gap, so here a term
    # needs every sample of its window. At m = 1 the two rules are the same.
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.normal(size=4001)) * 1e-9
    x[[50, 51, 52, 700, 1999, 3000]] = np.nan
    x[2500:2600] = np.nan
    fs = 1.0
    y = np.diff(x) * fs
    ours = imunoise.adev(y, fs, taus=[1, 4, 16])
    _, dev, _, n = allantools.gradev(x, rate=fs, data_type="phase", taus=[1, 4, 16])
    assert ours.n[0] == n[0]
    assert ours.dev[0] == pytest.approx(dev[0], rel=1e-10)
    assert np.all(ours.n[1:] < n[1:])


def test_a_300_s_gap_stays_within_the_confidence_interval():
    fs = 100.0
    y = noise("white", 200_000, seed=12) * 0.01 + np.cumsum(noise("white", 200_000, seed=13)) * 1e-5
    full = imunoise.adev(y, fs)
    gapped = y.copy()
    gapped[85_000:115_000] = np.nan
    r = imunoise.adev(gapped, fs)
    assert r.missing == 30_000
    common = np.isin(full.m, r.m)
    assert common.sum() == len(r.m) and len(r.m) >= len(full.m) - 1
    assert np.all(r.n < full.n[common])
    # Fewer terms, fewer degrees of freedom (where the noise type is the same: it is
    # identified on the longest gap-free run, 42.5 % of the record).
    same = r.alpha == full.alpha[common]
    assert same.sum() >= len(r.m) - 2
    assert np.all(r.edf[same] < full.edf[common][same])
    assert np.all((r.ci_low <= full.dev[common]) & (full.dev[common] <= r.ci_high))


def test_total_family_refuses_gaps_and_names_the_way_out():
    y = noise("white", 400, seed=3)
    y[10:15] = np.nan
    for func in REFUSING:
        name = func.__name__
        with pytest.raises(ValueError) as info:
            func(y, 1.0)
        assert str(info.value) == (
            f"x has 5 missing samples (NaN); {name} cannot skip gaps: "
            "pass gaps='longest' or gaps='splice'"
        )
        with pytest.warns(UserWarning, match="longest gap-free segment"):
            func(y, 1.0, gaps="longest")


def test_longest_and_splice_say_what_they_did():
    y = noise("white", 1000, seed=5)
    y[600:650] = np.nan
    y[100] = np.nan
    with pytest.warns(UserWarning, match=r"samples 101 to 599, 499 of 1000 samples \(49.9 %\)"):
        r = imunoise.adev(y, 1.0, gaps="longest")
    np.testing.assert_array_equal(r.var, imunoise.adev(y[101:600], 1.0).var)
    assert r.gaps == "longest" and r.missing == 51
    with pytest.warns(UserWarning, match=r"51 missing samples.*5.1 % of the record spliced"):
        r = imunoise.mtotdev(y, 1.0, gaps="splice")
    valid = y[~np.isnan(y)]
    np.testing.assert_array_equal(r.var, imunoise.mtotdev(valid, 1.0).var)


def test_gaps_argument_and_infinite_values_are_checked():
    y = noise("white", 200, seed=1)
    with pytest.raises(ValueError, match=r"one of 'skip', 'longest', 'splice'; got 'drop'"):
        imunoise.adev(y, 1.0, gaps="drop")
    with pytest.raises(TypeError, match="gaps must be one of"):
        imunoise.hdev(y, 1.0, gaps=None)
    y[3], y[9] = np.nan, np.inf
    for gaps in ("skip", "longest", "splice"):
        with pytest.raises(ValueError, match="sample 9 is inf"):
            imunoise.adev(y, 1.0, gaps=gaps)
    with pytest.raises(ValueError, match="all 3 are NaN"):
        imunoise.adev(np.full(3, np.nan), 1.0)
    y = noise("white", 200, seed=1)
    y[::3] = np.nan
    with pytest.raises(ValueError, match="fewer than 2 terms at every tau"):
        imunoise.adev(y, 1.0, taus=[2, 4])
    with pytest.warns(UserWarning, match="1 of 2 taus dropped"):
        assert list(imunoise.adev(y, 1.0, taus=[1, 4]).m) == [1]


def test_fit_takes_a_gapped_result():
    y = noise("white", 100_000, seed=8) * 1e-3
    y[40_000:45_000] = np.nan
    model = imunoise.fit(imunoise.adev(y, 100.0))
    assert model.N == pytest.approx(1e-3 / 10.0, rel=0.05)
    two = np.column_stack([y, noise("white", 100_000, seed=9) * 1e-3])
    r = imunoise.adev(two, 100.0)
    assert r.n.ndim == 2
    assert np.all(np.isfinite(imunoise.fit(r).N))
    boot = imunoise.fit(r, uncertainty="bootstrap", replicates=5, seed=0)
    assert np.all(np.isfinite(boot.N_std))


def test_describe_and_distribution_use_the_valid_samples():
    rng = np.random.default_rng(6)
    gyro = rng.normal(size=(5000, 3)) + [0.1, 0.2, 0.3]
    gyro[1000:1100] = np.nan
    gyro[7, 2] = np.nan
    log = imunoise.ImuLog.from_arrays(50.0, gyro=gyro)
    d = imunoise.describe(log)
    np.testing.assert_array_equal(d.missing, [100, 100, 101])
    np.testing.assert_allclose(d.mean, np.nanmean(gyro, axis=0), rtol=1e-12)
    np.testing.assert_allclose(d.var, np.nanvar(gyro, axis=0, ddof=1), rtol=1e-12)
    np.testing.assert_array_equal(d.min, np.nanmin(gyro, axis=0))
    assert np.all(np.isfinite(d.drift_per_hour))
    # Drift against the valid samples' times: a ramp with a hole keeps its slope.
    ramp = np.arange(1000.0)
    ramp[200:300] = np.nan
    assert imunoise.describe(ramp, fs=1.0).drift_per_hour[0] == pytest.approx(3600.0)
    assert d.rows()[2]["missing"] == 101 and "gyro Z" in d.table()
    dist = imunoise.distribution(gyro[:, 2])
    full = imunoise.distribution(gyro[~np.isnan(gyro[:, 2]), 2])
    assert dist.missing == 101 and dist.n == 4899
    np.testing.assert_array_equal(dist.counts, full.counts)
    assert dist.ks_statistic == full.ks_statistic
    with pytest.raises(ValueError, match="inf"):
        imunoise.describe([1.0, np.inf, 2.0])
    with pytest.raises(ValueError, match="3 valid samples; got 2 .1 NaN"):
        imunoise.distribution([1.0, np.nan, 2.0])
