r"""Sample statistics and distribution fits of still-IMU recordings.

:func:`describe` gives, per channel, the moments and extremes of a recording and
its linear drift; :func:`distribution` gives a histogram whose bins respect the
sensor's quantization, a normal fit and goodness-of-fit statistics.

Quantization-aware bins
-----------------------
Digital sensors (and logs printed with a fixed number of decimals) only produce
values on a grid :math:`x_0 + k\,q`. Ordinary automatic bin edges fall between
and on grid levels at random, so neighbouring bins hold 0, 1 or 2 levels and
the histogram shows a comb that is not in the data (the usual workaround is to
hand-pick 15, 30 or 100 bins per channel). :func:`quantization_step` estimates
``q`` as the largest step of which every difference between sorted unique
values is an integer multiple (a gcd over floats, tolerant of the rounding of
decimal text), and :func:`distribution` then uses bins that are a whole number
``k`` of steps wide with edges at :math:`x_0 + (j k - \tfrac12)\,q`: every level
sits in the middle of exactly one bin and every bin holds ``k`` levels.

Some sensors have a step that is not a decimal (a magnetometer LSB of 0.92 mGauss
printed with four decimals): the values then lie on the 0.1 mGauss print grid
but only every ninth or tenth grid point is used, and 1-step bins show a comb
of empty bins (real VN-100 magnetometer logs show clusters of two to five
adjacent print values about nine steps apart). :func:`distribution` finds such
regularly spaced clusters in the central 98 % of the data and uses their mean
spacing as the bin unit (``level_spacing``); inner edges that would cut a
cluster move to the middle of the nearest gap between occupied values, so every
sensor level sits in one bin (bin widths may then differ slightly; the density
accounts for it). Rare values between the sensor's levels (a print value or two
that turns up a few times between well-used clusters, as on real VN-100 logs)
are left out of the spacing estimate: a cluster holding less than
:data:`RARE_CLUSTER` of its busier neighbour's samples does not count as a level.

Range of the histogram
----------------------
The bins cover the bulk of the data, not its extremes: the central 99 % widened
by :data:`BULK_MARGIN` of its width on each side (±4.6 σ for normal data), never
beyond the smallest and largest sample. A few vibration spikes then no longer
squeeze the distribution into a thin spike in an empty axis; the samples left
outside are counted (``off_scale_below``, ``off_scale_above``) and
:meth:`Distribution.density` stays comparable to the fitted pdf (it is
normalised by all valid samples). ``extent="all"`` covers every sample.

Missing samples
---------------
NaN marks a missing sample (an :class:`imunoise.ImuLog` holds NaN where the
log has a gap on its uniform time grid). Every statistic is computed over the
valid samples of each channel, the drift against the valid samples' times, and
histograms and fits use the valid samples only; ``missing`` in the result says
how many were left out. ±∞ is an error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special as _special
from scipy import stats as _sstats

from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise._support.deprecation import old_call_forms
from imunoise._support.validate import sample_rate
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.readers.log import ImuLog

__all__ = [
    "Description",
    "Distribution",
    "describe",
    "distribution",
    "attitude_angles",
    "heading",
    "quantization_step",
    "unwrap_about_circular_mean",
    "SENSOR_CHANNELS",
]

#: ImuLog channels :func:`describe` reports, in this order (kept here as a public
#: name; the schema module owns the list).
SENSOR_CHANNELS = _schema.STATISTICS_CHANNELS

#: Largest number of bins :func:`distribution` builds.
MAX_BINS = 10_000
#: Probability in each tail outside the bulk of a histogram (central 99 %).
BULK_TAIL = 0.005
#: Margin on each side of the bulk, as a fraction of its width (the bulk then
#: spans 1/(1 + 2·0.4) = 56 % of the axis unless the data end sooner).
BULK_MARGIN = 0.4
#: A cluster of print values with less than this fraction of its busier
#: neighbour's samples is a rare in-between value, not a sensor level.
RARE_CLUSTER = 0.05
#: Above this many samples the KS p-value is the asymptotic (Kolmogorov) one.
KS_EXACT_MAX_N = 10_000
#: Anderson–Darling critical values for the normal with estimated mean and
#: variance (Stephens 1974; as scipy.stats.anderson) at these significance levels (%).
_AD_NORM = np.array([0.576, 0.656, 0.787, 0.918, 1.092])
_AD_LEVELS = np.array([15.0, 10.0, 5.0, 2.5, 1.0])
#: Sorted samples :func:`distribution` evaluates at once (the CDF, the moments): its
#: memory beyond the samples and their sorted copy is a few arrays of this length.
CHUNK = 1 << 20


@dataclass(frozen=True, repr=False)
class Description:
    """Per-channel sample statistics (see :func:`describe`).

    Every array has one entry per channel, in the order of ``names``.

    Attributes
    ----------
    names : tuple of str
        Channel names, e.g. ``"gyro X"``.
    sensors, units : tuple of str
        Sensor each channel belongs to and its unit.
    n : int
        Samples per channel, missing ones included (the length of the record).
    fs : float or None
        Sample rate in Hz (None when unknown: then ``drift_per_hour`` is NaN).
    mean, std, var, min, max : ndarray
        ``std``/``var`` with ``ddof=1``.
    drift_per_hour : ndarray
        Least-squares slope of the channel against time, in unit per hour.
    missing : ndarray of int
        Missing samples (NaN) per channel; the statistics use the other
        ``n - missing``.
    """

    names: tuple[str, ...]
    sensors: tuple[str, ...]
    units: tuple[str, ...]
    n: int
    fs: float | None
    mean: np.ndarray
    std: np.ndarray
    var: np.ndarray
    min: np.ndarray
    max: np.ndarray
    drift_per_hour: np.ndarray
    missing: np.ndarray

    def __post_init__(self) -> None:
        for name in ("mean", "std", "var", "min", "max", "drift_per_hour", "missing"):
            getattr(self, name).flags.writeable = False

    def rows(self) -> list[dict]:
        """One dict per channel: name, unit, mean, std, var, min, max, drift_per_hour,
        missing."""
        return [
            {
                "name": self.names[i],
                "unit": self.units[i],
                "mean": float(self.mean[i]),
                "std": float(self.std[i]),
                "var": float(self.var[i]),
                "min": float(self.min[i]),
                "max": float(self.max[i]),
                "drift_per_hour": float(self.drift_per_hour[i]),
                "missing": int(self.missing[i]),
            }
            for i in range(len(self.names))
        ]

    def table(self) -> str:
        """A fixed-width text table, one line per channel."""
        head = ("channel", "unit", "mean", "std", "var", "min", "max", "drift/h")
        lines = [head] + [
            (
                r["name"],
                r["unit"],
                *(
                    _fmt(r[k])
                    for k in ("mean", "std", "var", "min", "max", "drift_per_hour")
                ),
            )
            for r in self.rows()
        ]
        widths = [max(len(line[j]) for line in lines) for j in range(len(head))]
        out = []
        for line in lines:
            cells = [line[0].ljust(widths[0]), line[1].ljust(widths[1])]
            cells += [c.rjust(w) for c, w in zip(line[2:], widths[2:], strict=True)]
            out.append("  ".join(cells).rstrip())
        return "\n".join(out)

    def __str__(self) -> str:
        return self.table()

    def _facts(self) -> list[str]:
        """Length, rate, channels grouped by sensor (``gyro X Y Z``), missing samples."""
        groups: dict[str, list[str]] = {}
        for name, sensor in zip(self.names, self.sensors, strict=True):
            if not name.startswith(sensor):  # an array's columns: no sensor
                sensor = ""
            groups.setdefault(sensor, []).append(name[len(sensor):].strip())
        rate = f" at {_summary.number(self.fs)} Hz" if self.fs else ", rate unknown"
        return [
            f"{self.n} samples{rate}",
            _summary.plural(len(self.names), "channel") + ": "
            + ", ".join(" ".join([sensor, *axes]).strip() for sensor, axes in groups.items()),
            _summary.per_channel(self.missing, "missing"),
        ]

    def __repr__(self) -> str:
        return _summary.lines("Description(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """:meth:`rows` as a table, four significant digits."""
        keys = ("mean", "std", "var", "min", "max", "drift_per_hour")
        return _summary.html_table(
            ["channel", "unit", "mean", "std", "var", "min", "max", "drift/h", "missing"],
            [[r["name"], r["unit"], *(_summary.number(r[k]) for k in keys), r["missing"]]
             for r in self.rows()],
            caption="Description: " + ", ".join(self._facts()),
        )


def _fmt(v: float) -> str:
    return "—" if not np.isfinite(v) else f"{v:.6g}"


@old_call_forms(renamed={"log_or_array": "x"})
def describe(x, fs: float | None = None) -> Description:
    r"""Per-channel mean, standard deviation, variance, extremes and linear drift.

    Parameters
    ----------
    x : ImuLog or array_like, shape (n,) or (n, k)
        An :class:`imunoise.ImuLog` (its gyro, accel, mag, yaw/pitch/roll,
        temperature and pressure channels are described, axes named X/Y/Z), or
        rate samples. Yaw is taken about its circular mean (:func:`attitude_angles`)
        and its mean given in (−180°, 180°].
    fs : float, optional
        Sample rate in Hz; defaults to ``log.fs`` for a log. For arrays without
        ``fs`` the drift is NaN.

    Returns
    -------
    Description

    Notes
    -----
    ``std`` and ``var`` use ``ddof=1``. The drift is the ordinary least-squares
    slope of :math:`x_i` against :math:`t_i = i/f_s`,
    :math:`\hat b = \sum (t_i-\bar t)(x_i-\bar x) / \sum (t_i-\bar t)^2`,
    times 3600 (unit per hour). NaN samples are missing: each channel's
    statistics use its valid samples (and their times), ``missing`` counts the
    others; a channel with fewer than two valid samples gets NaN.
    """
    if isinstance(x, ImuLog):
        log = x
        fs = log.fs if fs is None else fs
        if len(log) < 2:
            raise ImunoiseValueError(f"x: the log {log.source!r} has {len(log) or 'no'} samples; "
                             "describe needs at least 2")
        blocks, names, sensors, units = [], [], [], []
        for sensor in SENSOR_CHANNELS:
            arr = getattr(log, sensor)
            if arr is None or sensor == "ypr" and not np.isfinite(arr).any():
                continue
            unit = _schema.CHANNELS[sensor][1]
            if sensor == "ypr":
                angles = attitude_angles(arr)
                arr, labels = np.column_stack(list(angles.values())), list(angles)
            else:
                arr = arr.reshape(len(arr), -1)
                labels = [_schema.sensor_label(sensor, j, arr.shape[1])
                          for j in range(arr.shape[1])]
            blocks.append(arr)
            names += labels
            sensors += [sensor] * len(labels)
            units += [unit] * len(labels)
        if not blocks:
            raise ImunoiseValueError(
                f"x has none of the channels {SENSOR_CHANNELS}; "
                f"got channels {log.channels}"
            )
        x = np.hstack(blocks) if len(blocks) > 1 else blocks[0]
    else:
        x = _as_samples(x, "x")
        x = x.reshape(len(x), -1)
        k = x.shape[1]
        names = [f"ch{j}" for j in range(k)] if k > 1 else ["x"]
        sensors = ["-"] * k
        units = [""] * k
    if fs is not None:
        fs = sample_rate(fs)
    n = x.shape[0]
    if n < 2:
        raise ImunoiseValueError(f"x needs at least 2 samples; got {n}")
    nan = np.isnan(x)
    missing = nan.sum(axis=0)
    if np.isinf(x).any():
        raise ImunoiseValueError("x must be finite or NaN (a missing sample); it contains inf")
    t = None if fs is None else np.arange(n, dtype=np.float64) / fs
    if missing.any():
        columns = [
            _describe_valid(x[~nan[:, j], j], None if t is None else t[~nan[:, j]])
            for j in range(x.shape[1])
        ]
        mean, var, lo, hi, drift = np.array(columns, dtype=np.float64).T
    else:
        mean = x.mean(axis=0)
        var = x.var(axis=0, ddof=1)
        lo, hi = x.min(axis=0), x.max(axis=0)
        drift = np.full(x.shape[1], np.nan) if t is None else _drift(t, x, mean)
    if "yaw" in names and sensors[names.index("yaw")] == "ypr":
        mean = mean.copy()
        mean[names.index("yaw")] = heading(mean[names.index("yaw")])
    return Description(
        names=tuple(names),
        sensors=tuple(sensors),
        units=tuple(units),
        n=int(n),
        fs=fs,
        mean=mean,
        std=np.sqrt(var),
        var=var,
        min=lo,
        max=hi,
        drift_per_hour=np.asarray(drift, dtype=np.float64),
        missing=missing.astype(np.int64),
    )


def _drift(t: np.ndarray, x: np.ndarray, mean) -> np.ndarray:
    """Least-squares slope of x (rows at times t) per hour."""
    tc = t - t.mean()
    return (tc @ (x - mean)) / (tc @ tc) * 3600.0


def _describe_valid(v: np.ndarray, t: np.ndarray | None) -> tuple:
    """(mean, var, min, max, drift/h) of one channel's valid samples ``v`` at
    times ``t``; NaN where too few samples define them."""
    if len(v) == 0:
        return (np.nan,) * 5
    mean = v.mean()
    var = v.var(ddof=1) if len(v) > 1 else np.nan
    drift = np.nan if t is None or len(v) < 2 else _drift(t, v, mean)
    return mean, var, v.min(), v.max(), drift


def _as_samples(x, name: str) -> np.ndarray:
    arr = np.asarray(x)
    if arr.dtype.kind not in "biuf":
        raise ImunoiseTypeError(f"{name} must hold real numbers; got dtype {arr.dtype}")
    arr = arr.astype(np.float64, copy=False)
    if arr.ndim not in (1, 2):
        raise ImunoiseValueError(f"{name} must be 1-D (n,) or 2-D (n, k); got shape {arr.shape}")
    return arr


def quantization_step(x, *, rtol: float = 1e-3) -> float | None:
    """The least significant step of quantized data, or None if there is none.

    Parameters
    ----------
    x : array_like
        Samples.
    rtol : float
        How far (as a fraction of the step) a difference may be from a whole
        multiple of the step; absorbs the rounding of decimal text to float.

    Returns
    -------
    float or None
        The largest ``q`` such that every difference between consecutive sorted
        unique values is a whole multiple of ``q`` (within ``rtol``), found
        among ``d_min / k`` for k = 1…10 and refined as the mean of
        ``d / round(d / q)``; None for constant data or data with no such grid
        (continuous values).
    """
    v = np.unique(np.asarray(x, dtype=np.float64).ravel())
    return _step_of_levels(v[np.isfinite(v)], rtol)


def _step_of_levels(v: np.ndarray, rtol: float = 1e-3) -> float | None:
    """:func:`quantization_step` of sorted finite values ``v`` (unique or not: the
    differences between equal values are left out), read :data:`CHUNK` values at a
    time: continuous data are told apart without an array of all the differences."""
    if len(v) < 2:
        return None
    scale = max(abs(v[0]), abs(v[-1]))
    # Differences at the level of float rounding are not steps of the data.
    tiny = 64 * np.finfo(np.float64).eps * scale

    def diffs():
        for a in range(0, len(v) - 1, CHUNK):
            d = np.diff(v[a:a + CHUNK + 1])
            yield d[d > tiny]

    dmin = min((float(d.min()) for d in diffs() if d.size), default=None)
    if dmin is None:
        return None
    for k in range(1, 11):
        q = dmin / k
        # chunk by chunk: the first chunk off the grid settles it
        if all(np.all(np.abs(r - np.round(r)) <= rtol) for r in (d / q for d in diffs())):
            d = np.concatenate(list(diffs()))
            return float(np.mean(d / np.round(d / q)))
    return None


@dataclass(frozen=True, repr=False)
class Distribution:
    """Histogram, normal fit and normality statistics (see :func:`distribution`).

    Attributes
    ----------
    n : int
        Number of valid samples (NaN left out).
    counts : ndarray of int, (B,)
    edges : ndarray, (B + 1,)
        Histogram bin edges, over the bulk of the data unless ``extent="all"``
        (see the module notes).
    step : float or None
        Detected quantization step (None: continuous data, ordinary bins).
    level_spacing : float or None
        Mean spacing of the occupied levels in the central 98 % of the data,
        the unit of the bins; equals ``step`` unless the sensor skips grid
        points (see the module notes).
    mu, sigma : float
        Maximum-likelihood normal fit (``scipy.stats.norm.fit``; sigma has ddof=0).
    mu_std, sigma_std : float
        Their standard uncertainties, correlation between samples included
        (batch means, see :func:`distribution`); NaN below
        :data:`UNCERTAINTY_BATCHES` · 10 samples.
    ks_statistic, ks_pvalue : float
        Kolmogorov–Smirnov test against N(mu, sigma).
    ad_statistic : float
        Anderson–Darling statistic for normality.
    ad_critical_values, ad_significance_levels : ndarray
        Critical values (of ``ad_statistic``) at significance levels in percent.
    skewness, excess_kurtosis : float
        Sample skewness and Fisher (excess) kurtosis, biased estimators.
    qq_theoretical, qq_sample : ndarray
        Q–Q data: standard normal quantiles and the matching sample quantiles.
    missing : int
        Missing samples (NaN) in ``x``, left out of everything above.
    off_scale_below, off_scale_above : int
        Valid samples below the first and above the last edge (outside the
        histogram; every statistic above still uses them). :attr:`off_scale`
        is their sum.
    """

    n: int
    counts: np.ndarray
    edges: np.ndarray
    step: float | None
    level_spacing: float | None
    mu: float
    sigma: float
    ks_statistic: float
    ks_pvalue: float
    ad_statistic: float
    ad_critical_values: np.ndarray
    ad_significance_levels: np.ndarray
    skewness: float
    excess_kurtosis: float
    qq_theoretical: np.ndarray
    qq_sample: np.ndarray
    missing: int = 0
    mu_std: float = float("nan")
    sigma_std: float = float("nan")
    off_scale_below: int = 0
    off_scale_above: int = 0

    @property
    def off_scale(self) -> int:
        """Valid samples outside the histogram's edges."""
        return self.off_scale_below + self.off_scale_above

    def __post_init__(self) -> None:
        for name in (
            "counts",
            "edges",
            "ad_critical_values",
            "ad_significance_levels",
            "qq_theoretical",
            "qq_sample",
        ):
            getattr(self, name).flags.writeable = False

    def pdf(self, x) -> np.ndarray:
        """Density of the fitted normal at ``x``."""
        return _sstats.norm.pdf(np.asarray(x, dtype=np.float64), self.mu, self.sigma)

    def density(self) -> np.ndarray:
        """Histogram normalised to a density, comparable to :meth:`pdf`: counts over
        all ``n`` valid samples times the bin width, so it integrates to the fraction
        of samples on scale (1 when :attr:`off_scale` is 0)."""
        widths = np.diff(self.edges)
        return self.counts / (self.n * widths)

    def _items(self) -> list[tuple[str, str]]:
        """(quantity, value) pairs of the summary: μ and σ rounded to their
        uncertainties, the rest to four significant digits."""
        num = _summary.number
        bins = f"{len(self.counts)}"
        if self.step:
            bins += f" (step {num(self.step)}"
            bins += (f", levels {num(self.level_spacing)} apart)"
                     if self.level_spacing and self.level_spacing != self.step else ")")
        if self.off_scale:
            bins += f", {self.off_scale_below} below and {self.off_scale_above} above the range"
        items = [("n", str(self.n)), ("normal fit", f"μ={_summary.estimate(self.mu, self.mu_std)} "
                                       f"σ={_summary.estimate(self.sigma, self.sigma_std)}"),
                 ("KS", f"D={num(self.ks_statistic)} p={num(self.ks_pvalue)}"),
                 ("AD", f"A²={num(self.ad_statistic)}"),
                 ("skewness", num(self.skewness)),
                 ("excess kurtosis", num(self.excess_kurtosis)), ("bins", bins)]
        return items + ([("missing", str(self.missing))] if self.missing else [])

    def __repr__(self) -> str:
        return _summary.lines("Distribution(", [f"{k} {v}" if k != "n" else f"n={v}"
                                                 for k, v in self._items()], sep=", ")

    def _repr_html_(self) -> str:
        return _summary.html_table(["quantity", "value"], self._items(),
                                   caption="Distribution: histogram, normal fit, normality")


