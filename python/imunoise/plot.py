r"""Figures of a noise analysis, drawn with matplotlib's Agg backend (no display needed).

Every function returns a :class:`matplotlib.figure.Figure`; :func:`save` writes it
as PNG and SVG. One figure per sensor holds its three axes. Axis colours are the
same in every figure (X blue, Y orange, Z green).

The functions take the objects the API returns: :func:`allan` an
:class:`~imunoise.AllanResult` and its :class:`~imunoise.NoiseModel`,
:func:`time_series` an :class:`~imunoise.ImuLog` (or an array and its rate),
:func:`histograms` :class:`~imunoise.Distribution` objects. ``result.plot(model)``,
``model.plot(result)`` and ``log.plot()`` call them.

Time series use min/max decimation: the samples are split into one bucket per
pixel column and each bucket is drawn as a vertical stroke from its minimum to
its maximum, so 10⁷ points draw in milliseconds and no spike disappears.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imunoise._support import atomic as _atomic
from imunoise._support import summary as _summary
from imunoise._support.schema import ATTITUDE_NAMES, CHANNELS, axis_names
from imunoise.allan import AllanResult
from imunoise.display import cell, format_value, percent, rounded
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.noise import FLICKER, TERMS, NoiseModel, _typed, model_variance
from imunoise.noise._terms import term_variances
from imunoise.readers.log import ImuLog
from imunoise.stats import Distribution

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imunoise._analysis.mount import OwnNoise
    from imunoise.dynamic import DynamicAllan
    from imunoise.spectrum import Spectrum

__all__ = [
    "AXIS_COLORS",
    "allan",
    "compensation",
    "decimate_minmax",
    "dynamic",
    "events",
    "histograms",
    "own_noise",
    "plain_ticks",
    "save",
    "spectrum",
    "style",
    "thermal",
    "time_series",
    "warmup",
]

AXIS_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd")
#: Shading of missing samples (gaps) on time plots.
GAP_COLOR = "#d62728"
#: Gaps of a log :func:`time_series` shades (the longest; every one would cost a
#: patch per panel).
SHADED_GAPS = 200
TERM_STYLES = {
    "Q": ("quantization Q", ":"),
    "N": ("white noise N", "--"),
    "B": ("bias instability B", "-."),
    "K": ("rate random walk K", (0, (5, 1, 1, 1))),
    "R": ("rate ramp R", (0, (1, 2))),
}
_RC = {
    "figure.dpi": 100,
    "savefig.dpi": 110,
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.fontsize": 7.5,
    "legend.frameon": False,
    "lines.linewidth": 1.2,
    "svg.fonttype": "none",
}


#: The unit an axis label gives when the caller did not say the data's: results are
#: in the input's units (``docs``: rate data in, deviations in the same units).
INPUT_UNIT = "input unit"


def _label(quantity: str, unit: str) -> str:
    """``"σ(τ) [rad/s]"``; ``"σ(τ) [input unit]"`` when the unit is not known."""
    return f"{quantity} [{unit or INPUT_UNIT}]"


def _per(unit: str) -> str:
    """The unit of a density over ``unit``: ``"1/deg"``, ``"1/(rad/s)"``."""
    u = unit or INPUT_UNIT
    return f"1/({u})" if any(c in u for c in "/ ·*^") else f"1/{u}"


def _channel_unit(name: str) -> str:
    """Unit of a channel named ``"gyro X"`` (or ``"gyro"``), as figures write it
    (``"m/s²"``); "" when not a log's."""
    sensor = name.split(" ")[0]
    return _symbols(CHANNELS[sensor][1]) if sensor in CHANNELS else ""


def _symbols(unit: str) -> str:
    """``"m/s^2"`` -> ``"m/s²"``: one spelling of a unit in every figure and table."""
    return unit.replace("^2", "²").replace("^3", "³")


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    return Figure


@contextmanager
def style() -> Iterator[None]:
    """Context manager applying the imunoise figure style."""
    import matplotlib

    with matplotlib.rc_context(_RC):
        yield


def _margins(fig, *, left=0.8, right=0.15, bottom=0.5, top=0.25, wspace=0.25, hspace=0.15,
             title: bool = False) -> None:
    """Fixed margins in inches (constrained layout costs more than the drawing)."""
    w, h = fig.get_size_inches()
    top += 0.3 if title else 0.0
    fig.subplots_adjust(left=left / w, right=1 - right / w, bottom=bottom / h, top=1 - top / h,
                        wspace=wspace, hspace=hspace)


