"""Each sensor's own noise from the logs of several sensors on one mount.

:func:`own_noise` aligns the logs (:func:`imunoise.align`), then, per axis of one
sensor channel, separates what the sensors share (the mount's motion) from what
each adds: with three logs the three-cornered hat
(:func:`imunoise.three_cornered_hat`), with two the Groslambert covariance
(:func:`imunoise.gcodev`), σ²_own,a = σ²_a − GCOV(a, b). Beside each sensor's own
deviation it keeps its plain deviation over the same span, so the two can be
read side by side: where they agree the sensor's noise dominates, where the plain
one is higher the motion does.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from imunoise import allan
from imunoise._analysis.align import Aligned, align
from imunoise._analysis.hat import HAT_KINDS, at_m, gcodev, own_variance, three_cornered_hat
from imunoise._analysis.timefreq import pdev
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.schema import ALLAN_SENSORS, axis_names
from imunoise._support.validate import confidence_level
from imunoise.allan import ONE_SIGMA, AllanResult, TauSpec
from imunoise.errors import (
    CoverageWarning,
    ImunoiseValueError,
    ImunoiseWarning,
)
from imunoise.readers.log import ImuLog

__all__ = ["OwnNoise", "own_noise"]

#: Methods by number of logs.
METHODS = {2: "Groslambert covariance", 3: "three-cornered hat"}


@dataclass(frozen=True, repr=False)
class OwnNoise:
    """Each sensor's own deviation beside its plain one, from logs of one mount.

    Attributes
    ----------
    sensor : str
        The channel analysed (``"gyro"`` or ``"accel"``).
    method : str
        ``"three-cornered hat"`` (three logs) or ``"Groslambert covariance"`` (two).
    own : tuple of AllanResult
        Each log's own deviation, in the order of the logs. ``var`` is signed:
        negative where the data put the sensor's noise below what the others
        resolve; there ``dev`` and ``edf`` are NaN, ``ci_low`` 0 and ``ci_high``
        the upper bound.
    plain : tuple of AllanResult
        Each log's plain deviation (motion and own noise) over the common span,
        at the taus of ``own``.
    negative : ndarray of bool, (logs, T) or (logs, T, channels)
        True where a log's own variance is negative.
    aligned : Aligned
        The logs on their common grid (what was cut and why).
    """

    sensor: str
    method: str
    own: tuple[AllanResult, ...]
    plain: tuple[AllanResult, ...]
    negative: np.ndarray
    aligned: Aligned

    def __post_init__(self) -> None:
        self.negative.flags.writeable = False

    @property
    def taus(self) -> np.ndarray:
        """The averaging times, s."""
        return self.own[0].taus

    def negative_taus(self, i: int) -> np.ndarray:
        """The taus where log ``i``'s own variance is negative on any axis."""
        below = self.negative[i].reshape(len(self.taus), -1).any(axis=1)
        return self.taus[below]

    def _names(self) -> list[str]:
        return [_summary.source_name(log.source) for log in self.aligned]

    def _facts(self) -> list[str]:
        counts = [int(np.count_nonzero(v)) for v in self.negative]
        return [f"{self.sensor} of {_summary.plural(len(self.own), 'log')}", self.method,
                _summary.tau_span(self.taus),
                f"common span {_summary.duration(self.aligned.duration)}",
                "negative at " + ", ".join(f"log {i} {k}" for i, k in enumerate(counts))]

    def __repr__(self) -> str:
        return _summary.lines("OwnNoise(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per log and axis: its own deviation at the first and last tau and its
        minimum, and the taus where its variance is negative."""
        k = self.own[0].channels
        axes = axis_names(k) if k > 1 else [""]
        names = [f"log {i} {a}".rstrip() for i in range(len(self.own)) for a in axes]
        dev = np.concatenate([np.reshape(r.dev, (len(r.taus), -1)) for r in self.own], axis=1)
        header, rows = _summary.curve_rows(self.taus, dev, names)
        negative = self.negative.reshape(len(self.own), len(self.taus), -1).sum(axis=1).ravel()
        return _summary.html_table(
            [*header, "negative taus"],
            [[*row, int(n)] for row, n in zip(rows, negative, strict=True)],
            caption="OwnNoise: " + ", ".join(self._facts()))


def own_noise(logs: Aligned | Sequence[ImuLog | str | os.PathLike], *, sensor: str = "gyro",
              taus: TauSpec = "octave", kind: str = "adev", confidence: float = ONE_SIGMA,
              clock: str = "timestamps") -> OwnNoise:
    r"""Each sensor's own deviation from the logs of two or three sensors on one mount.

    The logs are put on one grid (:func:`imunoise.align`; pass an :class:`Aligned`
    to choose its options), then per axis of ``sensor``: with three logs the
    three-cornered hat (:func:`imunoise.three_cornered_hat`), with two
    :math:`\sigma^2_{\mathrm{own},a} = \sigma^2_a - \mathrm{GCOV}(a, b)`
    (:func:`imunoise.gcodev`, ADEV only). The motion of the mount, common to the
    logs, cancels; each sensor's plain deviation over the same span is kept beside.

    Confidence for two logs, a conservative rule as the hat's: the own variance's
    standard deviation is at most the sum of σ²_a's χ² spread and GCOV's (the
    Wishart moment, see :func:`imunoise.gcodev`), its EDF that of a χ² of that mean
    and spread. Where an own variance is negative its ``dev`` is NaN, the result's
    ``negative`` marks it and a warning names the taus.

    Parameters
    ----------
    logs : Aligned or sequence of ImuLog or path
        Two or three logs of one mount (aligned with ``clock`` when not an
        :class:`Aligned`).
    sensor : {"gyro", "accel"}
        The channel analysed, all its axes.
    taus, confidence
        As for :func:`imunoise.adev`.
    kind : str
        The statistic, one of ``imunoise._analysis.hat.HAT_KINDS`` for three logs; two
        logs take ``"adev"`` only.
    clock : {"timestamps", "motion"}
        How to align logs that are not aligned yet (:func:`imunoise.align`).

    Returns
    -------
    OwnNoise
        ``own`` and ``plain`` per log, ``negative``, and the ``aligned`` logs.
    """
    if not isinstance(logs, Aligned):
        logs = align(logs, clock=clock)
    if sensor not in ALLAN_SENSORS:
        raise ImunoiseValueError(f"sensor must be one of {', '.join(ALLAN_SENSORS)}; got "
                                 f"{sensor!r}")
    if not isinstance(kind, str) or kind not in HAT_KINDS:
        raise ImunoiseValueError(f"kind must be one of {', '.join(HAT_KINDS)}; got {kind!r}")
    if len(logs) not in METHODS:
        raise ImunoiseValueError(f"logs must hold 2 or 3 logs (the Groslambert covariance or "
                                 f"the three-cornered hat); got {len(logs)}")
    if len(logs) == 2 and kind != "adev":
        raise ImunoiseValueError(f"kind must be 'adev' for two logs (the Groslambert "
                                 f"covariance is an Allan covariance); got {kind!r}")
    confidence = confidence_level(confidence)
    data = []
    for i, log in enumerate(logs):
        y = getattr(log, sensor)
        if not isinstance(y, np.ndarray):
            raise ImunoiseValueError(f"logs[{i}] has no {sensor} channel; it has "
                                     f"{', '.join(log.channels) or 'none'}")
        data.append(y)
    fs = logs.fs
    if len(logs) == 3:
        with warnings.catch_warnings():  # said below, naming the logs, not a, b, c
            warnings.filterwarnings("ignore", message="three_cornered_hat: sensor",
                                    category=ImunoiseWarning)
            hat = three_cornered_hat(*data, fs, taus=taus, kind=kind, confidence=confidence)
        own = tuple(hat)
        negative = hat.negative
        function = pdev if kind == "pdev" else getattr(allan, kind)
        plain = [function(y, fs, taus=taus, confidence=confidence) for y in data]
    else:
        own, negative, plain = _two(data, fs, taus, confidence)
    # gaps can leave the results different taus: the section compares them at each
    common = own[0].m
    for r in plain:
        common = np.intersect1d(common, r.m)
    rows = np.searchsorted(own[0].m, common)
    result = OwnNoise(sensor=sensor, method=METHODS[len(logs)],
                      own=tuple(at_m(r, common) for r in own),
                      plain=tuple(at_m(r, common) for r in plain),
                      negative=np.asarray(negative)[:, rows], aligned=logs)
    for i in range(len(logs)):
        below = result.negative_taus(i)
        if below.size:
            shown = ", ".join(f"{t:g}" for t in below[:8])
            more = f" and {below.size - 8} more" if below.size > 8 else ""
            _warn.warn(f"own_noise: log {i}'s own {kind} variance ({result.method}) is "
                       f"negative at tau = {shown}{more} s: its noise is below what the other "
                       "logs resolve there; its dev is NaN, ci_high the upper bound "
                       "(result.negative_taus)", CoverageWarning)
    return result


def _two(data: list[np.ndarray], fs: float, taus: TauSpec, confidence: float):
    """Each of two sensors' own Allan variance, σ²_a − GCOV(a, b), where it is
    negative, and their plain Allan deviations (at the same taus)."""
    cov = gcodev(data[0], data[1], fs, taus=taus, confidence=confidence)
    plain = [at_m(allan.adev(y, fs, taus=cov.taus, confidence=confidence), cov.m)
             for y in data]
    common = np.intersect1d(plain[0].m, plain[1].m)
    cov = at_m(cov, common)
    plain = [at_m(r, common) for r in plain]
    g = np.asarray(cov.var, dtype=np.float64)
    va, vb = (np.asarray(r.var, dtype=np.float64) for r in plain)
    with np.errstate(invalid="ignore", divide="ignore"):
        spread_cov = np.sqrt((va * vb + g**2) / np.asarray(cov.edf, dtype=np.float64))
    own, negative = [], []
    for r, v in zip(plain, (va, vb), strict=True):
        spread = v * np.sqrt(2.0 / np.asarray(r.edf, dtype=np.float64)) + spread_cov
        result, below = own_variance(r, v - g, spread, confidence)
        own.append(result)
        negative.append(below)
    return tuple(own), np.array(negative), plain
