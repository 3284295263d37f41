r"""The sensor's output filter, measured from the spectrum of its rate.

Real sensors pass their rate through an output filter (a Butterworth low-pass, a CIC
decimator, an FIR, a MEMS's own low-pass). Its gain G(f) = ``|H(f)|²`` bends the white
noise's spectrum above the white region, and the Allan deviation at short τ with it.
No term of the noise model has that shape; without it the fit draws the filter with a
resonance, Gauss–Markov terms or tones, and N comes out wrong. This module estimates G
from a Welch PSD (:func:`imunoise.psd`) and gives the factor c(τ) by which it scales
the white term's Allan variance.

The estimate, per channel (:func:`estimate_filter`):

- **The white level.** The line-free Welch values (below), averaged in bins of 1/20
  decade, are fitted with h0 + h₋₁/f + h₋₂/f² (white, flicker, walk; non-negative,
  weighted by each bin's χ² variance) from the lowest frequency up to the highest
  top whose quarter decade below it misses the fit by no more than 2 standard errors
  of its mean, and where white still dominates (:func:`_white_fit`); the levels are
  then read below that quarter decade, which passed only within its errors and may
  hold the filter's start. The filter acts on all of it, so
  G = PSD/(h0 + h₋₁/f + h₋₂/f²).
- **G = 1 up to the middle of the white band** (in log f, between where flicker and
  walk equal the white level and the band's top; the top must lie within two decades
  below fs/2, or the roll-off is a slow correlated process, no output filter): below
  it the low frequencies
  belong to flicker and walk; above it a gentle filter may already have started
  (|H|² of a real filter is even in f, so an FIR's or a CIC's starts as 1 − αf², and
  the band's top is only where that became visible), so it is measured there.
- **Above it, a running median** of the linear Welch grid over :data:`HALF_WIDTH`
  bins on either side, divided by the median of χ²_ν/ν (a median of Welch values is
  that much below their mean). A median keeps a monotone shape exactly (the median of
  a monotone window is its middle value: a roll-off of any order, a CIC's sinc³) and
  removes whatever is narrower than half its window: a line, which is a tone of the
  model, never the filter. The window is reflected at fs/2 (the spectrum of a sampled
  process is even about fs/2), so the last bins are estimated as well as the others.
  A band broader than the window (a filter's own peak, a mode of the sensor) is part
  of the measured shape and of G.
- **Whether there is a filter** (:func:`estimate_filter` returns None when not): an
  output filter attenuates. A Welch value above its local median beyond the χ²
  quantile at 10⁻³ shared over the bins is a line and left out; the others, averaged
  in 1/20-decade bins above the middle of the white band, must fall below the white
  level by more than their χ²_ν/ν quantile (and the level's own uncertainty) at a
  one-sided 5 % shared over the bins tested (Bonferroni), and the top quarter decade
  below fs/2 must lie lower than each quarter decade from fs/20 up to it
  (:func:`_falls_to_the_top`: a roll-off that has levelled to a shelf by then is a
  correlated process above white noise, which the Gauss–Markov terms describe).
  White noise passes as "no filter" 95 % of the time whatever the record's length;
  so does a spectrum that only rises above its white level (quantization's f², which
  the Q term describes).

The white level's error is G's common factor above the middle of the band, and the fit's
N follows it by half: on simulated FIR, CIC and Butterworth filters (1 h at 100 Hz) N from
h0 is within ±1 % (read up to the band's top, a filter's start pulled it 1–3 % low). The grid
of G is Welch's: f_k = k·(fs/2)/(L−1), k = 0…L−1, G[0] = 1.

The core (`_core.fit`) passes only the white term through G. The flicker and walk pass
the filter too; :meth:`OutputFilter.excess` is their share (from the spectrum's own
levels), which :func:`imunoise.fit` takes off the measured Allan variance.

The white term's Allan variance with the filter is (N²/τ)·c(τ),

.. math:: c(m) = 1 + 2m\int_0^{1/2} (G(\nu) - 1)\,
          \frac{2\sin^4(\pi\nu m)}{m^2\sin^2\pi\nu}\,d\nu,

ν = f/fs, m = τ·fs: the Allan variance of a sampled process with two-sided spectrum
S(ν) is ∫ S(ν)·2 sin⁴(πνm)/(m² sin²πν) dν over [−½, ½], 1/m for unit white noise.
The core evaluates it (and the Allan variance of the flicker and walk's share, the
same integral over another piecewise-linear density) exactly for G linear between the
grid's points, from the Fourier coefficients of G − 1 (``rust/fit/filter.rs``):
:meth:`OutputFilter.factor` and :meth:`OutputFilter.excess` read it from there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage as _ndimage
from scipy import optimize as _optimize
from scipy import signal as _signal
from scipy import stats as _stats

from imunoise._core import fit as _core_fit
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

__all__ = ["OutputFilter", "estimate_filter"]

#: Bins of the running median on either side of its centre: a line's Hann leakage
#: stays above a white floor 60 dB below it for ±8 bins, and a median ignores a
#: feature only while it holds less than half of the window.
HALF_WIDTH = 16
#: Familywise chance that white noise is taken for a filter.
FALSE_FILTER = 0.05
#: Log bins per decade of the test (the white read-off's own binning).
TEST_BINS_PER_DECADE = 20
#: Chance that a line-free Welch spectrum has a bin taken for a line (shared over the
#: bins: Bonferroni); the line check's own level (spectral_lines.FALSE_LINE).
FALSE_LINE = 1e-3
#: Standard errors by which the band's top bins may miss the white fit together
#: (two-sided 95 %): the band ends where the filter starts to show.
EDGE_Z = 2.0
#: Top bins of the band that must all follow the fit (a quarter decade: one bin that
#: happens to fit must not stretch the band).
EDGE_BINS = 5
#: Most times below fs/2 the white band's top may lie for its roll-off to be an output
#: filter's (two decades: a sensor sampled at over 100 times its bandwidth).
SLOWEST_FILTER = 100.0
#: Fewest log bins the white fit keeps (four coefficients and their scatter).
MIN_BINS = 8


@dataclass(frozen=True)
class OutputFilter:
    """The output filter of one channel, measured from its spectrum.

    Attributes
    ----------
    f : ndarray, (L,)
        Frequencies, Hz: k·(fs/2)/(L−1), k = 0…L−1.
    gain : ndarray, (L,)
        G(f) = ``|H(f)|²``, the output's power over the white level; 1 up to
        ``white_top``.
    fs : float
        Sample rate, Hz.
    white_top : float
        G is 1 up to here, Hz (the middle of the white band, in log f).
    white : float
        The one-sided white level h0 (units²/Hz) G is relative to.
    psd, low : ndarray, (L,)
        The running median of the PSD on ``f`` and the flicker and walk part of the
        level, h₋₁/f + h₋₂/f² (:meth:`excess`).
    white_std : float
        Relative standard uncertainty of ``white`` (of its fit to the log-binned
        spectrum): G above ``white_top`` scales as its inverse, and the fit's
        uncertainties carry it (0: not known).
    """

    f: np.ndarray
    gain: np.ndarray
    fs: float
    white_top: float
    white: float
    psd: np.ndarray = field(repr=False, default=None)
    low: np.ndarray = field(repr=False, default=None)
    white_std: float = 0.0

    def __post_init__(self) -> None:
        # Each array a read-only contiguous float copy: the core takes it as it is.
        for name in ("f", "gain", "psd", "low"):
            if getattr(self, name) is None:
                continue
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    def excess(self, taus) -> np.ndarray:
        """Allan variance the filter takes from the flicker and random walk of the
        spectrum's level (h₋₁/f + h₋₂/f²) at ``taus``: they pass the filter too."""
        if self.low is None:
            return np.zeros(np.size(taus))
        d = (self.gain - 1.0) * np.where(self.f > 0, self.low, 0.0)
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
        return _core_fit.density_allan(t, float(self.fs), np.ascontiguousarray(d))

    def factor(self, taus) -> np.ndarray:
        """c(τ): the white term's Allan variance with the filter over N²/τ, from the
        core (the same c(τ) the fit used)."""
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
        return _core_fit.filter_factor(t, float(self.fs), self.gain)

    def apply(self, x) -> np.ndarray:
        """``x``, (n,) or (n, k) sampled at ``fs``, through this filter: each rFFT bin
        times √G at its frequency (G linear between the grid's points), with the line
        from the first to the last sample taken off before and put back after (a
        record is no period of itself). A zero-phase filter whose output has the
        spectrum of ``x`` times G: how a bootstrap's replicates get the sensor's
        filter."""
        x = np.asarray(x, dtype=float)
        flat = x.reshape(x.shape[0], -1)
        n = flat.shape[0]
        amplitude = np.sqrt(np.interp(np.fft.rfftfreq(n, 1.0 / self.fs), self.f, self.gain))
        ramp = np.linspace(0.0, 1.0, n)
        out = np.empty_like(flat)
        for k in range(flat.shape[1]):  # a column at a time: the spectra stay small
            line = flat[0, k] + (flat[-1, k] - flat[0, k]) * ramp
            out[:, k] = np.fft.irfft(np.fft.rfft(flat[:, k] - line) * amplitude, n) + line
        return out.reshape(x.shape)

    def __repr__(self) -> str:
        low = float(self.gain.min())
        return (f"OutputFilter({self.gain.size} freqs to {self.fs / 2:g} Hz, white to "
                f"{self.white_top:.3g} Hz, gain down to {low:.3g})")


