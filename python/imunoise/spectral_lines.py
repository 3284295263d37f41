"""Whether a tone the Allan fit found is a line in the spectrum.

The Allan deviation sees a line only through its 1/τ fall with nulls at whole
periods, and a sum of terms can draw the same shape where there is none (an output
filter's roll-off, a band). The Welch spectrum sees a line directly: a narrow peak
standing above its neighbours. A tone is reported as a line only where the spectrum
shows one there; its frequency is then the spectrum's.

The test, on Welch's linear grid (:func:`imunoise.psd` before ``smooth``):

- search the bins within ``max(3 bins, 5 %)`` of the tone's frequency (the Allan
  fit places a line to a few per cent), or within its 95 % interval (1.96 standard
  uncertainties, up to half the frequency) where that is wider, for the highest
  one, P;
- the background is the geometric mean of the medians of the :data:`SIDE_BINS`
  bins on either side beyond a guard of :data:`GUARD_BINS` (a Hann window's main
  lobe spans ±2 bins), each median divided by the median of χ²_ν/ν (the medians of
  a sloping background on both sides average to its level at the peak). A peak
  with fewer than half of them on one side, next to 0 Hz or fs/2, is no line: one
  side's median is a slope's level beside the peak, not at it (a record's slow
  wander rises steeply toward 0 Hz);
- a line is there when P/background exceeds the F(ν, ν_b) quantile at 1 − α/k, k
  the bins searched (Bonferroni), α = :data:`FALSE_LINE`: a background bin alone
  would rarely reach it. ν is the bin's Welch EDF; ν_b that of the background,
  ν·:data:`SIDE_BINS` (the two sides' 2·SIDE_BINS bins, half of them independent
  under a Hann window overlapping by half) times 0.64, a median's efficiency
  against a mean.

A line at half the white noise's RMS on a record of ``n`` samples stands about
n/100 times above the background of the default segments; a filter's roll-off,
smooth over a few bins, stands at most a few times above it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from imunoise.errors import ImunoiseValueError

__all__ = ["SpectralLine", "check_line", "require_linear_grid"]

#: Chance that a line-free search window passes the test.
FALSE_LINE = 1e-3
#: Bins on each side of the peak left out of the background: the window's main lobe.
GUARD_BINS = 3
#: Bins on each side whose median is the background.
SIDE_BINS = 12
#: Variance of a mean over that of a median of the same normal sample: 2/π.
MEDIAN_EFFICIENCY = 2 / math.pi
#: Half-width of the search, relative to the tone's frequency, and its least in bins.
SEARCH_RELATIVE = 0.05
SEARCH_BINS = 3
#: A wider search reaches the Allan fit's 95 % interval of the frequency
#: (this many standard uncertainties) ...
SEARCH_STD = 1.96
#: ... up to this share of the frequency: where the interval is wider still, the
#: Allan curve has not placed the tone at all.
SEARCH_MOST = 0.5


@dataclass(frozen=True)
class SpectralLine:
    """A tone of the Allan fit, checked against the spectrum.

    Attributes
    ----------
    allan_frequency : float
        Where the Allan fit placed the tone, Hz.
    amplitude : float
        The Allan fit's amplitude A of A·sin(2πft), input units.
    in_spectrum : bool or None
        Whether the spectrum shows a line there; None: not checked (no spectrum).
    frequency : float
        The spectrum's peak, Hz (interpolated between bins); the Allan fit's
        frequency where not checked, NaN where the spectrum shows no line.
    ratio : float
        The peak over the local background (NaN where not checked).
    threshold : float
        The ratio a line must exceed (NaN where not checked).
    """

    allan_frequency: float
    amplitude: float
    in_spectrum: bool | None
    frequency: float
    ratio: float = math.nan
    threshold: float = math.nan

    @property
    def tone_frequency(self) -> float:
        """The model's ``Tone.freq`` of this line: the spectrum's where it shows the
        line, the Allan fit's otherwise."""
        return self.frequency if self.in_spectrum else self.allan_frequency

    @property
    def reported(self) -> bool:
        """Whether the line is reported: shown by the spectrum, or not checked."""
        return self.in_spectrum is not False


