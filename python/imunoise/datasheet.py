"""Datasheets as data: load a sensor specification and compare a fitted model.

A specification is a TOML file (``specs/vn100.toml`` ships with imunoise; see it
for the format). :func:`compare` takes the fitted models of a gyroscope and/or
an accelerometer and returns, for every specified quantity and every axis, the
measured value, the specification, their ratio and a verdict.

TOML is read with :mod:`tomllib` (Python ≥ 3.11) or the ``tomli`` back-port on
Python 3.10 (a dependency there).

Examples
--------
>>> import imunoise
>>> # models fitted to gyro (rad/s) and accelerometer (m/s²) Allan deviations:
>>> # cmp = imunoise.compare({"gyro": mg, "accel": ma}, "vn100")
>>> # print(cmp.text())
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from imunoise import display as _display
from imunoise import units as _units
from imunoise._support import summary as _summary
from imunoise._support.schema import axis_names
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on 3.10 only
    import tomli as tomllib

__all__ = ["Spec", "SpecItem", "Comparison", "load_spec", "compare", "available_specs",
           "verdict", "LIMITS", "VERDICTS", "COVERAGE_K", "TYPICAL_FACTOR"]


@dataclass(frozen=True)
class SpecItem:
    """One specified quantity: term, value in ``unit``, ``limit`` ("max"/"typical"/"min")."""

    sensor: str
    term: str
    quantity: str
    value: float
    unit: str
    limit: str


@dataclass(frozen=True)
class Spec:
    """A sensor datasheet: its name, source and specified items."""

    name: str
    source: str
    items: tuple[SpecItem, ...]


def available_specs() -> list[str]:
    """Names of the specifications shipped with imunoise."""
    folder = resources.files("imunoise") / "specs"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_spec(spec) -> Spec:
    """Load a specification by name (``"vn100"``) or from a TOML file path."""
    if isinstance(spec, Spec):
        return spec
    if not isinstance(spec, (str, Path)):
        raise ImunoiseTypeError(f"spec must be a name, a path or a Spec; got {type(spec).__name__}")
    path = Path(spec)
    name = str(spec).lower()
    # A file of that name wins; a name is the built-in datasheet only when no such
    # file exists (a folder called vn100 in the working directory is no spec)
    if path.is_file():
        text = path.read_text(encoding="utf-8")
        origin = str(path)
    elif name in available_specs():
        text = (resources.files("imunoise") / "specs" / f"{name}.toml").read_text(
            encoding="utf-8")
        origin = f"imunoise/specs/{name}.toml"
    elif path.suffix == ".toml" or path.exists():
        what = "is not a file" if path.exists() else "does not exist"
        raise ImunoiseValueError(f"spec file {str(path)!r} {what}")
    else:
        raise ImunoiseValueError(
            f"spec must be one of {available_specs()} or a .toml path; got {spec!r}"
        )
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ImunoiseValueError(f"spec {origin}: invalid TOML: {exc}") from None
    items = []
    for sensor in _units.SENSORS:
        for i, entry in enumerate(data.get(sensor, [])):
            where = f"spec {origin}: {sensor}[{i}]"
            try:
                item = SpecItem(
                    sensor=sensor,
                    term=str(entry["term"]),
                    quantity=str(entry.get("quantity", entry["term"])),
                    value=float(entry["value"]),
                    unit=str(entry["unit"]),
                    limit=_LIMIT_ALIASES.get(str(entry.get("limit", "max")),
                                             str(entry.get("limit", "max"))),
                )
            except (KeyError, TypeError, ValueError) as exc:
                raise ImunoiseValueError(f"{where}: needs term, value and unit ({exc})") from None
            if item.limit not in LIMITS:
                raise ImunoiseValueError(
                    f"{where}: limit must be 'max', 'typical' or 'min'; got {item.limit!r}")
            if not (math.isfinite(item.value) and item.value > 0):
                raise ImunoiseValueError(
                    f"{where}: value must be finite and > 0; got {item.value!r}")
            _units.unit_info(item.term, item.unit, sensor)  # validates term and unit
            items.append(item)
    if not items:
        raise ImunoiseValueError(
            f"spec {origin} specifies nothing (no [[gyro]] or [[accel]] entries)")
    return Spec(name=str(data.get("name", origin)), source=str(data.get("source", "")),
                items=tuple(items))


@dataclass(frozen=True, repr=False)
class Comparison:
    """Measured vs specified, one row per (quantity, axis).

    Each row is a dict: ``sensor, term, quantity, unit, limit, spec, axis,
    measured, std, ratio, ratio_std, verdict`` where ``ratio = measured/spec``
    (``ratio_std`` its standard uncertainty, ``std/spec``) and
    ``verdict`` follows the kind of spec (rules in docs/report.md): for a
    ``max`` (``min``) limit ``"pass"``, ``"fail"`` or ``"not significant"``
    (the one-sided 95 % interval straddles the limit); for a ``typical`` value
    ``"typical"`` (within a factor :data:`TYPICAL_FACTOR` of it), ``"above
    typical"`` or ``"below typical"``; ``"not resolved"`` when the data do not
    resolve that term (e.g. too short a log for B), except that a ``max`` the
    value's 95 % upper bound (``upper``, the model's :attr:`NoiseModel.upper`)
    stays below is a ``"pass"``. ``remark`` says it in words ("within a factor 1.5
    of typical", "2.3× typical", "no uncertainty", "not resolved, at most …").
    """

    spec: Spec
    rows: tuple[dict, ...]

    def _verdicts(self) -> str:
        """``"pass=8, fail=1, not resolved=3"``: rows per verdict, in order of appearance."""
        counts: dict[str, int] = {}
        for r in self.rows:
            counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
        return _summary.nonzero(counts)

    def __repr__(self) -> str:
        return _summary.lines(f"Comparison({self.spec.name!r}", [
            f"{_summary.plural(len(self.rows), 'row')}: {self._verdicts()}",
            "passed" if self.passed else "not passed"], sep=", ")

    def _repr_html_(self) -> str:
        """One row per (quantity, axis): measured ± standard uncertainty, the spec,
        the ratio and the verdict."""
        body = []
        for r in self.rows:
            spec = _display.cell(r["spec"])
            body.append([r["sensor"], f"{r['quantity']} ({r['term']})", r["axis"],
                         _display.cell(r["measured"], r["std"]),
                         f"{r['limit']} {spec} {r['label']}",
                         _display.cell(r["ratio"], r["ratio_std"]), r["verdict"]])
        return _summary.html_table(
            ["sensor", "quantity", "axis", "measured", "spec", "ratio", "verdict"], body,
            caption=f"Comparison with {self.spec.name}, "
                    f"{_summary.plural(len(self.rows), 'row')}: {self._verdicts()}")

    @property
    def passed(self) -> bool:
        """True when no row fails: "not significant", typical and "not resolved"
        rows do not fail (a typical value is not a limit)."""
        return all(r["verdict"] != "fail" for r in self.rows)

    def text(self) -> str:
        """Fixed-width text rendering; measured values rounded to their uncertainty."""
        header = ["sensor", "quantity", "axis", "measured", "spec", "ratio", "verdict"]
        body = []
        for r in self.rows:
            bound = {"max": "<", "min": ">"}.get(r["limit"], "typ.")
            word = r["verdict"] + (f" ({r['remark']})" if r.get("remark") else "")
            body.append([
                r["sensor"], f"{r['quantity']} ({r['term']})", r["axis"],
                (_display.format_value(r["measured"], r["std"]) if np.isfinite(r["measured"])
                 else _display.upper_bound(r.get("upper"))),
                f"{bound} {r['spec']:g} {r['label']}",
                _display.cell(r["ratio"], r["ratio_std"]),
                word,
            ])
        widths = [max(len(x[i]) for x in [header, *body]) for i in range(len(header))]
        lines = [f"{self.spec.name} — {self.spec.source}"]
        for row in [header, *body]:
            lines.append("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())
        lines.insert(2, "  ".join("-" * w for w in widths))
        return "\n".join(lines)


#: Kinds of spec entry; "typ" is read as "typical".
LIMITS = ("max", "typical", "min")
_LIMIT_ALIASES = {"typ": "typical", "maximum": "max", "minimum": "min"}
#: Coverage factor of the max/min verdicts: one-sided 95 % for a normal estimate.
COVERAGE_K = 1.645
#: A measured value within this factor of a typical one (either way) is "typical".
TYPICAL_FACTOR = 1.5
#: Every verdict word, in order of decreasing concern (scale.batch ranks with it).
VERDICTS = ("fail", "not significant", "above typical", "pass", "typical",
            "below typical", "not resolved")


def verdict(measured: float, std: float | None, spec: float, limit: str) -> tuple[str, str]:
    """``(verdict, remark)`` for one measured value against one spec entry.

    ``max``: "pass" when ``measured + k·u ≤ spec``, "fail" when ``measured − k·u
    > spec``, else "not significant" (k = :data:`COVERAGE_K`); without a usable
    uncertainty ``u`` pass/fail on the value, remarked "no uncertainty". ``min``
    mirrors ``max``. ``typical``: no pass/fail; "typical" within a factor
    :data:`TYPICAL_FACTOR`, else "above typical"/"below typical", the remark
    giving the ratio. A non-finite or non-positive ``measured`` is "not resolved".
    """
    if limit not in LIMITS:
        raise ImunoiseValueError(f"limit must be one of {LIMITS}; got {limit!r}")
    if not (math.isfinite(spec) and spec > 0):
        raise ImunoiseValueError(f"spec must be finite and > 0; got {spec!r}")
    if measured is None or not math.isfinite(measured) or measured <= 0:
        return "not resolved", ""
    if limit == "typical":
        ratio = measured / spec
        if 1.0 / TYPICAL_FACTOR <= ratio <= TYPICAL_FACTOR:
            return "typical", f"within a factor {TYPICAL_FACTOR:g} of typical"
        return ("above typical" if ratio > 1 else "below typical"), f"{ratio:.2g}× typical"
    sign = 1.0 if limit == "max" else -1.0     # min: the mirror image of max
    has_u = std is not None and math.isfinite(std) and std > 0
    margin = COVERAGE_K * std if has_u else 0.0
    remark = "" if has_u else "no uncertainty"
    if sign * (measured - spec) + margin <= 0:
        return "pass", remark
    if sign * (measured - spec) - margin > 0:
        return "fail", remark
    return "not significant", remark


def compare(models, spec="vn100", *, sensor: str = "gyro", input_units: dict | None = None,
            axes=None) -> Comparison:
    """Compare fitted noise models with a datasheet.

    Parameters
    ----------
    models : NoiseModel or dict
        ``{"gyro": model_g, "accel": model_a}`` (either key may be missing), or
        a single model whose kind is given by ``sensor``.
    spec : str, path or Spec
        A shipped specification name (``"vn100"``) or a TOML file.
    sensor : {"gyro", "accel"}
        Kind of a single model.
    input_units : dict, optional
        Units of the rate data per sensor, e.g. ``{"gyro": "deg/s"}``; default
        rad/s and m/s².
    axes : sequence of str, optional
        Axis names (default X, Y, Z for three channels).

    Returns
    -------
    Comparison
    """
    from imunoise.noise import NoiseModel

    if isinstance(models, NoiseModel):
        if sensor not in _units.SENSORS:
            raise ImunoiseValueError(f"sensor must be one of {_units.SENSORS}; got {sensor!r}")
        models = {sensor: models}
    if not isinstance(models, dict) or not models:
        raise ImunoiseTypeError(
            "models must be a NoiseModel or a dict {'gyro': model, 'accel': model}; "
            f"got {type(models).__name__}"
        )
    for key, m in models.items():
        if key not in _units.SENSORS:
            raise ImunoiseValueError(f"models keys must be 'gyro' or 'accel'; got {key!r}")
        if not isinstance(m, NoiseModel):
            raise ImunoiseTypeError(f"models[{key!r}] must be a NoiseModel; got {type(m).__name__}")
    input_units = dict(input_units or {})
    spec = load_spec(spec)
    rows = []
    for item in spec.items:
        model = models.get(item.sensor)
        if model is None:
            continue
        info = _units.unit_info(item.term, item.unit, item.sensor)
        iu = input_units.get(item.sensor)
        # The model's datasheet values: what a datasheet quotes from a curve.
        eq, eq_std = model.value(item.term), model.std(item.term)
        values = _units.convert(eq, item.term, info.name, sensor=item.sensor, input_unit=iu)
        stds = _units.convert(eq_std, item.term, info.name, sensor=item.sensor, input_unit=iu)
        uppers = _units.convert(np.atleast_1d(model.upper[item.term]), item.term, info.name,
                                sensor=item.sensor, input_unit=iu)
        sup = (eq > 0) & np.isfinite(eq)
        for i, ax in enumerate(axis_names(model.channels, axes)):
            measured = float(values[i])
            ok = bool(sup[i])
            ratio = measured / item.value if ok else math.nan
            word, remark = verdict(measured if ok else math.nan, float(stds[i]),
                                   item.value, item.limit)
            upper = math.nan if ok else float(uppers[i])
            if not ok and math.isfinite(upper):
                # Not resolved, but bounded: below a maximum the bound passes it.
                word = "pass" if item.limit == "max" and upper <= item.value else word
                remark = f"not resolved, at most {upper:.3g} {info.label} (95 %)"
            rows.append({
                "sensor": item.sensor,
                "term": item.term,
                "quantity": item.quantity,
                "unit": info.name,
                "label": info.label,
                "limit": item.limit,
                "spec": item.value,
                "axis": ax,
                "measured": measured if ok else math.nan,
                "std": float(stds[i]) if ok else math.nan,
                "ratio": ratio,
                "ratio_std": float(stds[i]) / item.value if ok else math.nan,
                "upper": upper,
                "verdict": word,
                "remark": remark,
            })
    if not rows:
        raise ImunoiseValueError(
            f"spec {spec.name!r} specifies nothing for the given models ({sorted(models)})"
        )
    return Comparison(spec=spec, rows=tuple(rows))
