"""The noise model a user reads: datasheet values, their uncertainties, tables and
exports, with the fitted components behind them under one name."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from imunoise import display as _display
from imunoise import units as _units
from imunoise._core import fit as _core_fit
from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.deprecation import old_call_forms
from imunoise.errors import ImunoiseDeprecationWarning, ImunoiseValueError
from imunoise.noise import _typed
from imunoise.noise._ambiguity import Tie
from imunoise.noise._components import (
    Components,
    PerTerm,
    Prediction,
    check_term,
    finite_list,
)
from imunoise.noise._filter import OutputFilter
from imunoise.noise._terms import NAMES, SENSOR_NAMES, TERMS
from imunoise.noise._typed import Term

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imunoise.allan import AllanResult
    from imunoise.spectral_lines import SpectralLine


def _moved(old: str, new: str) -> None:
    _warn.warn(f"NoiseModel.{old} is deprecated; use {new}", ImunoiseDeprecationWarning)


@dataclass(frozen=True, repr=False)
class NoiseModel(PerTerm):
    """A fitted noise model: the datasheet values N, B, K, Q, R per channel, in the
    input's units, with the fitted components behind them.

    ``N``, ``B``, ``K``, ``Q``, ``R`` are the numbers a datasheet quotes from the
    model's curve — the same numbers in every view (the repr, :meth:`table`, the
    report, ``imunoise fit``, :func:`imunoise.compare` and the Kalibr, OpenVINS
    and EKF exports). They are computed from all fitted components together:

    ====  ==================================================================
    N     the white rate noise level, the −½ line at τ = 1 s: the fitted N with
          every Gauss–Markov term whose hump (1.89 τc) lies before 1 s (white there)
    B     the model curve's flat minimum / 0.6643 over the fitted taus
    K     a random walk that keeps rising to the end of the record: the fitted K
          with any Gauss–Markov term whose hump (τ ≈ 1.89 τc) lies beyond the
          record's duration (:attr:`notes` says so); a bump within it is a
          bias state of its own, never added to K
    Q, R  the fitted coefficients
    ====  ==================================================================

    A value the data cannot show is NaN with :attr:`upper` its 95 % bound, never
    0; so is a K (or R) where a ramp (a walk) or a Gauss–Markov bump the taus show
    fits the rise of the longest taus as well (BIC within 2: the record cannot tell
    them apart; :attr:`notes` names the alternative). The fit's own parameters are
    :attr:`terms`. All arrays are read-only.

    Attributes
    ----------
    Q, N, B, K, R : ndarray
        Datasheet values: quantization (rate·s), white-noise density / angle or
        velocity random walk (rate·√s = rate/√Hz), bias instability (rate), rate
        random walk (rate/√s) and rate ramp (rate/s). Shape () for a one-channel
        result, (channels,) otherwise. NaN where the data do not resolve the value
        (never 0: a downstream filter would read 0 as "none"); :attr:`upper` then
        bounds it.
    Q_std, N_std, B_std, K_std, R_std : ndarray
        Standard uncertainties, propagated from the fit's covariance (NaN where
        not resolved).
    supported : dict[str, ndarray of bool]
        Whether each datasheet value is resolved by the data (``False``: the
        value is NaN, "not resolved", not "absent"). The one meaning of
        "not resolved" in every view.
    upper : dict[str, ndarray]
        Where a value is not resolved, the largest value the measured curve allows
        at 95 % confidence (the term alone stays below the Allan variance's
        one-sided upper confidence limit at every fitted tau, the 5 % shared over
        the octaves the taus span); NaN where the value is resolved. Tables print
        it as ``< bound``, and the Kalibr, OpenVINS and EKF exports use it, with a
        warning, where they need a number.
    notes : tuple of tuple of str
        Per channel, what a reader of the datasheet values needs to know: a slow
        Gauss–Markov term standing in for K (its hump lies beyond the record), or a
        bump within the record kept out of K.
    ties : tuple of tuple of Tie
        Per channel, the datasheet values (K, R) the record does not tell from an
        alternative term (:class:`imunoise.noise.Tie`: the alternative, the BIC
        difference, the value the chosen structure gave): not resolved.
    lines : tuple of tuple of SpectralLine
        Per channel, each fitted tone checked against the spectrum given to
        :func:`imunoise.fit` (``in_spectrum`` None where none was given): a tone is
        reported as a line only where the spectrum shows one, at its frequency,
        which is then the ``Tone``'s (``allan_frequency``: where the Allan curve
        alone had put it; :mod:`imunoise.spectral_lines`).
    terms : tuple of tuple of Term
        Per channel, the fitted terms, typed (``imunoise.noise.White``,
        ``GaussMarkov``, ``Tone``, …, each with its parameters and their standard
        uncertainties), in the model's order: the IEEE terms, Gauss–Markov terms by
        increasing τc, tones by increasing frequency, the resonance, the motion.
        ``model.terms[0]`` is the first channel's.
    components : Components
        Deprecated (a ``DeprecationWarning``; kept for one release): the same
        fitted terms as parallel arrays: IEEE coefficients of the fit, Gauss–Markov terms
        (σ, τc), the tone (A, f0) and the resonance (σ, f_r, τr), with their
        uncertainties, covariance and support ranges.
    method : str
        ``"wls"`` or ``"slopes"``.
    kind, fs, overlapping
        Copied from the Allan result.
    taus : ndarray
        The averaging times used by the fit.
    coverage : ndarray
        Share of the fitted taus where the model lies inside the measured 95 %
        confidence interval or within 5 % of the measured deviation, whichever
        is wider: how well the model follows the curve (1 = everywhere).
    discrepancy : ndarray
        ``"wls"``: δ, the relative standard deviation of the Allan variance that
        the model leaves unexplained beyond the estimates' own scatter.
    chi2, n_eff : ndarray
        ``"wls"``: Σ ω r²/var(ln σ̂²), the residual sum with the sampling
        variance alone and each tau weighted by its share ω of an octave, and
        n_eff = Σ ω, the octaves of evidence.
    readoff : dict[str, dict[str, ndarray]]
        The datasheet read-offs of the measured curve itself, whatever the
        model: ``"N"`` (slope −½ line at τ = 1 s), ``"K"`` (slope +½ line at
        τ = 3 s) and ``"B"`` (σ_min/0.6643 at the curve's minimum), each with
        ``value``, ``std`` and ``tau``, NaN where the curve has no such part;
        ``"B"`` also has ``low``/``high`` (95 % interval).

    Notes
    -----
    Before 0.2, ``N``…``R`` were the fitted IEEE coefficients, now
    ``components.N``…; ``equivalent(t)`` gave today's ``N``…; ``gm_sigma``,
    ``sine_freq``, ``resonance_tau``, ``cov``, ``tau_range``, ``gauss_markov()``,
    ``sine()`` and ``resonance()`` moved to :attr:`components`. The old spellings
    still work for one release with a ``DeprecationWarning`` naming the new one.
    """

    _arrays: Components = field(repr=False)
    terms: tuple[tuple[Term, ...], ...] = field(repr=False)
    method: str
    kind: str
    fs: float
    overlapping: bool
    taus: np.ndarray
    coverage: np.ndarray
    discrepancy: np.ndarray = field(repr=False)
    chi2: np.ndarray = field(repr=False)
    n_eff: np.ndarray = field(repr=False)
    readoff: dict[str, dict[str, np.ndarray]] = field(repr=False)
    upper: dict[str, np.ndarray] = field(repr=False)
    notes: tuple[tuple[str, ...], ...] = field(repr=False)
    lines: tuple[tuple[SpectralLine, ...], ...] = field(repr=False)
    filter: tuple[OutputFilter | None, ...] = field(default=(), repr=False)
    ties: tuple[tuple[Tie, ...], ...] = field(default=(), repr=False)

    # -- per term (channels, one_channel, value, std: PerTerm) ---------------
    def resolved(self, term: str) -> np.ndarray:
        """Whether ``term`` is resolved, shape (channels,)."""
        check_term(term)
        return np.atleast_1d(self.supported[term])

    # -- curves -------------------------------------------------------------
    def predict(self, taus=None) -> Prediction:
        """Model Allan deviation at ``taus`` (default: the fitted taus).

        Returns the total curve σ(τ) and each component's own curve, e.g.
        ``terms["N"]`` = (fitted N)/√τ, ``terms["GM1"]`` for the first
        Gauss–Markov term, ``terms["sine"]`` for the tone and
        ``terms["resonance"]`` for the resonance and ``terms["motion"]`` for a
        bounded motion (when a channel has one).
        """
        t = np.asarray(self.taus if taus is None else taus, dtype=float)
        if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(t <= 0):
            raise ImunoiseValueError(
                f"taus must be a non-empty 1-D array of finite values > 0; got {t!r}")
        channels = len(self.terms)
        curves = {name: np.zeros((t.size, channels)) for name in TERMS}
        kinds = list(_typed.KINDS)
        rank = {name: (kinds.index(_typed.IEEE[name].kind), name) for name in TERMS}
        total = np.zeros((t.size, channels))
        for c, terms in enumerate(self.terms):
            var = _typed.allan_variances(terms, t, self.fs)
            seen: dict[str, int] = {}
            for k, term in enumerate(terms):
                index = seen[term.kind] = seen.get(term.kind, -1) + 1
                name = term.curve(index)
                rank.setdefault(name, (kinds.index(term.kind), name))
                curves.setdefault(name, np.zeros((t.size, channels)))[:, c] += var[:, k]
            found = self.filter[c]
            if found is not None:
                # The white term through the channel's output filter, and the filter's
                # share of the spectrum's flicker and walk, which pass it too.
                curves["N"][:, c] *= found.factor(t)
                total[:, c] += found.excess(t)
        total = np.sqrt(np.maximum(total + sum(curves.values()), 0.0))
        ordered = sorted(curves, key=rank.__getitem__)
        if self.one_channel:
            return Prediction(taus=t, dev=total[:, 0],
                              terms={k: np.sqrt(curves[k][:, 0]) for k in ordered})
        return Prediction(taus=t, dev=total, terms={k: np.sqrt(curves[k]) for k in ordered})

    def floor(self, channel: int = 0) -> tuple[float, float] | None:
        """(τ, σ(τ)) of the model's floor over the fitted taus, where ``B`` is read
        (B = σ/√(2 ln2/π)); None where the curve has none (B not resolved)."""
        if self.method != "wls":
            return None
        found = self.filter[channel]
        return _core_fit.model_floor(
            [t.core() for t in self.terms[channel]],
            np.ascontiguousarray(self.taus, dtype=float), float(self.fs),
            filter=None if found is None else found.gain)

    def plot(self, result: AllanResult, **kwargs) -> Figure:
        """The model over ``result``, the Allan result it was fitted to, with its terms,
        read-off points and the data/model ratio: :func:`imunoise.plot.allan`."""
        from imunoise import plot

        return plot.allan(result, self, **kwargs)

    # -- deprecated spellings (0.1) ------------------------------------------
    def equivalent(self, term: str) -> np.ndarray:
        """Deprecated: the datasheet value, now ``model.<term>``."""
        _moved(f"equivalent({term!r})", f"model.{term}")
        return self.value(term)

    def equivalent_std(self, term: str) -> np.ndarray:
        """Deprecated: now ``model.<term>_std``."""
        _moved(f"equivalent_std({term!r})", f"model.{term}_std")
        return self.std(term)

    def gauss_markov(self, channel: int = 0) -> list[tuple[float, float]]:
        """Deprecated: the :class:`GaussMarkov` terms of ``model.terms[channel]``."""
        _moved("gauss_markov()", "model.terms")
        return self._arrays.gauss_markov(channel)

    def sine(self, channel: int = 0) -> list[tuple[float, float]]:
        """Deprecated: the :class:`Tone` terms of ``model.terms[channel]``."""
        _moved("sine()", "model.terms")
        return self._arrays.sine(channel)

    def resonance(self, channel: int = 0) -> list[tuple[float, float, float]]:
        """Deprecated: the :class:`Resonance` term of ``model.terms[channel]``."""
        _moved("resonance()", "model.terms")
        return self._arrays.resonance(channel)

    @property
    def components(self) -> Components:
        """Deprecated: the fitted terms as parallel arrays (``gm_sigma``, ``sine_freq``,
        …); :attr:`terms` holds them typed, per axis."""
        _moved("components", "model.terms (each axis's typed terms)")
        return self._arrays

    def __getattr__(self, name: str):
        # Only reached for names the class does not define: the fields that moved.
        if name in _MOVED_FIELDS:
            _moved(name, "model.terms")
            return getattr(self._arrays, name)
        raise AttributeError(f"'NoiseModel' object has no attribute {name!r}")

    # -- summaries ----------------------------------------------------------
    def _axis_facts(self, channel: int) -> str:
        """``"N=(1.234 ± 0.012)e-4 B=(1.2 ± 0.3)e-5, 1 GM, tone 13.4 Hz, covers 85 %"``:
        one channel's datasheet values in input units, each rounded to its
        uncertainty, then the components beyond the IEEE terms."""
        terms = [f"{t}={_summary.estimate(self.value(t)[channel], self.std(t)[channel])}"
                 for t in TERMS if self.resolved(t)[channel]]
        parts = self._arrays
        gm = len(parts.gauss_markov(channel))
        extra = "".join(f", tone {_summary.number(line.frequency)} Hz"
                        for line in self.lines[channel] if line.reported)
        extra += "".join(f", no line at {_summary.number(line.allan_frequency)} Hz (the "
                         "spectrum shows none: a filter's shape)"
                         for line in self.lines[channel] if not line.reported)
        extra += "".join(f", resonance {_summary.number(f)} Hz"
                         for _, f, _, _ in parts.resonance(channel))
        extra += "".join(f", bounded motion τc {_summary.number(tc)} s"
                         for _, tc in parts.motion(channel))
        return ((" ".join(terms) or "no term resolved") + (f", {gm} GM" if gm else "") + extra
                + f", covers {100 * float(np.atleast_1d(self.coverage)[channel]):.3g} %")

    def _title(self) -> str:
        return (f"{self.method} fit of {self.kind} at {_summary.number(self.fs)} Hz, "
                f"{_summary.plural(self.channels, 'channel')}")

    def __repr__(self) -> str:
        names = _schema.axis_names(self.channels)
        axes = [self._axis_facts(c) if self.one_channel else f"{names[c]}: {self._axis_facts(c)}"
                for c in range(self.channels)]
        return _summary.lines(f"NoiseModel({self._title()}", axes)

    def _repr_html_(self) -> str:
        """One row per axis: each datasheet value ± standard uncertainty in the
        input's units, rounded to it as in the repr (``< bound``, its 95 % upper
        bound, where the data do not resolve it), the fitted components and the
        coverage."""
        units = _INPUT_UNITS
        rows = []
        for c, name in enumerate(_schema.axis_names(self.channels)):
            row: list[object] = [name]
            for t in TERMS:
                v, e = self.value(t)[c], self.std(t)[c]
                row.append(_summary.estimate(v, e) if self.resolved(t)[c]
                           else _display.upper_bound(np.atleast_1d(self.upper[t])[c]))
            row.append(self._arrays.structure(c))
            row.append(f"{100 * float(np.atleast_1d(self.coverage)[c]):.3g} %")
            rows.append(row)
        return _summary.html_table(
            ["axis", *(f"{t} [{units[t]}]" for t in TERMS), "components", "coverage"],
            rows, caption=f"NoiseModel: {self._title()}, {_summary.tau_span(self.taus)}")

    # -- units and tables ---------------------------------------------------
    @old_call_forms(keyword_only=("units", "input_unit"))
    def in_units(self, sensor: str = "gyro", *, units: dict[str, str] | str | None = None,
                 input_unit: str | None = None) -> dict[str, dict]:
        """The datasheet values in datasheet units.

        Parameters
        ----------
        sensor : {"gyro", "accel"}
        units : dict or "datasheet", optional
            Target unit per term, e.g. ``{"N": "deg/s/sqrt(Hz)"}``; missing terms
            use :data:`imunoise.units.DEFAULT_UNITS`. ``"datasheet"``: the units MEMS
            datasheets write (:data:`imunoise.units.DATASHEET_UNITS`: °/s/√Hz, °/h,
            µg/√Hz, µg).
        input_unit : str, optional
            Unit of the rate data the model was fitted to (``"rad/s"`` default
            for gyros, ``"m/s^2"`` for accelerometers; also ``"deg/s"``, ``"g"``).

        Returns
        -------
        dict
            ``{term: {"value", "std", "upper", "unit", "label", "supported"}}`` with
            arrays shaped like the model's values (``value`` NaN and ``upper`` its
            95 % bound where not supported).
        """
        units = _units.unit_choice(units, sensor)
        unknown = set(units) - set(TERMS)
        if unknown:
            raise ImunoiseValueError(f"units keys must be among {TERMS}; got {sorted(unknown)}")
        out = {}
        shape = np.shape(self.N)
        for term in TERMS:
            info = _units.unit_info(term, units.get(term), sensor)
            supported = np.reshape(self.resolved(term), shape)
            out[term] = {
                "value": _units.convert(getattr(self, term), term, info.name, sensor=sensor,
                                        input_unit=input_unit),
                "upper": _units.convert(np.reshape(self.upper[term], shape), term, info.name,
                                        sensor=sensor, input_unit=input_unit),
                "std": _units.convert(np.where(supported, getattr(self, term + "_std"), np.nan),
                                      term, info.name, sensor=sensor, input_unit=input_unit),
                "unit": info.name,
                "label": info.label,
                "supported": supported,
            }
        return out

    @old_call_forms(keyword_only=("units", "input_unit", "axes", "terms"))
    def table(self, sensor: str = "gyro", *, units: dict[str, str] | str | None = None,
              input_unit: str | None = None, axes: Sequence[str] | None = None,
              terms: Sequence[str] = ("N", "B", "K", "Q", "R")) -> list[dict]:
        """Per-axis table in datasheet units: one row per datasheet value, then the
        fitted components beyond the IEEE terms where any axis has them (``σ1``,
        ``τc1``, … per Gauss–Markov term, ``A``, ``f0`` of the tone, ``σr``,
        ``f_r``, ``τr`` of the resonance, ``σθ``, ``τm`` of a bounded motion; σ and A
        in the unit of B, σθ in the unit of Q, times in s, frequencies in Hz).

        Each row is a dict with ``term``, ``quantity``, ``unit``, ``label``,
        ``missing`` (the text of an axis without the value: ``not resolved`` for
        a datasheet value, ``—`` for a component the axis's model does not have)
        and, per axis name (default X, Y, Z…), the value (NaN where not
        resolved), ``<axis>_std``, ``<axis>_upper`` (a datasheet value's 95 % bound
        where not resolved) and ``<axis>_supported``. Render it with
        :func:`format_table`. ``units`` as for :meth:`in_units` (``"datasheet"``:
        °/s/√Hz, °/h, µg/√Hz, µg).
        """
        axes = _schema.axis_names(self.channels, axes)
        conv = self.in_units(sensor, units=units, input_unit=input_unit)
        rows = []
        for term in terms:
            check_term(term)
            c = conv[term]
            row = {"term": term, "quantity": SENSOR_NAMES[sensor].get(term, NAMES[term]),
                   "unit": c["unit"], "label": c["label"], "missing": _display.NOT_RESOLVED}
            vals, stds, ups, sup = (np.atleast_1d(c[k])
                                    for k in ("value", "std", "upper", "supported"))
            for i, ax in enumerate(axes):
                row[ax] = float(vals[i])
                row[ax + "_std"] = float(stds[i])
                row[ax + "_upper"] = float(ups[i])
                row[ax + "_supported"] = bool(sup[i])
            rows.append(row)
        # σ and A in B's unit (a rate), a motion's σθ in Q's (rate·s)
        like = {None: "B", "Q": "Q"}
        for term, quantity, unit, values, stds in self._arrays.other_terms():
            as_term = like.get(unit)
            shown = conv[as_term]["unit"] if as_term else unit

            def scaled(v, as_term=as_term, shown=shown):
                if as_term is None or not np.isfinite(v):
                    return v
                return float(_units.convert(v, as_term, shown, sensor=sensor,
                                            input_unit=input_unit))

            row = {"term": term, "quantity": "component: " + quantity, "missing": _display.EMPTY,
                   "unit": shown, "label": conv[as_term]["label"] if as_term else unit}
            for i, ax in enumerate(axes):
                v, e = float(values[i]), float(stds[i])
                row[ax] = scaled(v)
                row[ax + "_std"] = scaled(e)
                row[ax + "_supported"] = bool(np.isfinite(v))
            rows.append(row)
        return rows

    def lab_table(self, sensor: str = "gyro", *, spec="vn100",
                  units: dict[str, str] | str | None = None, input_unit: str | None = None,
                  axes: Sequence[str] | None = None) -> list[dict]:
        """The lab report's table: N, B and K per axis beside the datasheet's value.

        The rows of :meth:`table` for N, B and K (same keys, same ``units``), each
        with ``spec`` (the datasheet's value in the row's unit, NaN when the
        datasheet does not give it), ``spec_text`` (as the datasheet prints it:
        ``"< 10 °/h"``, ``"0.0035 °/s/√Hz typ."``, ``"—"``) and ``spec_quantity``.

        Parameters
        ----------
        spec : str, path, :class:`imunoise.datasheet.Spec` or None
            The datasheet (:func:`imunoise.datasheet.load_spec`; default the VN-100's);
            None: no datasheet values.
        """
        from imunoise import datasheet

        items = datasheet.load_spec(spec).items if spec is not None else ()
        given = {item.term: item for item in items if item.sensor == sensor}
        rows = [r for r in self.table(sensor, units=units, input_unit=input_unit, axes=axes,
                                      terms=LAB_TERMS) if r["term"] in LAB_TERMS]
        for row in rows:
            item = given.get(row["term"])
            row["spec"], row["spec_text"], row["spec_quantity"] = float("nan"), "—", ""
            if item is None:
                continue
            label = _units.unit_info(row["term"], item.unit, sensor).label
            row["spec"] = float(_units.convert(
                _units.convert_back(item.value, row["term"], item.unit, sensor=sensor,
                                    input_unit=input_unit),
                row["term"], row["unit"], sensor=sensor, input_unit=input_unit))
            bound = {"max": "< ", "min": "> "}.get(item.limit, "")
            row["spec_text"] = (f"{bound}{item.value:g} {label}"
                                + (" typ." if item.limit == "typical" else ""))
            row["spec_quantity"] = item.quantity
        return rows

    def table_text(self, which: str = "gyro", /, **kwargs) -> str:
        """Text rendering of :meth:`table` (``which`` is the sensor, ``"gyro"`` or
        ``"accel"``), or with ``which="lab"`` of :meth:`lab_table` (pass
        ``sensor=``, default ``"gyro"``, and ``spec=``): N, B, K per axis beside the
        datasheet's values, in one unit."""
        axes = _schema.axis_names(self.channels, kwargs.get("axes"))
        if which == "lab":
            rows = self.lab_table(kwargs.pop("sensor", "gyro"), **kwargs)
            return format_table(rows, axes, datasheet=True)
        sensor = kwargs.pop("sensor", which)
        if which not in ("gyro", sensor):
            raise ImunoiseValueError(f"table_text takes the sensor once; got {which!r} and "
                             f"sensor={sensor!r}")
        return format_table(self.table(sensor, **kwargs), axes)

    # -- exports ------------------------------------------------------------
    @old_call_forms(keyword_only=("accel", "path"))
    def to_kalibr(self, *, accel: NoiseModel | None = None, path=None, **kwargs) -> str:
        """Kalibr ``imu.yaml`` text with this model as the gyroscope.

        See :func:`imunoise.export.kalibr_yaml` for the options; with ``path``
        the file is also written atomically.
        """
        from imunoise import export
        from imunoise._support import atomic as _atomic

        text = export.kalibr_yaml(gyro=self, accel=accel, **kwargs)
        if path is not None:
            _atomic.write_text(path, text)
        return text

    def to_dict(self) -> dict:
        """Plain-Python view of the model (lists and floats), e.g. for JSON: the
        datasheet values under their names (``None`` where not resolved, with
        ``"upper"`` the bound), each axis's fitted terms under ``"terms"`` (and as
        parallel arrays under ``"components"``, for one release), each axis's output
        filter under ``"filter"`` (white band's top, Hz; frequencies and gains; None
        where none was measured), and each axis's ties under ``"ties"`` (the values
        not resolved because an alternative term fits as well)."""
        d = {"method": self.method, "kind": self.kind, "fs": self.fs,
             "overlapping": self.overlapping, "channels": self.channels,
             "taus": self.taus.tolist(), "units": dict(_INPUT_UNITS)}
        for term in TERMS:
            d[term] = {"value": finite_list(self.value(term)), "std": finite_list(self.std(term)),
                       "upper": finite_list(np.atleast_1d(self.upper[term])),
                       "supported": self.resolved(term).tolist()}
        d["notes"] = [list(n) for n in self.notes]
        d["terms"] = [[t.to_dict() for t in terms] for terms in self.terms]
        d["ties"] = [[asdict(t) for t in ties] for ties in self.ties]
        d["filter"] = [None if f is None else
                       {"white_top": float(f.white_top), "frequency": f.f.tolist(),
                        "gain": f.gain.tolist()} for f in self.filter]
        d["components"] = self._arrays.to_dict()
        d["coverage"] = np.atleast_1d(self.coverage).tolist()
        d["discrepancy"] = np.atleast_1d(self.discrepancy).tolist()
        d["readoff"] = {term: {k: finite_list(a) for k, a in parts.items()}
                        for term, parts in self.readoff.items()}
        return d


#: Units of the values relative to the input's rate unit.
_INPUT_UNITS = {"Q": "rate*s", "N": "rate*sqrt(s)", "B": "rate", "K": "rate/sqrt(s)",
                "R": "rate/s"}

#: Fields that moved from NoiseModel to NoiseModel.components in 0.2.
_MOVED_FIELDS = frozenset({
    "gm_sigma", "gm_tau", "gm_sigma_std", "gm_tau_std", "sine_amplitude", "sine_freq",
    "sine_amplitude_std", "sine_freq_std", "resonance_sigma", "resonance_freq",
    "resonance_tau", "resonance_sigma_std", "resonance_freq_std", "resonance_tau_std",
    "cov", "tau_range",
})


#: The terms of the lab table (:meth:`NoiseModel.lab_table`): what a lab report asks for.
LAB_TERMS = ("N", "B", "K")


def table_cell(row: dict, axis: str, number) -> str:
    """One axis's cell of a :meth:`NoiseModel.table` row: ``number(value, std)``
    where resolved, else ``< bound`` for a datasheet value the data do not resolve
    (``not resolved`` without a bound) and ``—`` for a component the axis lacks."""
    if row[axis + "_supported"]:
        return number(row[axis], row[axis + "_std"])
    if row.get("missing") == _display.NOT_RESOLVED:
        return _display.upper_bound(row.get(axis + "_upper"))
    return row.get("missing", _display.NOT_RESOLVED)


def format_table(rows: list[dict], axes: Sequence[str], *, datasheet: bool = False) -> str:
    """Render :meth:`NoiseModel.table` rows as fixed-width text.

    Terms the data do not resolve print as ``< bound`` (their 95 % upper bound;
    ``not resolved`` without one: the report's and ``imunoise fit``'s wording
    too), a component an axis's model does not have as ``—``; values carry ``± std``, rounded to it
    (:func:`imunoise.display.format_value`). With ``datasheet`` (rows of
    :meth:`NoiseModel.lab_table`), two more columns: the datasheet's value in the
    row's unit and as the datasheet prints it.
    """
    def cell(row, ax):
        return table_cell(row, ax, _display.format_value)

    header = ["coefficient", "unit", *axes]
    body = [[f"{r['term']} {r['quantity']}", r["label"], *(cell(r, a) for a in axes)]
            for r in rows]
    if datasheet:
        header += ["datasheet", "as printed"]
        for line, r in zip(body, rows, strict=True):
            line += [_display.cell(r["spec"], digits=3), r["spec_text"]]
    widths = [max(len(str(x[i])) for x in [header, *body]) for i in range(len(header))]
    lines = ["  ".join(str(x).ljust(w) for x, w in zip(line, widths, strict=True)).rstrip()
             for line in [header, *body]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)
