"""A fitted noise model in the report's words and tables: the datasheet table per
axis, one sentence per axis, and the comparison with a datasheet. ``imunoise fit``
prints the same table and sentences."""

from __future__ import annotations

import math

import numpy as np

from imunoise import datasheet
from imunoise import units as _units
from imunoise._support.schema import axis_names
from imunoise.display import percent
from imunoise.errors import ImunoiseValueError
from imunoise.noise import NoiseModel, _typed, resolution_noise
from imunoise.noise._model import table_cell
from imunoise.report.formatting import format_number, format_three
from imunoise.report.term_words import TermWords

__all__ = ["REPORT_UNITS", "comparison_rows", "datasheet_rows", "lab_rows",
           "model_sentences", "record_uncertainty", "report_units", "units_of"]

#: The report's units when none are asked for: one family per sensor (the gyro's in
#: degrees and hours, the accelerometer's in µg), so a table never mixes mg and µg
#: for one accelerometer.
REPORT_UNITS: dict[str, dict[str, str]] = {
    "gyro": dict(_units.DEFAULT_UNITS["gyro"]),
    "accel": {"Q": "m/s", "N": "ug/sqrt(Hz)", "B": "ug", "K": "ug/sqrt(s)", "R": "ug/s"},
}


def report_units(units, spec=None) -> dict[str, dict[str, str]]:
    """``{sensor: {term: unit}}`` of every table of a report: ``None`` the report's
    own (:data:`REPORT_UNITS`); ``"datasheet"`` the datasheet's own units where
    ``spec`` gives the term (the VN-100's °/s/√Hz, °/h, mg/√Hz, mg), the rest in
    the same family (an accelerometer's K in mg/√s beside B in mg), else
    :data:`imunoise.units.DATASHEET_UNITS`; a dict of term -> unit is used as
    given for every sensor."""
    if isinstance(units, dict):
        return {s: dict(units) for s in _units.SENSORS}
    if units is None:
        return {s: dict(u) for s, u in REPORT_UNITS.items()}
    out = {s: _units.unit_choice("datasheet", s) for s in _units.SENSORS}
    given = set()
    for item in datasheet.load_spec(spec).items if spec is not None else ():
        if item.sensor in out:
            out[item.sensor][item.term] = _units.unit_info(item.term, item.unit,
                                                          item.sensor).name
            given.add((item.sensor, item.term))
    accel = out["accel"]
    for prefix in ("mg", "ug"):  # the accelerometer's family, from its B
        if accel.get("B", "").startswith(prefix):
            for term, unit in (("N", f"{prefix}/sqrt(Hz)"), ("K", f"{prefix}/sqrt(s)"),
                               ("R", f"{prefix}/s")):
                if ("accel", term) not in given:
                    accel[term] = unit
    return out


def units_of(units, sensor: str):
    """One sensor's units out of :func:`report_units`' mapping (or ``units`` as
    given: ``None``, ``"datasheet"``, a dict of term -> unit)."""
    if isinstance(units, dict) and units and set(units) <= set(_units.SENSORS):
        return units.get(sensor)
    return units


#: Coverage (share of taus the model follows) below which the report says that
#: the coefficients only summarise the curve.
POOR_COVERAGE = 0.8


def datasheet_rows(model: NoiseModel, sensor: str, units: str | dict | None = None, *,
                   symbols: bool = False) -> tuple[list[str], list[list[str]]]:
    """Noise coefficients per axis in datasheet units, as text.

    Returns the header (``quantity, term, unit``, then one column per axis) and
    one row per term of :meth:`NoiseModel.table`; a cell is ``value ± std``,
    ``not resolved`` where the data do not resolve the coefficient, or ``—``
    where the axis's model has no such term. ``units`` as for
    :meth:`NoiseModel.table` (``"datasheet"``: °/s/√Hz, °/h, µg/√Hz, µg).
    ``symbols``: units as the report writes them (``°/√h``; default the ASCII name
    ``deg/sqrt(h)`` a terminal shows).
    """
    axes = axis_names(model.channels)
    out = []
    for r in model.table(sensor, axes=axes, units=units_of(units, sensor)):
        cells = [r["quantity"], r["term"], r["label"] if symbols else r["unit"]]
        cells += [table_cell(r, a, format_number) for a in axes]
        out.append(cells)
    return ["quantity", "term", "unit", *axes], out


