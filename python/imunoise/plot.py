r"""Figures of a noise analysis, drawn with matplotlib's Agg backend (no display needed).

Every function returns a :class:`matplotlib.figure.Figure`; :func:`save` writes it
as PNG and SVG. One figure per sensor holds its three axes. Axis colours are the
same in every figure (X blue, Y orange, Z green).

Time series use min/max decimation: the samples are split into one bucket per
pixel column and each bucket is drawn as a vertical stroke from its minimum to
its maximum, so 10⁷ points draw in milliseconds and no spike disappears.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imunoise._schema import axis_names
from imunoise.noise import FLICKER, TERMS, NoiseModel, model_variance

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "AXIS_COLORS",
    "allan",
    "decimate_minmax",
    "histograms",
    "save",
    "style",
    "time_series",
]

AXIS_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd")
#: Shading of missing samples (gaps) on time plots.
GAP_COLOR = "#d62728"
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
        raise ValueError(f"columns must be >= 1; got {columns}")
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
    y: np.ndarray,
    fs: float,
    *,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
    columns: int = 1600,
    gaps: Sequence[tuple[float, float]] = (),
) -> Figure:
    """Time series of a sensor's axes, one panel per axis, min/max decimated.

    Parameters
    ----------
    y : ndarray, (n,) or (n, k)
        Samples.
    fs : float
        Sample rate in Hz (the time axis is in seconds, minutes or hours by length).
    title, unit : str
        Figure title and y-axis unit.
    names : sequence of str, optional
        Axis names; default X, Y, Z (``value`` for one column).
    columns : int
        Buckets per panel (≈ pixel width of the saved figure).
    gaps : sequence of (start, duration)
        Missing samples, in seconds from the first sample, shaded on every panel.
    """
    new_figure = _plt()
    y = np.asarray(y, dtype=np.float64).reshape(len(y), -1)
    k = y.shape[1]
    names = list(names) if names is not None else axis_names(k)
    duration = len(y) / fs
    scale, tunit = (1.0, "s") if duration < 600 else (60.0, "min")
    if duration >= 3 * 3600:
        scale, tunit = 3600.0, "h"
    with style():
        fig = new_figure(figsize=(9, 1.7 * k + 0.6))
        axes = fig.subplots(k, 1, sharex=True, squeeze=False)[:, 0]
        for j, ax in enumerate(axes):
            _draw_series(ax, 0.0, fs * scale, y[:, j], AXIS_COLORS[j % 4], columns)
            for start, length in gaps:
                # at least a visible sliver, however short the gap
                width = max(length, duration / columns) / scale
                ax.axvspan(start / scale, start / scale + width, color=GAP_COLOR, alpha=0.35,
                           linewidth=0)
            ax.set_ylabel(f"{names[j]} [{unit}]" if unit else names[j])
            ax.margins(x=0)
        axes[-1].set_xlabel(f"time [{tunit}]")
        _margins(fig, left=0.95, bottom=0.45, title=bool(title))
        if title:
            fig.suptitle(title)
    return fig


def histograms(
    dists: Sequence,
    *,
    title: str = "",
    unit: str = "",
    names: Sequence[str] | None = None,
) -> Figure:
    """Histograms (as densities) with the fitted normal pdf, one panel per axis.

    Parameters
    ----------
    dists : sequence of :class:`imunoise.stats.Distribution`
        One per axis.
    """
    new_figure = _plt()
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
            ax.set_title(
                f"{names[j]}: μ={d.mu:.4g}, σ={d.sigma:.3g}\n"
                f"skew {d.skewness:.2f}, ex. kurt {d.excess_kurtosis:.2f}",
                fontsize=8,
            )
            ax.set_xlabel(unit)
            ax.grid(False)
        axes[0].set_ylabel("density")
        _margins(fig, left=0.6, bottom=0.45, top=0.55, wspace=0.3, title=bool(title))
        if title:
            fig.suptitle(title)
    return fig


def _coefficient_curves(coeffs: Mapping[str, float], grid: np.ndarray) -> dict[str, np.ndarray]:
    """Deviation of each IEEE term of hand-given coefficients and their total at
    ``grid``, by :func:`imunoise.noise.model_variance` (the model's one formula)."""
    out = {t: np.sqrt(model_variance(grid, **{t: coeffs.get(t, 0.0)})) for t in TERMS}
    out["total"] = np.sqrt(model_variance(grid, **{t: coeffs.get(t, 0.0) for t in TERMS}))
    return out


def _model_curves(model: NoiseModel, grid: np.ndarray, channel: int) -> dict[str, np.ndarray]:
    """Deviation of each term of a fitted model and its total at ``grid``."""
    pred = model.predict(grid)
    out = {name: np.reshape(v, (grid.size, -1))[:, channel] for name, v in pred.terms.items()}
    out["total"] = np.reshape(pred.dev, (grid.size, -1))[:, channel]
    return out


def _readoff_points(model: NoiseModel, channel: int) -> dict[str, float]:
    """The model's datasheet equivalents N (τ = 1 s), K (τ = 3 s), B for the marks."""
    return {t: float(np.atleast_1d(model.equivalent(t))[channel]) for t in ("N", "K", "B")}


def allan(
    result,
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

    taus = np.asarray(result.taus, dtype=np.float64)
    dev = np.asarray(result.dev, dtype=np.float64).reshape(len(taus), -1)
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
                elinewidth=0.8, capsize=1.5, label=f"{kind} ({result.confidence:.1%} CI)",
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
                for g, ls in (("GM1", (0, (1, 1))), ("GM2", (0, (3, 1, 1, 1)))):
                    if g in curves and np.any(curves[g] > 0):
                        ax.plot(grid, curves[g], color="tab:brown", linestyle=ls,
                                linewidth=0.9, label="Gauss–Markov bias")
                if marks.get("N", 0.0) > 0:
                    ax.plot([1.0], [marks["N"]], marker="s", color="crimson", ms=5,
                            linestyle="none", label="N at τ=1 s")
                if marks.get("K", 0.0) > 0:
                    ax.plot([3.0], [marks["K"]], marker="^", color="purple", ms=5,
                            linestyle="none", label="K at τ=3 s")
                if marks.get("B", 0.0) > 0:
                    imin = int(np.argmin(curves["total"]))
                    ax.plot([grid[imin]], [marks["B"] * FLICKER], marker="D",
                            color="darkgreen", ms=5, linestyle="none",
                            label="B·0.664 floor")
            ax.set_xscale("log")
            ax.set_yscale("log")
            if not show_res:
                ax.set_xlabel("τ [s]")
            ax.set_title(names[j])
            ax.grid(True, which="both", alpha=0.25)
            ymin = np.nanmin(np.where(lo[:, j] > 0, lo[:, j], np.nan))
            ymax = np.nanmax(hi[:, j])
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
            ax.text(0.02, 0.06, f"follows {cover:.0%} of taus", transform=ax.transAxes,
                    fontsize=7)
            if j == 0:
                ax.set_ylabel("data/model")
            axes[j].tick_params(labelbottom=False)
        if spans:
            span = min(max(spans), 0.9)  # shared by the residual panels
            res_axes[0].set_ylim(1 - 1.15 * span, 1 + 1.15 * span)
        ymin = np.nanmin([a for a, _ in lims])
        ymax = np.nanmax([b for _, b in lims])
        if np.isfinite(ymin) and np.isfinite(ymax) and ymin > 0:
            axes[0].set_ylim(ymin / 1.5, ymax * 1.5)  # shared by all panels
        axes[0].set_ylabel(f"σ(τ) [{unit}]" if unit else "σ(τ)")
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
            fig.savefig(out, format=fmt)
            written.append(out)
    return written
