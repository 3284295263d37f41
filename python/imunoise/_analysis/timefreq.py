r"""Statistics of the phase from time and frequency metrology: PDEV, MTIE and TIE rms.

They work on the phase x (the integral of the rate: time error in seconds for a
clock, angle for a gyro) at N points, taken as given for ``data_type="phase"`` and
built from rate samples as allantools does, :math:`x_0 = 0`,
:math:`x_{k} = \sum_{i<k}(y_i - \bar y)/f_s` (N = n + 1), for ``"freq"``. With
:math:`\tau = m/f_s`:

- parabolic variance (Vernotte et al. 2016), the least-squares (Ω) counter's
  two-sample variance,
  :math:`\sigma^2_P(\tau) = \frac{72}{M m^4 \tau^2}\sum_{i=0}^{M-1}\Big[\sum_{k=0}^{m-1}
  \big(\tfrac{m-1}{2} - k\big)(x_{i+k} - x_{i+k+m})\Big]^2`, M = N − 2m, for m > 1,
  and the overlapping Allan variance at m = 1 (where the weights vanish);
- maximum time interval error, :math:`\mathrm{MTIE}(\tau) = \max_i\,(\max - \min)
  \{x_i … x_{i+m}\}` over the N − m windows of m + 1 points (ITU-T G.810);
- TIE rms, :math:`\sqrt{\tfrac{1}{N-m}\sum_i (x_{i+m} - x_i)^2}`.

These are allantools' definitions (pdev, mtie, tierms), and the values equal
allantools' to rounding. Unlike the Allan variances, MTIE and TIE rms keep the
phase's linear trend (a rate offset) for phase input, as allantools does; rate
input has its mean removed first.

Gaps: a missing sample (NaN) leaves out every term (window) whose span holds it —
a rate sample missing breaks the phase between its two points, a phase point
missing breaks both intervals beside it — and ``r.n`` counts the terms used; as in
:mod:`imunoise.allan`, ``gaps="longest"`` and ``"splice"`` analyse the longest
gap-free run or join the runs.

References
----------
F. Vernotte, M. Lenczner, P.-Y. Bourgeois, E. Rubiola, "The parabolic variance
(PVAR): a wavelet variance based on the least-square fit", IEEE Trans. UFFC 63(4),
2016.
S. Bregni, "Fast algorithms for TVAR and MTIE computation in characterization of
network synchronization performance", 2001.
ITU-T G.810 (1996), Definitions and terminology for synchronization networks.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy import signal as _signal

from imunoise._core import allan as _core_allan
from imunoise._support import warn as _warn
from imunoise._support.runs import true_runs
from imunoise._support.validate import confidence_level, no_infinity, sample_rate, samples
from imunoise.allan import (
    DATA_TYPES,
    GAPS,
    ONE_SIGMA,
    AllanResult,
    TauSpec,
    chi2_interval,
    gapped_samples,
)
from imunoise.errors import ImunoiseValueError
from imunoise.taus import averaging_factors, keep_estimable

__all__ = ["pdev", "mtie", "tierms"]


def phase_points(x, fs: float, data_type: str, gaps: str, kind: str):
    """The phase of ``x`` as (N, channels) points, ready for a phase statistic.

    Returns ``(phase, broken, one_d, missing, fs)``: ``phase`` with missing points
    set to 0, ``broken`` (N − 1, channels) True where the interval between two
    phase points is unknown, whether x was 1-D, the missing samples (rate input) or
    phase points (phase input) per channel, and the checked fs.
    """
    if not isinstance(data_type, str) or data_type not in DATA_TYPES:
        error = ValueError if isinstance(data_type, str) else TypeError
        raise error(f"data_type must be one of 'freq', 'phase'; got {data_type!r}")
    fs = sample_rate(fs)
    if data_type == "freq":
        data, one_d, missing = gapped_samples(x, gaps, kind, True)
        nan = np.isnan(data)
        if missing is None:
            missing = nan.sum(axis=0)
        if nan.all(axis=0).any():
            raise ImunoiseValueError(f"x has no valid samples in channel "
                             f"{int(np.flatnonzero(nan.all(axis=0))[0])}: all are NaN")
        no_infinity(data)
        # allantools' frequency2phase: the mean rate removed, phase from 0
        with np.errstate(invalid="ignore"):
            centred = np.where(nan, 0.0, data - np.nanmean(data, axis=0))
        phase = np.concatenate([np.zeros((1, data.shape[1])), np.cumsum(centred, axis=0)])
        return phase / fs, nan, one_d, missing, fs
    if not isinstance(gaps, str) or gaps not in GAPS:
        error = ValueError if isinstance(gaps, str) else TypeError
        raise error(f"gaps must be one of 'skip', 'longest', 'splice'; got {gaps!r}")
    data, one_d = samples(x)
    if data.shape[0] < 2:
        raise ImunoiseValueError(f"x as phase must have at least 2 points (one interval); got "
                         f"{data.shape[0]}")
    no_infinity(data)
    nan = np.isnan(data)
    missing = nan.sum(axis=0)
    bad = nan.any(axis=1)
    if bad.all():
        raise ImunoiseValueError(f"x has no valid phase points: all {len(bad)} are NaN")
    if gaps == "longest" and bad.any():
        starts, ends = true_runs(~bad)
        i = int(np.argmax(ends - starts))
        a, b = int(starts[i]), int(ends[i])
        _warn.warn(
            f"x has {int(bad.sum())} missing phase points (NaN): {kind} analyses the "
            f"longest gap-free segment, points {a} to {b - 1}, {b - a} of {len(bad)}"
        )
        data, nan = data[a:b], nan[a:b]
    elif gaps == "splice" and bad.any():
        # the rate samples between valid points, joined: the phase jump over each
        # gap is left out, as for spliced rate input
        rate = np.diff(data, axis=0)
        keep = ~np.isnan(rate).any(axis=1)
        _warn.warn(
            f"x has {int(bad.sum())} missing phase points (NaN): {kind} splices over "
            f"them, joining the {int(keep.sum())} valid intervals as if they were "
            "contiguous; this biases long taus"
        )
        first = data[np.flatnonzero(~bad)[0]]
        data = first + np.concatenate([np.zeros((1, data.shape[1])),
                                       np.cumsum(rate[keep], axis=0)])
        nan = np.zeros(data.shape, dtype=bool)
    if data.shape[0] < 2:
        raise ImunoiseValueError(f"x's longest gap-free run has {data.shape[0]} phase point; "
                         f"{kind} needs at least 2")
    broken = nan[:-1] | nan[1:]
    return np.where(nan, 0.0, data), broken, one_d, missing, fs


def valid_windows(broken: np.ndarray, span: int, count: int) -> np.ndarray:
    """(count, channels) True where the window of phase points i … i + span holds
    no broken interval (intervals i … i + span − 1), for i < count."""
    runs = np.concatenate([np.zeros((1, broken.shape[1]), dtype=np.int64),
                           np.cumsum(broken, axis=0, dtype=np.int64)])
    return (runs[span:span + count] - runs[:count]) == 0


def averaging_grid(taus, fs: float, n_points: int, kind: str, terms) -> np.ndarray:
    """The averaging factors of ``taus`` at which ``terms(m)`` (the number of
    terms of the statistic) is at least 2."""
    m, user_given = averaging_factors(taus, fs, n_points - 1)
    m = keep_estimable(m, terms(np.maximum(m, 1)), fs, user_given, kind)
    if m.size == 0:
        # m = 1 has n_points − c terms: two of them need c + 2 points
        least = n_points - int(terms(np.array([1]))[0]) + 2
        raise ImunoiseValueError(f"x has {n_points} phase points (rate samples + 1), too few for "
                         f"any tau of {kind} (at least {least}: two terms at tau = 1/fs)")
    return m


def tau_result(kind, m, var, dev, terms, edf, alpha, identified, *, fs, confidence, one_d,
            missing, gaps, n_points, data_type) -> AllanResult:
    """An AllanResult from (T, channels) arrays."""
    ci_low, ci_high = chi2_interval(dev, edf, confidence)
    squeeze = (lambda a: a[:, 0]) if one_d else (lambda a: a)
    same = one_d or bool(np.all(terms == terms[:, :1]))
    return AllanResult(
        kind=kind, overlapping=True, taus=m / fs, m=m.astype(np.int64), dev=squeeze(dev),
        var=squeeze(var), n=(terms[:, 0] if same else terms).astype(np.int64),
        edf=squeeze(edf), ci_low=squeeze(ci_low), ci_high=squeeze(ci_high),
        alpha=squeeze(alpha).astype(np.int64), alpha_identified=squeeze(identified),
        fs=fs, confidence=confidence, n_samples=int(n_points - 1),
        missing=int(np.asarray(missing)[0]) if one_d else np.asarray(missing, np.int64),
        gaps=gaps, data_type=data_type,
    )


def _pdev_terms(n_points: int):
    return lambda m: np.where(m == 1, n_points - 2, n_points - 2 * m)


def pdev(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
         confidence: float = ONE_SIGMA, gaps: str = "skip",
         data_type: str = "freq") -> AllanResult:
    r"""Parabolic deviation (PDEV; Vernotte et al. 2016), allantools' ``pdev``.

    .. math::

        \sigma^2_P(m\tau_0) = \frac{72}{M\,m^4\,(m\tau_0)^2}\sum_{i=0}^{M-1}
        \Big[\sum_{k=0}^{m-1}\Big(\frac{m-1}{2} - k\Big)(x_{i+k} - x_{i+k+m})\Big]^2,
        \qquad M = N - 2m,

    over the N phase points, for m > 1; at m = 1 the weights vanish and PDEV is the
    overlapping Allan deviation (N − 2 terms), as allantools defines it. The
    variance of the frequency a least-squares (Ω) counter reads: like MDEV it
    separates white from flicker phase noise (τ^−3/2 against τ^−1), but its wavelet
    spans 2τ, as ADEV's, so it reaches taus up to N/2 (MDEV: N/3). M = N − 2m follows
    allantools (the sum's last start, N − 2m, is left out).

    Confidence: no EDF algorithm is published for PVAR; the MDEV EDF of Greenhall's
    algorithm at the same m (ADEV's where MDEV has no term, m > N/3) scales the
    overlapping ADEV's, for the noise type identified at each tau and the gaps
    as ADEV pools them. Vernotte et al. find PVAR's degrees of freedom at least
    MVAR's for every power-law noise, so the interval errs wide: on 200 records of
    2048 samples of white PM, white FM and random-walk FM the EDF used is 0.5–1.1
    times the records' own (2·mean²/variance of the estimates), m = 1 … 512.

    Cost: one correlation of length m per tau (FFT for long m), O(N log N); the
    sum above is O(N m) (allantools loops over it in Python).

    ``x``, ``fs``, ``taus``, ``confidence``, ``gaps`` and ``data_type`` as for
    :func:`imunoise.adev`; the result's ``kind`` is ``"pdev"``.

    References
    ----------
    F. Vernotte, M. Lenczner, P.-Y. Bourgeois, E. Rubiola, "The parabolic variance
    (PVAR): a wavelet variance based on the least-square fit", IEEE Trans. UFFC
    63(4), 611–623, 2016.
    """
    phase, broken, one_d, missing, fs = phase_points(x, fs, data_type, gaps, "pdev")
    confidence = confidence_level(confidence)
    n_points, channels = phase.shape
    if n_points < 4:
        raise ImunoiseValueError(f"x has {n_points} phase points, too few for pdev (at least 4: "
                         f"two terms at m = 1)")
    m = averaging_grid(taus, fs, n_points, "pdev", _pdev_terms(n_points))
    var = np.empty((m.size, channels))
    terms = np.empty((m.size, channels), dtype=np.int64)
    for t, mj in enumerate(int(v) for v in m):
        if mj == 1:
            values = phase[2:] - 2.0 * phase[1:-1] + phase[:-2]
            valid = valid_windows(broken, 2, n_points - 2)
            scale = 2.0
        else:
            count = n_points - 2 * mj
            lag = phase[:-mj] - phase[mj:]
            # the weights sum to zero: a constant lag (a rate offset) is removed first
            # so that the correlation's rounding is relative to the noise, not to it
            lag = lag - lag.mean(axis=0)
            weights = (mj - 1) / 2.0 - np.arange(mj)
            values = np.column_stack([
                _signal.correlate(lag[:count + mj - 1, c], weights, mode="valid")
                for c in range(channels)])
            # allantools' sum stops one start short of the last: M = N − 2m terms
            valid = valid_windows(broken, 2 * mj - 1, count)
            scale = mj**4 / 72.0
        values = np.where(valid, values, 0.0)
        terms[t] = valid.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            var[t] = (values**2).sum(axis=0) / (scale * terms[t]) * (fs / mj) ** 2
    var = np.where(terms >= 2, var, np.nan)
    alpha, identified, edf = _pdev_edf(phase, broken, m, n_points, fs, data_type)
    return tau_result("pdev", m, var, np.sqrt(var), terms, edf, alpha, identified, fs=fs,
                   confidence=confidence, one_d=one_d, missing=missing, gaps=gaps,
                   n_points=n_points, data_type=data_type)


def _pdev_edf(phase, broken, m, n_points, fs, data_type):
    """Noise type and EDF of PDEV at ``m`` (see :func:`pdev`): the overlapping ADEV's
    analysis of the same record, its EDF times MDEV/ADEV's gap-free EDF ratio."""
    rate = np.diff(phase, axis=0) * fs
    rate[broken] = np.nan
    core = _core_allan.analyse(rate, "oadev", m.astype(np.uint64))
    ms = m.astype(np.uint64)
    ratio = np.ones(core.alpha.shape)
    for c in range(core.alpha.shape[1]):
        alphas = core.alpha[:, c].astype(np.int32)
        with np.errstate(invalid="ignore", divide="ignore"):
            r = (_core_allan.estimator_edf("mdev", n_points, alphas, ms)
                 / _core_allan.estimator_edf("oadev", n_points, alphas, ms))
        ratio[:, c] = np.where(np.isfinite(r), np.minimum(r, 1.0), 1.0)
    return core.alpha, core.alpha_identified, core.edf * ratio


def _tie_grid(taus, fs, n_points, kind):
    return averaging_grid(taus, fs, n_points, kind, lambda m: n_points - m)


def _no_interval(kind, m, dev, terms, *, fs, one_d, missing, gaps, n_points, data_type,
                 confidence):
    nan = np.full(dev.shape, np.nan)
    return tau_result(kind, m, dev**2, dev, terms, nan, np.zeros(dev.shape, dtype=np.int64),
                   np.zeros(dev.shape, dtype=bool), fs=fs, confidence=confidence,
                   one_d=one_d, missing=missing, gaps=gaps, n_points=n_points,
                   data_type=data_type)


def mtie(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
         gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Maximum time interval error (ITU-T G.810), allantools' ``mtie``.

    .. math::

        \mathrm{MTIE}(m\tau_0) = \max_{0 \le i < N - m}\Big(\max_{i \le j \le i+m} x_j
        - \min_{i \le j \le i+m} x_j\Big)

    over the N phase points: the largest peak-to-peak phase excursion in any window
    of m + 1 points (``r.n`` = N − m windows). In the phase's units (seconds for a
    clock's time error, the angle for a gyro's rate).

    Cost: the windows' maxima and minima come from those of windows of 2^k points
    (the doubling of Bregni's binary decomposition), O(N log N) for all taus, O(N)
    per tau beyond; allantools slides each window (O(N m) per tau).

    No confidence interval: MTIE is an extreme value, for which no degrees of
    freedom are defined; ``ci_low``, ``ci_high`` and ``edf`` are NaN and ``alpha``
    is 0 (not identified: ``alpha_identified`` False). ``var`` is ``dev²``.

    ``x``, ``fs``, ``taus``, ``gaps`` and ``data_type`` as for :func:`imunoise.adev`
    (rate input is integrated with its mean removed; phase input is taken as
    given, its rate offset included). ``kind == "mtie"``.
    """
    phase, broken, one_d, missing, fs = phase_points(x, fs, data_type, gaps, "mtie")
    n_points, channels = phase.shape
    m = _tie_grid(taus, fs, n_points, "mtie")
    dev = np.empty((m.size, channels))
    terms = np.empty((m.size, channels), dtype=np.int64)
    # hi[k]/lo[k]: max/min of the 2^k points from each start, built as taus need them
    hi, lo, width = phase, phase, 1
    for t, mj in enumerate(int(v) for v in m):
        points = mj + 1
        while 2 * width <= points:
            hi = np.maximum(hi[:-width], hi[width:])
            lo = np.minimum(lo[:-width], lo[width:])
            width *= 2
        count = n_points - mj
        # a window of `points` is the union of the 2^k windows at its two ends
        shift = points - width
        span = (np.maximum(hi[:count], hi[shift:shift + count])
                - np.minimum(lo[:count], lo[shift:shift + count]))
        valid = valid_windows(broken, mj, count)
        terms[t] = valid.sum(axis=0)
        dev[t] = np.where(valid, span, -np.inf).max(axis=0)
    dev = np.where(terms >= 2, dev, np.nan)
    return _no_interval("mtie", m, dev, terms, fs=fs, one_d=one_d, missing=missing,
                        gaps=gaps, n_points=n_points, data_type=data_type,
                        confidence=ONE_SIGMA)


def tierms(x: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
           gaps: str = "skip", data_type: str = "freq") -> AllanResult:
    r"""Time interval error rms (ITU-T G.810), allantools' ``tierms``.

    .. math::

        \mathrm{TIE_{rms}}(m\tau_0) = \sqrt{\frac{1}{N-m}\sum_{i=0}^{N-m-1}
        (x_{i+m} - x_i)^2}

    over the N phase points (``r.n`` = N − m). In the phase's units. Unlike TDEV it
    keeps the rate offset of phase input (TIE rms grows as its m/fs there).

    No confidence interval: none is defined for it in the literature (its terms
    overlap and, without the offset removed, are not zero-mean); ``ci_low``,
    ``ci_high`` and ``edf`` are NaN, ``alpha`` 0 and not identified.

    ``x``, ``fs``, ``taus``, ``gaps`` and ``data_type`` as for :func:`mtie`;
    ``kind == "tierms"``.
    """
    phase, broken, one_d, missing, fs = phase_points(x, fs, data_type, gaps, "tierms")
    n_points, channels = phase.shape
    m = _tie_grid(taus, fs, n_points, "tierms")
    dev = np.empty((m.size, channels))
    terms = np.empty((m.size, channels), dtype=np.int64)
    for t, mj in enumerate(int(v) for v in m):
        count = n_points - mj
        valid = valid_windows(broken, mj, count)
        step = np.where(valid, phase[mj:] - phase[:-mj], 0.0)
        terms[t] = valid.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            dev[t] = np.sqrt((step**2).sum(axis=0) / terms[t])
    dev = np.where(terms >= 2, dev, np.nan)
    return _no_interval("tierms", m, dev, terms, fs=fs, one_d=one_d, missing=missing,
                        gaps=gaps, n_points=n_points, data_type=data_type,
                        confidence=ONE_SIGMA)
