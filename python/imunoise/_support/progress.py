"""The one progress display of imunoise: tqdm bars on stderr, and only when wanted.

Every long-running entry point (the report, ``imunoise convert``, the batch) takes
``progress: bool | None``: True shows bars, False never does, None shows them when
stderr is a terminal (so pipes, logs and tests stay clean). tqdm is imported only
when a bar is shown.

While a bar is on screen, warnings are written through ``tqdm.write`` (the bar is
cleared, the warning printed on its own lines, the bar redrawn), so a warning never
lands in the middle of a bar's line, on a terminal or in a pipe (``--progress``). A
step bar's total is fixed when it is made: callers count their steps first.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable

__all__ = ["Progress", "byte_bar", "wanted"]


def wanted(progress: bool | None) -> bool:
    """Whether to show bars: ``progress`` itself, or None for "stderr is a terminal"."""
    return sys.stderr.isatty() if progress is None else bool(progress)


class Progress:
    """A bar that counts steps (sections of a report, logs of a batch), or nothing.

    Parameters
    ----------
    progress : bool or None
        See :func:`wanted`.
    total : int
        Number of steps.
    unit : str
        What a step is, shown after the count.
    desc : str, optional
        Label shown before the bar until :meth:`step` names a step.
    leave : bool
        Keep the finished bar on screen.
    """

    def __init__(self, progress: bool | None, total: int, *, unit: str = "step",
                 desc: str | None = None, leave: bool = False) -> None:
        self._bar = None
        if wanted(progress):
            from tqdm import tqdm

            self._bar = tqdm(total=total, file=sys.stderr, unit=unit, desc=desc, leave=leave)
            self._restore = _warnings_above_bars()

    @property
    def shown(self) -> bool:
        """True when the bar is on screen."""
        return self._bar is not None

    def step(self, what: str | None = None) -> None:
        """Count one step; ``what`` (optional) replaces the label."""
        if self._bar is None:
            return
        if what is not None:
            self._bar.set_description(what)
        self._bar.update(1)

    def bytes(self, label: str) -> Callable[[int, int], None] | None:
        """A :func:`byte_bar` callback when this bar is shown, else None."""
        return byte_bar(label) if self._bar is not None else None

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._restore()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def byte_bar(label: str) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback in bytes, as the readers and
    :func:`imunoise.scale.convert` call it; the bar closes itself at ``done >= total``."""
    from tqdm import tqdm

    bar = tqdm(total=0, file=sys.stderr, unit="B", unit_scale=True, desc=label, leave=False)
    restore = _warnings_above_bars()

    def update(done: int, total: int) -> None:
        if bar.disable:  # closed
            return
        bar.total = total
        bar.n = done
        bar.refresh()
        if done >= total:
            bar.close()
            restore()

    return update


class _AboveBars:
    """A text stream for warnings: each line goes out through ``tqdm.write`` to stderr."""

    def write(self, text: str) -> None:
        from tqdm import tqdm

        for line in text.rstrip("\n").splitlines():
            tqdm.write(line, file=sys.stderr)

    def flush(self) -> None:
        sys.stderr.flush()


def _warnings_above_bars() -> Callable[[], None]:
    """Route warnings through :class:`_AboveBars` (keeping whatever formats them, e.g.
    the CLI's one-line form); returns the function that undoes it."""
    saved = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        saved(message, category, filename, lineno, _AboveBars(), line)

    warnings.showwarning = show

    def restore() -> None:
        if warnings.showwarning is show:
            warnings.showwarning = saved

    return restore
