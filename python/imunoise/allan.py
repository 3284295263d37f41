r"""The Allan-variance family with confidence intervals.

All statistics take rate samples :math:`y_0 … y_{n-1}` (gyro rate, acceleration,
fractional frequency, …) at a uniform sample rate ``fs`` and work on the
cumulative sum of the mean-removed data, :math:`c_k = \sum_{i<k}(y_i - \bar y)`
(n + 1 points; the phase is :math:`x = c/f_s`), in Rust with compensated
summation: the overlapping Allan and Hadamard variances sweep all their taus in
one blocked pass, the others take one O(n) pass per tau (Theo1 and ThêoBR
O(n log² m) at long taus). With :math:`\tau = m/f_s` and N = n + 1:

- overlapping Allan variance
  :math:`\sigma^2_y(\tau) = \frac{1}{2m^2(N-2m)}\sum_{k=0}^{N-2m-1}(c_{k+2m}-2c_{k+m}+c_k)^2`
  (non-overlapping: k in steps of m);
- modified Allan variance, SP 1065 eq. 14; time variance
  :math:`\sigma_x^2 = \tau^2\,\mathrm{Mod}\,\sigma_y^2/3`;
- Hadamard variance (third differences, divisor 6), overlapping by default
  (``ohdev``: the overlapping one under allantools' name);
- total variance, SP 1065 eq. 25 (phase reflected about both ends);
- the total family beyond it (MTOT, TTOT, HTOT, Theo1, ThêoBR, ThêoH), see each
  function.

:data:`KINDS` lists them all; each is a function of the same name.

Confidence intervals: the noise type α is identified at each tau by the lag-1
autocorrelation method (Riley & Greenhall 2004) — where the decimated series is
too short (< 30 points) α is the median of the three nearest identified taus — then the
equivalent degrees of freedom follow Greenhall's algorithm (TOTVAR: SP 1065
Table 7), and the bounds are the χ² quantiles
:math:`\sigma^2\,\nu/\chi^2_{\nu}(1-p/2) \le \sigma^2 \le \sigma^2\,\nu/\chi^2_{\nu}(p/2)`.

Bias correction
---------------
MTOTDEV, TTOTDEV, HTOTDEV and Theo1 take ``bias_correction=``: divide the
variance by the published bias factor for the noise type identified at each tau
(``alpha`` in the result; each function lists its factors). Default False: the
estimate is then a function of the data alone, reproducible and equal to
allantools' and Stable32's uncorrected values; the correction depends on the
noise identification, which is uncertain where the curve changes slope, and a
misidentified tau would jump. Turn it on to compare with Allan-variance values of
the same noise (a datasheet, a fitted model).

Phase input
-----------
Every function takes ``data_type="phase"`` (allantools' convention): ``x`` is then the
phase, the integral of the rate — time error in seconds for a clock, angle for a
gyro — sampled at ``fs``, n + 1 points spanning n intervals. It is differentiated,
:math:`y_i = (x_{i+1} - x_i)\,f_s`, and analysed as rate samples: the cumulative sum
above gives back :math:`c_k = (x_k - x_0)f_s` less a linear trend, and every
statistic here is a function of second or higher differences of the phase (the
total family of the detrended or reflected phase), which no linear trend changes.
So the conversion is exact — the values equal allantools' with phase input to
rounding. A missing phase point (NaN) makes both rate samples beside it missing:
a term whose span holds it is left out (``gaps="skip"``), and ``r.missing`` counts
missing phase points. ``r.n_samples`` is n, the number of intervals.

Gaps
----
A missing sample is NaN on the uniform time grid (±∞ stays an error). Every
function takes ``gaps=``:

- ``"skip"`` (default): a term whose window touches a missing sample is left
  out and ``r.n`` counts the terms used; the mean removed is that of the valid
  samples. ADEV (overlapping or not), MDEV, TDEV and HDEV (overlapping or not)
  support it. Taus at which no channel keeps two terms are dropped; a channel
  with fewer than two terms at a kept tau gets NaN there. The noise type is
  identified on the longest gap-free run, and the EDF pools the runs: run s,
  with Greenhall's EDF ν_s for its length, carries the share w_s of the terms
  used, and 1/ν = Σ w_s²/ν_s (the runs treated as independent; exactly
  Greenhall's EDF when there is no gap). The total family (TOTDEV, MTOTDEV,
  TTOTDEV, HTOTDEV, Theo1, ThêoBR, ThêoH) reflects or detrends the record around
  every point and cannot skip gaps: with NaN in ``x`` it raises ValueError.
- ``"longest"``: the longest run of rows without NaN (in any channel) is
  analysed, with a warning saying what share of the record that is.
- ``"splice"``: rows with NaN are dropped and the rest joined, as if the gaps
  had not happened (the behaviour of tools that ignore time stamps), with a
  warning saying how many samples were spliced over. Splicing joins stretches
  of the record that were not adjacent in time and biases the long taus.

A record without NaN gives the same result, bit for bit, whatever ``gaps`` is.

References
----------
W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008).
C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
finite differences", Proc. 35th PTTI (2003).
W. J. Riley and C. A. Greenhall, "Power law noise identification using the lag 1
autocorrelation", Proc. 18th EFTF (2004).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, TypeAlias

import numpy as np
import numpy.typing as npt
from scipy import stats as _stats

from imunoise._core import allan as _core_allan
from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.runs import true_runs
from imunoise._support.validate import (
    confidence_level,
    integer,
    no_infinity,
    sample_rate,
    samples,
)
from imunoise.errors import (
    CoverageWarning,
    GapWarning,
    ImunoiseTypeError,
    ImunoiseValueError,
    ImunoiseWarning,
)
from imunoise.taus import averaging_factors, keep_estimable

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imunoise.noise import NoiseModel

#: One-sigma confidence, erf(1/√2).
ONE_SIGMA = 0.6826894921370859

#: Values of the ``gaps=`` keyword (see the module notes).
GAPS = ("skip", "longest", "splice")

#: A tau specification: a grid name, points per decade, or taus in seconds
#: (see :func:`imunoise.taus.averaging_factors`).
TauSpec: TypeAlias = "str | int | npt.ArrayLike"

#: SP 1065 (Riley 2008) / Riley, "Confidence intervals and bias corrections for the
#: Stable32 variance functions" (2000): biased/unbiased variance ratio by α.
_MTOT_BIAS = {2: 0.94, 1: 0.83, 0: 0.73, -1: 0.70, -2: 0.69}
_HTOT_BIAS = {0: 0.995, -1: 0.851, -2: 0.771, -3: 0.717, -4: 0.679}
#: Howe, "TheoH: a hybrid, high-confidence statistic" (Metrologia 2006) and
#: SP 1065: AVAR/Theo1 = a + b/m^c by α (white FM: 1, unbiased).
_THEO1_BIAS = {
    2: (0.09, 0.74, 0.40),
    1: (0.14, 0.82, 0.30),
    0: (1.00, 0.00, 1.00),
    -1: (1.87, -1.05, 0.79),
    -2: (2.70, -1.53, 0.85),
}


def _mtot_bias(alpha: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Multiplier of the MTOT variance that removes the published bias; alpha (T, ch)."""
    table = np.vectorize(lambda a: 1.0 / _MTOT_BIAS[int(np.clip(a, -2, 2))])
    return table(alpha)