def unchecked(amplitude: float, f0: float) -> SpectralLine:
    """A tone without a spectrum to check it against."""
    return SpectralLine(allan_frequency=f0, amplitude=amplitude, in_spectrum=None,
                        frequency=f0)


def require_linear_grid(spectrum) -> None:
    """The test reads neighbouring Welch bins: a smoothed spectrum has none."""
    if spectrum.bins_per_decade:
        raise ImunoiseValueError("spectrum must be on Welch's linear grid (imunoise.psd), not "
                                 f"smoothed; got bins_per_decade={spectrum.bins_per_decade}")


def check_line(spectrum, channel: int, f0: float, amplitude: float = math.nan,
               f0_std: float = math.nan) -> SpectralLine:
    """Whether ``spectrum`` (from :func:`imunoise.psd`, not smoothed) shows a line
    near ``f0`` Hz in ``channel``, ``f0_std`` the Allan fit's standard uncertainty of
    ``f0`` (NaN: unknown); see the module for the test."""
    require_linear_grid(spectrum)
    f = np.asarray(spectrum.f, float)
    p = np.asarray(spectrum.psd, float)
    p = p if p.ndim == 1 else p[:, channel]
    edf = np.asarray(spectrum.edf, float)
    df = f[1] - f[0] if f.size > 1 else math.nan
    none = SpectralLine(allan_frequency=f0, amplitude=amplitude, in_spectrum=False,
                        frequency=math.nan)
    if not (f.size > 2 * (GUARD_BINS + SIDE_BINS) and math.isfinite(f0) and f0 > 0):
        return none
    spread = min(SEARCH_STD * f0_std, SEARCH_MOST * f0) if f0_std > 0 else 0.0
    half = max(SEARCH_BINS * df, SEARCH_RELATIVE * f0, spread)
    search = np.flatnonzero(np.abs(f - f0) <= half)
    if search.size == 0:
        return none
    peak = int(search[np.argmax(p[search])])
    left = p[max(0, peak - GUARD_BINS - SIDE_BINS):max(0, peak - GUARD_BINS)]
    right = p[peak + GUARD_BINS + 1:peak + GUARD_BINS + 1 + SIDE_BINS]
    sides = [s for s in (left, right) if s.size >= SIDE_BINS // 2]
    if len(sides) < 2:  # one side alone is a slope's level beside the peak, not at it
        return none
    nu = float(edf[peak])
    if not (nu > 0 and p[peak] > 0):
        return none
    median_chi2 = stats.chi2.median(nu) / nu
    background = math.exp(np.mean([math.log(max(np.median(s), 1e-300)) for s in sides]))
    background /= median_chi2
    ratio = float(p[peak] / background)
    nu_background = MEDIAN_EFFICIENCY * SIDE_BINS * len(sides) / 2 * nu
    threshold = float(stats.f.ppf(1.0 - FALSE_LINE / search.size, nu, nu_background))
    if ratio <= threshold:
        return SpectralLine(allan_frequency=f0, amplitude=amplitude, in_spectrum=False,
                            frequency=math.nan, ratio=ratio, threshold=threshold)
    return SpectralLine(allan_frequency=f0, amplitude=amplitude, in_spectrum=True,
                        frequency=_interpolated_peak(f, p, peak), ratio=ratio,
                        threshold=threshold)


def _interpolated_peak(f: np.ndarray, p: np.ndarray, k: int) -> float:
    """The peak's frequency from a parabola through the log powers of bins k − 1, k,
    k + 1 (a Hann window's main lobe is near-Gaussian: its log is a parabola)."""
    if k == 0 or k == f.size - 1 or not np.all(p[k - 1:k + 2] > 0):
        return float(f[k])
    a, b, c = np.log(p[k - 1:k + 2])
    denom = a - 2 * b + c
    shift = 0.5 * (a - c) / denom if denom < 0 else 0.0
    return float(f[k] + max(-0.5, min(0.5, shift)) * (f[1] - f[0]))