def estimate_filter(spectrum, channel: int = 0) -> OutputFilter | None:
    """The output filter of ``channel`` from ``spectrum`` (:func:`imunoise.psd`, on
    Welch's linear grid), or None where the spectrum shows none (see the module)."""
    from imunoise.spectral_lines import require_linear_grid
    from imunoise.spectrum import Spectrum

    if not isinstance(spectrum, Spectrum):
        raise ImunoiseTypeError(f"spectrum must be a Spectrum (imunoise.psd); got "
                                f"{type(spectrum).__name__}")
    require_linear_grid(spectrum)
    if not 0 <= channel < spectrum.channels:
        raise ImunoiseValueError(
            f"channel must be in [0, {spectrum.channels - 1}]; got {channel}")
    f = np.asarray(spectrum.f, dtype=float)
    p = np.asarray(spectrum.psd, dtype=float)
    p = p if p.ndim == 1 else p[:, channel]
    edf = np.asarray(spectrum.edf, dtype=float)
    if f.size < 2 * HALF_WIDTH + 1 or not np.all(np.isfinite(p)) or not np.any(p > 0):
        return None
    # The running median, unbiased: a Welch value is S·χ²_ν/ν, whose median is below S.
    smooth = _running_median(p, HALF_WIDTH) / (_per_edf(_stats.chi2.median, edf) / edf)
    # A bin is a line where it stands above the local median beyond the χ² quantile
    # at FALSE_LINE shared over the bins: the white fit and the test are about shape.
    quantile = _per_edf(lambda nu: _stats.chi2.ppf(1 - FALSE_LINE / f.size, nu), edf)
    clean = p <= smooth * quantile / edf
    fb, pb, eb = _log_bins(f[clean], p[clean], edf[clean], spectrum.nperseg)
    fitted = _white_fit(fb, pb, eb)
    if fitted is None:
        return None
    (h0, h1, h2), top, u_h0 = fitted
    # A white band that ends more than two decades below fs/2 is no output filter's
    # passband (a sensor sampled at over 100 times its bandwidth): a shape that slow
    # is a correlated process, a Gauss–Markov bias whose plateau the fit took for
    # the white level.
    if top < float(spectrum.fs) / 2 / SLOWEST_FILTER:
        return None
    # G is 1 up to the middle (in log f) of the white band, from where flicker and
    # walk have faded to where the filter shows: a gentle filter (an FIR's 1 − αf²)
    # starts below the point where the band test can see it, and is measured there.
    start = math.sqrt(_crossover(h0, h1, h2, fb[0]) * top)
    tested = fb > start
    relative = pb / (h0 + h1 / fb + h2 / fb**2)
    if not (_attenuates(fb[tested], relative[tested], eb[tested], u_h0)
            and _falls_to_the_top(fb, relative, eb, float(spectrum.fs))):
        return None
    fs = float(spectrum.fs)
    size = spectrum.nperseg // 2 + 1
    grid = np.arange(size) * (fs / 2) / (size - 1)
    # On Welch's grid with 0 Hz: the grid itself for an even nperseg, else linear
    # between its points and held at the last one up to fs/2.
    numerator = np.interp(grid, np.r_[0.0, f], np.r_[smooth[0], smooth])
    low = np.zeros(size)
    low[1:] = h1 / grid[1:] + h2 / grid[1:] ** 2
    return OutputFilter(f=grid, gain=_gain(grid, numerator, low, h0, start), fs=fs,
                        white_top=float(start), white=float(h0), psd=numerator, low=low,
                        white_std=float(u_h0))