def _htot_bias(alpha: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The same for HTOT: none for phase noise (α > 0), nor at m = 1 (OHDEV)."""
    f = np.vectorize(lambda a: 1.0 / _HTOT_BIAS[int(a)] if a <= 0 else 1.0)(
        np.clip(alpha, -4, 2)
    )
    return np.where((m == 1)[:, None], 1.0, f)


def _theo1_bias(alpha: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The same for Theo1: AVAR/Theo1 = a + b/m^c."""
    a, b, c = (
        np.vectorize(lambda al, k=k: _THEO1_BIAS[int(np.clip(al, -2, 2))][k])(alpha)
        for k in range(3)
    )
    return a + b / (m[:, None].astype(float) ** c)


@dataclass(frozen=True)
class _Kind:
    """How one public statistic maps onto the core."""

    #: Core statistic (one of ``imunoise._core.allan.STATISTICS``); the overlapping
    #: one where there is a choice.
    statistic: str
    #: Core statistic for ``overlapping=False`` (None: always overlapping).
    non_overlapping: str | None = None
    #: ThêoH: the core statistic at the taus up to 10 % of the record.
    short_taus: str | None = None
    #: Multiplier of the variance for ``bias_correction=True`` (None: no keyword).
    bias: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    #: Variance × τ²/3: a time deviation, in input units × s (TDEV, TTOTDEV).
    time_scaled: bool = False
    #: ``taus`` are 0.75·m/fs, the averaging time a Theo1-based value belongs to
    #: (False: m/fs).
    effective_tau: bool = False
    #: Theo1 is defined for even m only: odd m of a named grid are skipped.
    even_m: bool = False

    @property
    def statistics(self) -> frozenset[str]:
        """Every core statistic this kind uses."""
        names = (self.statistic, self.non_overlapping, self.short_taus)
        return frozenset(name for name in names if name is not None)


#: Public name → how it is computed. The functions of the same names, :data:`KINDS`,
#: ``__all__`` and the CLI's ``--kind`` choices all come from this table.
_REGISTRY: Mapping[str, _Kind] = MappingProxyType(
    {
        "adev": _Kind("oadev", non_overlapping="adev"),
        "mdev": _Kind("mdev"),
        "hdev": _Kind("ohdev", non_overlapping="hdev"),
        # allantools' name for the overlapping Hadamard deviation, hdev's default
        "ohdev": _Kind("ohdev"),
        "tdev": _Kind("mdev", time_scaled=True),
        "totdev": _Kind("totdev"),
        "mtotdev": _Kind("mtotdev", bias=_mtot_bias),
        "ttotdev": _Kind("mtotdev", bias=_mtot_bias, time_scaled=True),
        "htotdev": _Kind("htotdev", bias=_htot_bias),
        "theo1": _Kind("theo1", bias=_theo1_bias, even_m=True),
        "theobr": _Kind("theobr", effective_tau=True),
        "theoh": _Kind("theobr", short_taus="oadev", effective_tau=True),
    }
)

#: Public names of the statistics, each a function of this module (and of
#: ``imunoise``) and a value of :attr:`AllanResult.kind`.
KINDS: tuple[str, ...] = tuple(_REGISTRY)

#: Values of the ``data_type=`` keyword: rate samples (allantools' "freq") or phase.
DATA_TYPES = ("freq", "phase")

__all__ = ["AllanResult", *KINDS, "KINDS", "GAPS", "DATA_TYPES", "ONE_SIGMA",
           "chi2_interval"]

#: Statistics (core names) that can leave out the terms touching a missing sample.
_SKIPS_GAPS = frozenset(_core_allan.GAP_SKIPPING)


@dataclass(frozen=True, repr=False)
class AllanResult:
    """A deviation evaluated at a set of taus.

    Arrays of per-tau values have shape ``(T,)`` for 1-D input and
    ``(T, channels)`` for 2-D input ``(n, channels)``. All arrays are read-only.

    Attributes
    ----------
    kind : str
        The statistic, one of :data:`KINDS`, or ``"pdev"``, ``"mtie"``, ``"tierms"``
        (:func:`imunoise.pdev` …) or ``"gcodev"`` (the function that made the result).
    overlapping : bool
        Whether the estimator uses every start sample (stride 1) or stride m.
    taus : ndarray, (T,)
        Averaging times in seconds, ``m / fs`` (``"theobr"``/``"theoh"``: the
        averaging time each value belongs to, see ``m``).
    m : ndarray of int, (T,)
        Averaging factors (ThêoBR points of ``"theobr"``/``"theoh"``: Theo1's even m,
        at ``taus = 0.75 * m / fs``).
    dev, var : ndarray
        The deviation and its square, in the input's units (TDEV: units × s).
    n : ndarray of int, (T,) or (T, channels)
        Number of terms in each estimate (Stable32's N); with ``gaps="skip"`` the
        terms actually used. Shape (T,) unless the channels' gaps differ so that
        they used different numbers of terms; then (T, channels).
    edf : ndarray
        Equivalent degrees of freedom: Greenhall's for the noise type ``alpha``
        (the total family and Theo1: SP 1065's). Where a channel's phase noise
        (α ≥ 1) begins only beyond the first tau — a bounded motion, a cycle —
        its phase points are counted that corner apart (the EDF of the phase
        decimated by the corner, never more than Greenhall's): Greenhall's
        white-PM EDF counts every sample as a draw and overstated it up to
        a thousandfold there against the Monte Carlo spread.
    ci_low, ci_high : ndarray
        Bounds of the ``confidence`` interval on ``dev``.
    alpha : ndarray of int
        Power-law noise type used for the EDF: rate PSD ∝ f^α (2 white PM,
        1 flicker PM, 0 white FM / white rate noise, −1 flicker FM, −2 random walk FM).
    alpha_identified : ndarray of bool
        False where α was taken from the nearest identified taus (the median of
        up to three) because the series was too short to identify it there.
    fs : float
        Sample rate in Hz.
    confidence : float
        Two-sided confidence level of ``ci_low``/``ci_high``.
    n_samples : int
        Samples the estimates were computed over: the length of ``x`` (with its
        missing samples, for ``gaps="skip"``), of its longest gap-free run
        (``"longest"``), or of the spliced record (``"splice"``).
    missing : int or ndarray of int, (channels,)
        Missing samples (NaN) in ``x`` per channel (int for 1-D input).
    gaps : str
        How missing samples were treated: ``"skip"``, ``"longest"`` or ``"splice"``.
    data_type : str
        ``"freq"`` (rate samples, the default) or ``"phase"`` (their integral,
        see the module notes); for phase input ``n_samples`` counts the intervals
        between phase points, len(x) − 1, so that n_samples/fs is the record's
        length, and ``missing`` the missing phase points.
    """

    kind: str
    overlapping: bool
    taus: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    var: np.ndarray
    n: np.ndarray
    edf: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    alpha: np.ndarray
    alpha_identified: np.ndarray
    fs: float
    confidence: float
    n_samples: int
    missing: int | np.ndarray = 0
    gaps: str = "skip"
    data_type: str = "freq"

    def __post_init__(self) -> None:
        for name in (
            "taus",
            "m",
            "dev",
            "var",
            "n",
            "edf",
            "ci_low",
            "ci_high",
            "alpha",
            "alpha_identified",
        ):
            getattr(self, name).flags.writeable = False
        if isinstance(self.missing, np.ndarray):
            self.missing.flags.writeable = False

    @property
    def channels(self) -> int:
        """Number of channels (1 for 1-D input)."""
        return 1 if self.dev.ndim == 1 else self.dev.shape[1]

    def __len__(self) -> int:
        return len(self.taus)

    def _facts(self) -> list[str]:
        """Channels, taus, rate, length, missing samples, gaps mode and confidence."""
        return [
            _summary.plural(self.channels, "channel"),
            _summary.tau_span(self.taus),
            f"fs {_summary.number(self.fs)} Hz",
            f"{self.n_samples} samples = {_summary.duration(self.n_samples / self.fs)}",
            _summary.per_channel(self.missing, "missing"),
            f"gaps={self.gaps}",
            f"{100 * self.confidence:.3g} % CI",
        ]

    def _title(self) -> str:
        return f"{self.kind} {'overlapping' if self.overlapping else 'non-overlapping'}"

    def __repr__(self) -> str:
        return _summary.lines(f"AllanResult({self._title()}", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """The facts, and per channel the deviation at the first and last tau and its
        minimum."""
        header, rows = _summary.curve_rows(self.taus, self.dev,
                                           _schema.axis_names(self.channels))
        missing = np.broadcast_to(self.missing, (self.channels,))
        return _summary.html_table(
            [*header, "missing"],
            [[*row, int(k)] for row, k in zip(rows, missing, strict=True)],
            caption=f"AllanResult: {self._title()}, " + ", ".join(self._facts()),
        )

    def plot(self, model: NoiseModel | None = None, **kwargs) -> Figure:
        """The deviation with its error bars, and ``model`` (:func:`imunoise.fit`) with
        its terms and read-off points when given: :func:`imunoise.plot.allan`."""
        from imunoise import plot

        return plot.allan(self, model, **kwargs)


def adev(
    x: npt.ArrayLike,
    fs: float,
    *,
    taus: TauSpec = "octave",
    overlapping: bool = True,
    confidence: float = ONE_SIGMA,
    gaps: str = "skip",
    data_type: str = "freq",
) -> AllanResult:
    """Allan deviation, overlapping by default.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, channels)
        Rate samples (any real dtype, any memory order).
    fs : float
        Sample rate in Hz.
    taus : {"octave", "decade", "all"}, int or array_like, optional
        Tau grid; see :func:`imunoise.taus.averaging_factors`. Taus whose
        estimator would have fewer than two terms are dropped.
    overlapping : bool, optional
        Overlapping estimator (stride 1, the default and the better one) or the
        classic non-overlapping one (stride m).
    confidence : float, optional
        Two-sided confidence level of the interval, default one sigma (68.3 %).
    gaps : {"skip", "longest", "splice"}, optional
        How NaN (missing samples) in ``x`` are treated, see the module notes:
        leave out the terms touching one (default), analyse the longest gap-free
        segment, or drop them and join the rest (both with a warning).
    data_type : {"freq", "phase"}, optional
        ``"freq"`` (default): ``x`` holds rate samples. ``"phase"``: ``x`` holds
        their integral at the same rate (time error in seconds for a clock, angle
        for a gyro), n + 1 points for n intervals; see the module notes.

    Returns
    -------
    AllanResult

    Examples
    --------
    >>> import numpy as np, imunoise
    >>> y = np.random.default_rng(0).normal(size=100_000)
    >>> r = imunoise.adev(y, fs=100.0)
    >>> bool(abs(r.dev[0] - 1.0) < 0.01)
    True
    """
    return _deviation("adev", x, fs, taus, confidence, gaps, overlapping=overlapping,
                      data_type=data_type)


def mdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
         confidence: float = ONE_SIGMA, gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    """Modified Allan deviation (SP 1065 eq. 14); see :func:`adev` for the parameters."""
    return _deviation("mdev", x, fs, taus, confidence, gaps, data_type=data_type)


def tdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
         confidence: float = ONE_SIGMA, gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    """Time deviation, τ·MDEV/√3 (SP 1065 eq. 16), in input units × seconds;
    see :func:`adev` for the parameters."""
    return _deviation("tdev", x, fs, taus, confidence, gaps, data_type=data_type)


def hdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave", overlapping: bool = True,
         confidence: float = ONE_SIGMA, gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    """Hadamard deviation (SP 1065 eqs. 17–20), overlapping by default; insensitive
    to a linear drift of the rate. See :func:`adev` for the parameters."""
    return _deviation("hdev", x, fs, taus, confidence, gaps, overlapping=overlapping,
                      data_type=data_type)


def ohdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
          confidence: float = ONE_SIGMA, gaps: str = "skip",
          data_type: str = "freq") -> AllanResult:
    """Overlapping Hadamard deviation (SP 1065 eq. 20), allantools' ``ohdev``: the same
    values as :func:`hdev` (overlapping by default), under the name allantools users
    know; ``kind == "ohdev"``. See :func:`adev` for the parameters."""
    return _deviation("ohdev", x, fs, taus, confidence, gaps, data_type=data_type)


def totdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
           confidence: float = ONE_SIGMA, gaps: str = "skip",
           data_type: str = "freq") -> AllanResult:
    """Total deviation (SP 1065 eq. 25): the overlapping Allan deviation of the
    phase extended by reflection at both ends, better confidence at long taus.
    No bias correction is applied (it is small for white and flicker FM).
    Cannot skip gaps: NaN in ``x`` needs ``gaps="longest"`` or ``"splice"``.
    See :func:`adev` for the parameters."""
    return _deviation("totdev", x, fs, taus, confidence, gaps, data_type=data_type)


def mtotdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
            confidence: float = ONE_SIGMA, bias_correction: bool = False,
            gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Modified total deviation (SP 1065 eq. 27; Howe & Vernotte 1999).

    Each of the N − 3m + 1 phase subsequences of 3m points (N = n + 1) has its
    linear trend removed (from the means of its two halves), is extended by
    uninverted even reflection to 9m points, and contributes the mean of its 6m
    squared second differences of m-point phase means:
    :math:`\mathrm{Mod\,Tot}\,\sigma^2(\tau) = \frac{1}{2\tau^2(N-3m+1)}
    \sum_i \frac{1}{6m}\sum_j (\bar x_j - 2\bar x_{j+m} + \bar x_{j+2m})^2`.
    Taus up to N/3 (as allantools). EDF: SP 1065 Table 8.

    ``x``, ``fs``, ``taus``, ``confidence`` and ``gaps`` as for :func:`adev`;
    cannot skip gaps (``gaps="longest"`` or ``"splice"`` for data with NaN).
    ``bias_correction`` as in the module notes, with the SP 1065 factors white PM
    0.94, flicker PM 0.83, white FM 0.73, flicker FM 0.70, random-walk FM 0.69.
    """
    return _deviation("mtotdev", x, fs, taus, confidence, gaps, bias_correction=bias_correction,
                      data_type=data_type)


def ttotdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
            confidence: float = ONE_SIGMA, bias_correction: bool = False,
            gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Time total deviation, τ·MTOTDEV/√3 (SP 1065 eq. 28, with τ² in the variance;
    the τ³ printed there is a typo), in input units × seconds. Parameters, EDF and
    bias correction as for :func:`mtotdev`."""
    return _deviation("ttotdev", x, fs, taus, confidence, gaps, bias_correction=bias_correction,
                      data_type=data_type)


def htotdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
            confidence: float = ONE_SIGMA, bias_correction: bool = False,
            gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Hadamard total deviation (SP 1065 eq. 29; Howe, Beard, Greenhall, Riley 2005).

    The MTOT construction applied to the *rate* samples: each of the n − 3m + 1
    subsequences of 3m samples is detrended, reflected to 9m samples, and
    contributes the mean of its 6m squared second differences of m-sample means
    divided by 6. At m = 1 the overlapping Hadamard deviation is returned (as
    Stable32 and allantools do). Insensitive to a linear rate drift. Taus up to n/3.
    EDF: SP 1065 gives none for HTOT; the overlapping Hadamard EDF (Greenhall) is
    used, a conservative lower bound.

    ``x``, ``fs``, ``taus``, ``confidence`` and ``gaps`` as for :func:`adev`;
    cannot skip gaps (``gaps="longest"`` or ``"splice"`` for data with NaN).
    ``bias_correction`` as in the module notes, with the SP 1065 factors white FM
    0.995, flicker FM 0.851, random-walk FM 0.771, flicker-walk FM 0.717,
    random-run FM 0.679; none is published for phase noise (α > 0), where no
    correction is applied, nor at m = 1.
    """
    return _deviation("htotdev", x, fs, taus, confidence, gaps, bias_correction=bias_correction,
                      data_type=data_type)


def theo1(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
          confidence: float = ONE_SIGMA, bias_correction: bool = False,
          gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Theo1 deviation (SP 1065 eq. 30; Howe & Peppler 2003), even m only.

    :math:`\mathrm{Theo1}(m) = \frac{1}{0.75\,(N-m)(m\tau_0)^2}\sum_{i=0}^{N-m-1}
    \sum_{\delta=0}^{m/2-1}\frac{[(x_i - x_{i-\delta+m/2}) + (x_{i+m} - x_{i+\delta+m/2})]^2}
    {m/2-\delta}` over the N = n + 1 phase points, for even 2 ≤ m < N.

    Tau convention: ``r.taus`` is m/fs, the averaging factor, as allantools reports
    it and as the NBS14 reference table lists it; the estimate belongs to the Allan
    variance at the *effective* averaging time 0.75·m/fs (multiply ``r.taus`` by
    0.75 to plot Theo1 next to ADEV). Odd m from a grid are skipped; explicit odd
    taus are dropped with a warning. ``r.n`` counts (N − m)·m/2 terms, as allantools
    does. Noise identification uses the factor 0.75·m; EDF: the SP 1065 Theo1
    formulas (Howe & Tasset) with r = 0.75·m.

    ``x``, ``fs``, ``taus``, ``confidence`` and ``gaps`` as for :func:`adev`;
    cannot skip gaps (``gaps="longest"`` or ``"splice"`` for data with NaN).
    ``bias_correction`` as in the module notes: the variance is multiplied by
    AVAR/Theo1 = a + b/m^c (Howe 2006, SP 1065): white PM 0.09 + 0.74/m^0.40,
    flicker PM 0.14 + 0.82/m^0.30, white FM 1, flicker FM 1.87 − 1.05/m^0.79,
    random-walk FM 2.70 − 1.53/m^0.85.
    """
    return _deviation("theo1", x, fs, taus, confidence, gaps, bias_correction=bias_correction,
                      data_type=data_type)