@old_call_forms(keyword_only=("bins",))
def distribution(x, *, bins="auto", qq_points: int = 1001, extent: str = "bulk",
                 overwrite_input: bool = False) -> Distribution:
    r"""Histogram with quantization-aware bins, normal fit and normality tests.

    Parameters
    ----------
    x : array_like, 1-D
        Samples of one channel; NaN marks a missing sample and is left out.
    bins : "auto", str, int or array_like
        ``"auto"`` (or any rule of :func:`numpy.histogram_bin_edges`) gives that
        rule's bin width (no narrower than the Rice rule's, :math:`2n^{1/3}` bins
        over the range), rounded up to a whole number of quantization steps
        when the data are quantized (see the module notes); an int asks for
        about that many bins over the range (also aligned to the step); an
        array gives the edges as they are.
    extent : {"bulk", "all"}
        Range the bins cover (rules and int ``bins`` only): ``"bulk"`` the
        central 99 % with a margin (see the module notes; the samples outside
        are counted in ``off_scale_below``/``off_scale_above``), ``"all"``
        every sample.
    qq_points : int
        Number of Q–Q points (sample quantiles at probabilities
        :math:`p_i = (i + 0.5)/m`), so plots stay light for 10⁷ samples.
    overwrite_input : bool
        Allow a float64 ``x`` to be sorted in place (as ``numpy.median``'s option):
        the one sort then needs no copy of the samples. The result is the same.

    Returns
    -------
    Distribution

    Notes
    -----
    Everything is computed from one sort of the data. The KS p-value is the
    exact one (``scipy.stats.kstwo``, as ``scipy.stats.kstest``) up to
    :data:`KS_EXACT_MAX_N` samples and the asymptotic Kolmogorov one
    (``kstwobign``) above, where the exact one costs half a second per channel
    and differs in digits nobody reads. A² uses the sample standard deviation
    (ddof = 1) as ``scipy.stats.anderson`` does.

    ``mu_std`` is the batch-means standard error: the valid samples, in time
    order, cut into :data:`UNCERTAINTY_BATCHES` equal batches, and
    :math:`u(\mu) = s_{\bar x_b}/\sqrt{b}`. Unlike :math:`\sigma/\sqrt{n}`
    it grows with the correlation of the samples up to the batch length (a
    sensor's filter, a wandering bias), which is what makes the mean of a still
    log less certain than independent samples would. With the effective sample
    count :math:`n_\mathrm{eff} = \min(n, \sigma^2/u(\mu)^2)`,
    ``sigma_std`` is :math:`\sigma/\sqrt{2(n_\mathrm{eff}-1)}`. They round
    the report's μ and σ (GUM style).

    The KS test uses the parameters fitted from the same data, so its p-value
    is optimistic (Lilliefors); on quantized data ties inflate the statistic
    too. With 10⁴–10⁶ samples any real sensor fails a normality test: read the
    statistics, skewness and kurtosis as effect sizes, not verdicts. The
    Anderson–Darling statistic and its critical values are those of
    ``scipy.stats.anderson(x, "norm")`` (Stephens 1974).
    """
    arr = np.asarray(x)
    if arr.dtype.kind not in "biuf":
        raise ImunoiseTypeError(f"x must hold real numbers; got dtype {arr.dtype}")
    arr = arr.astype(np.float64, copy=False)
    if arr.ndim != 1:
        raise ImunoiseValueError(f"x must be 1-D; got shape {arr.shape}")
    if np.isinf(arr).any():
        raise ImunoiseValueError("x must be finite or NaN (a missing sample); it contains inf")
    if not isinstance(overwrite_input, bool):
        raise ImunoiseTypeError(f"overwrite_input must be True or False; got {overwrite_input!r}")
    owned = overwrite_input and arr is x  # x itself, not a float64 copy of it
    nan = np.isnan(arr)
    missing = int(np.count_nonzero(nan))
    if missing:
        arr = arr[~nan]
        owned = True
    del nan
    if len(arr) < 3:
        extra = f" ({missing} NaN left out)" if missing else ""
        raise ImunoiseValueError(f"x needs at least 3 valid samples; got {len(arr)}{extra}")
    if not (isinstance(qq_points, int | np.integer) and qq_points >= 2):
        raise ImunoiseValueError(f"qq_points must be an integer >= 2; got {qq_points!r}")
    if extent not in ("bulk", "all"):
        raise ImunoiseValueError(f'extent must be "bulk" or "all"; got {extent!r}')

    n = len(arr)
    means = _batch_means(arr)  # in time order, before the sort
    if owned:
        arr.sort()
        xs = arr
    else:
        xs = np.sort(arr)
    del arr
    step = _step_of_levels(xs)
    shown = _bulk(xs) if extent == "bulk" else xs
    if step is None:
        spacing = None
        edges = _edges(shown, bins, None)
    else:
        levels = xs[np.concatenate(([True], xs[1:] != xs[:-1]))]
        spacing = _level_spacing(xs, levels, step)
        edges = _edges(shown, bins, spacing)
        if isinstance(bins, str) or np.ndim(bins) == 0:
            edges = _snap(edges, levels, step)
    # Histogram from the sorted samples: [a, b) bins, the last one closed, as np.histogram.
    idx = np.searchsorted(xs, edges, side="left")
    idx[-1] = np.searchsorted(xs, edges[-1], side="right")
    counts = np.diff(idx)
    off_scale = {"off_scale_below": int(idx[0]), "off_scale_above": int(n - idx[-1])}
    # Normal fit by maximum likelihood (what scipy.stats.norm.fit returns).
    # in units of the largest |x|: squares and fourth powers of values near 1e100
    # would overflow
    scale = max(abs(float(xs[0])), abs(float(xs[-1]))) or 1.0
    mu_u = _chunk_sum(xs, lambda v: v / scale) / n
    sigma_u = float(np.sqrt(_chunk_sum(xs, lambda v: np.square(v / scale - mu_u)) / n))
    mu, sigma = mu_u * scale, sigma_u * scale
    if sigma > 0:
        ks_stat, ad_stat, skew, kurt = _normality(xs, scale, mu_u, sigma_u)
        if n <= KS_EXACT_MAX_N:
            ks_p = float(_sstats.kstwo.sf(ks_stat, n))
        else:
            ks_p = float(_sstats.kstwobign.sf(ks_stat * np.sqrt(n)))
        ad_crit = np.around(_AD_NORM / (1.0 + 4.0 / n - 25.0 / n / n), 3)
    else:
        ks_stat = ks_p = ad_stat = skew = kurt = float("nan")
        ad_crit = np.full(5, np.nan)
    p = (np.arange(qq_points) + 0.5) / qq_points
    h = (n - 1) * p
    lo = np.floor(h).astype(np.int64)
    hi = np.minimum(lo + 1, n - 1)
    return Distribution(
        n=n,
        counts=counts.astype(np.int64),
        edges=edges,
        step=step,
        level_spacing=spacing,
        mu=mu,
        sigma=sigma,
        ks_statistic=ks_stat,
        ks_pvalue=ks_p,
        ad_statistic=ad_stat,
        ad_critical_values=ad_crit,
        ad_significance_levels=_AD_LEVELS.copy(),
        skewness=skew,
        excess_kurtosis=kurt,
        qq_theoretical=_sstats.norm.ppf(p),
        qq_sample=xs[lo] + (h - lo) * (xs[hi] - xs[lo]),
        missing=missing,
        **_fit_uncertainty(means, n, sigma),
        **off_scale,
    )