def _crossover(h0, h1, h2, lowest):
    """Frequency where the white level equals flicker and walk together (the lowest
    frequency when white dominates everywhere)."""
    # h0 f² − h1 f − h2 = 0
    f = (h1 + math.sqrt(h1 * h1 + 4 * h0 * h2)) / (2 * h0)
    return max(f, lowest)


def _gain(f, psd, low, white, top):
    """G on ``f``: 1 up to ``top``, the measured ``psd`` over the level ``white`` +
    ``low`` above it; never below 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        above = psd / (white + low)
    gain = np.where(f <= top, 1.0, above)
    gain[0] = 1.0
    return np.maximum(gain, 0.0)


def _per_edf(function, edf: np.ndarray) -> np.ndarray:
    """``function`` of each bin's EDF, evaluated once per distinct value: a Welch
    spectrum has two (its ends and the rest), and scipy's χ² quantiles cost
    microseconds each over millions of frequencies."""
    values, which = np.unique(edf, return_inverse=True)
    return np.asarray(function(values), dtype=float)[which]


def _running_median(p: np.ndarray, half: int) -> np.ndarray:
    """Median of ``p`` over ``half`` bins either side, reflected at both ends (the
    spectrum of a sampled process is even about 0 and fs/2): scipy's selection
    filter, the same values as the sorted windows' middle element."""
    return _ndimage.median_filter(p, size=2 * half + 1, mode="mirror")