def theobr(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
           confidence: float = ONE_SIGMA, gaps: str = "skip",
           ratio_ladder: str = "taylor-howe", ratio_block: int = 1,
          data_type: str = "freq") -> AllanResult:
    r"""ThêoBR deviation: Theo1 with its bias relative to the Allan variance removed
    by the data's own AVAR/Theo1 ratio (Howe & Tasset 2004; Howe 2006; SP 1065
    §5.2.15). An estimate of the Allan deviation out to τ ≈ 0.75·T (T the record
    length) without knowing the noise type.

    .. math::

        \mathrm{Th\hat eoBR}(m) = \Big[\frac{1}{n+1}\sum_{i=0}^{n}
        \frac{\mathrm{AVAR}(9+3i)}{\mathrm{Theo1}(12+4i)}\Big]\,\mathrm{Theo1}(m),
        \qquad n = \lfloor 0.1\,N/3\rfloor - 3,

    over the N = n_samples + 1 phase points (so at least 89 samples), AVAR the
    overlapping Allan variance and Theo1 as in :func:`theo1`; each ratio compares
    the two at the same τ = (9 + 3i)/fs, from 9/fs to 10 % of the record. Even
    10 ≤ m ≤ N − 1, the range SP 1065 gives.

    Tau convention: unlike :func:`theo1`, ``r.taus`` is the averaging time the
    value belongs to, τ = 0.75·m/fs, so the curve lies on the Allan deviation's
    axis; ``r.m`` holds Theo1's even m. Named grids pick the even m ≥ 10 of the
    grid; an array of taus (seconds of averaging time) is rounded to the nearest
    even m. ``r.n`` counts Theo1's (N − m)·m/2 terms. Noise identification at
    0.75·m.

    EDF: Theo1's (SP 1065, Howe & Tasset, r = 0.75·m) combined with the bias
    ratio's, 1/ν = 1/ν_Theo1 + 1/ν_κ. Every tau is multiplied by the same
    estimated ratio κ, whose relative scatter (≈ 11 % for white FM) does not
    shrink with the record length; ν_κ by noise type (white PM … random-walk FM:
    10⁴, 400, 150, 250, 340) was measured by simulation. Stable32 and Howe's papers
    use Theo1's EDF alone, whose 68 % intervals then hold the true white-FM
    deviation in only 30–60 % of records at short taus.

    Cost: the bias ratio needs Theo1 at n + 1 ≈ N/30 factors up to M ≈ 0.13·N,
    whatever taus are asked for; one exact sweep gives them all in about 1.25·M²
    integer products (eight at a time with AVX-512 IFMA, where the CPU has it): a few
    seconds at 720,000 samples, minutes beyond 5·10⁶ (a warning says so beforehand).
    Ctrl-C stops it. Channels run in parallel. For much longer records use
    ``ratio_block`` (docs/total.md gives its error).

    Parameters
    ----------
    x, fs, taus, confidence, gaps
        As for :func:`adev` (taus: see the tau convention above); cannot skip gaps
        (``gaps="longest"`` or ``"splice"`` for data with NaN).
    ratio_ladder : {"taylor-howe", "sp1065"}
        The ratios averaged: ``"taylor-howe"``, n = ⌊0.1·N/3⌋ − 3 (Taylor & Howe
        2010, Stable32); ``"sp1065"``, n = ⌊N/6⌋ − 3 as SP 1065 eq. 33 prints it
        (ratios out to half the record; the sweep reaches ≈ 2N/3, about 25 times
        the work, and the ladder stops at the last AVAR with a term).
    ratio_block : int
        1 (default): the exact bias ratio. b > 1: the "fast ThêoBR": the ratio from
        the record averaged in blocks of b samples (b² less work; Theo1 at the taus
        still from every sample); needs n/b ≥ 89. Its error against the exact ratio
        by noise type is in docs/total.md.

    Returns
    -------
    AllanResult
        ``kind == "theobr"``.
    """
    data, one_d, missing, fs, confidence = _theo_input(x, fs, confidence, gaps, "theobr",
                                                       data_type)
    n = data.shape[0]
    m, user_given = _theo1_factors(taus, fs, n)
    m = _keep_theobr(m, n, fs, user_given, "theobr", lower=0.0)
    if m.size == 0:
        raise ImunoiseValueError(f"none of the taus is in range for theobr; got {taus!r}")
    ratio = _ratio_options(ratio_ladder, ratio_block, n)
    _warn_theobr_cost("theobr", n, m, data.shape[1], ratio)
    core = _core_allan.analyse(data, "theobr", m.astype(np.uint64), **ratio)
    return _assemble(
        "theobr", True, 0.75 * m / fs, m, core.var, core.terms, core.alpha,
        core.alpha_identified, core.edf, fs=fs, confidence=confidence, one_d=one_d,
        missing=missing, gaps=gaps, n_samples=n, data_type=data_type,
    )