def decimate_minmax(y: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-column minimum and maximum of ``y``.

    Parameters
    ----------
    y : ndarray, (n,)
        Samples.
    columns : int
        Number of buckets (pixel columns).

    Returns
    -------
    start, lo, hi : ndarray
        Index of the first sample of each bucket and the bucket's min and max
        over its valid samples (NaN, a missing sample, is ignored; a bucket of
        missing samples only is NaN, so the plot shows a hole). With
        ``n <= columns`` every sample is its own bucket.
    """
    y = np.asarray(y, dtype=np.float64)
    n = len(y)
    if columns < 1:
        raise ImunoiseValueError(f"columns must be >= 1; got {columns}")
    if n <= columns:
        idx = np.arange(n)
        return idx, y.copy(), y.copy()
    start = (np.arange(columns, dtype=np.int64) * n) // columns
    start = np.unique(start)
    with np.errstate(invalid="ignore"):  # NaN (missing samples) only where a bucket is all NaN
        return start, np.fmin.reduceat(y, start), np.fmax.reduceat(y, start)


def _draw_series(ax, t0: float, fs: float, y: np.ndarray, color: str, columns: int) -> None:
    start, lo, hi = decimate_minmax(y, columns)
    t = t0 + start / fs
    if len(y) <= columns:
        ax.plot(t, y, color=color, linewidth=0.8)
        return
    # One vertical stroke per bucket, joined: a closed band from min to max.
    ax.fill_between(t, lo, hi, color=color, linewidth=0.6, edgecolor=color, step="post")


def time_series(
    y: np.ndarray | ImuLog,
    fs: float | None = None,
    *,
    channels: str | Sequence[str] | None = None,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
    columns: int = 1600,
    gaps: Sequence[tuple[float, float]] | None = None,
) -> Figure:
    """Time series, one panel per axis, min/max decimated, missing samples shaded.

    Parameters
    ----------
    y : ndarray, (n,) or (n, k), list of k arrays (n,), or ImuLog
        Samples of one sensor (a list: its columns, not stacked into a copy), or a
        log: then one column of panels per channel
        (titled with the channel and its unit), at the log's rate, with the log's
        longest :data:`SHADED_GAPS` gaps shaded.
    fs : float
        Sample rate in Hz of an array (the time axis is in seconds, minutes or
        hours by length); not given with a log.
    channels : str or sequence of str, optional
        With a log: the channels to draw (default every channel it has).
    title, unit : str
        Figure title and, for an array, the y-axis unit (a log's units are its
        channels'; its default title is its file name).
    names : sequence of str, optional
        Axis names of an array; default X, Y, Z (``value`` for one column).
    columns : int
        Buckets per panel (≈ pixel width of the saved figure).
    gaps : sequence of (start, duration), optional
        Missing samples, in seconds from the first sample, shaded on every panel
        (default: none for an array, the log's own for a log).
    """
    if isinstance(y, ImuLog):
        if fs is not None or unit or names is not None:
            given = [k for k, v in (("fs", fs), ("unit", unit), ("names", names)) if v]
            raise ImunoiseValueError(f"fs, unit and names must not be given with an ImuLog (it has "
                             f"its own); got {', '.join(given)}")
        log = y
        chosen = _log_channels(log, channels)
        blocks = [(name, _symbols(CHANNELS[name][1]), _channel_axes(name), getattr(log, name))
                  for name in chosen]
        source = "" if log.source.startswith("<") else _summary.source_name(log.source)
        if len(blocks) == 1:  # one sensor: the array layout, the channel in the title
            name = blocks[0][0]
            blocks = [("", *blocks[0][1:])]
            source = f"{name} ({source})" if source else name
        if gaps is None:
            gaps = [(a - log.gaps.t0, d) for a, d, _k in log.gaps.largest(SHADED_GAPS).rows()]
        return _series_figure(blocks, log.fs, title or source, columns, gaps)
    if channels is not None:
        raise ImunoiseValueError(f"channels must be None for an array (it picks channels of an "
                         f"ImuLog); got {channels!r}")
    if fs is None:
        raise ImunoiseValueError("fs must be given for an array (the sample rate, Hz); got None")
    if isinstance(y, list) and all(isinstance(c, np.ndarray) and c.ndim == 1 for c in y):
        if len({len(c) for c in y}) > 1:
            raise ImunoiseValueError(f"y's columns must have one length; got {[len(c) for c in y]}")
        k = len(y)
    else:
        y = np.asarray(y, dtype=np.float64).reshape(len(y), -1)
        k = y.shape[1]
    names = list(names) if names is not None else axis_names(k)
    return _series_figure([("", unit, names, y)], fs, title, columns, gaps or ())


def _channel_axes(channel: str) -> list[str]:
    """Panel labels of a log channel's columns (yaw, pitch, roll for ``ypr``)."""
    if channel == "ypr":
        return list(ATTITUDE_NAMES)
    return axis_names(CHANNELS[channel][0])


def _log_channels(log: ImuLog, channels: str | Sequence[str] | None) -> list[str]:
    """The channels of ``log`` to draw, checked."""
    if channels is None:
        if not log.channels:
            raise ImunoiseValueError(f"log must have a channel to plot; got none in {log.source}")
        return list(log.channels)
    chosen = [channels] if isinstance(channels, str) else list(channels)
    absent = [c for c in chosen if c not in log.channels]
    if absent or not chosen:
        raise ImunoiseValueError(f"channels must be among the log's {list(log.channels)}; got "
                         f"{chosen!r}")
    return chosen


def _series_figure(blocks, fs: float, title: str, columns: int, gaps) -> Figure:
    """One column of panels per block ``(heading, unit, axis names, (n,) or (n, k))``;
    a block without a heading labels its panels ``name [unit]``."""
    new_figure = _plt()
    blocks = [(head, unit, names, _columns(v)) for head, unit, names, v in blocks]
    rows = max(len(v) for *_, v in blocks)
    n = len(blocks[0][3][0])
    duration = n / fs
    scale, tunit = (1.0, "s") if duration < 600 else (60.0, "min")
    if duration >= 3 * 3600:
        scale, tunit = 3600.0, "h"
    wide = len(blocks) > 1
    with style():
        size = (min(3.4 * len(blocks), 16.0), 1.5 * rows + 0.9) if wide else (9, 1.7 * rows + 0.6)
        fig = new_figure(figsize=size)
        grid = fig.subplots(rows, len(blocks), sharex=True, squeeze=False)
        for b, (head, unit, names, y) in enumerate(blocks):
            k = len(y)
            for j in range(k):
                ax = grid[j, b]
                _draw_series(ax, 0.0, fs * scale, y[j], AXIS_COLORS[j % 4], columns)
                for start, length in gaps:
                    # at least a visible sliver, however short the gap
                    width = max(length, duration / columns) / scale
                    ax.axvspan(start / scale, start / scale + width, color=GAP_COLOR,
                               alpha=0.35, linewidth=0)
                ax.set_ylabel(_label(names[j], unit))
                ax.margins(x=0)
            if head:
                grid[0, b].set_title(f"{head} [{unit}]" if unit else head)
            for ax in grid[k:, b]:
                ax.set_visible(False)
            grid[k - 1, b].tick_params(labelbottom=True)
            grid[k - 1, b].set_xlabel(f"time [{tunit}]")
        if wide:
            _margins(fig, left=0.9, bottom=0.45, top=0.45, wspace=0.45, hspace=0.2,
                     title=bool(title))
        else:
            _margins(fig, left=0.95, bottom=0.45, title=bool(title))
        if title:
            fig.suptitle(title)
    return plain_ticks(fig)


def _columns(v) -> list[np.ndarray]:
    """The columns of ``v``: (n,) or (n, k) samples, or a list of (n,) columns."""
    if isinstance(v, list):
        return [np.asarray(c, dtype=np.float64) for c in v]
    arr = np.asarray(v, dtype=np.float64).reshape(len(v), -1)
    return [arr[:, j] for j in range(arr.shape[1])]


def histograms(
    dists: Distribution | Sequence[Distribution],
    *,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
) -> Figure:
    """Histograms (as densities) with the fitted normal pdf, one panel per axis.

    The x axis is the distribution's range (its bulk, see
    :func:`imunoise.distribution`); samples beyond it are counted in the panel's
    upper corners ("← 3", "12 →"). Tick labels are plain numbers: where the values
    share leading digits the shared part goes into the axis label ("yaw + 134 [deg]"
    over "−0.05 0 0.05"; :func:`plain_ticks`), and fewer ticks are drawn when labels
    would touch.

    Parameters
    ----------
    dists : :class:`imunoise.stats.Distribution` or a sequence of them
        One per axis (:func:`imunoise.distribution` of each column).
    """
    new_figure = _plt()
    dists = [dists] if isinstance(dists, Distribution) else list(dists)
    wrong = [type(d).__name__ for d in dists if not isinstance(d, Distribution)]
    if wrong or not dists:
        raise ImunoiseTypeError(
            f"dists must be Distribution objects (imunoise.distribution of each "
                        f"axis); got {wrong or 'none'}")
    k = len(dists)
    names = list(names) if names is not None else axis_names(k)
    with style():
        fig = new_figure(figsize=(3.2 * k, 2.8))
        axes = fig.subplots(1, k, squeeze=False)[0]
        for j, (ax, d) in enumerate(zip(axes, dists, strict=True)):
            color = AXIS_COLORS[j % 4]
            ax.stairs(d.density(), d.edges, fill=True, color=color, alpha=0.45)
            x = np.linspace(d.edges[0], d.edges[-1], 400)
            if d.sigma > 0:
                ax.plot(x, d.pdf(x), color="k", linewidth=1.1, label="normal fit")
            ax.set_xlim(d.edges[0], d.edges[-1])
            ax.set_title(
                f"{names[j]}: μ = {rounded(d.mu, d.mu_std)}, σ = {rounded(d.sigma, d.sigma_std)}"
                f"\nskew {cell(d.skewness, digits=3)}, "
                f"ex. kurt {cell(d.excess_kurtosis, digits=3)}",
                fontsize=8,
            )
            for count, xpos, align, text in (
                    (d.off_scale_below, 0.01, "left", "← {}"),
                    (d.off_scale_above, 0.99, "right", "{} →")):
                if count:
                    ax.text(xpos, 0.98, text.format(count), transform=ax.transAxes,
                            ha=align, va="top", fontsize=7, color="0.3")
            ax.set_xlabel(_label(names[j], unit))
            ax.set_ylabel(_label("density", _per(unit)))  # each panel has its own scale
            ax.grid(False)
        _margins(fig, left=0.7, bottom=0.45, top=0.55, wspace=0.4, title=bool(title))
        if title:
            fig.suptitle(title)
        _readable_ticks(fig, axes)
    return fig


#: Most x ticks a histogram panel tries before dropping to fewer.
HIST_TICKS = 5


def _readable_ticks(fig, axes) -> None:
    """x tick labels that never touch: plain numbers (an offset the values share,
    "−134" of a yaw near −134°, goes into the axis label, :func:`plain_ticks`), then
    fewer ticks (down to two) until no two labels of a panel, or of neighbouring
    panels, overlap on the renderer."""
    from matplotlib.ticker import MaxNLocator

    for ax in axes:
        _plain_axis(ax.xaxis, offset_threshold=2)
        _plain_axis(ax.yaxis)
    renderer = _renderer(fig)
    for i, ax in enumerate(axes):
        for nbins in range(HIST_TICKS, 1, -1):
            ax.xaxis.set_major_locator(MaxNLocator(nbins=nbins, steps=[1, 2, 2.5, 5, 10]))
            if not _tick_labels_overlap(fig, list(axes[max(i - 1, 0): i + 1]), renderer):
                break


def plain_ticks(fig) -> Figure:
    """Tick labels without matplotlib's corner text, on every linear axis of ``fig``.

    Where matplotlib would write an offset in the axis's corner (an accelerometer's
    Z axis near −9.97 m/s² as "0.0 0.1" with "−10" apart) the offset moves into the
    axis label in the axis's own unit ("accel Z + 10 [m/s²]") and the ticks count
    from it; a scientific multiplier ("1e−5") is never used (plain decimals).
    Called by every figure function; idempotent. Returns ``fig``."""
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            _plain_axis(axis)
    return fig


def _plain_axis(axis, *, offset_threshold: int | None = None) -> None:
    """:func:`plain_ticks` for one axis (``offset_threshold``: matplotlib's
    ``axes.formatter.offset_threshold`` for deciding whether the values share
    leading digits; default its rc value, 4)."""
    import matplotlib
    from matplotlib.ticker import ScalarFormatter

    fmt = axis.get_major_formatter()
    if axis.get_scale() != "linear" or type(fmt) is not ScalarFormatter:
        return  # a log axis, a formatter of the figure's own, or one already plain
    rc = {} if offset_threshold is None else {
        "axes.formatter.offset_threshold": offset_threshold}
    with matplotlib.rc_context(rc):
        probe = ScalarFormatter(useOffset=True)
    probe.set_axis(axis)
    locs = [x for x in axis.get_majorticklocs() if np.isfinite(x)]
    probe.set_locs(locs)
    shift = float(probe.offset) if locs else 0.0
    axis.set_major_formatter(_Shifted(shift))
    label = axis.get_label_text()
    if shift and label:
        name, bracket, rest = label.partition(" [")
        sign = "−" if shift > 0 else "+"
        axis.set_label_text(f"{name} {sign} {abs(shift):.12g}{bracket}{rest}")


@cache
def _shifted_class():
    from matplotlib.ticker import ScalarFormatter

    class Shifted(ScalarFormatter):
        """Ticks counted from ``shift`` (written in the axis label), never an offset
        or a power of ten in the corner."""

        def __init__(self, shift: float = 0.0):
            super().__init__(useOffset=False)
            self.set_scientific(False)
            self.offset = shift

        def get_offset(self) -> str:
            return ""

    return Shifted


def _Shifted(shift: float = 0.0):  # noqa: N802 - a class made on first use (lazy matplotlib)
    return _shifted_class()(shift)


#: Pixels two neighbouring tick labels of an axis keep apart at the least.
TICK_GAP_PX = 4


def _renderer(fig):
    """The renderer ``fig`` is saved with (an Agg canvas is attached when it has none)."""
    if not hasattr(fig.canvas, "get_renderer"):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    return fig.canvas.get_renderer()


def _tick_labels_overlap(fig, axes, renderer=None) -> bool:
    """Whether any two visible x or y tick labels of ``axes`` (together) overlap on
    the renderer (the figure drawn as it would be saved)."""
    renderer = renderer or _renderer(fig)
    from matplotlib.transforms import Bbox

    boxes = []
    for ax in axes:
        for axis, (dx, dy) in ((ax.xaxis, (TICK_GAP_PX / 2, 0)), (ax.yaxis, (0, TICK_GAP_PX / 2))):
            # the ticks as drawn: the locator's positions within the view limits
            for tick in axis._update_ticks():
                if tick.label1.get_visible() and tick.label1.get_text():
                    x0, y0, x1, y1 = tick.label1.get_window_extent(renderer).extents
                    boxes.append(Bbox.from_extents(x0 - dx, y0 - dy, x1 + dx, y1 + dy))
    for a in range(len(boxes)):
        for b in range(a + 1, len(boxes)):
            if boxes[a].overlaps(boxes[b]):
                return True
    return False


def _coefficient_curves(coeffs: Mapping[str, float], grid: np.ndarray) -> dict[str, np.ndarray]:
    """Deviation of each IEEE term of hand-given coefficients and their total at
    ``grid``, by :func:`imunoise.noise.model_variance` (the model's one formula)."""
    out = {t: np.sqrt(model_variance(grid, **{t: coeffs.get(t, 0.0)})) for t in TERMS}
    out["total"] = np.sqrt(model_variance(grid, **{t: coeffs.get(t, 0.0) for t in TERMS}))
    return out


def _model_curves(model: NoiseModel, grid: np.ndarray, channel: int) -> dict[str, np.ndarray]:
    """Deviation of each term of a fitted model and its total at ``grid`` (the white
    term through the model's output filter)."""
    pred = model.predict(grid)
    out = {name: np.reshape(v, (grid.size, -1))[:, channel] for name, v in pred.terms.items()}
    out["total"] = np.reshape(pred.dev, (grid.size, -1))[:, channel]
    return out


def _tone_envelope(model: NoiseModel, grid: np.ndarray, channel: int,
                   curve: np.ndarray) -> np.ndarray:
    """The tones' Allan deviation drawn without its comb of zeros at whole periods
    (which drew spikes across the panel): each tone's own curve up to its first
    peak (below one period, ≈ 0.37/f0), its upper envelope beyond — the sampled form
    2·(A²/2)·sin⁴(πνm)/(m² sin²πν) with sin⁴ → 1, A/(m·|sin πν|), ν = f0/fs,
    m = τ·fs, capped at the peak — and the tones' variances added."""
    tones = _typed.pairs(model.terms[channel], _typed.Tone, "amplitude", "freq")
    if not tones:
        return curve
    fs = float(model.fs)
    total = np.zeros_like(grid)
    for amplitude, f0 in tones:
        own = np.sqrt(term_variances(grid, fs, np.zeros(len(TERMS)), tone=[(amplitude, f0)])
                      [:, len(TERMS)])
        envelope = amplitude / (grid * fs * abs(np.sin(np.pi * f0 / fs)))
        first = grid <= 1.0 / f0
        if not first.any():
            total += envelope**2
            continue
        peak = int(np.argmax(np.where(first, own, -np.inf)))
        drawn = np.where(np.arange(grid.size) <= peak, own, np.minimum(envelope, own[peak]))
        total += drawn**2
    return np.sqrt(total)


def _data_floor(model: NoiseModel, channel: int) -> tuple[float, float] | None:
    """(τ, B) of the data's own read-off floor, or None where the curve has none."""
    tau = float(np.ravel(model.readoff["B"]["tau"])[channel])
    value = float(np.ravel(model.readoff["B"]["value"])[channel])
    return (tau, value) if np.isfinite(tau) and np.isfinite(value) else None


def _readoff_points(model: NoiseModel, channel: int) -> dict[str, float]:
    """The model's datasheet values N (τ = 1 s), K (τ = 3 s), B for the marks."""
    return {t: float(model.value(t)[channel]) for t in ("N", "K", "B")}


def allan(
    result: AllanResult,
    model: NoiseModel | None = None,
    *,
    coefficients: Sequence[Mapping[str, float]] | None = None,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
    residuals: bool = True,
) -> Figure:
    r"""Allan deviation of a sensor's axes on log-log axes, one panel per axis.

    Parameters
    ----------
    result : AllanResult
        1-D or 2-D result; the error bars are its ``ci_low``/``ci_high``.
    model : NoiseModel, optional
        A fit of ``result`` (:func:`imunoise.fit`). The model total and each of
        its terms are drawn (Gauss–Markov terms included), the datasheet
        read-off points of the model are marked — N at τ = 1 s, K at τ = 3 s and
        the floor :math:`B\sqrt{2\ln2/\pi}` (≈ 0.664 B) at the total's minimum —
        and, with ``residuals``, a panel below each axis shows data/model with the
        measured interval and the ±5 % band.
    coefficients : sequence of mapping, optional
        Instead of ``model``: per axis, IEEE coefficients ``{"Q", "N", "B", "K",
        "R"}`` in the result's units (no Gauss–Markov terms, no residuals).
    residuals : bool
        Draw the data/model panel when a model is given (default True).
    """
    new_figure = _plt()
    from matplotlib.ticker import NullFormatter

    if not isinstance(result, AllanResult):
        raise ImunoiseTypeError(
            f"result must be an AllanResult (imunoise.adev and its family); got "
                        f"{type(result).__name__}")
    if model is not None and not isinstance(model, NoiseModel):
        raise ImunoiseTypeError(f"model must be a NoiseModel (imunoise.fit) or None; got "
                        f"{type(model).__name__} (per-axis coefficients go in coefficients=)")
    if model is not None and coefficients is not None:
        raise ImunoiseValueError("model and coefficients must not both be given; got both")
    taus = np.asarray(result.taus, dtype=np.float64)
    dev = np.asarray(result.dev, dtype=np.float64).reshape(len(taus), -1)
    if model is not None and model.channels != dev.shape[1]:
        raise ImunoiseValueError(f"model must have the {dev.shape[1]} channel(s) of result; got "
                         f"{model.channels}")
    if coefficients is not None and len(coefficients) != dev.shape[1]:
        raise ImunoiseValueError(f"coefficients must have one mapping per channel of result "
                         f"({dev.shape[1]}); got {len(coefficients)}")
    lo = np.asarray(result.ci_low, dtype=np.float64).reshape(dev.shape)
    hi = np.asarray(result.ci_high, dtype=np.float64).reshape(dev.shape)
    k = dev.shape[1]
    names = list(names) if names is not None else axis_names(k)
    kind = getattr(result, "kind", "adev").upper()
    grid = np.geomspace(taus[0], taus[-1], 200)
    show_res = model is not None and residuals
    with style():
        fig = new_figure(figsize=(3.6 * k, 3.9 + (1.3 if show_res else 0.0)))
        if show_res:
            gs = fig.add_gridspec(2, k, height_ratios=(3, 1), hspace=0.08)
            axes = [fig.add_subplot(gs[0, j]) for j in range(k)]
            res_axes = [fig.add_subplot(gs[1, j], sharex=axes[j]) for j in range(k)]
            for ax, res in zip(axes[1:], res_axes[1:], strict=True):
                ax.sharey(axes[0])
                res.sharey(res_axes[0])
                ax.tick_params(labelleft=False)
                res.tick_params(labelleft=False)
        else:
            axes = list(fig.subplots(1, k, squeeze=False, sharey=True)[0])
            res_axes = []
        lims: list[tuple[float, float]] = []
        for j, ax in enumerate(axes):
            color = AXIS_COLORS[j % 4]
            yerr = np.vstack([dev[:, j] - lo[:, j], hi[:, j] - dev[:, j]])
            ax.errorbar(
                taus, dev[:, j], yerr=yerr, fmt="o", ms=2.5, color=color,
                elinewidth=0.8, capsize=1.5,
                label=f"{kind} ({percent(result.confidence, digits=1)} CI)",
            )
            marks: dict[str, float] = {}
            if model is not None:
                curves = _model_curves(model, grid, j)
                marks = _readoff_points(model, j)
            elif coefficients is not None:
                curves = _coefficient_curves(coefficients[j], grid)
                c = coefficients[j]
                marks = {t: c.get(t, 0.0) for t in ("N", "K", "B")}
            if model is not None or coefficients is not None:
                ax.plot(grid, curves["total"], color="k", linewidth=1.2, label="model")
                for term, (label, ls) in TERM_STYLES.items():
                    if term in curves and np.any(curves[term] > 0):
                        ax.plot(grid, curves[term], color="0.45", linestyle=ls,
                                linewidth=0.9, label=f"{label}")
                for g, ls in (("GM1", (0, (1, 1))), ("GM2", (0, (3, 1, 1, 1))),
                              ("GM3", (0, (5, 2)))):
                    if g in curves and np.any(curves[g] > 0):
                        ax.plot(grid, curves[g], color="tab:brown", linestyle=ls,
                                linewidth=0.9, label="Gauss–Markov bias")
                if "sine" in curves and np.any(curves["sine"] > 0):
                    if model is not None:
                        tone = _tone_envelope(model, grid, j, curves["sine"])
                        label = "tone (envelope)"
                    else:  # zeros at whole periods: masked on the log axis
                        tone, label = np.where(curves["sine"] > 0, curves["sine"], np.nan), "tone"
                    ax.plot(grid, tone, color="tab:olive", linewidth=0.9, label=label)
                if "resonance" in curves and np.any(curves["resonance"] > 0):
                    band = np.where(curves["resonance"] > 0, curves["resonance"], np.nan)
                    ax.plot(grid, band, color="tab:cyan", linewidth=0.9, label="resonance")
                if "motion" in curves and np.any(curves["motion"] > 0):
                    rocking = np.where(curves["motion"] > 0, curves["motion"], np.nan)
                    ax.plot(grid, rocking, color="tab:brown", linewidth=0.9, linestyle="-.",
                            label="bounded motion (mount)")
                drawn = {*TERM_STYLES, "GM1", "GM2", "GM3", "sine", "resonance", "motion",
                         "total"}
                for name in (n for n in curves if n not in drawn):  # a kind named by its curve
                    if np.any(curves[name] > 0):
                        ax.plot(grid, np.where(curves[name] > 0, curves[name], np.nan),
                                color="0.3", linewidth=0.9, linestyle=(0, (2, 2)), label=name)
                if marks.get("N", 0.0) > 0:
                    ax.plot([1.0], [marks["N"]], marker="s", color="crimson", ms=5,
                            linestyle="none", label="N at τ=1 s")
                if marks.get("K", 0.0) > 0:
                    ax.plot([3.0], [marks["K"]], marker="^", color="purple", ms=5,
                            linestyle="none", label="K at τ=3 s")
                if marks.get("B", 0.0) > 0:
                    # where model.B is read: the model's floor over the fitted taus
                    # (beyond them a model without a walk keeps falling)
                    fitted = (grid >= taus[0]) & (grid <= taus[-1]) if model is None else (
                        (grid >= model.taus[0]) & (grid <= model.taus[-1]))
                    floor = model.floor(j) if model is not None else None
                    at = floor[0] if floor is not None else grid[int(np.argmin(
                        np.where(fitted, curves["total"], np.inf)))]
                    ax.plot([at], [marks["B"] * FLICKER], marker="D",
                            color="darkgreen", ms=5, linestyle="none",
                            label="B·0.664 floor")
                read = _data_floor(model, j) if model is not None else None
                if read is not None:
                    ax.plot([read[0]], [read[1] * FLICKER], marker="D", mfc="none",
                            color="darkgreen", ms=7, linestyle="none",
                            label="data's floor (read-off B)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            if not show_res:
                ax.set_xlabel("τ [s]")
            ax.set_title(names[j])
            ax.grid(True, which="both", alpha=0.25)
            # a statistic without an interval (MTIE, TIE rms) is scaled by its curve
            low = np.where(np.isfinite(lo[:, j]), lo[:, j], dev[:, j])
            high = np.where(np.isfinite(hi[:, j]), hi[:, j], dev[:, j])
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN channel
                ymin = np.nanmin(np.where(low > 0, low, np.nan))
                ymax = np.nanmax(high)
            shown = [marks.get(t, 0.0) for t in ("N", "K")]
            shown = [v for v in shown if v > 0]
            if shown:  # keep the read-off points (N at 1 s, K at 3 s) inside the axes
                ymin = min(ymin, min(shown) / 1.5)
                ymax = max(ymax, max(shown) * 1.5)
            ax.yaxis.set_minor_formatter(NullFormatter())
            lims.append((ymin, ymax))
        spans: list[float] = []
        for j, ax in enumerate(res_axes):
            pred = np.reshape(model.predict(taus).dev, dev.shape)[:, j]
            ratio = dev[:, j] / pred
            ax.axhspan(0.95, 1.05, color="0.88", zorder=0, label="±5 %")
            ax.axhline(1.0, color="k", linewidth=0.8)
            ax.errorbar(taus, ratio, yerr=np.vstack([(dev[:, j] - lo[:, j]) / pred,
                                                     (hi[:, j] - dev[:, j]) / pred]),
                        fmt="o", ms=2, color=AXIS_COLORS[j % 4], elinewidth=0.6)
            ax.set_xscale("log")
            ax.set_xlabel("τ [s]")
            ax.grid(True, which="both", alpha=0.25)
            finite = ratio[np.isfinite(ratio)]
            spans.append(max(0.1, float(np.max(np.abs(finite - 1)))) if finite.size else 0.1)
            cover = np.atleast_1d(model.coverage)[j]
            ax.text(0.02, 0.06, f"follows {percent(cover)} of taus", transform=ax.transAxes,
                    fontsize=7)
            if j == 0:
                ax.set_ylabel("data/model\n[ratio]")
            axes[j].tick_params(labelbottom=False)
        if spans:
            span = min(max(spans), 0.9)  # shared by the residual panels
            res_axes[0].set_ylim(1 - 1.15 * span, 1 + 1.15 * span)
        ymin = np.nanmin([a for a, _ in lims])
        ymax = np.nanmax([b for _, b in lims])
        if np.isfinite(ymin) and np.isfinite(ymax) and ymin > 0:
            axes[0].set_ylim(ymin / 1.5, ymax * 1.5)  # shared by all panels
        axes[0].set_ylabel(_label("σ(τ)", unit))
        seen: dict[str, object] = {}
        for ax in axes:
            for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
                seen.setdefault(lab, h)
        labels, handles = list(seen), list(seen.values())
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 5),
                   bbox_to_anchor=(0.5, 0.0))
        rows = -(-len(labels) // 5)
        _margins(fig, left=0.85, bottom=0.55 + 0.22 * rows, top=0.3, wspace=0.08,
                 title=bool(title))
        if title:
            fig.suptitle(title)
    return fig


def save(fig: Figure, path, *, formats: Sequence[str] = ("png", "svg")) -> list[Path]:
    """Save ``fig`` as ``path.<fmt>`` for each format; returns the paths written."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    written = []
    with style():
        for fmt in formats:
            out = path.with_suffix(f".{fmt}")
            with _atomic.replacing(out) as fh:
                fig.savefig(fh, format=fmt)
            written.append(out)
    return written


# -- spectrum and dynamic ADEV (imunoise.spectrum, imunoise.dynamic) -------------------


def spectrum(
    result: Spectrum,
    model: NoiseModel | None = None,
    *,
    amplitude: bool = False,
    bins_per_decade: int = 20,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
) -> Figure:
    """One-sided PSD (or ASD with ``amplitude``), log-binned, one panel per axis: the
    ``confidence`` band, the white band the N read-off used (shaded) with its level
    2N² and the value of N, and ``model``'s PSD (:func:`imunoise.spectrum.model_psd`,
    total and terms, its resonance included) with its reported tones marked at their
    frequencies, when given."""
    from imunoise.spectrum import Spectrum, model_psd_terms

    new_figure = _plt()
    if not isinstance(result, Spectrum):
        raise ImunoiseTypeError(
            f"result must be a Spectrum (imunoise.psd); got {type(result).__name__}")
    if model is not None and not isinstance(model, NoiseModel):
        raise ImunoiseTypeError(f"model must be a NoiseModel (imunoise.fit) or None; got "
                        f"{type(model).__name__}")
    s = result.smooth(bins_per_decade)
    k = result.channels
    shape = (len(s.f), k)
    power = 0.5 if amplitude else 1.0
    p, lo, hi = (np.reshape(a, shape) ** power for a in (s.psd, s.ci_low, s.ci_high))
    white_n = np.atleast_1d(result.N)
    white_std = np.atleast_1d(result.N_std)
    bands = np.reshape(result.band, (k, 2))
    terms = model_psd_terms(model, s.f) if model is not None else {}
    names = list(names) if names is not None else axis_names(k)
    unit = unit or INPUT_UNIT
    level_unit = f"{unit}/√Hz" if amplitude else f"({unit})²/Hz"
    with style():
        fig = new_figure(figsize=(min(3.6 * k, 14.0), 3.4))
        axes = np.atleast_1d(fig.subplots(1, k, sharey=True))
        for j, ax in enumerate(axes):
            color = AXIS_COLORS[j % 4]
            ax.fill_between(s.f, lo[:, j], hi[:, j], color=color, alpha=0.25, linewidth=0)
            ax.loglog(s.f, p[:, j], color=color, label="PSD" if not amplitude else "ASD")
            ax.axvspan(*bands[j], color="0.85", alpha=0.5, linewidth=0, label="white band")
            level = (2 * white_n[j] ** 2) ** power
            value = f"N = {format_value(white_n[j], white_std[j])} {unit}/√Hz"
            ax.plot(bands[j], [level, level], color="k", linewidth=1.6,
                    label="N read-off (level 2N²)")
            ax.text(0.03, 0.04, value, transform=ax.transAxes, fontsize=7,
                    bbox={"facecolor": "white", "alpha": 0.8, "linewidth": 0, "pad": 1})
            for k, line in enumerate(result.lines[j]):
                ax.axvline(line, color="0.3", linestyle=":", linewidth=0.8,
                           label="line (left out)" if k == 0 else None)
            if terms:
                total = sum(np.reshape(v, shape)[:, j] for v in terms.values())
                ax.loglog(s.f, total ** power, color="k", linestyle="-", linewidth=0.8,
                          alpha=0.7, label="model")
                for name, values in terms.items():
                    text, dash = TERM_STYLES.get(name, (name, (0, (2, 2))))
                    ax.loglog(s.f, np.reshape(values, shape)[:, j] ** power, color="0.4",
                              linestyle=dash, linewidth=0.8, label=text)
            if model is not None:
                # the model's tones are lines, no density: marked where reported
                shown_lines = [line for line in model.lines[j] if line.reported]
                for k, line in enumerate(shown_lines):
                    ax.axvline(line.frequency, color="tab:olive", linewidth=1.0,
                               label="model's line (tone)" if k == 0 else None)
            ax.set_title(names[j])
            ax.set_xlabel("frequency [Hz]")
        # the panels share y: one range holding every panel's spectrum and band (a
        # line's peak included; the model's terms may leave it below)
        shown = np.concatenate([lo[lo > 0], hi[np.isfinite(hi)], p[np.isfinite(p)]])
        if shown.size:
            axes[0].set_ylim(np.min(shown) / 3, np.max(shown) * 3)
        axes[0].set_ylabel(("ASD " if amplitude else "PSD ") + f"[{level_unit}]")
        if title:
            fig.suptitle(title)
        rows = _shared_legend(fig, axes, per_row=4)
        fig.set_size_inches(fig.get_size_inches()[0], 3.0 + 0.2 * rows)
        _margins(fig, bottom=0.5 + 0.2 * rows, title=bool(title))
    return fig


def _shared_legend(fig, axes, *, per_row: int) -> int:
    """One legend for the figure, below its panels: each label once (the first panel
    to draw it gives its handle), ``per_row`` to a row. Returns the rows it takes.
    A legend inside a small panel covers its data."""
    seen: dict[str, object] = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(lab, h)
    if not seen:
        return 0
    fig.legend(list(seen.values()), list(seen), loc="lower center",
               ncol=min(len(seen), per_row), bbox_to_anchor=(0.5, 0.0))
    return -(-len(seen) // per_row)


def dynamic(
    result: DynamicAllan,
    *,
    title: str = "",
    names: Sequence[str] | None = None,
    limit: float = 4.0,
) -> Figure:
    """Dynamic Allan deviation as a heat map, one panel per axis: time (window centre)
    across, tau up, colour the window's ADEV over the whole-record ADEV on a log scale
    (1 white, noisier red, quieter blue, clipped at ``limit`` and 1/``limit``); the
    stationarity summary's departures are marked above each panel."""
    import matplotlib
    from matplotlib.colors import LogNorm

    from imunoise.dynamic import DynamicAllan

    new_figure = _plt()
    if not isinstance(result, DynamicAllan):
        raise ImunoiseTypeError(f"result must be a DynamicAllan (imunoise.dynamic_adev); got "
                        f"{type(result).__name__}")
    if not (isinstance(limit, (int, float)) and limit > 1):
        raise ImunoiseValueError(f"limit must be a number > 1; got {limit!r}")
    k = result.channels
    ratio = np.reshape(result.ratio, (len(result.times), len(result.taus), k))
    names = list(names) if names is not None else axis_names(k)
    span = result.times[-1] + result.window / 2
    scale, tunit = (1.0, "s") if span < 600 else (60.0, "min")
    if span >= 3 * 3600:
        scale, tunit = 3600.0, "h"
    t_edges = _edges(result.times, result.step) / scale
    tau_edges = np.sqrt(result.taus[:-1] * result.taus[1:]) if len(result.taus) > 1 else None
    tau_edges = (np.r_[result.taus[0] / 1.4, tau_edges, result.taus[-1] * 1.4]
                 if tau_edges is not None else np.r_[result.taus[0] / 1.4, result.taus[0] * 1.4])
    departures = result.stationarity.intervals
    with style():
        fig = new_figure(figsize=(min(3.8 * k, 14.0), 3.2))
        axes = np.atleast_1d(fig.subplots(1, k, sharey=True))
        norm = LogNorm(vmin=1 / limit, vmax=limit)
        cmap = matplotlib.colormaps["RdBu_r"].with_extremes(bad=NO_ESTIMATE)
        for j, ax in enumerate(axes):
            mesh = ax.pcolormesh(t_edges, tau_edges, np.clip(ratio[:, :, j], 1 / limit, limit).T,
                                 cmap=cmap, norm=norm, shading="flat")
            if not np.isfinite(ratio[:, :, j]).all():  # a proxy: the legend names the grey
                ax.fill_between([], [], color=NO_ESTIMATE,
                                label="no estimate (too few terms in the window)")
            ax.set_yscale("log")
            ax.grid(False)
            for d in departures:
                if d.channel == j:  # a bar above the map, not a cell of it
                    ax.axvspan(d.start / scale, d.end / scale, ymin=1.02, ymax=1.07,
                               color="k", linewidth=0, clip_on=False,
                               label="departs from its typical level (bar above the map)")
            ax.set_xlim(0, result.n_samples / result.fs / scale)  # the record's time
            ax.set_title(names[j], pad=14)
            ax.set_xlabel(f"window centre [{tunit}]")
        axes[0].set_ylabel("τ [s]")
        rows = _shared_legend(fig, axes, per_row=1)
        fig.set_size_inches(fig.get_size_inches()[0], 3.2 + 0.2 * rows)
        _margins(fig, right=0.9, bottom=0.5 + 0.2 * rows, top=0.45, title=bool(title))
        bar = fig.colorbar(mesh, ax=list(axes), pad=0.02, fraction=0.04)
        bar.set_label("ADEV / whole-record ADEV [ratio]")
        ticks = [v for v in (0.25, 0.5, 1.0, 2.0, 4.0, 8.0) if 1 / limit <= v <= limit]
        bar.set_ticks(ticks, labels=[f"{v:g}" for v in ticks])
        bar.minorticks_off()
        if title:
            fig.suptitle(title)
    return fig


#: Colour of a dynamic-ADEV cell without an estimate (white would read as ratio 1).
NO_ESTIMATE = "0.72"


def _edges(centres: np.ndarray, step: float) -> np.ndarray:
    """Cell edges around evenly spaced centres."""
    return np.r_[centres - step / 2, centres[-1] + step / 2]


# --- events, warm-up and temperature (issue 13) -------------------------------------

#: Shading of detected events on time plots.
EVENT_COLOR = "#9467bd"
#: Events whose peak (σ) :func:`events` writes on the first panel (the largest).
EVENT_LABELS = 12


def events(y, found, fs: float | None = None, *, title: str = "", unit: str = "",
           names: Sequence[str] | None = None, columns: int = 1600) -> Figure:
    """Time series with the events of :func:`imunoise.events` shaded (purple) on
    every panel and the peak (in sigmas) of the :data:`EVENT_LABELS` largest written at
    their start.

    ``y`` is an array (n,) or (n, k) with its ``fs``, or an ImuLog (then its
    channels searched by ``found``, gyro and accel, are drawn).
    """
    if isinstance(y, ImuLog):
        sensors = [s for s in ("gyro", "accel") if getattr(y, s) is not None
                   and any(n.startswith(s) for n in found.names)]
        fig = time_series(y, channels=sensors, title=title, columns=columns)
    else:
        fig = time_series(y, fs if fs is not None else found.fs, title=title, unit=unit,
                          names=names, columns=columns)
    duration = found.n_samples / found.fs
    scale = 1.0 if duration < 600 else 60.0 if duration < 3 * 3600 else 3600.0
    width = duration / columns
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for a, b in zip(found.start, found.end, strict=True):
            ax.axvspan(a / scale, (a + max(b - a, width)) / scale, color=EVENT_COLOR,
                       alpha=0.3, linewidth=0)
    _peak_labels(fig, fig.axes[0], found, scale)
    return fig


def _peak_labels(fig, ax, found, scale: float) -> None:
    """The peak (σ) of the :data:`EVENT_LABELS` largest events at their start, inside
    ``ax``; a label that would touch one already written (a larger event's) is left
    out: the report's events table gives every peak."""
    renderer = _renderer(fig)
    placed = []
    for i in np.argsort(found.peak)[::-1]:
        if len(placed) == EVENT_LABELS:
            break
        x = found.start[i] / scale
        lo, hi = ax.get_xlim()
        # written from the event's start, rightwards (leftwards near the right edge)
        text = ax.annotate(f"{found.peak[i]:.0f}σ", (x, 0.97),
                           xycoords=("data", "axes fraction"), fontsize=6,
                           color=EVENT_COLOR, va="top",
                           ha="right" if x > lo + 0.93 * (hi - lo) else "left")
        x0, y0, x1, y1 = text.get_window_extent(renderer).extents
        box = (x0 - TICK_GAP_PX, x1 + TICK_GAP_PX)
        if any(box[0] < b and a < box[1] for a, b in placed):
            text.remove()
        else:
            placed.append(box)


def warmup(result, *, title: str = "", unit: str = "") -> Figure:
    """Moving-average bias of each channel over the whole log with the fitted
    exponential transient and the settle point (dashed line; the part before it
    shaded), and the temperature under them when the log has it."""
    new_figure = _plt()
    k = len(result.names)
    rows = k + (result.temperature is not None)
    scale, tunit = (60.0, "min") if result.time[-1] < 3 * 3600 else (3600.0, "h")
    t = result.time / scale
    fitted = result.fitted()
    with style():
        fig = new_figure(figsize=(9, 1.45 * rows + 0.7))
        axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
        for j, name in enumerate(result.names):
            ax = axes[j]
            ax.plot(t, result.bias[:, j], color=AXIS_COLORS[j % 3], linewidth=0.9,
                    label=f"{_summary.number(result.block)} s mean")
            if result.significant[j]:
                ax.plot(t, fitted[:, j], color="k", linewidth=0.8, linestyle="--",
                        label=f"τ {_summary.duration(result.tau[j])}")
                ax.legend(loc="upper right")
            ax.set_ylabel(_label(name, unit or _channel_unit(name)))
        if result.temperature is not None:
            axes[-1].plot(t, result.temperature, color="#d62728", linewidth=0.9)
            axes[-1].set_ylabel("temperature [°C]")
        for ax in axes:
            if result.settle > 0:
                ax.axvspan(0, result.settle / scale, color="0.85", linewidth=0)
                ax.axvline(result.settle / scale, color="k", linewidth=0.8, linestyle=":")
            ax.margins(x=0)
        axes[-1].set_xlabel(f"time [{tunit}]")
        where = (f"settled at {_summary.duration(result.settle)}" if result.settle > 0
                 else "no warm-up transient")
        fig.suptitle(title or f"Bias over time: {where}")
        _margins(fig, left=1.0, bottom=0.45, title=True)
    return plain_ticks(fig)


def thermal(result, *, title: str = "") -> Figure:
    """Block-mean bias against block-mean temperature per channel, with the fit and
    its slope in datasheet units."""
    new_figure = _plt()
    k = len(result.names)
    cols = min(k, 3)
    rows = -(-k // cols)
    slope, slope_std, units = result.datasheet(1)
    order = np.argsort(result.block_temperature)
    grid_t = np.linspace(*result.temperature_range, 100)
    curve = result.predict(grid_t)
    with style():
        fig = new_figure(figsize=(3.3 * cols, 2.4 * rows + 0.6))
        axes = fig.subplots(rows, cols, squeeze=False)
        for j, name in enumerate(result.names):
            ax = axes[j // cols, j % cols]
            ax.plot(result.block_temperature[order], result.block_bias[order, j], ".",
                    color=AXIS_COLORS[j % 3], markersize=2.5)
            ax.plot(grid_t, curve[:, j], color="k", linewidth=1.0,
                    label=f"{slope[j]:.3g} ± {slope_std[j]:.2g} {units[j]}")
            ax.set_title(name)
            ax.set_xlabel("temperature [°C]")
            ax.set_ylabel(_label("bias", _channel_unit(name)))
            ax.legend(loc="best")
        for j in range(k, rows * cols):
            axes[j // cols, j % cols].set_visible(False)
        fig.suptitle(title or "Bias against temperature")
        _margins(fig, left=0.8, bottom=0.5, top=0.3, wspace=0.45, hspace=0.6, title=True)
    return plain_ticks(fig)


def compensation(before: AllanResult, after: AllanResult, *, title: str = "",
                 unit: str = "") -> Figure:
    """Allan deviation per axis before (solid) and after (dashed) a correction, e.g.
    the temperature compensation of :func:`imunoise.thermal`."""
    from matplotlib.ticker import NullFormatter

    new_figure = _plt()
    b = np.asarray(before.dev).reshape(len(before.taus), -1)
    a = np.asarray(after.dev).reshape(len(after.taus), -1)
    names = axis_names(b.shape[1])
    with style():
        fig = new_figure(figsize=(6.5, 4.2))
        ax = fig.subplots()
        for j, name in enumerate(names):
            color = AXIS_COLORS[j % 4]
            ax.loglog(before.taus, b[:, j], color=color, label=f"{name} before")
            ax.loglog(after.taus, a[:, j], color=color, linestyle="--", label=f"{name} after")
        ax.set_xlabel("τ [s]")
        ax.set_ylabel(_label("σ(τ)", unit))
        # decades only, as plot.allan labels them: matplotlib labels the minor ticks
        # ("6 × 10⁻⁴") of an axis that spans under two decades (kept where no decade
        # falls inside the axis, which would then have no label at all)
        low, high = ax.get_ylim()
        if np.floor(np.log10(high)) >= np.ceil(np.log10(low)):
            ax.yaxis.set_minor_formatter(NullFormatter())
        ax.legend(ncol=2)
        fig.suptitle(title or "Allan deviation before and after compensation")
        _margins(fig, left=0.9, bottom=0.5, title=True)
    return plain_ticks(fig)


#: Colours of the logs in :func:`own_noise` (one per sensor).
LOG_COLORS = ("#1f77b4", "#d62728", "#2ca02c")


def own_noise(result: OwnNoise, *, title: str = "", unit: str = "",
              names: Sequence[str] | None = None) -> Figure:
    """Each sensor's own deviation (markers, error bars) beside its plain one (line),
    one panel per axis, a colour per log (:func:`imunoise.own_noise`).

    Where a sensor's own variance is negative the upper end of its interval is
    drawn as an open downward triangle (an upper bound), never left out.
    """
    new_figure = _plt()
    if not hasattr(result, "own") or not hasattr(result, "plain"):
        raise ImunoiseTypeError(f"result must be an OwnNoise (imunoise.own_noise); got "
                                f"{type(result).__name__}")
    taus = np.asarray(result.taus, dtype=np.float64)
    k = result.own[0].channels
    names = list(names) if names is not None else [
        _summary.source_name(log.source) for log in result.aligned]
    with style():
        fig = new_figure(figsize=(3.6 * k, 4.2))
        axes = list(fig.subplots(1, k, squeeze=False, sharey=True)[0])
        for i, (own, plain) in enumerate(zip(result.own, result.plain, strict=True)):
            color = LOG_COLORS[i % len(LOG_COLORS)]
            dev = np.asarray(own.dev, dtype=np.float64).reshape(len(taus), -1)
            lo = np.asarray(own.ci_low, dtype=np.float64).reshape(dev.shape)
            hi = np.asarray(own.ci_high, dtype=np.float64).reshape(dev.shape)
            base = np.asarray(plain.dev, dtype=np.float64).reshape(dev.shape)
            below = np.asarray(result.negative[i]).reshape(dev.shape)
            for j, ax in enumerate(axes):
                ax.loglog(taus, base[:, j], color=color, linewidth=1.0, alpha=0.7,
                          label=f"{names[i]} plain")
                ok = ~below[:, j]
                yerr = np.vstack([dev[ok, j] - lo[ok, j], hi[ok, j] - dev[ok, j]])
                # an unbounded end (EDF far below 1) draws no bar rather than failing
                yerr = np.where(np.isfinite(yerr), np.maximum(yerr, 0.0), 0.0)
                ax.errorbar(taus[ok], dev[ok, j], yerr=yerr, fmt="o", ms=3, color=color,
                            elinewidth=0.8, capsize=1.5, label=f"{names[i]} own")
                if below[:, j].any():
                    ax.plot(taus[~ok], hi[~ok, j], linestyle="none", marker="v", mfc="none",
                            color=color, ms=6, label=f"{names[i]} own < (negative variance)")
        # the curves set the range: an interval of an EDF far below 1 runs to 1e100
        values = np.concatenate([np.ravel(r.dev) for r in (*result.own, *result.plain)])
        values = values[np.isfinite(values) & (values > 0)]
        if values.size:
            axes[0].set_ylim(values.min() / 3.0, values.max() * 3.0)
        for ax, axis in zip(axes, axis_names(k), strict=True):
            ax.set_title(axis)
            ax.set_xlabel("τ [s]")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].set_ylabel(_label("σ(τ)", unit))
        seen: dict[str, object] = {}  # one entry per label over all panels
        for ax in axes:
            for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
                seen.setdefault(label, handle)
        fig.legend(list(seen.values()), list(seen), loc="lower center",
                   ncol=min(len(seen), 3), fontsize="small", frameon=False)
        fig.suptitle(title or f"{result.sensor}: own ({result.method}) and plain deviation")
        _margins(fig, left=0.8, bottom=0.6 + 0.22 * ((len(seen) + 2) // 3), title=True)
    return plain_ticks(fig)
