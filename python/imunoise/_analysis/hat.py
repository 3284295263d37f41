r"""Several sensors on one mount: the Groslambert covariance and the three-cornered hat.

Sensors on one mount see the same motion m(t) plus their own noise,
:math:`a = m + n_a`, :math:`b = m + n_b`, :math:`c = m + n_c`. The motion cancels in
their differences, whose Allan variances are sums of the sensors' own ones when
the noises are independent: :math:`\sigma^2_{ab} = \sigma^2_a + \sigma^2_b`, and so

.. math::

    \sigma^2_a = \tfrac12(\sigma^2_{ab} + \sigma^2_{ac} - \sigma^2_{bc}),\quad
    \sigma^2_b = \tfrac12(\sigma^2_{ab} + \sigma^2_{bc} - \sigma^2_{ac}),\quad
    \sigma^2_c = \tfrac12(\sigma^2_{ac} + \sigma^2_{bc} - \sigma^2_{ab})

(the three-cornered hat; Gray & Allan 1974, Riley's "3-cornered hat" notes). The
Groslambert covariance of two sensors, :math:`\mathrm{GCOV}(a, b)`, is the Allan
covariance of their phases: the motion they share, when their own noises are
independent, so :math:`\sigma^2_a - \mathrm{GCOV}(a, b)` is a's own noise from two
sensors only.

References
----------
J. E. Gray, D. W. Allan, "A method for estimating the frequency stability of an
individual oscillator", Proc. 28th Frequency Control Symposium, 1974.
F. Vernotte, C. E. Calosso, E. Rubiola, "Three-cornered hat versus Allan
covariance", Proc. IFCS 2016.
E. Lantz, C. E. Calosso, E. Rubiola, V. Giordano, C. Fluhr, B. Dubois, F. Vernotte,
"KLT-based quality controlled compression of the Groslambert covariance",
IEEE Trans. UFFC 66(12), 2019 (arXiv:1904.05849).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import stats as _stats

from imunoise import allan
from imunoise._analysis.timefreq import (
    averaging_grid,
    pdev,
    phase_points,
    tau_result,
    valid_windows,
)
from imunoise._core import allan as _core_allan
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.validate import confidence_level, samples
from imunoise.allan import ONE_SIGMA, AllanResult, TauSpec, chi2_interval
from imunoise.errors import ImunoiseValueError

__all__ = ["HAT_KINDS", "ThreeCorneredHat", "at_m", "gcodev", "own_variance",
           "three_cornered_hat"]

#: Statistics the hat can combine: each a quadratic form of the data, whose
#: expectation for independent noises adds (ThêoBR and ThêoH scale Theo1 by a
#: ratio of the data itself, so they are not).
HAT_KINDS = ("adev", "mdev", "tdev", "hdev", "ohdev", "pdev", "totdev", "mtotdev",
             "ttotdev", "htotdev", "theo1")

_SENSORS = ("a", "b", "c")


def _same_shape(a, b, c=None):
    """The three (or two) inputs as arrays of one shape, or ValueError naming the
    one that differs from ``a``."""
    arrays = {"a": samples(a, "a")[0], "b": samples(b, "b")[0]}
    if c is not None:
        arrays["c"] = samples(c, "c")[0]
    first = arrays["a"]
    for name, arr in list(arrays.items())[1:]:
        if arr.shape[0] != first.shape[0]:
            raise ImunoiseValueError(f"{name} must have as many samples as a ({first.shape[0]}); "
                             f"got {arr.shape[0]}")
        if arr.shape[1] != first.shape[1]:
            raise ImunoiseValueError(f"{name} must have the {first.shape[1]} channel(s) of a; got "
                             f"{arr.shape[1]}")
    return arrays


def gcodev(a: npt.ArrayLike, b: npt.ArrayLike, fs: float, *, taus: TauSpec = "octave",
           confidence: float = ONE_SIGMA, gaps: str = "skip",
           data_type: str = "freq") -> AllanResult:
    r"""Groslambert covariance deviation (GCODEV) of two series, allantools' ``gcodev``.

    .. math::

        \mathrm{GCOV}(m\tau_0) = \frac{1}{2(m\tau_0)^2 (N-2m)}\sum_{k=0}^{N-2m-1}
        (x^a_{k+2m} - 2x^a_{k+m} + x^a_k)(x^b_{k+2m} - 2x^b_{k+m} + x^b_k)

    over the N phase points of each (the overlapping Allan variance with one factor
    from each series). With a and b two sensors on one mount, it is the Allan
    variance of what they share (the mount's motion) and ``adev(a).var − r.var`` is
    a's own noise; with a − c and b − c (a reference c's noise common to both) it
    is c's. The covariance can be negative: ``r.var`` keeps its sign and ``r.dev``
    is :math:`\sqrt{|\mathrm{GCOV}|}`, allantools' value.

    Confidence: the sample covariance of ν independent pairs has variance
    :math:`(\sigma_a^2\sigma_b^2 + \mathrm{GCOV}^2)/\nu` (the Wishart moment; for
    a = b the χ² variance 2σ⁴/ν); ν is the smaller of the two series' Allan-variance
    EDF (Greenhall, for the noise types identified at each tau), σ² their
    overlapping Allan variances, and the normal interval on \|GCOV\| (clipped at 0)
    gives ``ci_low``/``ci_high`` on ``dev``. ``edf`` is that ν and ``alpha`` a's noise
    type. The KLT distribution of Lantz et al. (2019) is sharper; this one is simple
    and errs wide.

    Parameters
    ----------
    a, b : array_like, shape (n,) or (n, channels)
        Two records of one quantity at one rate, sample for sample (same shape).
    fs, taus, confidence, gaps, data_type
        As for :func:`imunoise.adev`; a term is left out where either series has a
        missing sample in its span.

    Returns
    -------
    AllanResult
        ``kind == "gcodev"``; ``var`` the signed covariance.
    """
    arrays = _same_shape(a, b)
    confidence = confidence_level(confidence)
    xa, broken_a, one_d, missing_a, fs = phase_points(a, fs, data_type, gaps, "gcodev")
    xb, broken_b, _, missing_b, _ = phase_points(b, fs, data_type, gaps, "gcodev")
    if xa.shape != xb.shape:  # "longest" runs of different lengths
        raise ImunoiseValueError(f"a's and b's gaps must leave runs of one length for "
                         f"gaps={gaps!r}; got {xa.shape[0]} and {xb.shape[0]} phase points "
                         "(pass gaps='skip')")
    del arrays
    broken = broken_a | broken_b
    n_points, channels = xa.shape
    m = averaging_grid(taus, fs, n_points, "gcodev", lambda m: n_points - 2 * m)
    cov = np.empty((m.size, channels))
    terms = np.empty((m.size, channels), dtype=np.int64)
    for t, mj in enumerate(int(v) for v in m):
        count = n_points - 2 * mj
        valid = valid_windows(broken, 2 * mj, count)
        da = xa[2 * mj:] - 2.0 * xa[mj:-mj] + xa[:count]
        db = xb[2 * mj:] - 2.0 * xb[mj:-mj] + xb[:count]
        terms[t] = valid.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            cov[t] = np.where(valid, da * db, 0.0).sum(axis=0) / (2.0 * terms[t])
    cov = np.where(terms >= 2, cov * (fs / m[:, None]) ** 2, np.nan)
    dev = np.sqrt(np.abs(cov))
    own = [_core_allan.analyse(_rate(x, br, fs), "oadev", m.astype(np.uint64))
           for x, br in ((xa, broken_a), (xb, broken_b))]
    edf = np.minimum(own[0].edf, own[1].edf)
    spread = np.sqrt((own[0].var * own[1].var + cov**2) / edf)
    z = _stats.norm.ppf(0.5 + confidence / 2.0)
    result = tau_result("gcodev", m, cov, dev, terms, edf, own[0].alpha,
                     own[0].alpha_identified, fs=fs, confidence=confidence, one_d=one_d,
                     missing=missing_a + missing_b, gaps=gaps, n_points=n_points,
                     data_type=data_type)
    squeeze = (lambda v: v[:, 0]) if one_d else (lambda v: v)
    low = np.sqrt(np.maximum(np.abs(cov) - z * spread, 0.0))
    high = np.sqrt(np.abs(cov) + z * spread)
    return _replace(result, ci_low=squeeze(low), ci_high=squeeze(high))


def _rate(phase, broken, fs):
    """Rate samples of a phase, NaN over its broken intervals."""
    rate = np.diff(phase, axis=0) * fs
    rate[broken] = np.nan
    return rate


def _replace(result: AllanResult, **fields) -> AllanResult:
    from dataclasses import replace

    return replace(result, **fields)


@dataclass(frozen=True, repr=False)
class ThreeCorneredHat:
    """Each of three sensors' own deviation, from their pairwise differences.

    Unpacks as its three results: ``ra, rb, rc = imunoise.three_cornered_hat(...)``.

    Attributes
    ----------
    a, b, c : AllanResult
        Each sensor's own deviation (``kind`` the statistic combined, e.g.
        ``"adev"``, so :func:`imunoise.fit` takes it). ``var`` is the hat's
        variance, negative where the data put the sensor's noise below what the
        differences resolve; there ``dev`` and ``edf`` are NaN, ``ci_low`` is 0 and
        ``ci_high`` the upper bound (see :func:`three_cornered_hat`). ``n`` is the
        fewer terms of the two differences holding the sensor, ``alpha`` the noise
        type of the one with the smaller variance (the sensor's share is larger).
    ab, ac, bc : AllanResult
        The deviations of the differences a − b, a − c and b − c.
    negative : ndarray of bool, (3, T) or (3, T, channels)
        True where sensor a, b or c (first axis) has a negative hat variance.
    """

    a: AllanResult
    b: AllanResult
    c: AllanResult
    ab: AllanResult
    ac: AllanResult
    bc: AllanResult
    negative: np.ndarray

    def __post_init__(self) -> None:
        self.negative.flags.writeable = False

    def __iter__(self):
        return iter((self.a, self.b, self.c))

    def __len__(self) -> int:
        return 3

    def _facts(self) -> list[str]:
        counts = [int(np.count_nonzero(v)) for v in self.negative]
        return [f"{self.a.kind}", _summary.tau_span(self.a.taus),
                f"fs {_summary.number(self.a.fs)} Hz",
                "negative at " + ", ".join(f"{s} {k}" for s, k in zip(_SENSORS, counts,
                                                                        strict=True))]

    def __repr__(self) -> str:
        return _summary.lines("ThreeCorneredHat(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per sensor (and channel) its own deviation at the first and last tau and
        its minimum, and the taus where its variance is negative."""
        names = [f"{s} {c}" if self.a.channels > 1 else s
                 for s in _SENSORS for c in range(self.a.channels)]
        dev = np.concatenate([np.reshape(r.dev, (len(r.taus), -1)) for r in self], axis=1)
        header, rows = _summary.curve_rows(self.a.taus, dev, names)
        negative = self.negative.reshape(3, len(self.a.taus), -1).sum(axis=1).ravel()
        return _summary.html_table(
            [*header, "negative taus"],
            [[*row, int(k)] for row, k in zip(rows, negative, strict=True)],
            caption="ThreeCorneredHat: " + ", ".join(self._facts()))


def three_cornered_hat(a: npt.ArrayLike, b: npt.ArrayLike, c: npt.ArrayLike, fs: float, *,
                       taus: TauSpec = "octave", kind: str = "adev",
                       confidence: float = ONE_SIGMA, gaps: str = "skip",
                       data_type: str = "freq") -> ThreeCorneredHat:
    r"""Three sensors' own deviations from their differences (the three-cornered hat).

    Three records of one quantity on one mount (three gyros on one axis) share the
    mount's motion, which cancels in their differences; for independent own noises

    .. math::

        \sigma^2_a = \tfrac12(\sigma^2_{ab} + \sigma^2_{ac} - \sigma^2_{bc})

    and likewise for b and c, σ²_ab the ``kind`` variance of a − b (the Allan
    variance by default). The motion may be far above every sensor's noise: each
    sensor's plain ADEV is then the motion's, and the hat still gives its own.

    Confidence (a conservative rule): each pairwise variance has the χ² spread
    :math:`s_p = \sigma^2_p\sqrt{2/\nu_p}` of its own EDF ν_p; the three share
    sensors and are correlated, so the hat's standard deviation is bounded by
    the worst correlation Cauchy–Schwarz allows, :math:`s \le \tfrac12(s_{ab} +
    s_{ac} + s_{bc})`, and the hat's EDF is that of a χ² with its mean and that
    spread, :math:`\nu = 2\sigma^4_a/s^2`; the interval is the χ² one
    (:func:`imunoise.allan.chi2_interval`). Where the hat's variance is negative
    (a sensor's noise below the others' estimation error) ``dev`` and ``edf`` are NaN,
    ``negative`` says so, a warning names the taus, ``ci_low`` is 0 and ``ci_high``
    :math:`\sqrt{\max(0, \sigma^2_a + z\,s)}`, z the normal quantile of the
    interval's upper end.

    Parameters
    ----------
    a, b, c : array_like, shape (n,) or (n, channels)
        The three records, sample for sample (same shape).
    fs, taus, confidence, gaps, data_type
        As for :func:`imunoise.adev`.
    kind : str
        The statistic, one of :data:`HAT_KINDS` (default ``"adev"``, overlapping).

    Returns
    -------
    ThreeCorneredHat
        Unpacks as ``(a, b, c)``, each an :class:`AllanResult`; ``negative`` marks
        the negative variances.

    Examples
    --------
    >>> import numpy as np, imunoise
    >>> fs, n = 100.0, 200_000
    >>> motion = 0.5 * np.sin(2 * np.pi * 0.7 * np.arange(n) / fs)
    >>> a, b, c = (motion + imunoise.simulate(n, fs, N=k, seed=i)
    ...            for i, k in enumerate((0.01, 0.02, 0.03)))
    >>> ra, rb, rc = imunoise.three_cornered_hat(a, b, c, fs, taus=np.array([1.0]))
    >>> bool(abs(ra.dev[0] - 0.01) < 0.001)
    True
    """
    if not isinstance(kind, str) or kind not in HAT_KINDS:
        raise ImunoiseValueError(f"kind must be one of {', '.join(HAT_KINDS)}; got {kind!r}")
    arrays = _same_shape(a, b, c)
    confidence = confidence_level(confidence)
    one_d = np.ndim(a) == 1
    function = pdev if kind == "pdev" else getattr(allan, kind)
    shaped = {k: (v[:, 0] if one_d else v) for k, v in arrays.items()}
    pairs = {
        name: function(shaped[name[0]] - shaped[name[1]], fs, taus=taus,
                       confidence=confidence, gaps=gaps, data_type=data_type)
        for name in ("ab", "ac", "bc")
    }
    # gaps can leave the pairs different taus: the hat needs all three at each
    common = np.intersect1d(np.intersect1d(pairs["ab"].m, pairs["ac"].m), pairs["bc"].m)
    pairs = {k: at_m(r, common) for k, r in pairs.items()}
    var = {k: np.asarray(r.var, dtype=np.float64) for k, r in pairs.items()}
    spread = {k: var[k] * np.sqrt(2.0 / np.asarray(r.edf, dtype=np.float64))
              for k, r in pairs.items()}
    s = 0.5 * (spread["ab"] + spread["ac"] + spread["bc"])
    # sensor -> (the two pairs holding it, the pair without it)
    layout = {"a": ("ab", "ac", "bc"), "b": ("ab", "bc", "ac"), "c": ("ac", "bc", "ab")}
    own, negative = {}, []
    for sensor, (p, q, other) in layout.items():
        v = 0.5 * (var[p] + var[q] - var[other])
        smaller = var[p] <= var[q]
        own[sensor], below = own_variance(
            pairs[p], v, s, confidence, n=_fewer(pairs[p].n, pairs[q].n),
            alpha=np.where(smaller, pairs[p].alpha, pairs[q].alpha),
            alpha_identified=np.where(smaller, pairs[p].alpha_identified,
                                      pairs[q].alpha_identified))
        negative.append(below)
        if below.any():
            taus_below = common[below.reshape(len(common), -1).any(axis=1)] / fs
            shown = ", ".join(f"{t:g}" for t in taus_below[:8])
            more = f" and {taus_below.size - 8} more" if taus_below.size > 8 else ""
            _warn.warn(
                f"three_cornered_hat: sensor {sensor}'s {kind} variance is negative at tau "
                f"= {shown}{more} s (its own noise is below the other two sensors' "
                "estimation error there): its dev is NaN, ci_high the upper bound"
            )
    return ThreeCorneredHat(a=own["a"], b=own["b"], c=own["c"], ab=pairs["ab"],
                            ac=pairs["ac"], bc=pairs["bc"], negative=np.array(negative))


def own_variance(base: AllanResult, var: np.ndarray, spread: np.ndarray, confidence: float,
                 **fields) -> tuple[AllanResult, np.ndarray]:
    """``base`` carrying a sensor's own variance ``var`` (a difference of variances,
    so possibly negative) of standard deviation ``spread``, and where it is negative.

    ``edf`` is that of a χ² of this mean and spread, ν = 2·var²/spread², and the
    interval the χ² one; where ``var`` < 0, ``dev`` and ``edf`` are NaN, ``ci_low``
    0 and ``ci_high`` the upper bound √max(0, var + z·spread), z the normal
    quantile of the interval's upper end. ``fields`` replace more of ``base``."""
    below = var < 0
    z = _stats.norm.ppf(0.5 + confidence / 2.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        edf = np.where(below, np.nan, 2.0 * var**2 / spread**2)
        dev = np.where(below, np.nan, np.sqrt(np.abs(var)))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        low, high = chi2_interval(dev, edf, confidence)
    # an EDF far below 1 (a variance near 0 against its spread) puts both χ² quantiles
    # at 0 in floating point: the interval's lower end is then 0, not inf
    low = np.where(below | ~np.isfinite(low), 0.0, low)
    high = np.where(below, np.sqrt(np.maximum(var + z * spread, 0.0)), high)
    return _replace(base, var=var, dev=dev, edf=edf, ci_low=low, ci_high=high,
                    **fields), below


def _fewer(n_p: np.ndarray, n_q: np.ndarray) -> np.ndarray:
    """The smaller term count of two pairs, (T,) or (T, channels) as either is."""
    n_p, n_q = np.asarray(n_p), np.asarray(n_q)
    if n_p.ndim != n_q.ndim:
        n_p, n_q = (v if v.ndim == 2 else v[:, None] for v in (n_p, n_q))
    return np.minimum(n_p, n_q)


def at_m(result: AllanResult, m: np.ndarray) -> AllanResult:
    """``result`` at the averaging factors ``m`` (a subset of its own)."""
    if np.array_equal(result.m, m):
        return result
    rows = np.searchsorted(result.m, m)
    fields = {name: np.asarray(getattr(result, name))[rows]
              for name in ("taus", "m", "dev", "var", "edf", "ci_low", "ci_high", "alpha",
                           "alpha_identified")}
    fields["n"] = np.asarray(result.n)[rows]
    return _replace(result, **fields)