def theoh(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
          confidence: float = ONE_SIGMA, gaps: str = "skip",
          ratio_ladder: str = "taylor-howe", ratio_block: int = 1,
          data_type: str = "freq") -> AllanResult:
    r"""ThêoH deviation: the overlapping Allan deviation at short taus and ThêoBR
    (:func:`theobr`) at long ones (Howe, "ThêoH: a hybrid, high-confidence
    statistic that improves on the Allan deviation", Metrologia 43, 2006; SP 1065
    §5.2.16). One curve from τ0 to ≈ 0.75·T with the Allan deviation's meaning and
    ThêoBR's confidence at long taus.

    .. math::

        \mathrm{Th\hat eoH}(\tau) = \begin{cases}
        \mathrm{AVAR}(\tau), & \tau \le k \\
        \mathrm{Th\hat eoBR}(m),\ \tau = 0.75\,m/f_s, & \tau > k
        \end{cases}

    with k the largest tau of the grid at most 10 % of the record length
    T = n_samples/fs. For ``taus="all"`` this is SP 1065's definition, where k is
    the largest τ ≤ 10 % T (SP 1065 puts τ = k itself on the ThêoBR side when
    0.75·m hits it exactly; here k stays an AVAR point, so a grid's last AVAR tau
    is never lost). Named grids: AVAR at the grid's m ≤ 0.1·n, ThêoBR at its even
    m ≥ 10 with 0.75·m/fs > k. An array of taus (seconds) is split the same way:
    taus ≤ 10 % T are AVAR taus (rounded to whole samples), the others are
    rounded to the nearest ThêoBR tau 0.75·(even m)/fs.

    ``r.taus`` is the averaging time of every point; ``r.m`` the estimator's own
    averaging factor (AVAR's m, then Theo1's even m: the ThêoBR points are those
    with ``r.taus * r.fs < r.m``); ``r.n`` its number of terms. EDF: Greenhall's
    for the overlapping AVAR, ThêoBR's (see :func:`theobr`); the noise type is identified
    over the whole curve (the longest taus take it from the nearest identified
    ones, as elsewhere). Needs at least 89 samples; cost: that of :func:`theobr`
    (the bias ratio), which a warning announces when it is long.

    Parameters (``ratio_ladder``, ``ratio_block`` included) and result as for
    :func:`theobr`, with ``kind == "theoh"``.
    """
    data, one_d, missing, fs, confidence = _theo_input(x, fs, confidence, gaps, "theoh",
                                                       data_type)
    n = data.shape[0]
    # Validates taus and gives the AVAR candidates (rounded to whole samples).
    m_avar, user_given = averaging_factors(taus, fs, n)
    short = m_avar <= 0.1 * n
    if user_given:
        arr = np.asarray(taus, dtype=np.float64)
        long_taus = arr[~short]
        dropped = int(np.count_nonzero(short & (m_avar < 1)))
        m_avar = m_avar[short & (m_avar >= 1)]
        if dropped:
            _warn.warn(
                f"{dropped} of {arr.size} taus dropped: theoh needs tau >= 1/fs = {1 / fs:g} s",
                CoverageWarning,
            )
        m_avar = np.unique(m_avar)
        k = int(m_avar.max()) if m_avar.size else 0
        m_theo = _theo1_factors(long_taus, fs, n)[0] if long_taus.size else m_avar[:0]
    else:
        m_avar = m_avar[short]
        k = int(m_avar.max())
        m_theo, _ = _theo1_factors(taus, fs, n)
    m_theo = _keep_theobr(m_theo, n, fs, user_given, "theoh", lower=k)
    if m_avar.size + m_theo.size == 0:
        raise ImunoiseValueError(f"none of the taus is in range for theoh; got {taus!r}")
    ratio = _ratio_options(ratio_ladder, ratio_block, n)
    _warn_theobr_cost("theoh", n, m_theo, data.shape[1], ratio)
    m = np.concatenate([m_avar, m_theo]).astype(np.int64)
    kind = _REGISTRY["theoh"]
    below_k = kind.short_taus or kind.statistic
    statistics = [below_k] * m_avar.size + [kind.statistic] * m_theo.size
    core = _core_allan.analyse_plan(data, statistics, m.astype(np.uint64), **ratio)
    tau = np.concatenate([m_avar / fs, 0.75 * m_theo / fs])
    return _assemble(
        "theoh", True, tau, m, core.var, core.terms, core.alpha, core.alpha_identified,
        core.edf, fs=fs, confidence=confidence, one_d=one_d, missing=missing, gaps=gaps,
        n_samples=n, data_type=data_type,
    )


def _deviation(
    kind: str,
    x: npt.ArrayLike,
    fs: float,
    taus: TauSpec,
    confidence: float,
    gaps: str,
    *,
    overlapping: bool = True,
    bias_correction: bool = False,
    data_type: str = "freq",
) -> AllanResult:
    """A statistic of :data:`KINDS` whose taus are m/fs, as its registry entry says.
    Called from the public function itself (the warnings' stack levels count on it)."""
    _check_bool("overlapping", overlapping)
    x, phase_missing = _rate_samples(x, fs, data_type)
    spec = _REGISTRY[kind]
    statistic = spec.non_overlapping if not overlapping and spec.non_overlapping else spec.statistic
    data, one_d, missing = gapped_samples(x, gaps, kind, statistic in _SKIPS_GAPS)
    fs = sample_rate(fs)
    confidence = confidence_level(confidence)
    _check_bool("bias_correction", bias_correction)
    n = data.shape[0]
    m, user_given = averaging_factors(taus, fs, n)
    if spec.even_m and not user_given:
        m = m[m % 2 == 0]
    m = m.astype(np.uint64)
    terms = _core_allan.estimator_terms(statistic, n + 1, m)
    m = keep_estimable(m.astype(np.int64), terms.astype(np.int64), fs, user_given, kind)
    if m.size == 0:
        raise ImunoiseValueError(
            f"x has {n} samples, too few for any tau of {kind} "
            f"(the shortest tau needs at least {_minimum_samples(statistic)})"
        )
    core = _core_allan.analyse(data, statistic, m.astype(np.uint64))
    var, terms, alpha, identified, edf = (
        core.var, core.terms, core.alpha, core.alpha_identified, core.edf
    )
    if missing is None:
        missing = core.missing.astype(np.int64)
        if missing.any():
            m, var, terms, alpha, identified, edf = _keep_gapped(
                kind, m, var, terms, alpha, identified, edf, fs, user_given, data
            )
    if phase_missing is not None:
        missing = phase_missing
    tau = m / fs
    if bias_correction and spec.bias is not None:
        var = var * spec.bias(alpha, m)
    if spec.time_scaled:
        with np.errstate(over="ignore", invalid="ignore"):
            scaled = var * (tau**2 / 3.0)[:, None]
        if np.any(np.isfinite(var) & ~np.isfinite(scaled)):
            raise ImunoiseValueError(
                f"fs is too small ({fs!r} Hz): {kind} = tau·deviation/√3 overflows double "
                f"precision at tau = {tau.max():g} s"
            )
        var = scaled
    return _assemble(
        kind, overlapping, tau, m, var, terms, alpha, identified, edf, fs=fs,
        confidence=confidence, one_d=one_d, missing=missing, gaps=gaps, n_samples=n,
        data_type=data_type,
    )


def adev_by_column(column: Callable[[int], np.ndarray], k: int, fs: float, *,
                   taus: TauSpec = "octave", confidence: float = ONE_SIGMA) -> AllanResult:
    """:func:`adev` of the (n, k) samples whose column j is ``column(j)`` (a 1-D
    float64 array, read when its turn comes), one column and the core's working
    arrays for it in memory rather than all k: the core analyses each channel on its
    own, so the result is that of the stacked array. Should the columns keep
    different taus (gaps that leave one channel too few terms at the longest), the
    stacked array is analysed instead."""
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        results = [adev(column(j), fs, taus=taus, confidence=confidence) for j in range(k)]
    if any(not np.array_equal(r.m, results[0].m) for r in results):
        return adev(np.column_stack([column(j) for j in range(k)]), fs, taus=taus,
                    confidence=confidence)
    for message in dict.fromkeys((str(w.message), w.category) for w in said):
        _warn.warn(*message)  # once each, as the stacked array's call says it
    first = results[0]

    def stacked(name: str) -> np.ndarray:
        return np.column_stack([getattr(r, name) for r in results])

    terms = stacked("n")
    return AllanResult(
        kind=first.kind, overlapping=first.overlapping, taus=first.taus, m=first.m,
        dev=stacked("dev"), var=stacked("var"),
        n=terms[:, 0].copy() if np.all(terms == terms[:, :1]) else terms,
        edf=stacked("edf"), ci_low=stacked("ci_low"), ci_high=stacked("ci_high"),
        alpha=stacked("alpha"), alpha_identified=stacked("alpha_identified"), fs=first.fs,
        confidence=first.confidence, n_samples=first.n_samples,
        missing=np.array([r.missing for r in results], dtype=np.int64), gaps=first.gaps)