def _chunk_sum(xs: np.ndarray, f) -> float:
    """Σ f(xs) over chunks of :data:`CHUNK` samples (numpy's pairwise sum within each:
    one chunk is ``np.sum(f(xs))``)."""
    return float(sum(np.add.reduce(f(xs[a:a + CHUNK])) for a in range(0, len(xs), CHUNK)))


def _normality(xs: np.ndarray, scale: float, mu_u: float,
               sigma_u: float) -> tuple[float, float, float, float]:
    """KS D, Anderson–Darling A², skewness and excess kurtosis of the sorted samples
    ``xs`` against the normal fit (mean ``mu_u``, σ ``sigma_u`` in units of ``scale``),
    a chunk of :data:`CHUNK` samples at a time: ``scipy.stats.norm``'s cdf, logcdf and
    logsf are ``ndtr(x)``, ``log_ndtr(x)`` and ``log_ndtr(−x)`` of the standardised
    samples."""
    n = len(xs)
    mu, sigma = mu_u * scale, sigma_u * scale
    w_scale = sigma_u * np.sqrt(n / (n - 1))  # A² with ddof = 1, as scipy.stats.anderson
    ks = -np.inf
    ad = m3 = m4 = 0.0
    for a in range(0, n, CHUNK):
        b = min(n, a + CHUNK)
        x = xs[a:b]
        i = np.arange(a + 1, b + 1, dtype=np.float64)
        cdf = _special.ndtr((x - mu) / sigma)
        ks = max(ks, float(np.max(i / n - cdf)), float(np.max(cdf - (i - 1) / n)))
        u = x / scale
        # sample i pairs with sample n + 1 − i: the mirror chunk, reversed
        mirror = xs[n - b:n - a][::-1] / scale
        ad += float(np.add.reduce((2 * i - 1.0) / n * (
            _special.log_ndtr((u - mu_u) / w_scale)
            + _special.log_ndtr(-((mirror - mu_u) / w_scale)))))
        standard = (u - mu_u) / sigma_u
        square = standard * standard
        m3 += float(np.add.reduce(square * standard))
        m4 += float(np.add.reduce(square * square))
    return ks, float(-n - ad), m3 / n, m4 / n - 3.0


