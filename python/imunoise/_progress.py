"""The one progress display of imunoise: tqdm bars on stderr, and only when wanted.

Every long-running entry point (the report, ``imunoise convert``, the batch) takes
``progress: bool | None``: True shows bars, False never does, None shows them when
stderr is a terminal (so pipes, logs and tests stay clean). tqdm is imported only
when a bar is shown.
"""

from __future__ import annotations

import sys
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

    def set_total(self, total: int) -> None:
        """Change the number of steps once it is known (e.g. which report sections apply)."""
        if self._bar is not None:
            self._bar.total = total
            self._bar.refresh()

    def bytes(self, label: str) -> Callable[[int, int], None] | None:
        """A :func:`byte_bar` callback when this bar is shown, else None."""
        return byte_bar(label) if self._bar is not None else None

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def byte_bar(label: str) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback in bytes, as the readers and
    :func:`imunoise.scale.convert` call it; the bar closes itself at ``done >= total``."""
    from tqdm import tqdm

    bar = tqdm(total=0, file=sys.stderr, unit="B", unit_scale=True, desc=label, leave=False)

    def update(done: int, total: int) -> None:
        bar.total = total
        bar.n = done
        bar.refresh()
        if done >= total:
            bar.close()

    return update
