"""What the report writes one channel's terms with: the unit of each kind of value,
its spelling of numbers, the channel's spectral lines and its N. Each kind of term
writes its own clause with it (``describe`` and ``remark`` of the classes in
:mod:`imunoise.noise._typed`), so the report's sentences iterate ``model.terms``
without naming kinds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imunoise import units as _units
from imunoise.display import percent
from imunoise.report.formatting import format_number, format_three
from imunoise.spectral_lines import SpectralLine

__all__ = ["TermWords"]


@dataclass(frozen=True)
class TermWords:
    """One channel's means of writing its terms' clauses.

    Attributes
    ----------
    sensor : {"gyro", "accel"}
    units : dict[str, imunoise.units.Unit]
        The unit a value is written in, by the IEEE term of its dimension: a rate
        as B's, an angle as Q's, a density as N's.
    fs : float
        The data's rate, Hz.
    taus : ndarray
        The fitted curve's taus, s.
    n : float
        The channel's datasheet N (input units), NaN where not resolved.
    lines : tuple of SpectralLine
        The channel's tones checked against the spectrum (``NoiseModel.lines``).
    """

    sensor: str
    units: dict[str, _units.Unit]
    fs: float
    taus: np.ndarray
    n: float
    lines: tuple[SpectralLine, ...]

    def amount(self, value: float, std: float | None, dimension: str) -> str:
        """``value ± std`` (input units) in the unit of ``dimension`` (``"B"``,
        ``"Q"`` or ``"N"``), followed by the unit: ``"3.1 ± 0.2 °/h"``; a bare
        value where ``std`` is None."""
        unit = self.units[dimension]
        if std is None:
            shown = float(_units.convert(value, dimension, unit.name, sensor=self.sensor))
            return f"{format_number(shown)} {unit.label}"
        shown, shown_std = _units.convert(np.array([value, std]), dimension, unit.name,
                                          sensor=self.sensor)
        return f"{format_number(shown, shown_std)} {unit.label}"

    def number(self, value: float, std: float | None = None) -> str:
        """A number without a unit, rounded to its uncertainty (``format_number``)."""
        return format_number(value, std)

    def three(self, value: float) -> str:
        """Three significant digits (``format_three``): a ratio, a rough size."""
        return format_three(value)

    def percent(self, fraction: float) -> str:
        """A fraction as a whole percentage: ``"62 %"``."""
        return percent(fraction)

    def line(self, freq: float) -> SpectralLine | None:
        """The spectral check of the model's tone at ``freq`` Hz
        (:attr:`SpectralLine.tone_frequency`), or None where the model has none."""
        return next((line for line in self.lines if line.tone_frequency == freq), None)