def _bulk(xs: np.ndarray) -> np.ndarray:
    """The sorted samples ``xs`` within the histogram's range: the central
    1 − 2·:data:`BULK_TAIL` widened by :data:`BULK_MARGIN` of its width on each side.
    When the bulk has no width (one level holds 99 %), every sample."""
    q_lo, q_hi = sorted_quantiles(xs, [BULK_TAIL, 1.0 - BULK_TAIL])
    width = q_hi - q_lo
    if not width > 0:
        return xs
    i = np.searchsorted(xs, q_lo - BULK_MARGIN * width, side="left")
    j = np.searchsorted(xs, q_hi + BULK_MARGIN * width, side="right")
    return xs[i:j]


def sorted_quantiles(xs: np.ndarray, q) -> np.ndarray:
    """``np.quantile(xs, q)`` (its default, linear method) of the sorted samples ``xs``
    (no NaN), the same numbers without its partitioned copy of ``xs``: the order
    statistics either side of (n − 1)·q, interpolated as numpy's ``_lerp`` does (from
    the upper one when the weight is at least 1/2)."""
    n = len(xs)
    virtual = (n - 1) * np.asarray(q, dtype=np.float64)
    below = np.floor(virtual)
    previous = np.clip(below, 0, n - 1).astype(np.intp)
    following = np.clip(below + 1, 0, n - 1).astype(np.intp)
    top = virtual >= n - 1
    previous[top] = following[top] = n - 1
    gamma = virtual - np.where(top, -1.0, np.maximum(below, 0.0))
    a, b = xs[previous], xs[following]
    diff = b - a
    return np.where(gamma >= 0.5, b - diff * (1 - gamma), a + diff * gamma)