def _log_bins(f, p, edf, nperseg):
    """Means of ``p`` in bins of 1/:data:`TEST_BINS_PER_DECADE` decade with their EDF
    (the Hann window correlates neighbouring Welch values)."""
    edges = np.floor(np.log10(f) * TEST_BINS_PER_DECADE).astype(np.int64)
    starts = np.flatnonzero(np.r_[True, edges[1:] != edges[:-1]])
    counts = np.diff(np.r_[starts, f.size])
    centre = np.exp(np.add.reduceat(np.log(f), starts) / counts)
    corr = _hann_bin_correlation(nperseg)
    lags = np.arange(corr.size)
    inflation = np.array([1 + 2 * np.sum((1 - lags[1:c] / c) * corr[1:c]) if c > 1 else 1.0
                          for c in counts])
    return (centre, np.add.reduceat(p, starts) / counts,
            np.add.reduceat(edf, starts) / inflation)


def _white_fit(f, p, edf):
    """The white region of the log-binned spectrum: ``p`` ≈ h0 + h₋₁/f + h₋₂/f² (h ≥ 0)
    from the lowest bin up to the highest whose :data:`EDGE_BINS` top bins together
    follow the fit within :data:`EDGE_Z` standard errors of their mean (no tolerance
    beside it: a filter's start inside the band pulls h0 down, the 1/f terms bending to
    follow it). Returns ((h0, h₋₁, h₋₂), the band's top in Hz, relative standard error
    of h0), or None without a white level."""
    top = f.size
    while True:
        h, cov = _fit_levels(_basis(f[:top]), p[:top], edf[:top])
        edge = slice(max(top - EDGE_BINS, 0), top)
        model = _basis(f[edge]) @ h
        off = np.sum(edf[edge] * (p[edge] / model - 1)) / np.sum(edf[edge])
        # The top must also be white (h0 above flicker and walk there): deep in a
        # roll-off, a fit whose 1/f terms bend with it may pass the edge test.
        white = h[0] > h[1] / f[top - 1] + h[2] / f[top - 1] ** 2
        if top <= MIN_BINS or (white and abs(off) <= EDGE_Z * math.sqrt(
                2 / np.sum(edf[edge]))):
            break
        top -= 1
    # The level is read below the top EDGE_BINS: they passed the test only within two
    # standard errors, and a filter may have started there (they hold the most Welch
    # values of the band, so even a 1 % start there pulls h0 down by most of it).
    below = top - EDGE_BINS
    if below >= MIN_BINS:
        h, cov = _fit_levels(_basis(f[:below]), p[:below], edf[:below])
    if not h[0] > 0:
        return None
    return (h[0], h[1], h[2]), float(f[top - 1]), math.sqrt(cov[0, 0]) / h[0]


