r"""The power spectral density of rate noise, and its link to the Allan variance.

Convention
----------
:func:`psd` returns the **one-sided** density :math:`S_y(f)`, :math:`0 < f \le f_s/2`,
in the input's units²/Hz, so that :math:`\int_0^{f_s/2} S_y\,df` is the variance of
the samples (Parseval); the amplitude spectral density is :math:`\sqrt{S_y}` in
units/√Hz (``Spectrum.asd``). The estimate is Welch's (``scipy.signal.welch``: Hann
segments overlapping by half, each segment's mean removed, averaged periodograms).

White noise and N
-----------------
A one-sided white level :math:`S_y = h_0` has Allan variance :math:`h_0/(2\tau)`; the
IEEE 952 model writes it :math:`N^2/\tau`, so

.. math:: N = \sqrt{h_0/2}

— N is the square root of the **two-sided** density (units/√Hz = units·√s), the
convention of :func:`imunoise.fit`, :func:`imunoise.simulate` (white samples of standard
deviation :math:`N\sqrt{f_s}`) and of datasheets that quote an angle random walk. The
one-sided ASD of the same noise is √2·N: read a spectrum plot's flat level and divide
by √2. :func:`psd` reads N off automatically (see :class:`Spectrum`, ``band=``).

Power laws of the five IEEE terms
---------------------------------
One-sided rate PSD of each IEEE 952 (Annex C) term and its Allan variance
(:data:`POWER_LAWS`; f ≪ fs/2 where a sampled form differs):

======  ======================================  ====================  ===============
term    :math:`S_y(f)` (one-sided)              :math:`\sigma^2(\tau)`  α (S ∝ f^α)
======  ======================================  ====================  ===============
Q       :math:`8Q^2f_s\sin^2(\pi f/f_s) \approx 2(2\pi f)^2Q^2/f_s`  :math:`3Q^2/\tau^2`  2
N       :math:`2N^2`                            :math:`N^2/\tau`      0
B       :math:`B^2/(\pi f)`                     :math:`(2\ln 2/\pi)B^2`  −1
K       :math:`2K^2/(2\pi f)^2`                 :math:`K^2\tau/3`     −2
R       :math:`2R^2/(2\pi f)^3`                 :math:`R^2\tau^2/2`   −3
======  ======================================  ====================  ===============

(IEEE 952 gives the two-sided forms, half of these.) The Allan variance of a
one-sided power law :math:`h_\alpha f^\alpha` is the classic table (SP 1065 Table 3):
:math:`h_0/(2\tau)`, :math:`2\ln2\,h_{-1}`, :math:`(2\pi)^2h_{-2}\tau/6`, and
:math:`3f_hh_2/((2\pi)^2\tau^2)` with :math:`f_h = f_s/2`; the ramp R is deterministic and
its "PSD" is formal. A first-order Gauss–Markov term (the sampled AR1 of
:func:`imunoise.fit`, φ = e^(−1/(fs·τc))) has
:math:`S_y = 2\sigma^2(1-\varphi^2)/(f_s|1-\varphi e^{-2\pi i f/f_s}|^2)`.
:func:`model_psd` sums them to overlay a fitted :class:`imunoise.NoiseModel`.

References
----------
P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra",
IEEE Trans. Audio Electroacoust. 15(2), 1967.
D. B. Percival and A. T. Walden, *Spectral Analysis for Physical Applications*,
Cambridge 1993, §6.17 (EDF of Welch's estimate, eq. 292b).
IEEE Std 952-1997, Annex C. W. J. Riley, NIST SP 1065 (2008), Table 3.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from scipy import optimize as _optimize
from scipy import signal as _signal
from scipy import stats as _stats

from imunoise._support import schema as _schema
from imunoise._support import stream as _stream
from imunoise._support import summary as _summary
from imunoise._support.runs import true_runs
from imunoise._support.validate import (
    confidence_level,
    integer,
    no_infinity,
    positive_finite,
    sample_rate,
    samples,
)
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imunoise.noise import NoiseModel

__all__ = [
    "POWER_LAWS",
    "PowerLaw",
    "Spectrum",
    "coefficient_from_psd",
    "model_psd",
    "model_psd_terms",
    "psd",
    "resonance_psd",
    "term_psd",
]

#: Share of a gapped record's present samples its default Welch segments must cover.
_GAPPED_COVERAGE = 0.5

#: One-sigma confidence, erf(1/√2).
_ONE_SIGMA = 0.6826894921370859


@dataclass(frozen=True)
class PowerLaw:
    """One IEEE term as a power law: one-sided PSD ``psd_factor · C² · f^alpha`` (Q:
    times 1/fs) and Allan variance ``avar_factor · C² · τ^mu``, C the coefficient."""

    alpha: int
    psd_factor: float
    mu: int
    avar_factor: float


#: The five IEEE 952 terms (see the module notes).
POWER_LAWS: Mapping[str, PowerLaw] = MappingProxyType({
    "Q": PowerLaw(2, 2 * (2 * math.pi) ** 2, -2, 3.0),
    "N": PowerLaw(0, 2.0, -1, 1.0),
    "B": PowerLaw(-1, 1 / math.pi, 0, 2 * math.log(2) / math.pi),
    "K": PowerLaw(-2, 2 / (2 * math.pi) ** 2, 1, 1 / 3),
    "R": PowerLaw(-3, 2 / (2 * math.pi) ** 3, 2, 0.5),
})

# Relative misfit a binned PSD may show against the white-region model before the
# automatic band stops below it (sensor filters bend the top of the spectrum).
_BAND_TOLERANCE = 0.01
# Bins per decade of the internal log-binned spectrum the read-off fits.
_FIT_BINS_PER_DECADE = 20
# A binned value this many times the median of its _LINE_NEIGHBOURS neighbours is a line.
_LINE_RATIO = 1.5
_LINE_NEIGHBOURS = 7
# Fewest binned points the automatic white band keeps.
_MIN_BAND_BINS = 8
# Binned points at the band's top that must all follow the fit (a quarter decade: one
# bin that happens to fit above a filter's resonance must not stretch the band).
_EDGE_BINS = 5


@dataclass(frozen=True, repr=False)
class Spectrum:
    r"""One-sided power spectral density with its confidence band and the white-noise
    read-off N.

    Arrays over frequency have shape ``(F,)`` for 1-D input and ``(F, channels)``
    otherwise; read-only.

    Attributes
    ----------
    f : ndarray, (F,)
        Frequencies, Hz (0 excluded; log-bin centres, the geometric mean of the bin's
        frequencies, after :meth:`smooth`).
    psd : ndarray
        One-sided density :math:`S_y(f)`, input units²/Hz.
    ci_low, ci_high : ndarray
        ``confidence`` interval on ``psd``: :math:`S\nu/\chi^2_\nu(1-p/2)`,
        :math:`S\nu/\chi^2_\nu(p/2)`.
    edf : ndarray, (F,)
        Equivalent degrees of freedom of each value: Welch's
        :math:`\nu = 2K/(1 + 2\sum_{j<K}(1-j/K)\rho_j^2)` over K segments with the
        window's overlap correlation ρ_j (Percival & Walden eq. 292b); a log bin of
        n values has nν/(1 + 2Σ_l(1−l/n)r_l), r_l the window's correlation of
        periodogram values l bins apart (4/9 for adjacent Hann bins).
    N, N_std : ndarray
        White-noise coefficient √(h0/2) (input units/√Hz, the IEEE/two-sided
        convention: the one-sided ASD level is √2·N) and its standard uncertainty.
        Shape () or (channels,).
    white, flicker, walk : ndarray
        The read-off's fitted one-sided levels h0 (units²/Hz), h₋₁ (units²) and
        h₋₂ (units²·Hz) of :math:`S = h_0 + h_{-1}/f + h_{-2}/f^2` (0 where unresolved;
        flicker and walk are 0 for a user ``band``).
    band : ndarray, (2,) or (channels, 2)
        Frequencies (Hz) the read-off used.
    band_auto : bool
        Whether ``band`` was chosen automatically.
    lines : tuple of ndarray
        Per channel, the frequencies (Hz, log-bin centres) of the spectral lines the
        automatic read-off left out: bins above 1.5 times the median of their seven
        neighbours and at least twice the fitted level (a resonance, a vibration; the
        Allan deviation counts them as noise at the taus near 1/(2f)). Empty for a
        user ``band``.
    fs : float
        Sample rate, Hz.
    nperseg : int
        Samples per Welch segment (resolution fs/nperseg).
    n_samples : int
        Samples of the record.
    confidence : float
        Two-sided level of ``ci_low``/``ci_high``.
    segments : int
        Welch segments averaged.
    segments_skipped : int
        Segments left out because they hold a missing (NaN) sample: a record with
        gaps (or with :meth:`imunoise.Events.exclude`'s events) is analysed in the
        unbroken segments between them.
    bins_per_decade : int
        0 for Welch's linear grid, else the log binning of :meth:`smooth`.
    """

    f: np.ndarray
    psd: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    edf: np.ndarray
    N: np.ndarray
    N_std: np.ndarray
    white: np.ndarray
    flicker: np.ndarray
    walk: np.ndarray
    band: np.ndarray
    band_auto: bool
    lines: tuple[np.ndarray, ...]
    fs: float
    nperseg: int
    n_samples: int
    confidence: float
    segments: int = 0
    segments_skipped: int = 0
    bins_per_decade: int = 0

    def __post_init__(self) -> None:
        for name in ("f", "psd", "ci_low", "ci_high", "edf", "N", "N_std", "white",
                     "flicker", "walk", "band"):
            getattr(self, name).flags.writeable = False
        for found in self.lines:
            found.flags.writeable = False

    @property
    def channels(self) -> int:
        """Number of channels (1 for 1-D input)."""
        return 1 if self.psd.ndim == 1 else self.psd.shape[1]

    @property
    def asd(self) -> np.ndarray:
        """Amplitude spectral density √S, input units/√Hz (one-sided)."""
        return np.sqrt(self.psd)

    @property
    def asd_low(self) -> np.ndarray:
        """Lower bound of the interval on :attr:`asd`."""
        return np.sqrt(self.ci_low)

    @property
    def asd_high(self) -> np.ndarray:
        """Upper bound of the interval on :attr:`asd`."""
        return np.sqrt(self.ci_high)

    def __len__(self) -> int:
        return len(self.f)

    def smooth(self, bins_per_decade: int = 10) -> Spectrum:
        """The spectrum averaged in logarithmic frequency bins (for plotting): each
        bin's mean density, with the EDF that averaging gains; N is unchanged."""
        bins = integer(bins_per_decade, "bins_per_decade", 1)
        if self.bins_per_decade:
            raise ImunoiseValueError("this spectrum is already log-binned; smooth the original")
        f, p, edf = _log_bins(self.f, _columns(self.psd), self.edf, bins,
                              self._bin_correlation)
        low, high = _chi2_band(p, edf, self.confidence)
        squeeze = _squeezer(self.psd.ndim == 1)
        return replace(self, f=f, psd=squeeze(p), ci_low=squeeze(low),
                       ci_high=squeeze(high), edf=edf, bins_per_decade=bins)

    @property
    def _bin_correlation(self) -> np.ndarray:
        return _window_bin_correlation(self.nperseg)

    def _facts(self) -> list[str]:
        N = np.atleast_1d(self.N)
        Nstd = np.atleast_1d(self.N_std)
        read = ", ".join(_summary.number(v) for v in N)
        std = ", ".join(_summary.number(v) for v in Nstd)
        return [
            _summary.plural(self.channels, "channel"),
            f"{len(self.f)} freqs {_summary.number(self.f[0])}–{_summary.number(self.f[-1])} Hz",
            f"fs {_summary.number(self.fs)} Hz",
            f"{self.n_samples} samples = {_summary.duration(self.n_samples / self.fs)}",
            f"N {read} ± {std} /√Hz",
        ] + ([f"{self.segments_skipped} of {self.segments + self.segments_skipped} "
              "segments left out (missing samples)"] if self.segments_skipped else [])

    def __repr__(self) -> str:
        return _summary.lines("Spectrum(one-sided PSD", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per channel: N ± std, the band it was read in, the density range."""
        names = _schema.axis_names(self.channels)
        band = self.band.reshape(-1, 2)
        p = _columns(self.psd)
        rows = [
            [name, _summary.number(np.atleast_1d(self.N)[j]),
             _summary.number(np.atleast_1d(self.N_std)[j]),
             f"{_summary.number(band[j, 0])}–{_summary.number(band[j, 1])}",
             _summary.number(np.nanmin(p[:, j])), _summary.number(np.nanmax(p[:, j]))]
            for j, name in enumerate(names)
        ]
        return _summary.html_table(
            ["axis", "N [/√Hz]", "N std", "white band [Hz]", "min PSD", "max PSD"], rows,
            caption="Spectrum: " + ", ".join(self._facts()),
        )

    def plot(self, model: NoiseModel | None = None, **kwargs) -> Figure:
        """The smoothed PSD with its band, the N read-off and ``model``'s PSD:
        :func:`imunoise.plot.spectrum`."""
        from imunoise import plot

        return plot.spectrum(self, model, **kwargs)


def psd(
    x: npt.ArrayLike,
    fs: float,
    *,
    nperseg: int | None = None,
    confidence: float = _ONE_SIGMA,
    band: tuple[float, float] | None = None,
) -> Spectrum:
    """One-sided power spectral density (Welch) with confidence bands and N read-off.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, channels)
        Rate samples; NaN = missing. Segments holding a missing sample (in any
        channel) are left out of the average (``Spectrum.segments_skipped``).
    fs : float
        Sample rate, Hz.
    nperseg : int, optional
        Samples per Welch segment (Hann window, 50 % overlap). Default: the largest
        power of two ≤ n/8 (about 15 segments), at least 16 and at most n; for a
        record with gaps, the longest such power of two whose gap-free segments
        hold at least half of the present samples.
    confidence : float, optional
        Two-sided level of the band (default one sigma, 68.3 %).
    band : (f_low, f_high), optional
        Frequencies (Hz) where the noise is white: N is √(mean level/2) there,
        weighted by EDF. Default: chosen automatically — the spectrum, log-binned,
        is fitted with :math:`h_0 + h_{-1}/f + h_{-2}/f^2` (white, flicker, random
        walk; non-negative, weighted by each bin's EDF, iterated), from the lowest
        frequency up to the highest bin the fit still describes to within 1 % (plus
        its own scatter, 3σ): a sensor's anti-alias filter, which bends the top
        down, or quantization noise, which bends it up, is left out. N_std comes
        from the fit's covariance, inflated by the reduced χ² when it exceeds 1.

    Returns
    -------
    Spectrum

    Examples
    --------
    >>> import imunoise
    >>> y = imunoise.simulate(200_000, 100.0, N=1e-3, seed=1)
    >>> s = imunoise.psd(y, 100.0)
    >>> bool(abs(s.N / 1e-3 - 1) < 0.02)
    True
    """
    data, one_d = samples(x)
    no_infinity(data)
    fs = sample_rate(fs)
    confidence = confidence_level(confidence)
    n = data.shape[0]
    if n < 16:
        raise ImunoiseValueError(f"x must have at least 16 samples for a spectrum; got {n}")
    present = _stream.present_rows(data)
    if nperseg is None:
        seg = _default_nperseg(n)
        if not present.all():
            seg = _gapped_nperseg(present, seg)
    else:
        seg = integer(nperseg, "nperseg", 16)
    if seg > n:
        raise ImunoiseValueError(f"nperseg must be <= the number of samples ({n}); got {seg}")
    starts = _segment_starts(present, seg)
    if not starts.size:
        longest = _longest_run(present)
        raise ImunoiseValueError(
            f"x has no stretch of nperseg = {seg} samples without a missing (NaN) sample "
            f"(the longest is {longest}); pass nperseg <= {longest}"
            if longest >= 16 else
            f"x has no stretch of 16 samples without a missing (NaN) sample (the longest is "
            f"{longest}): a spectrum needs unbroken stretches"
        )
    user_band = None if band is None else _check_band(band, fs)
    largest = float(max(np.nanmax(data), -np.nanmin(data)))  # max |x|, without |x|'s copy
    _stream.release(data)  # the scans' pages of a memory map (read again by segments)
    with np.errstate(over="ignore"):
        f, p = _welch(data, fs, seg, starts) if largest < 1e150 else (None, None)
    if p is None or not np.all(np.isfinite(p)):
        raise ImunoiseValueError(f"x is too large for a spectrum: its power overflows (largest |x| "
                         f"{largest:.3g})")
    edf = np.full(f.shape, _welch_edf(seg, starts))
    if seg % 2 == 0:
        edf[-1] /= 2  # the Nyquist value is real: one χ² degree of freedom per segment
    low, high = _chi2_band(p, edf, confidence)
    fb, pb, edfb = _log_bins(f, p, edf, _FIT_BINS_PER_DECADE, _window_bin_correlation(seg))
    reads = [_read_white(fb, pb[:, j], edfb, user_band) for j in range(p.shape[1])]
    h, h_std, bands, lines = (list(v) for v in zip(*reads, strict=True))
    h, h_std, bands = np.array(h), np.array(h_std), np.array(bands)
    N = np.sqrt(h[:, 0] / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        N_std = np.where(N > 0, h_std / (4 * N), np.nan)
    squeeze = _squeezer(one_d)
    scalar = (lambda a: a[0]) if one_d else (lambda a: a)
    return Spectrum(
        f=f, psd=squeeze(p), ci_low=squeeze(low), ci_high=squeeze(high), edf=edf,
        N=np.asarray(scalar(N)), N_std=np.asarray(scalar(N_std)),
        white=np.asarray(scalar(h[:, 0])), flicker=np.asarray(scalar(h[:, 1])),
        walk=np.asarray(scalar(h[:, 2])), band=np.asarray(scalar(bands)),
        band_auto=user_band is None, lines=tuple(lines), fs=fs, nperseg=seg, n_samples=n,
        confidence=confidence, segments=int(starts.size),
        segments_skipped=_segment_count(n, seg) - int(starts.size),
    )


def term_psd(term: str, coefficient: npt.ArrayLike, f: npt.ArrayLike, *,
             fs: float | None = None) -> np.ndarray:
    """One-sided PSD of IEEE term ``term`` ("Q", "N", "B", "K", "R") with
    ``coefficient`` (input units: Q rate·s, N rate·√s, B rate, K rate/√s, R rate/s)
    at frequencies ``f`` (Hz, > 0). Q needs ``fs`` (its sampled form
    8Q²fs·sin²(πf/fs)). See :data:`POWER_LAWS`."""
    law = _law(term)
    c = np.asarray(coefficient, dtype=float)
    f = _check_frequencies(f)
    if term == "Q":
        fs = sample_rate(fs, "fs (needed for Q)") if fs is not None else _need_fs()
        return 8.0 * c**2 * fs * np.sin(np.pi * f / fs) ** 2
    return law.psd_factor * c**2 * f**law.alpha


def coefficient_from_psd(term: str, level: npt.ArrayLike, f: npt.ArrayLike, *,
                         fs: float | None = None) -> np.ndarray:
    """The coefficient of IEEE term ``term`` whose one-sided PSD is ``level``
    (units²/Hz) at ``f`` (Hz): the inverse of :func:`term_psd` (e.g. N = √(S/2))."""
    _law(term)
    unit = term_psd(term, 1.0, f, fs=fs)
    level = np.asarray(level, dtype=float)
    if np.any(level < 0):
        raise ImunoiseValueError("level must be >= 0 (a power spectral density)")
    return np.sqrt(level / unit)


def model_psd(model: NoiseModel, f: npt.ArrayLike) -> np.ndarray:
    """One-sided PSD of a fitted noise model at ``f`` (Hz): its IEEE terms and its
    Gauss–Markov terms summed, shape (F,) for a one-channel model else (F, channels);
    the terms alone: :func:`model_psd_terms`."""
    parts = model_psd_terms(model, f)
    return sum(parts.values())


def model_psd_terms(model: NoiseModel, f: npt.ArrayLike) -> dict[str, np.ndarray]:
    """Each fitted term of ``model`` that is present (non-zero) as its one-sided PSD
    at ``f``, by the name ``fit(terms=...)`` asks for it: keys "Q", "N", "B", "K",
    "R", "GM1", … (GM: the sampled AR1, see the module), "resonance"
    (:func:`resonance_psd`) and "motion" (the rate of the angle's AR1). The white
    term passes the channel's measured output filter. A tone is a line, no
    density: plots mark its frequency (:attr:`NoiseModel.lines`)."""
    from imunoise.noise import _typed

    f = _check_frequencies(f)
    fs = float(model.fs)
    channels = 1 if model.one_channel else model.channels
    filters = getattr(model, "filter", ()) or (None,) * channels
    out: dict[str, np.ndarray] = {}
    for j in range(channels):
        for name, density in _typed.psd_parts(model.terms[j], f, fs).items():
            if name == "N" and filters[j] is not None:
                density = density * np.interp(f, filters[j].f, filters[j].gain)
            if np.any(density > 0):
                out.setdefault(name, np.zeros((f.size, channels)))[:, j] = density
    return {k: (v[:, 0] if model.one_channel else v) for k, v in out.items()}


def resonance_psd(sigma: float, f_r: float, tau_r: float, skew: float, f, fs: float):
    r"""One-sided PSD at ``f`` of the model's resonance: the sampled process of
    autocovariance :math:`\sigma^2\,\mathrm{Re}[(1-i\beta)z^{|h|}]`,
    :math:`z = e^{-1/(f_s\tau_r) + 2\pi i f_r/f_s}`, β its skew times the bound that
    keeps the spectrum non-negative:

    .. math:: S(f) = \frac{2\sigma^2}{f_s}\,\mathrm{Re}\left[(1-i\beta)
              \frac{1-z^2}{(1-z e^{-i\omega})(1-z e^{i\omega})}\right],
              \quad \omega = 2\pi f/f_s

    (the sum of the autocovariance's geometric series); at f = 0 it is 2N² of the
    white tail its Allan variance has beyond τr."""
    from imunoise.noise._terms import quadrature_bound

    z = math.exp(-1.0 / (fs * tau_r)) * complex(math.cos(2 * math.pi * f_r / fs),
                                                math.sin(2 * math.pi * f_r / fs))
    bound = quadrature_bound(f_r, tau_r, fs)
    beta = skew * bound if math.isfinite(bound) else 0.0
    e = np.exp(-2j * np.pi * np.asarray(f, float) / fs)
    series = (1 - z * z) / ((1 - z * e) * (1 - z * np.conj(e)))
    return np.maximum(2 * sigma**2 / fs * ((1 - 1j * beta) * series).real, 0.0)


# -- the estimate ---------------------------------------------------------------------


def _default_nperseg(n: int) -> int:
    return min(n, max(16, 1 << max(int(math.floor(math.log2(max(n, 1) / 8))), 0)))


def _segment_count(n: int, seg: int) -> int:
    """Welch's segments of ``seg`` samples, overlapping by half, in ``n`` samples."""
    return 1 + (n - seg) // (seg - seg // 2)


def _segment_starts(present: np.ndarray, seg: int) -> np.ndarray:
    """Starts of Welch's segments (``seg`` samples, overlapping by half) that hold no
    missing sample; ``present`` (n,) is False where a row misses one."""
    starts = (seg - seg // 2) * np.arange(_segment_count(len(present), seg))
    if present.all():
        return starts
    # missing rows before each row (32-bit counts where they fit: a long record's)
    missing = np.zeros(len(present) + 1, dtype=np.int32 if len(present) < 2**31 else np.int64)
    np.cumsum(~present, out=missing[1:])
    return starts[missing[starts + seg] == missing[starts]]


#: Segment samples (segments × length × channels) the Welch average transforms at once:
#: ``scipy.signal.welch`` holds every segment, its windowed copy and its transform
#: together, about four times a long record (1.3 GB for 2 h of gyro at 800 Hz); a
#: gap-free record with more is averaged a group of segments at a time.
WELCH_PIECE = 1 << 22


def _welch(data: np.ndarray, fs: float, seg: int, starts: np.ndarray):
    """Frequencies (0 excluded) and the mean Hann periodogram (F, channels) of the
    segments of ``data`` starting at ``starts``, each with its mean removed:
    ``scipy.signal.welch`` where no segment is left out."""
    complete = starts.size == _segment_count(len(data), seg)
    if complete and starts.size * seg * data.shape[1] <= WELCH_PIECE:
        f, p = _signal.welch(data, fs=fs, window="hann", nperseg=seg, noverlap=seg // 2,
                             detrend="constant", scaling="density", axis=0)
        return f[1:], p[1:]
    pieces = starts.size * seg * data.shape[1] // WELCH_PIECE if complete else \
        starts.size * seg // (1 << 22)
    p = 0.0
    window = _signal.get_window("hann", seg)
    scale = 1.0 / (fs * np.sum(window * window))
    # at most one piece per segment (more left empty pieces, whose spectra do not add);
    # a channel at a time (a segment of a long record is large)
    for chunk in np.array_split(starts, min(starts.size, max(1, pieces))):
        part = np.empty((seg // 2 + 1, data.shape[1]))
        for c in range(data.shape[1]):
            pieces = np.lib.stride_tricks.sliding_window_view(data[:, c], seg)[chunk]
            _stream.release(data)  # a memory map's pages: those of the next piece only
            part[:, c] = _periodograms(pieces, window, scale).sum(axis=0)
        p = p + part
    return np.fft.rfftfreq(seg, 1.0 / fs)[1:], (p / starts.size)[1:]


def _periodograms(segments: np.ndarray, window: np.ndarray, scale: float) -> np.ndarray:
    """One-sided Hann periodograms (density) of ``segments`` (k, L), each less its mean:
    ``scipy.signal.welch`` of one segment, without its per-call set-up (a window and
    its sums per call: a third of the time on a long record's segments)."""
    x = segments - segments.mean(axis=-1, keepdims=True)
    x *= window
    spectrum = np.fft.rfft(x, axis=-1)
    del x
    p = spectrum.real ** 2
    p += spectrum.imag ** 2
    del spectrum
    p *= scale
    p[..., 1:-1 if segments.shape[-1] % 2 == 0 else None] *= 2.0  # both sides but 0, Nyquist
    return p


def _welch_edf(seg: int, starts: np.ndarray) -> float:
    """Percival & Walden eq. 292b for Hann segments overlapping by half: 2K/(1 +
    2Σ_j (pairs_j/K) ρ_j²) over the K segments at ``starts``, pairs_j of them j steps
    apart (K − j for an unbroken record, the equation's 1 − j/K)."""
    step = seg - seg // 2
    k = starts.size
    w = _signal.get_window("hann", seg)
    norm = np.sum(w * w)
    total = 0.0
    for j in range(1, k):
        shift = j * step
        if shift >= seg:
            break
        rho = np.sum(w[:-shift] * w[shift:]) / norm
        pairs = np.count_nonzero(np.isin(starts + shift, starts))
        total += pairs / k * rho * rho
    return 2.0 * k / (1.0 + 2.0 * total)


def _gapped_nperseg(present: np.ndarray, seg: int) -> int:
    """The longest power-of-two segment, at most ``seg``, whose gap-free Welch
    segments hold at least :data:`_GAPPED_COVERAGE` of the present samples (16 if
    none does): long segments resolve low frequencies, but between many gaps few fit."""
    wanted = _GAPPED_COVERAGE * np.count_nonzero(present)
    while seg > 16:
        if _segment_starts(present, seg).size * (seg - seg // 2) >= wanted:
            return seg
        seg //= 2
    return 16


def _longest_run(present: np.ndarray) -> int:
    """Length of the longest run of True in ``present``."""
    starts, stops = true_runs(present)
    return int((stops - starts).max()) if starts.size else 0


def _window_bin_correlation(seg: int) -> np.ndarray:
    """Correlation r_l of the periodogram values of white noise l bins apart under the
    Hann window, |Σ w² e^(−2πi nl/L)|² / (Σ w²)², for l = 0, 1, 2, … while it matters."""
    w2 = _signal.get_window("hann", seg) ** 2
    spectrum = np.abs(np.fft.rfft(w2)) ** 2 / np.sum(w2) ** 2
    r = spectrum[: min(8, spectrum.size)]
    return r[r > 1e-6]


def _log_bins(f, p, edf, bins_per_decade: int, correlation: np.ndarray):
    """Means of ``p`` (F, channels) in logarithmic frequency bins, with their EDF."""
    edges = np.floor(np.log10(f) * bins_per_decade).astype(np.int64)
    starts = np.flatnonzero(np.r_[True, edges[1:] != edges[:-1]])
    counts = np.diff(np.r_[starts, f.size])
    sums = np.add.reduceat(p, starts, axis=0)
    centre = np.exp(np.add.reduceat(np.log(f), starts) / counts)
    edf_sum = np.add.reduceat(edf, starts)
    lags = np.arange(correlation.size)
    inflation = np.array([
        1 + 2 * np.sum((1 - lags[1:c] / c) * correlation[1:c]) if c > 1 else 1.0
        for c in counts
    ])
    return centre, sums / counts[:, None], edf_sum / inflation


def _chi2_band(p, edf, confidence: float):
    tail = (1.0 - confidence) / 2.0
    # the quantiles once per distinct EDF, not per frequency: a Welch spectrum has
    # two values (millions of frequencies on a day's log) and each costs microseconds
    values, which = np.unique(edf, return_inverse=True)
    upper, lower = (_stats.chi2.ppf(q, values)[which] for q in (1 - tail, tail))
    if np.ndim(p) == 2:
        edf, upper, lower = edf[:, None], upper[:, None], lower[:, None]
    return p * edf / upper, p * edf / lower


# -- the white-noise read-off ---------------------------------------------------------


def _read_white(f, p, edf, user_band):
    """(h0, h₋₁, h₋₂), the standard deviation of h0, and the band used, of one
    channel's log-binned spectrum."""
    if user_band is not None:
        inside = (f >= user_band[0]) & (f <= user_band[1])
        if np.count_nonzero(inside) < 1:
            raise ImunoiseValueError(
                f"band {user_band} holds no frequency of the spectrum "
                f"({f[0]:.4g}–{f[-1]:.4g} Hz)"
            )
        h, std = _fit_levels(f[inside], p[inside], edf[inside], columns=1)
        return np.r_[h, 0.0, 0.0], std, np.array(user_band, dtype=float), np.empty(0)
    if not np.any(p > 0):  # a constant channel: no noise, no band to choose
        return np.zeros(3), np.nan, np.array([f[0], f[-1]]), np.empty(0)
    lines = _lines(p)
    keep = ~lines
    top = f.size
    while True:
        band = keep[:top]
        h, std = _fit_levels(f[:top][band], p[:top][band], edf[:top][band], columns=3)
        edge = np.flatnonzero(band)[-_EDGE_BINS:]
        model = h[0] + h[1] / f[edge] + h[2] / f[edge] ** 2
        scatter = np.sqrt(2 / edf[edge] + _BAND_TOLERANCE**2)
        if np.count_nonzero(band) <= _MIN_BAND_BINS or np.all(
                np.abs(p[edge] / model - 1) <= 3 * scatter):
            break
        top -= 1
    level = h[0] + h[1] / f + h[2] / f**2
    strong = lines & (p > 2 * level) & (f <= f[top - 1])
    return h, std, np.array([f[0], f[top - 1]]), f[strong]


def _lines(p: np.ndarray) -> np.ndarray:
    """Bins of a log-binned spectrum that hold a spectral line (a resonance, vibration):
    above 1.5 times the median of the seven bins around them, and their neighbours (the
    window leaks a line into them). The white-band fit leaves them out instead of
    ending the band below them."""
    half = _LINE_NEIGHBOURS // 2
    padded = np.pad(p, half, mode="edge")
    local = np.median(np.lib.stride_tricks.sliding_window_view(padded, _LINE_NEIGHBOURS), axis=1)
    peak = p > _LINE_RATIO * local
    return peak | np.r_[peak[1:], False] | np.r_[False, peak[:-1]]


def _fit_levels(f, p, edf, columns: int):
    """Non-negative weighted least squares of p on [1, 1/f, 1/f²][:columns], each
    value weighted by its variance 2S²/ν (S from the previous iteration); the level
    h0 and its standard deviation (covariance of the active terms, times the reduced
    χ² when above 1)."""
    basis = np.stack([f**-k for k in range(columns)], axis=1)
    top = float(np.max(p)) if p.size else 0.0
    if not top > 0:  # a constant channel: no noise at all
        return np.zeros(columns), 0.0
    h, std = _fit_scaled(basis, p / top, edf)  # in units of the largest value: the
    return h * top, std * top                  # weights neither overflow nor underflow


def _fit_scaled(basis, p, edf):
    """:func:`_fit_levels` on ``p`` whose largest value is 1."""
    expected = p.copy()
    for _ in range(4):
        w = np.sqrt(edf / 2) / np.maximum(expected, 1e-12)
        h, _ = _optimize.nnls(basis * w[:, None], p * w)
        fitted = basis @ h
        if not np.all(fitted > 0):
            break
        expected = fitted
    active = h > 0
    if not active[0]:
        return h, np.nan
    a = basis[:, active] * w[:, None]
    cov = np.linalg.pinv(a.T @ a)
    dof = max(p.size - int(active.sum()), 1)
    chi2 = float(np.sum(((p - basis @ h) * w) ** 2)) / dof
    return h, float(math.sqrt(cov[0, 0] * max(chi2, 1.0)))


# -- arguments -------------------------------------------------------------------------


def _check_band(band, fs: float) -> tuple[float, float]:
    try:
        low, high = band
    except (TypeError, ValueError):
        raise ImunoiseTypeError(
            f"band must be a pair (f_low, f_high) in Hz; got {band!r}") from None
    low = positive_finite(low, "band[0]", unit="Hz")
    high = positive_finite(high, "band[1]", unit="Hz")
    if not low < high <= fs / 2:
        raise ImunoiseValueError(
            f"band must satisfy 0 < f_low < f_high <= fs/2 = {fs / 2:g} Hz; got {band!r}"
        )
    return low, high


def _check_frequencies(f) -> np.ndarray:
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(f) & (f > 0)):
        raise ImunoiseValueError("f must hold positive finite frequencies (Hz)")
    return f


def _law(term) -> PowerLaw:
    if term not in POWER_LAWS:
        raise ImunoiseValueError(f"term must be one of {', '.join(POWER_LAWS)}; got {term!r}")
    return POWER_LAWS[term]


def _need_fs():
    raise ImunoiseValueError("fs is required for term 'Q' (its PSD depends on the sample rate)")


def _columns(a: np.ndarray) -> np.ndarray:
    return a[:, None] if a.ndim == 1 else a


def _squeezer(one_d: bool):
    return (lambda a: a[:, 0]) if one_d else (lambda a: a)