def lab_rows(models: dict[str, NoiseModel], spec,
             units: str | dict | None = None) -> tuple[list[str], list[list[str]]]:
    """The lab table of every sensor (:meth:`NoiseModel.lab_table`) as text: N, B and
    K per axis and the datasheet's value in the same unit, and as it prints it.

    Returns the header (``sensor, quantity, unit``, one column per axis of the
    first model, ``datasheet, as printed``) and one row per sensor and term."""
    axes: list[str] = []
    out = []
    for sensor, model in models.items():
        names = axis_names(model.channels)
        axes = axes or names
        for r in model.lab_table(sensor, spec=spec, units=units_of(units, sensor), axes=names):
            cells = [sensor, f"{r['quantity']} ({r['term']})", r["label"]]
            cells += [table_cell(r, a, format_number) for a in names]
            cells += [""] * (len(axes) - len(names))
            cells += [format_number(r["spec"]), r["spec_text"]]
            out.append(cells)
    return ["sensor", "quantity", "unit", *axes, "datasheet", "as printed"], out


def model_sentences(model: NoiseModel, sensor: str,
                    units: str | dict | None = None, *, steps=None) -> list[str]:
    """One sentence per axis: the fitted components, how well the model follows the curve
    (and, below :data:`POOR_COVERAGE`, that its coefficients only summarise it),
    each term's clause in its kind's own words (``describe`` and ``remark`` of its
    class in :mod:`imunoise.noise._typed`: a Gauss–Markov term, a tone, a
    resonance, a bounded motion), whether the model's N and B agree with the
    datasheet read-offs of the curve and, given ``steps`` (per axis, the samples'
    resolution in input units — :func:`imunoise.stats.quantization_step` —, None
    where unknown), what that resolution adds to N and Q; in ``units`` (as for
    :meth:`NoiseModel.table`; σ and amplitudes in the unit of B). Emphasis is
    Markdown ``**``."""
    if steps is not None and len(steps) != model.channels:
        raise ImunoiseValueError(f"steps must have one value per channel ({model.channels}); "
                         f"got {len(steps)}")
    chosen = _units.unit_choice(units_of(units, sensor), sensor)
    shown = {t: _units.unit_info(t, chosen.get(t), sensor) for t in ("B", "N", "Q")}
    b_unit, n_unit, q_unit = shown["B"], shown["N"], shown["Q"]
    out = []
    for c, axis in enumerate(axis_names(model.channels)):
        terms = model.terms[c]
        parts = [f"{axis}: fitted components {_typed.structure(terms)}"]
        cover = float(np.atleast_1d(model.coverage)[c])
        delta = float(np.atleast_1d(model.discrepancy)[c])
        parts.append(f"follows {percent(cover)} of the taus (inside the 95 % interval or "
                     "within 5 %)" + (f", residual discrepancy {percent(delta / 2, digits=1)} "
                                      "in σ" if delta > 0.01 else ""))
        if cover < POOR_COVERAGE:
            parts.append("**the model does not describe this curve: read its coefficients "
                         "as a summary only** (see the data/model panel)")
        # Each kind writes its own clause (Term.describe, Term.remark), so a new
        # kind needs no branch here.
        words = TermWords(sensor, shown, model.fs, model.taus, float(model.value("N")[c]),
                          model.lines[c])
        parts += [text for term in terms if (text := term.describe(words))]
        parts += [text for term in terms if (text := term.remark(words))]
        if steps is not None:
            parts += _resolution_sentence(model, c, steps[c], sensor, (b_unit, n_unit, q_unit))
        for term, unit in (("N", n_unit), ("B", b_unit)):
            parts += _readoff_agreement(model, c, term, unit, sensor)
        parts += [f"{tie.term} not resolved: {tie.instead()} fits the rise of the longest "
                  f"taus as well (BIC {tie.delta_bic:+.2g}), so the record cannot tell them "
                  "apart (the table gives its 95 % bound)"
                  for tie in (model.ties[c] if model.ties else ())]
        out.append("; ".join(parts) + ".")
    return out