def _keep_gapped(kind, m, var, terms, alpha, identified, edf, fs, user_given, data):
    """Drops the taus at which the gaps leave no channel two terms (warning when
    they were asked for explicitly); NaN where one channel has fewer than two."""
    enough = terms >= 2
    keep = enough.any(axis=1)
    if not keep.any():
        raise ImunoiseValueError(
            f"x's gaps leave {kind} fewer than 2 terms at every tau: no gap-free run is "
            f"long enough (pass gaps='splice' to join the runs)"
        )
    if user_given and not keep.all():
        # The rule: say what limited the taus (the record is long enough for them,
        # or keep_estimable would have dropped them: its gap-free runs are not) and
        # which argument changes it; a bare "gaps in x" left users guessing.
        run = longest_valid_run(data)
        _warn.warn(
            f"{int(np.count_nonzero(~keep))} of {len(m)} taus dropped: the missing "
            f"samples (NaN) of x split it into gap-free runs of at most {run / fs:g} s "
            f"({run} samples), too short for 2 {kind} terms beyond tau = "
            f"{m[keep].max() / fs:g} s (the record's length would allow "
            f"{m.max() / fs:g} s); ask taus up to that, or pass gaps='splice' to join "
            "the runs",
            GapWarning,
        )
    enough = enough[keep]
    return (
        m[keep],
        np.where(enough, var[keep], np.nan),
        terms[keep],
        alpha[keep],
        identified[keep],
        np.where(enough, edf[keep], np.nan),
    )


def _assemble(
    kind: str,
    overlapping: bool,
    tau: np.ndarray,
    m: np.ndarray,
    var: np.ndarray,
    terms: np.ndarray,
    alpha: np.ndarray,
    identified: np.ndarray,
    edf: np.ndarray,
    *,
    fs: float,
    confidence: float,
    one_d: bool,
    missing: np.ndarray,
    gaps: str,
    n_samples: int,
    data_type: str = "freq",
) -> AllanResult:
    """The result object from the core's (T, channels) arrays."""
    dev = np.sqrt(var)
    ci_low, ci_high = chi2_interval(dev, edf, confidence)
    squeeze = (lambda a: a[:, 0]) if one_d else (lambda a: a)
    same_terms = one_d or bool(np.all(terms == terms[:, :1]))
    return AllanResult(
        kind=kind,
        overlapping=overlapping,
        taus=tau,
        m=m,
        dev=squeeze(dev),
        var=squeeze(var),
        n=(terms[:, 0] if same_terms else terms).astype(np.int64),
        edf=squeeze(edf),
        ci_low=squeeze(ci_low),
        ci_high=squeeze(ci_high),
        alpha=squeeze(alpha).astype(np.int64),
        alpha_identified=squeeze(identified),
        fs=fs,
        confidence=confidence,
        n_samples=int(n_samples),
        missing=int(missing[0]) if one_d else np.asarray(missing, dtype=np.int64),
        gaps=gaps,
        data_type=data_type,
    )


def chi2_interval(
    dev: npt.ArrayLike, edf: npt.ArrayLike, confidence: float
) -> tuple[np.ndarray, np.ndarray]:
    """Two-sided χ² interval on a deviation with ``edf`` degrees of freedom
    (SP 1065 eq. 45): σ·√(ν/χ²(1 − p/2, ν)) ≤ σ ≤ σ·√(ν/χ²(p/2, ν)), p = 1 − confidence."""
    tail = (1.0 - confidence) / 2.0
    with np.errstate(invalid="ignore", divide="ignore"):
        low = dev * np.sqrt(edf / _stats.chi2.ppf(1.0 - tail, edf))
        high = dev * np.sqrt(edf / _stats.chi2.ppf(tail, edf))
    return low, high


def _theo_input(x, fs, confidence, gaps, kind: str, data_type: str):
    """The checked rate samples, fs and confidence of a Thêo statistic (no gap
    skipping; a record long enough for ThêoBR)."""
    x, phase_missing = _rate_samples(x, fs, data_type)
    data, one_d, missing = gapped_samples(x, gaps, kind, False)
    if phase_missing is not None:
        missing = phase_missing
    fs = sample_rate(fs)
    confidence = confidence_level(confidence)
    _check_theo_length(kind, data.shape[0])
    return data, one_d, missing, fs, confidence


def _check_theo_length(kind: str, n: int) -> None:
    """ThêoBR's bias ratio exists from ``THEOBR_MIN_SAMPLES`` on (the core's number)."""
    if n < _core_allan.THEOBR_MIN_SAMPLES:
        raise ImunoiseValueError(
            f"x has {n} samples, too few for {kind}: its bias ratio averages "
            f"n = floor(0.1·N/3) − 3 + 1 terms over the N = samples + 1 phase points, "
            f"which needs at least {_core_allan.THEOBR_MIN_SAMPLES} samples"
        )


def _theo1_factors(taus, fs: float, n: int) -> tuple[np.ndarray, bool]:
    """Theo1's even averaging factors for a tau specification of ThêoBR: the even m
    of a named grid, or each tau in seconds (an averaging time, 0.75·m/fs) rounded
    to the nearest even m."""
    m, user_given = averaging_factors(taus, fs, n)  # validates taus
    if not user_given:
        return m[m % 2 == 0], False
    half = np.round(np.asarray(taus, dtype=np.float64) * fs / 1.5)
    return 2 * np.clip(half, 0, n + 1).astype(np.int64), True