#: Batches of the batch-means standard error of the normal fit's mean.
UNCERTAINTY_BATCHES = 20


def _batch_means(v: np.ndarray) -> np.ndarray | None:
    """The means of :data:`UNCERTAINTY_BATCHES` equal batches of the samples ``v`` in
    time order; None when a batch would hold fewer than 10."""
    b = UNCERTAINTY_BATCHES
    size = len(v) // b
    if size < 10:
        return None
    return v[: b * size].reshape(b, size).mean(axis=1)


def _fit_uncertainty(means: np.ndarray | None, n: int, sigma: float) -> dict[str, float]:
    """``mu_std`` (from the batch means ``means`` of ``n`` samples, :func:`_batch_means`)
    and ``sigma_std``."""
    if means is None:
        return {"mu_std": float("nan"), "sigma_std": float("nan")}
    b = len(means)
    mu_std = float(np.std(means, ddof=1) / np.sqrt(b))
    with np.errstate(over="ignore"):  # a ratio above 1e154 is more than len(v) anyway
        ratio = float(np.square(np.float64(sigma) / mu_std)) if mu_std > 0 else np.inf
    n_eff = min(float(n), ratio)
    return {"mu_std": mu_std, "sigma_std": sigma / np.sqrt(2.0 * max(n_eff - 1.0, 1.0))}