#: Share of N (in amplitude) that the samples' resolution adds above which the
#: sentence says so; from :data:`RESOLUTION_LIMITS` on, that it limits N.
RESOLUTION_SHOWN = 0.1
RESOLUTION_LIMITS = 0.3

#: Q more than this multiple of what the samples' count explains is the sensor's.
Q_OWN = 3.0


def _resolution_sentence(model: NoiseModel, c: int, step, sensor: str, units) -> list[str]:
    """What the samples' resolution ``step`` (input units) adds to N — rounding each
    sample — and how Q compares with counts of an integrated angle of that size
    (:func:`imunoise.noise.resolution_noise`); nothing where the step is unknown, or
    adds less than :data:`RESOLUTION_SHOWN` of N and Q is not resolved. On the
    ADIS16405 accelerometers and a phone gyro, whose noise per sample is about one
    count, the rounding is 20–30 % of N."""
    if step is None or not (np.isfinite(step) and step > 0):
        return []
    b_unit, n_unit, q_unit = units
    n_round, q_count = resolution_noise(float(step), model.fs)
    n_now, q_now = float(model.value("N")[c]), float(model.value("Q")[c])
    share = n_round / n_now if n_now > 0 else math.inf
    out = []
    if share >= RESOLUTION_SHOWN:
        shown = _units.convert(float(step), "B", b_unit.name, sensor=sensor)
        added = _units.convert(n_round, "N", n_unit.name, sensor=sensor)
        text = (f"the samples are whole multiples of {format_three(shown)} "
                f"{b_unit.label}: rounding to it adds white noise of "
                f"{format_three(added)} {n_unit.label}"
                + (f", {percent(share)} of N" if math.isfinite(share) else ""))
        if share >= RESOLUTION_LIMITS:
            text += (" — **the log's resolution limits the N measured here** (record with "
                     "more digits, or the sensor's binary output)")
        out.append(text)
    if q_now > 0:
        shown = _units.convert(float(step), "B", b_unit.name, sensor=sensor)
        counted = _units.convert(q_count, "Q", q_unit.name, sensor=sensor)
        ratio = q_now / q_count
        times = f"{ratio:.0f}" if ratio >= 10 else f"{ratio:.2g}"
        integral = "velocity" if sensor == "accel" else "angle"
        out.append(f"counts of an integrated {integral} of the samples' resolution "
                   f"({format_three(shown)} {b_unit.label}) would give Q = "
                   f"{format_three(counted)} {q_unit.label}; the model's Q is {times}× that"
                   + (": more than the log's resolution explains (the sensor's own "
                      "quantization, or its filter)" if ratio > Q_OWN else ""))
    return out


def _readoff_agreement(model: NoiseModel, c: int, term: str, unit, sensor: str) -> list[str]:
    """``"N read-off … vs model … (agree)"`` for one channel, or nothing when the
    curve has no such read-off or the model no such value."""
    read = float(np.atleast_1d(model.readoff[term]["value"])[c])
    std = float(np.atleast_1d(model.readoff[term]["std"])[c])
    eq = float(model.value(term)[c])
    if not (np.isfinite(read) and eq > 0):
        return []
    eq_std = float(model.std(term)[c])
    read_c, std_c, eq_c, eq_std_c = _units.convert(np.array([read, std, eq, eq_std]), term,
                                                  unit.name, sensor=sensor)
    diff = abs(read - eq) / max(std, 1e-300)
    verdict = ("agree" if diff <= 2 or abs(read / eq - 1) <= 0.05 else
               "differ: the curve is not the ideal slope there (filter, bumps)")
    return [f"{term} read-off {format_number(read_c, std_c)} vs model "
            f"{format_number(eq_c, eq_std_c)} {unit.label} ({verdict})"]