def _keep_theobr(m, n: int, fs: float, user_given: bool, kind: str, lower: float):
    """Even m in ThêoBR's range (10 ≤ m ≤ N − 1) with 0.75·m > ``lower`` (in
    samples), unique and sorted; warns when explicit taus are dropped."""
    m = np.asarray(m, dtype=np.int64)
    statistic = _REGISTRY[kind].statistic
    terms = _core_allan.estimator_terms(statistic, n + 1, m.astype(np.uint64)).astype(np.int64)
    keep = (terms > 1) & (0.75 * m > lower)
    dropped = int(np.count_nonzero(~keep))
    if dropped and user_given:
        above = f", above the last AVAR tau {lower / fs:g} s" if lower > 0 else ""
        _warn.warn(
            f"{dropped} of {m.size} taus dropped: {kind}'s ThêoBR taus are 0.75·m/fs for "
            f"even 10 <= m <= {n} (here {7.5 / fs:g} s to {0.75 * n / fs:g} s{above})",
            CoverageWarning,
        )
    return np.unique(m[keep])


#: ThêoBR's bias-ratio ladders (see :func:`theobr`).
RATIO_LADDERS = ("taylor-howe", "sp1065")


def _ratio_options(ladder, block, n: int) -> dict:
    """The checked ``ratio_ladder`` and ``ratio_block`` as the core's keywords."""
    if not isinstance(ladder, str) or ladder not in RATIO_LADDERS:
        raise ImunoiseValueError(f"ratio_ladder must be one of {RATIO_LADDERS}; got {ladder!r}")
    block = integer(block, "ratio_block", 1)
    need = _core_allan.THEOBR_MIN_SAMPLES
    if n // block < need:
        raise ImunoiseValueError(
            f"ratio_block must leave at least {need} block averages of the {n} samples "
            f"(ratio_block <= {n // need}); got {block}"
        )
    return {"ratio_ladder": ladder, "ratio_block": block}


def _warn_theobr_cost(kind: str, n: int, m: np.ndarray, channels: int, ratio: dict) -> None:
    """The bias ratio needs Theo1 at N/30 averaging factors: say so up front when
    that is long."""
    if m.size == 0:
        return
    seconds = channels * _core_allan.theobr_seconds(n + 1, [int(v) for v in m], **ratio)
    if seconds > 60:
        per = 30 if ratio["ratio_ladder"] == "taylor-howe" else 6
        _warn.warn(
            f"{kind}'s bias ratio needs Theo1 at N/{per} averaging factors (cost ~N²): "
            f"{n} samples will take roughly {seconds / 60:.0f} minutes; ratio_block=b "
            "(the fast ThêoBR) computes the ratio on averages of b samples in ~1/b² the time"
 , ImunoiseWarning       )


def _minimum_samples(statistic: str) -> int:
    for n in range(1, 16):
        if _core_allan.estimator_terms(statistic, n + 1, np.array([1], dtype=np.uint64))[0] > 1:
            return n
    return 16


def longest_valid_run(data: np.ndarray) -> int:
    """Length of the longest stretch of rows of ``data`` (n, channels) with no NaN in
    some channel (the best channel's longest gap-free run)."""
    best = 0
    for c in range(data.shape[1]):
        bad = np.flatnonzero(np.isnan(data[:, c]))
        edges = np.concatenate(([-1], bad, [data.shape[0]]))
        best = max(best, int(np.diff(edges).max()) - 1)
    return best


def gapped_samples(x, gaps, kind: str, skips: bool):
    """float64 (n, channels) samples ready for the core, whether x was 1-D, and the
    missing samples per channel (None when the core counts them: ``gaps="skip"``
    for a statistic that skips gaps, without a scan here)."""
    data, one_d = samples(x)
    if not isinstance(gaps, str) or gaps not in GAPS:
        error = ValueError if isinstance(gaps, str) else TypeError
        raise error(f"gaps must be one of 'skip', 'longest', 'splice'; got {gaps!r}")
    if gaps == "skip" and skips:
        return data, one_d, None
    nan = np.isnan(data)
    missing = nan.sum(axis=0)
    if not missing.any():
        return data, one_d, missing
    bad = nan.any(axis=1)
    n, dropped = len(bad), int(np.count_nonzero(bad))
    infinite = np.argwhere(np.isinf(data))
    if infinite.size:
        k, c = infinite[0]
        raise ImunoiseValueError(
            f"x must be finite or NaN (a missing sample); sample {k} is {data[k, c]}"
            + (f" (channel {c})" if data.shape[1] > 1 else "")
        )
    if gaps == "skip":
        raise ImunoiseValueError(
            f"x has {dropped} missing samples (NaN); {kind} cannot skip gaps: "
            "pass gaps='longest' or gaps='splice'"
        )
    if dropped == n:
        raise ImunoiseValueError(f"x has no valid samples: all {n} are NaN")
    if gaps == "longest":
        starts, ends = true_runs(~bad)
        i = int(np.argmax(ends - starts))
        a, b = int(starts[i]), int(ends[i])
        _warn.warn(
            f"x has {dropped} missing samples (NaN): {kind} analyses the longest gap-free "
            f"segment, samples {a} to {b - 1}, {b - a} of {n} samples ({100 * (b - a) / n:.3g} %)",
            GapWarning,
        )
        return data[a:b], one_d, missing
    _warn.warn(
        f"x has {dropped} missing samples (NaN): {kind} splices over them, joining the "
        f"{n - dropped} valid samples as if they were contiguous ({100 * dropped / n:.3g} % "
        "of the record spliced out); this biases long taus", GapWarning
    )
    return data[~bad], one_d, missing


def _rate_samples(x, fs, data_type: str):
    """``x`` as rate samples, and the missing phase points per channel (None for
    rate input, whose missing samples are counted where they are analysed).

    Phase x (n + 1 points) becomes y_i = (x_{i+1} − x_i)·fs (n samples). Every
    statistic of the family is a function of the phase's differences (second or
    higher, or the detrended phase), so this is exact, not an approximation; a
    missing phase point makes the two rate samples beside it missing, so a term
    whose span holds it is left out, as for rate input."""
    if not isinstance(data_type, str) or data_type not in DATA_TYPES:
        error = ValueError if isinstance(data_type, str) else TypeError
        raise error(f"data_type must be one of 'freq', 'phase'; got {data_type!r}")
    if data_type == "freq":
        return x, None
    data, one_d = samples(x)
    if data.shape[0] < 2:
        raise ImunoiseValueError(f"x as phase must have at least 2 points (one interval); got "
                         f"{data.shape[0]}")
    # checked before differencing: inf − inf would be NaN, a silent missing sample
    no_infinity(data)
    y = np.diff(data, axis=0) * sample_rate(fs)
    return (y[:, 0] if one_d else y), np.isnan(data).sum(axis=0)


def _check_bool(name, value) -> None:
    if not isinstance(value, (bool, np.bool_)):
        raise ImunoiseTypeError(f"{name} must be True or False; got {value!r}")