def _level_spacing(xs: np.ndarray, levels: np.ndarray, step: float) -> float:
    """Spacing of the sensor's levels in the central 98 % of ``x`` (see module notes).

    Occupied print-grid values are grouped into clusters (runs separated by gaps
    of more than 1.5 steps); a cluster with less than :data:`RARE_CLUSTER` of its
    busier neighbour's samples is a rare in-between value and left out. When the
    remaining clusters' centres (count-weighted) are regularly spaced (spacing
    with a coefficient of variation below 0.3, at least 5 gaps) their mean
    spacing is returned; otherwise (dense levels, or gaps that are just random
    sparsity) ``step``.
    """
    n = len(xs)
    lo, hi = xs[int(0.01 * (n - 1))], xs[int(np.ceil(0.99 * (n - 1)))]
    a, b = np.searchsorted(levels, lo), np.searchsorted(levels, hi, side="right")
    v = levels[a:b]
    if len(v) < 3:
        return step
    counts = np.diff(np.searchsorted(xs, np.append(v, np.inf), side="left")).astype(float)
    first = np.flatnonzero(np.concatenate(([True], np.diff(v) > 1.5 * step)))
    total = np.add.reduceat(counts, first)
    centre = np.add.reduceat(counts * (v - v[0]), first) / total + v[0]
    busier = np.maximum(np.append(total[1:], 0.0), np.insert(total[:-1], 0, 0.0))
    centre = centre[total >= RARE_CLUSTER * busier]
    if len(centre) < 6:
        return step
    spacing = np.diff(centre)
    mean = float(spacing.mean())
    if mean < 1.5 * step or spacing.std() > 0.3 * mean:
        return step
    return mean