def comparison_rows(models: dict[str, NoiseModel], spec,
                    units: str | dict | None = None, *,
                    seconds: dict[str, float] | None = None,
                    ) -> tuple[list[str], list[list[str]]]:
    """Measured vs datasheet (:func:`imunoise.datasheet.compare`) as text rows, the
    measured and specified values in ``units`` (as for :meth:`NoiseModel.table`: the
    report's one unit per quantity, whatever unit the datasheet file uses).

    ``seconds`` (per sensor, the length of the record the model was fitted to):
    the ``±`` of a measured value and its verdict use the larger of the fit's
    standard uncertainty and :func:`record_uncertainty` — what the Allan deviation
    at the τ the term is read at can claim from a record this long (the plan
    line's uncertainty, at 68.3 %). A fit's standard uncertainty alone can be far
    smaller (it pools every τ) and fail a sensor that meets its datasheet."""
    cmp = datasheet.compare(models, spec)
    header = ["sensor", "quantity", "axis", "unit", "measured", "spec", "ratio", "verdict"]
    relative = {sensor: record_uncertainty(m, seconds[sensor])
                for sensor, m in models.items() if seconds and sensor in seconds}
    out = []
    for r in cmp.rows:
        bound = {"max": "<", "min": ">"}.get(r["limit"], "typ.")
        term, sensor = r["term"], r["sensor"]
        word, remark, std = r["verdict"], r.get("remark", ""), r["std"]
        rel = relative.get(sensor, {}).get(term, math.nan)
        if math.isfinite(r["measured"]) and math.isfinite(rel) and rel * r["measured"] > std:
            std = rel * r["measured"]
            if r["limit"] in ("max", "min"):
                word, remark = datasheet.verdict(r["measured"], std, r["spec"], r["limit"])
        unit = _units.unit_info(term, _units.unit_choice(units_of(units, sensor), sensor)
                                .get(term), sensor)
        if math.isfinite(r.get("upper", math.nan)):  # the bound in the table's unit
            upper = _units.convert(_units.convert_back(r["upper"], term, r["unit"],
                                                       sensor=sensor), term, unit.name,
                                   sensor=sensor)
            remark = f"{'' if word == 'not resolved' else 'not resolved, '}at most " \
                     f"{float(upper):.3g} {unit.label} (95 % bound)"
        measured, std_shown, spec_value = (
            _units.convert(_units.convert_back(v, term, r["unit"], sensor=sensor), term,
                           unit.name, sensor=sensor)
            for v in (r["measured"], std, r["spec"]))
        out.append([
            sensor, f"{r['quantity']} ({term})", r["axis"], unit.label,
            format_number(measured, std_shown), f"{bound} {format_number(spec_value)}",
            format_number(r["ratio"], std / r["spec"] if math.isfinite(std) else math.nan),
            word + (f" ({remark})" if remark else ""),
        ])
    return header, out


#: Confidence of :func:`record_uncertainty`: one standard uncertainty.
ONE_SIGMA = 0.6826894921370859


def record_uncertainty(model: NoiseModel, seconds: float) -> dict[str, float]:
    """Relative standard uncertainty (68.3 %) of N, B and K that a record of
    ``seconds`` allows, from the Allan deviation's degrees of freedom at the τ each
    is read at (:func:`imunoise.plan`, as the report's plan lines); ``{}`` where
    the planner has nothing to say."""
    from imunoise.planner import plan

    try:
        p = plan(model, fs=model.fs, confidence=ONE_SIGMA)
    except ValueError:
        return {}
    return {k: v for k, v in p.uncertainty(seconds).items() if math.isfinite(v)}