def _basis(f):
    return np.stack([np.ones(f.size), 1 / f, 1 / f**2], axis=1)


def _fit_levels(basis, p, edf):
    """Non-negative weighted least squares of ``p`` on ``basis``, each value weighted by
    its variance 2S²/ν with S from the previous pass; the coefficients and their
    covariance (of the active ones; 0 for the others)."""
    scale = float(np.max(p))
    y = p / scale
    expected = y.copy()
    for _ in range(4):
        w = np.sqrt(edf / 2) / np.maximum(expected, 1e-12)
        h = _optimize.nnls(basis * w[:, None], y * w)[0]
        fitted = basis @ h
        if not np.all(fitted > 0):
            break
        expected = fitted
    active = h > 0
    cov = np.zeros((h.size, h.size))
    a = basis[:, active] * w[:, None]
    cov[np.ix_(active, active)] = np.linalg.pinv(a.T @ a)
    return h * scale, cov * scale**2


def _attenuates(f, relative, edf, u_level) -> bool:
    """Whether some bin of the log-binned spectrum over the white level (``relative``)
    lies below 1 by more than its sampling error (the χ²_ν/ν quantile: a bin of few
    Welch values is skewed) and the level's relative error ``u_level``, one-sided at
    :data:`FALSE_FILTER` shared over the bins."""
    if not relative.size:
        return False
    share = FALSE_FILTER / relative.size
    low = _stats.chi2.ppf(share, edf) / edf * math.exp(-_stats.norm.isf(share) * u_level)
    return bool(np.any(relative < low))


def _falls_to_the_top(f, relative, edf, fs) -> bool:
    """Whether the spectrum over the white level is lower in the top quarter decade
    below fs/2 than in each quarter decade from fs/20 up to it, one-sided at
    :data:`FALSE_FILTER` each: an output filter bounds the band below fs/2 and
    attenuates most at its top (a low-pass of any order, a CIC's or an FIR's lobes:
    their gain still falls over the last quarter decade). A spectrum that has
    levelled to a shelf by then is white noise above a correlated process that has
    faded (a Gauss–Markov bias whose plateau the white fit took for the level, a
    fast one whose shoulder ends below fs/2), the model's own terms; fs/20 is where
    the resonance search stops for the same reason (a slower shape spans more than
    20 samples)."""
    top = f >= fs / 2 * 10**-0.25
    if not top.any():
        return True
    level = np.sum(edf[top] * relative[top]) / edf[top].sum()
    for k in (1, 2, 3):
        ref = (f >= fs / 2 * 10 ** (-0.25 * (k + 1))) & (f < fs / 2 * 10 ** (-0.25 * k))
        if not ref.any():
            continue
        drop = math.log(level / (np.sum(edf[ref] * relative[ref]) / edf[ref].sum()))
        spread = math.sqrt(2 / edf[top].sum() + 2 / edf[ref].sum())
        if drop >= -_stats.norm.isf(FALSE_FILTER) * spread:
            return False
    return True


def _hann_bin_correlation(seg: int) -> np.ndarray:
    """Correlation of Hann periodogram values l bins apart (white noise), l = 0, 1, …
    while above 10⁻⁶: |Σ w² e^(−2πi nl/L)|² / (Σ w²)²."""
    w2 = _signal.get_window("hann", seg) ** 2
    r = np.abs(np.fft.rfft(w2)) ** 2 / np.sum(w2) ** 2
    r = r[: min(8, r.size)]
    return r[r > 1e-6]