def _snap(edges: np.ndarray, v: np.ndarray, step: float) -> np.ndarray:
    """Move inner edges within half a step of a level (``v``: sorted unique) into a gap."""
    if len(v) < 2 or len(edges) < 3:
        return edges
    inner = edges[1:-1].copy()
    i = np.clip(np.searchsorted(v, inner), 1, len(v) - 1)
    near = np.minimum(np.abs(inner - v[i - 1]), np.abs(v[i] - inner))
    bad = near < 0.5 * step * (1 - 1e-6)
    if np.any(bad):
        mids = 0.5 * (v[:-1] + v[1:])
        j = np.clip(np.searchsorted(mids, inner[bad]), 1, len(mids) - 1)
        left, right = mids[j - 1], mids[j]
        inner[bad] = np.where(inner[bad] - left <= right - inner[bad], left, right)
    return np.unique(np.concatenate([edges[:1], inner, edges[-1:]]))


def _edges(x: np.ndarray, bins, step: float | None) -> np.ndarray:
    lo, hi = float(x.min()), float(x.max())
    if not isinstance(bins, str) and np.ndim(bins) == 1:
        edges = np.asarray(bins, dtype=np.float64)
        if len(edges) < 2 or np.any(np.diff(edges) <= 0):
            raise ImunoiseValueError("bins as an array must be at least 2 increasing edges")
        return edges
    if isinstance(bins, str):
        try:
            rule = np.histogram_bin_edges(x, bins=bins)
        except ValueError as exc:
            raise ImunoiseValueError(
                f"bins must be a numpy bin rule, an int or edges; got {bins!r}"
            ) from exc
        width = float(rule[1] - rule[0]) if len(rule) > 1 else 0.0
        # at most the Rice count of bins: on a peaked distribution (a still log with a
        # few vibration bursts, a moving log's attitude) the Freedman–Diaconis width
        # follows the narrow peak and cuts the tails into bins of one sample or none
        width = max(width, (hi - lo) / (2.0 * len(x) ** (1.0 / 3.0)))
    elif isinstance(bins, int | np.integer) and not isinstance(bins, bool) and bins >= 1:
        width = (hi - lo) / int(bins)
    else:
        raise ImunoiseValueError(
            f"bins must be a numpy bin rule, a positive int or edges; got {bins!r}")
    if step is None or hi == lo:
        nb = 1 if width <= 0 else int(min(MAX_BINS, max(1, np.ceil((hi - lo) / width))))
        return np.histogram_bin_edges(x, bins=nb)
    k = max(1, int(np.ceil(width / step * (1 - 1e-9))))
    levels = int(round((hi - lo) / step)) + 1
    k = max(k, int(np.ceil(levels / MAX_BINS)))
    nb = int(np.ceil(levels / k))
    return lo + (np.arange(nb + 1) * k - 0.5) * step


