r"""Warm-up: the settling transient at the start of a still log.

A sensor switched on drifts while it warms: the bias follows roughly
:math:`b(t) = b_\infty + A\,e^{-t/\tau}`. Left in the record, the transient looks
like rate random walk or rate ramp at long averaging times. :func:`warmup`
finds it per channel and says where the sensor settled, with the evidence.

Method
------
1. The bias over time: means of ``block``-second blocks (default: 1/300 of the
   log, at least 1 s) — the moving-average bias the report plots.
2. Per channel, :math:`b_\infty + A e^{-t/\tau}` is fitted to the block means by
   least squares (a grid over τ with the linear parameters solved exactly, then
   ``scipy.optimize.curve_fit`` for the covariance of :math:`A, \tau`).
3. The transient is **significant** when the exponential explains more of the
   block means than it does in records of the sensor's own stationary noise, at
   ``alpha`` (default 10⁻³), and τ is shorter than half the log (a longer
   "transient" is drift the log cannot separate from bias wander). The null
   records are a parametric bootstrap: the noise model (:func:`imunoise.fit`)
   of the second half of the log, simulated at the block rate
   (:data:`NULL_RECORDS` records), each fitted like the data; p is the share of
   them whose best exponential explains at least as much. Rate random walk and
   flicker wander make exponentials fit well by chance, and only a null that
   contains them says how well: an F-test, even with an AR(1) correction, found
   "transients" with p < 10⁻¹⁰ in simulated still logs with the VN-100's
   datasheet noise. Why the second half: removing the best exponential from the
   whole log also removes part of the wander, and a null fitted to what is left
   is too quiet (p at its floor on stationary simulated logs), while the whole
   log, transient included, inflates the null's K until a 20σ transient is no
   longer significant; a transient of τ < T/4 has decayed by e⁻² at T/2. The
   uncertainties of A and τ are inflated by the AR(1) factor
   :math:`(1+\rho_1)/(1-\rho_1)` of the residuals (lag-1 autocorrelation
   :math:`\rho_1`).
4. The channel has **settled** when the fitted transient has fallen below the
   tolerance :math:`\varepsilon`: :math:`t_s = \tau \ln(|A|/\varepsilon)`
   (0 when :math:`|A| \le \varepsilon`), with its uncertainty propagated from the
   covariance of :math:`(A, \tau)`. The default :math:`\varepsilon` is the
   floor of the Allan deviation of the channel with the transient removed
   (its bias-instability level): after :math:`t_s` what is left of the
   transient is smaller than the bias wander any analysis will report.
5. The log's settle point is the latest :math:`t_s` over the significant channels,
   at most the end of the log (then it has not settled within the log).

Where the log has temperature, its own exponential fit (τ, the final temperature
and the time it is within ``temperature_tolerance`` of it) is part of the
evidence: a bias transient with the temperature's time constant is thermal.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy import optimize as _opt
from scipy import stats as _stats

from imunoise._analysis.channels import rate_columns
from imunoise._simulation.simulate import simulate
from imunoise._support import stream as _stream
from imunoise._support import summary as _summary
from imunoise.allan import adev, adev_by_column
from imunoise.errors import ImunoiseValueError
from imunoise.noise import _typed, fit, model_variance
from imunoise.readers.log import ImuLog

__all__ = ["Warmup", "warmup", "ALPHA"]

#: Significance level of the test "exponential transient vs constant bias".
ALPHA = 1e-3
#: Blocks of the default bias series (the log's length / this).
BLOCKS = 300
#: Fewest blocks a fit needs.
MIN_BLOCKS = 20
#: Records of the sensor's stationary noise the significance test simulates.
NULL_RECORDS = 1999
#: Confidence of the upper limit of the Allan variance that bounds the null's
#: rate random walk (see ``_random_walk_bound``): one-sigma, because a 95 % bound
#: makes the null so loud that a transient several times that wander is missed.
BOUND_CONFIDENCE = 0.683
#: Correlation times of the exponential fit: this many per log, log-spaced.
TAU_GRID = 80


@dataclass(frozen=True, repr=False)
class Warmup:
    r"""Where a still log settled (see :func:`warmup`).

    Per-channel arrays follow ``names``.

    Attributes
    ----------
    fs : float
        Sample rate, Hz.
    n_samples : int
        Samples of the log.
    names : tuple of str
        Channels analysed.
    time : ndarray, (m,)
        Centre of each block, s.
    bias : ndarray, (m, k)
        Block-mean bias of each channel (the moving-average bias).
    block : float
        Block length, s.
    final, amplitude, tau : ndarray
        Fitted :math:`b_\infty`, :math:`A`, :math:`\tau` (s) per channel.
    amplitude_std, tau_std : ndarray
        Their standard uncertainties (from the fit's covariance, residual-scaled).
    p_value : ndarray
        Share of stationary-noise records (parametric bootstrap, see
        :func:`warmup`) whose best exponential explains as much as the data's.
    significant : ndarray of bool
        ``p_value < alpha`` and :math:`\tau` < half the log.
    tolerance : ndarray
        :math:`\varepsilon` per channel, channel unit.
    settle_time, settle_time_std : ndarray
        :math:`t_s` per channel (0 where not significant) and its uncertainty, s.
    settle : float
        The log's settle point: the latest significant :math:`t_s`, s (0: no transient).
    temperature : ndarray or None
        Block-mean temperature, °C, when the log has it.
    temperature_tau, temperature_final, temperature_settle : float
        Exponential fit of the temperature (τ s, final °C) and the time it is
        within ``temperature_tolerance`` of the final value (NaN without temperature).
    alpha : float
        Significance level used.
    """

    fs: float
    n_samples: int
    names: tuple[str, ...]
    time: np.ndarray
    bias: np.ndarray
    block: float
    final: np.ndarray
    amplitude: np.ndarray
    tau: np.ndarray
    amplitude_std: np.ndarray
    tau_std: np.ndarray
    p_value: np.ndarray
    significant: np.ndarray
    tolerance: np.ndarray
    settle_time: np.ndarray
    settle_time_std: np.ndarray
    settle: float
    temperature: np.ndarray | None
    temperature_tau: float
    temperature_final: float
    temperature_settle: float
    alpha: float

    @property
    def settle_index(self) -> int:
        """First sample after the settle point."""
        return min(self.n_samples, int(np.ceil(self.settle * self.fs)))

    @property
    def settled(self) -> bool:
        """True when the settle point leaves at least half the log."""
        return self.settle <= 0.5 * self.n_samples / self.fs

    def fitted(self, t=None) -> np.ndarray:
        """The fitted bias :math:`b_\\infty + A e^{-t/\\tau}` at ``t`` (default: the
        block centres), (len(t), k)."""
        t = self.time if t is None else np.asarray(t, dtype=float)
        return self.final + self.amplitude * np.exp(-t[:, None] / self.tau)

    def trim(self, data):
        """``data`` from the settle point on (an ImuLog, or an array of the log's
        samples on the same grid)."""
        i = self.settle_index
        if isinstance(data, ImuLog):
            if len(data) != self.n_samples:
                raise ImunoiseValueError(f"data has {len(data)} samples; warm-up was found on "
                                 f"{self.n_samples}")
            return _slice_log(data, i)
        arr = np.asarray(data)
        if arr.shape[0] != self.n_samples:
            raise ImunoiseValueError(f"data has {arr.shape[0]} samples; warm-up was found on "
                             f"{self.n_samples}")
        return arr[i:]

    def rows(self) -> list[dict]:
        """One dict per channel: name, amplitude, tau, their std, p_value, significant,
        tolerance, settle_time, settle_time_std."""
        keys = ("amplitude", "amplitude_std", "tau", "tau_std", "p_value", "tolerance",
                "settle_time", "settle_time_std")
        return [
            {"name": n, **{k: float(getattr(self, k)[j]) for k in keys},
             "significant": bool(self.significant[j])}
            for j, n in enumerate(self.names)
        ]

    def _facts(self) -> list[str]:
        parts = [
            f"settled at {_summary.duration(self.settle)}" if self.settle > 0
            else "no warm-up transient",
            f"of {_summary.duration(self.n_samples / self.fs)}",
        ]
        parts += [f"{r['name']} τ {_summary.duration(r['tau'])} t_s "
                  f"{_summary.duration(r['settle_time'])}" for r in self.rows() if r["significant"]]
        if self.temperature is not None:
            parts.append(f"temperature τ {_summary.duration(self.temperature_tau)}")
        return parts

    def __repr__(self) -> str:
        return _summary.lines("Warmup(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        rows = [[r["name"], _summary.number(r["amplitude"]), _summary.duration(r["tau"]),
                 f"{r['p_value']:.2g}", _summary.number(r["tolerance"]),
                 _summary.duration(r["settle_time"])] for r in self.rows()]
        facts = self._facts()
        # the log's facts, and the temperature's when it has one (the axes are rows)
        caption = facts[:2] + (facts[-1:] if self.temperature is not None else [])
        return _summary.html_table(
            ["channel", "A", "τ", "p", "tolerance", "t_s"], rows,
            caption="Warmup: " + ", ".join(caption),
        )


def _slice_log(log: ImuLog, start: int) -> ImuLog:
    arrays = {name: getattr(log, name)[start:] for name in log.channels}
    time = None if log.time is None else log.time[start:]
    return ImuLog(fs=log.fs, source=log.source, format=log.format,
                  issues=type(log.issues).none(), time=time, messages=log.messages, **arrays)


#: Rows of the log whose block means :func:`warmup` takes at once.
BIAS_GROUP_ROWS = 1 << 20


def warmup(
    data,
    fs: float | None = None,
    *,
    channels=None,
    block: float | None = None,
    tolerance=None,
    alpha: float = ALPHA,
    temperature=None,
    temperature_tolerance: float = 0.1,
    seed: int | None = 0,
) -> Warmup:
    r"""Detect the warm-up transient of a still log and where it settled.

    Parameters
    ----------
    data : ImuLog or array_like, shape (n,) or (n, k)
        A log (gyro and accel are analysed) or rate samples (NaN = missing).
    fs : float, optional
        Sample rate, Hz (required for arrays).
    channels : str or sequence of str, optional
        Log channels to analyse (default gyro and accel).
    block : float, optional
        Block length of the bias series, s (default: the log's length / 300, ≥ 1 s).
    tolerance : float or array_like, optional
        :math:`\varepsilon` per channel (or one for all), channel unit. Default: the
        floor of each channel's Allan deviation with the fitted transient removed.
    alpha : float
        Significance level of the transient (default :data:`ALPHA`).
    seed : int or None
        Seed of the null records of the significance test (default 0, so the same
        log always gives the same p-values).
    temperature : array_like, optional
        Temperature samples, °C (default: the log's).
    temperature_tolerance : float
        °C: the temperature has settled within this of its fitted final value.

    Returns
    -------
    Warmup
    """
    cols, fs, names = rate_columns(data, fs, channels)  # one channel in memory at a time
    n = cols.n
    duration = n / fs
    if not 0 < alpha < 1:
        raise ImunoiseValueError(f"alpha must be in (0, 1); got {alpha!r}")
    if block is None:
        block = max(1.0, duration / BLOCKS)
    elif isinstance(block, bool) or not (np.isfinite(block) and block > 0):
        raise ImunoiseValueError(f"block must be positive and finite (s); got {block!r}")
    size = max(1, int(round(block * fs)))
    m = n // size
    if m < MIN_BLOCKS:
        raise ImunoiseValueError(f"data must hold at least {MIN_BLOCKS} blocks of {block:g} s "
                         f"({MIN_BLOCKS * size} samples); got {n}")
    t = (np.arange(m) + 0.5) * size / fs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks stay NaN
        # a group of blocks at a time: nanmean copies what it is given (NaN → 0) and
        # each block's mean depends on its own samples only
        # (a sensor at a time: its columns side by side, summed as the whole log's were;
        # a memory map's pages given back behind it)
        group = max(1, BIAS_GROUP_ROWS // size)
        parts = []
        for x in cols.arrays():
            parts.append(np.concatenate([
                np.nanmean(np.asarray(x[g * size:min(g + group, m) * size], dtype=np.float64)
                           .reshape(-1, size, x.shape[1]), axis=1) for g in range(0, m, group)]))
            _stream.release(x)
        bias = np.hstack(parts)
    k = len(cols)
    temp = _temperature(data, temperature, n)
    fits = [_fit_exponential(t, bias[:, j], duration) for j in range(k)]
    final, amp, tau, amp_sd, tau_sd = (np.array(v) for v in zip(*fits, strict=True))
    p = _null_p_values(cols, fs, t, bias, duration, seed)
    significant = (p < alpha) & (tau < duration / 2)
    tol = _tolerance(tolerance, cols, amp, tau, fs)
    ts, ts_sd = _settle_times(amp, tau, amp_sd, tau_sd, tol, significant)
    ts = np.minimum(ts, duration)
    t_fit = (np.nan, np.nan, np.nan)
    temp_blocks = None
    if temp is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            temp_blocks = np.nanmean(temp[: m * size].reshape(m, size), axis=1)
        c, a, ttau, _sa, _st = _fit_exponential(t, temp_blocks, duration)
        settle_t = ttau * np.log(abs(a) / temperature_tolerance) if abs(a) > temperature_tolerance \
            else 0.0
        t_fit = (ttau, c, float(settle_t))
    return Warmup(
        fs=fs, n_samples=n, names=names, time=t, bias=bias, block=size / fs,
        final=final, amplitude=amp, tau=tau, amplitude_std=amp_sd, tau_std=tau_sd,
        p_value=p, significant=significant, tolerance=tol, settle_time=ts,
        settle_time_std=ts_sd, settle=float(ts.max()) if ts.size else 0.0,
        temperature=temp_blocks, temperature_tau=t_fit[0], temperature_final=t_fit[1],
        temperature_settle=t_fit[2], alpha=float(alpha),
    )


def _temperature(data, temperature, n) -> np.ndarray | None:
    if temperature is None:
        if isinstance(data, ImuLog) and data.temperature is not None:
            return np.asarray(data.temperature, dtype=float)
        return None
    temp = np.asarray(temperature, dtype=float).reshape(-1)
    if temp.shape[0] != n:
        raise ImunoiseValueError(
            f"temperature must have {n} samples (one per row); got {temp.shape[0]}")
    return temp


def _exp_model(t, c, a, tau):
    return c + a * np.exp(-t / tau)


def _tau_grid(t: np.ndarray, duration: float) -> np.ndarray:
    return np.geomspace(t[1] - t[0], 2 * duration, TAU_GRID)


def _grid_fits(t: np.ndarray, y: np.ndarray, taus: np.ndarray) -> tuple[np.ndarray, ...]:
    """Least-squares c + A e^{-t/τ} of each column of ``y`` (m, r) at every τ of
    ``taus``: the projection on the centred exponential. Returns the variance each
    explains (len(taus), r), A (len(taus), r) and the exponentials' means (len(taus),)."""
    yc = y - y.mean(axis=0)
    explained = np.zeros((len(taus), y.shape[1]))
    amplitude = np.zeros_like(explained)
    means = np.zeros(len(taus))
    for i, tau in enumerate(taus):
        e = np.exp(-t / tau)
        means[i] = e.mean()
        e = e - means[i]
        norm = float(e @ e)
        if norm > 0:
            dot = e @ yc
            explained[i], amplitude[i] = dot**2 / norm, dot / norm
    return explained, amplitude, means


def _explained(t: np.ndarray, y: np.ndarray, taus: np.ndarray) -> np.ndarray:
    """Share of the variance of each column of ``y`` (m, r) that the best
    c + A e^{-t/τ} over ``taus`` explains, (r,)."""
    total = np.sum((y - y.mean(axis=0)) ** 2, axis=0)
    best = _grid_fits(t, y, taus)[0].max(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0, best / total, 0.0)


def _null_p_values(cols, fs, t, bias, duration, seed) -> np.ndarray:
    """p of each channel's transient against records of its own stationary noise
    (the noise model of the second half of the columns ``cols``, simulated at the
    block rate)."""
    k = bias.shape[1]
    p = np.ones(k)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ok = (np.sum(np.isfinite(bias), axis=0) >= MIN_BLOCKS) & (
            np.nanmax(bias, axis=0) > np.nanmin(bias, axis=0))
    if not ok.any():
        return p
    taus = _tau_grid(t, duration)
    taus = taus[taus < duration / 2]  # as the significance rule: longer is drift
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a poorly followed curve still bounds the wander
        # a column at a time: one half-column and the Allan core's arrays for it
        chosen = np.flatnonzero(ok)
        half = adev_by_column(lambda c: cols.stacked([chosen[c]], cols.n // 2, cols.n)[:, 0],
                              len(chosen), fs)
        model = fit(half, warn_coverage=False)
    k_floor = _random_walk_bound(half, model)
    rng = np.random.default_rng(seed)
    block_rate = 1.0 / (t[1] - t[0])
    for c, j in enumerate(np.flatnonzero(ok)):
        kept = np.isfinite(bias[:, j])  # blocks a gap emptied are left out of both
        observed = _explained(t[kept], bias[kept, j:j + 1], taus)[0]
        # No rate ramp in the null: a trend is what the test looks for, and a ramp
        # the half log's fit took for its long-tau rise (a random-walk realisation
        # can look like one) explained the transient away; the rise goes to the
        # random-walk bound instead.
        coef = {term: _upper(model, term, c) for term in ("N", "B", "K")}
        coef["K"] = max(coef["K"], float(k_floor[c]))
        null = simulate(len(t), block_rate, channels=NULL_RECORDS, seed=rng,
                        gm=_typed.pairs(model.terms[c], _typed.GaussMarkov, "sigma", "tau_c"),
                        **coef)
        p[j] = _bootstrap_p(observed, _explained(t[kept], null[kept], taus))
    return p


def _bootstrap_p(observed: float, null: np.ndarray) -> float:
    """p of ``observed`` among the null records' statistics ``null`` (the observed
    record counted with them, so p is never 0)."""
    return (1 + np.count_nonzero(null >= observed)) / (len(null) + 1)


def _random_walk_bound(result, model, min_edf: float = 5.0) -> np.ndarray:
    """Per channel, the rate random walk K the half log cannot exclude: the one whose
    K²τ/3 makes up what the model's other terms leave of the upper
    :data:`BOUND_CONFIDENCE` confidence limit of the Allan variance (χ² with the
    estimate's degrees of freedom ν: σ²·ν/χ²_{1−c}(ν)) at the longest τ with at least
    ``min_edf`` degrees of freedom. A 2.5 h half of a VN-100 log does not resolve its
    K (2e-6 rad/s/√s), and a null without it calls its wander a transient; a half
    whose random walk happened to wander little measures K = 0 at its point
    estimate, and a null built on that called still channels warming up (p = 5e-4;
    docs/events.md)."""
    edf = np.reshape(result.edf, (len(result.taus), -1))
    dev = np.reshape(result.dev, edf.shape)
    out = np.zeros(edf.shape[1])
    for c in range(edf.shape[1]):
        usable = np.flatnonzero((edf[:, c] >= min_edf) & np.isfinite(dev[:, c]))
        if usable.size:
            i = usable[-1]
            tau = result.taus[i : i + 1]
            others = {t: _typed.coefficient(model.terms[c], t) for t in ("Q", "N", "B")}
            upper = dev[i, c] ** 2 * edf[i, c] / _stats.chi2.ppf(1 - BOUND_CONFIDENCE,
                                                                  edf[i, c])
            rest = upper - float(model_variance(tau, **others)[0])
            out[c] = np.sqrt(3.0 / tau[0] * max(rest, 0.0))
    return out


def _upper(model, term: str, c: int) -> float:
    """A coefficient of the null model at its value + 2 standard uncertainties: half a
    log estimates the wander loosely, and a null that is too quiet calls wander a
    transient."""
    fitted = _typed.ieee_term(model.terms[c], term)
    if fitted is None:
        return 0.0
    value, std = fitted.value, float(getattr(fitted, term + "_std"))
    return value + 2 * std if value > 0 and np.isfinite(std) else value


def _transient(amp, tau, a, b, fs) -> np.ndarray:
    """The fitted transients A e^{-t/τ} at samples a … b − 1, (b − a, k); 0 where none
    was fitted."""
    t = np.arange(a, b) / fs
    finite = np.isfinite(tau) & (tau > 0)
    return np.where(finite, amp * np.exp(-t[:, None] / np.where(finite, tau, 1.0)), 0.0)


def _residual(cols, amp, tau, fs, j: int) -> np.ndarray:
    """Channel ``j`` of ``cols`` without its fitted transient (:func:`_transient`), one
    channel in memory at a time (the transient a block of rows at a time)."""
    out = cols.owned(j)
    for a in range(0, len(out), _stream.BLOCK_ROWS):
        b = min(len(out), a + _stream.BLOCK_ROWS)
        out[a:b] -= _transient(amp[j:j + 1], tau[j:j + 1], a, b, fs)[:, 0]
    return out


def _fit_exponential(t, y, duration):
    """(final, A, τ, u(A), u(τ)) of c + A e^{-t/τ} fitted to y (NaN blocks left out)."""
    ok = np.isfinite(y)
    t, y = t[ok], y[ok]
    nan = (float(np.nanmean(y)) if y.size else np.nan, 0.0, np.inf, np.nan, np.nan)
    if y.size < MIN_BLOCKS or np.ptp(y) == 0:
        return nan
    taus = _tau_grid(t, duration)
    explained, amplitude, means = _grid_fits(t, y[:, None], taus)
    i = int(np.argmax(explained[:, 0]))  # the least residual sum of squares
    tau, a = taus[i], float(amplitude[i, 0])
    c = float(y.mean()) - a * means[i]
    try:
        with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore"):
            warnings.simplefilter("ignore", _opt.OptimizeWarning)  # trial τ may go negative
            popt, pcov = _opt.curve_fit(_exp_model, t, y, p0=(c, a, tau), maxfev=2000)
        if popt[2] > 0 and np.all(np.isfinite(pcov)):
            c, a, tau = popt
            sd = np.sqrt(np.diag(pcov))
        else:
            sd = np.array([np.nan, np.nan, np.nan])
    except RuntimeError:
        sd = np.array([np.nan, np.nan, np.nan])
    resid = y - _exp_model(t, c, a, tau)
    rss1 = float(np.sum(resid**2))
    # correlated residuals (bias wander) carry less evidence than their count:
    # the AR(1) variance inflation (1 + ρ)/(1 − ρ) widens u(A), u(τ)
    rho = float(np.clip(np.dot(resid[:-1], resid[1:]) / rss1, 0.0, 0.95)) if rss1 > 0 else 0.0
    sd = sd * np.sqrt((1 + rho) / (1 - rho))
    return float(c), float(a), float(tau), float(sd[1]), float(sd[2])


def _tolerance(tolerance, cols, amp, tau, fs) -> np.ndarray:
    """The given tolerance per channel, or the Allan-deviation floor of the columns
    ``cols`` without their transient (channel by channel: the Allan statistics of one
    channel do not depend on the others)."""
    k = len(cols)
    if tolerance is not None:
        tol = np.broadcast_to(np.asarray(tolerance, dtype=float), (k,)).copy()
        if not np.all(np.isfinite(tol) & (tol > 0)):
            raise ImunoiseValueError(f"tolerance must be positive and finite; got {tolerance!r}")
        return tol
    floor = np.empty(k)
    for j in range(k):
        r = adev(_residual(cols, amp, tau, fs, j), fs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            floor[j] = np.nanmin(r.dev)
    # a constant channel has no floor: nothing in it ever needs to settle
    return np.where(np.isfinite(floor) & (floor > 0), floor, np.inf)


def _settle_times(amp, tau, amp_sd, tau_sd, tol, significant):
    ratio = np.abs(amp) / tol
    on = significant & (ratio > 1)
    log_ratio = np.log(np.where(on, ratio, 1.0))
    tau, tau_sd, amp_sd = (np.where(on, v, 0.0) for v in (tau, tau_sd, amp_sd))
    ts = tau * log_ratio
    sd = np.where(on, np.hypot(log_ratio * tau_sd, tau * amp_sd / np.where(on, amp, 1.0)), 0.0)
    return ts, np.abs(sd)