def attitude_angles(ypr) -> dict[str, np.ndarray]:
    """``{"yaw": …, "pitch": …, "roll": …}`` in degrees from a log's ``ypr`` (n, 3),
    yaw unwrapped about its circular mean (:func:`unwrap_about_circular_mean`) so a
    heading near ±180° stays in one piece."""
    ypr = np.asarray(ypr, dtype=float)
    return {name: unwrap_about_circular_mean(ypr[:, j]) if name == "yaw" else ypr[:, j]
            for j, name in enumerate(_schema.ATTITUDE_NAMES)}


def heading(angle_deg: float) -> float:
    """An angle (degrees) moved by whole turns into (−180°, 180°]."""
    a = (float(angle_deg) + 180.0) % 360.0 - 180.0
    return 180.0 if a == -180.0 else a


def unwrap_about_circular_mean(angle_deg: np.ndarray) -> np.ndarray:
    """Angles (degrees) moved by whole turns into the half-turn around their
    circular mean, the mean itself in (−180°, 180°]: a heading that jitters across
    ±180° keeps its true spread instead of splitting into two clusters 360° apart."""
    a = np.asarray(angle_deg, dtype=float)
    ok = np.isfinite(a)
    if not ok.any():
        return a.copy()
    # in place, one array at a time: a channel of a long log is large
    r = a[ok]
    sin_mean = np.mean(np.sin(np.radians(r, out=r), out=r))
    r[:] = a[ok]
    cos_mean = np.mean(np.cos(np.radians(r, out=r), out=r))
    centre = float(np.degrees(np.arctan2(sin_mean, cos_mean)))
    del r
    out = a - centre  # centre + (a − centre + 180°) mod 360° − 180°, one array
    out += 180.0
    np.remainder(out, 360.0, out=out)
    np.add(centre, out, out=out)
    out -= 180.0
    return out
