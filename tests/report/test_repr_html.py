"""Every result object shows as a small, well-formed, escaped HTML table in a notebook
whose numbers are the text repr's (#28 item 4), and every class a public function
returns has one."""

from __future__ import annotations

import inspect
import re
import typing
import warnings
from html.parser import HTMLParser
from importlib import resources
from pathlib import Path

import imunoise
import numpy as np
import pytest
from helpers.mount import mount_logs
from imunoise.recording.recorder import Recording
from imunoise.report.build import Report

LOG = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
#: Tags that have no end tag.
VOID = {"br", "hr", "img", "col", "wbr"}
#: A number as the reprs and tables print it (the mantissa and exponent of "(1.2 ± 0.3)e-5"
#: count as numbers of their own).
NUMBER = re.compile(r"\d+(?:\.\d+)?")
#: Classes a public function returns that are records of a lookup table, not results.
NOT_RESULTS = {"Unit"}


class _Table(HTMLParser):
    """Checks that every tag is closed in order; collects the text."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.open: list[str] = []
        self.tags: list[str] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag not in VOID:
            self.open.append(tag)

    def handle_endtag(self, tag):
        assert self.open and self.open[-1] == tag, f"</{tag}> closes {self.open}"
        self.open.pop()

    def handle_data(self, data):
        self.text.append(data)


def parse(page: str) -> _Table:
    table = _Table()
    table.feed(page)
    table.close()
    assert not table.open, f"unclosed tags {table.open}"
    return table


def _thermal_log():
    fs = 10.0
    t = np.arange(36_000) / fs
    temperature = 30 + 8 * (1 - np.exp(-t / 900))
    gyro = imunoise.simulate(t.size, fs, N=2e-4, channels=3, seed=2)
    gyro += 5e-4 * np.exp(-t / 300)[:, None] + 2e-5 * (temperature - 34)[:, None]
    return imunoise.ImuLog.from_arrays(fs, gyro=gyro, temperature=temperature)


@pytest.fixture(scope="module")
def objects(tmp_path_factory):
    from imunoise import scale

    log = imunoise.read(LOG, fs=40.0)
    # a damaged copy read from bytes: two gaps, issues, and the source "<bytes>" to escape
    lines = LOG.read_bytes().split(b"\n")
    lines[100] = lines[100].replace(b"*", b"*0")
    damaged = imunoise.read(b"\n".join(lines), fs=40.0)
    result = imunoise.adev(log.gyro, log.fs)
    x = imunoise.simulate(96_000, 40.0, N=6e-5, B=2e-5, channels=3, seed=0)
    x[48_000:60_000] *= 2
    dynamic = imunoise.dynamic_adev(x, 40.0, window=300.0, step=60.0)
    thermal_log = _thermal_log()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        model = imunoise.fit(result)
        accel = imunoise.fit(imunoise.adev(log.accel, log.fs))
        out = tmp_path_factory.mktemp("convert")
        conversion = scale.convert(LOG, out / "log.npy", fs=40.0)
    report = Report(out_dir=Path("out"), html=Path("out/report.html"),
                    markdown=Path("out/report.md"), figures=(Path("out/figures/a.png"),) * 3,
                    model_files=(Path("out/noise.json"), Path("out/imu.yaml")),
                    description=imunoise.describe(log), distributions={}, allan={"gyro": result},
                    models={"gyro": model}, logs=(log,))
    units = tmp_path_factory.mktemp("fleet")
    paths = [imunoise.simulate_log(units / f"unit{i}.bin", 0.05, 40.0, format="vn-binary",
                                   seed=i) for i in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fleet = imunoise.fleet(paths, client=False, progress=False)
    mount = imunoise.align(mount_logs(20_000, 40.0, (0.01, 0.02, 0.03), starts=(0, 100, 50),
                                      ends=(19_000, 20_000, 19_500), jitter=0.2))
    return {
        "Fleet": fleet,
        "ImuLog": log, "damaged ImuLog": damaged, "ParseIssues": damaged.issues,
        "Gaps": damaged.gaps, "AllanResult": result, "NoiseModel": model,
        "Components": model.components, "Prediction": model.predict(),
        "Description": imunoise.describe(log), "Distribution": imunoise.distribution(log.mag[:, 0]),
        "Comparison": imunoise.compare({"gyro": model, "accel": accel}),
        "Spectrum": imunoise.psd(x, 40.0), "DynamicAllan": dynamic,
        "Stationarity": dynamic.stationarity, "Events": imunoise.events(log),
        "Warmup": imunoise.warmup(thermal_log), "Thermal": imunoise.thermal(thermal_log),
        "Conversion": conversion, "Report": report,
        "Plan": imunoise.plan(model, fs=40.0),
        "Recording": Recording(path="still.vn", bytes=1_234_567, seconds=4.5, outages=(),
                               identity={}, settings={}, previous={}, restored=True),
        "ThreeCorneredHat": imunoise.three_cornered_hat(
            *(x[:20_000, 0] + x[:20_000, k] for k in range(3)), 40.0),
        "Aligned": mount, "OwnNoise": imunoise.own_noise(mount),
    }


NAMES = ("ImuLog", "damaged ImuLog", "ParseIssues", "Gaps", "AllanResult", "NoiseModel",
         "Components", "Prediction", "Description", "Distribution", "Comparison", "Spectrum",
         "DynamicAllan", "Stationarity", "Events", "Warmup", "Thermal", "Conversion", "Report",
         "Plan", "Recording", "ThreeCorneredHat", "Fleet", "Aligned", "OwnNoise")


@pytest.mark.parametrize("name", NAMES)
def test_html_is_a_well_formed_table_with_the_reprs_numbers(objects, name):
    obj = objects[name]
    page = obj._repr_html_()
    assert page.startswith("<table") and page.endswith("</table>")
    table = parse(page)
    assert "caption" in table.tags and table.tags.count("tr") >= 2  # a header and a row
    text = " ".join(table.text)
    assert type(obj).__name__ in text
    shown = set(NUMBER.findall(text))
    # every number of the text repr, except the count of parts it had no room for
    numbers = NUMBER.findall(re.sub(r"… \d+ more", "", repr(obj)))
    assert numbers, repr(obj)
    missing = [n for n in numbers if n not in shown]
    assert not missing, f"{missing} of {obj!r} not in the table: {text}"


def test_html_escapes_text(objects):
    page = objects["damaged ImuLog"]._repr_html_()
    assert "&lt;bytes&gt;" in page and "<bytes>" not in page
    assert "<bytes>" in " ".join(parse(page).text)


def test_model_table_rounds_like_the_repr(objects):
    model = objects["NoiseModel"]
    page = model._repr_html_()
    n = imunoise.display.format_value(model.value("N")[0], model.std("N")[0])
    assert f"N={n}" in repr(model) and f"<td>{n}</td>" in page


def test_every_class_a_public_function_returns_has_an_html_table():
    functions = set()
    for name in imunoise.__all__:
        obj = getattr(imunoise, name)
        members = ([getattr(obj, m) for m in getattr(obj, "__all__", [])]
                   if inspect.ismodule(obj) else
                   [getattr(obj, m) for m in dir(obj) if not m.startswith("_")]
                   if inspect.isclass(obj) else [obj])
        functions |= {f for f in members if inspect.isfunction(f) or inspect.ismethod(f)}
    returned = set()
    for f in functions:
        try:
            hint = typing.get_type_hints(f).get("return")
        except NameError:  # annotations naming types imported only for checking
            continue
        for cls in typing.get_args(hint) or (hint,):
            if inspect.isclass(cls) and cls.__module__.startswith("imunoise"):
                returned.add(cls)
    assert {"AllanResult", "NoiseModel", "ImuLog", "Conversion", "Report"} <= {
        c.__name__ for c in returned}
    lacking = sorted(c.__name__ for c in returned
                     if not hasattr(c, "_repr_html_") and c.__name__ not in NOT_RESULTS)
    assert not lacking, f"no _repr_html_: {lacking}"
    assert {c for c in NAMES if " " not in c} >= {
        c.__name__ for c in returned if c.__name__ not in NOT_RESULTS}
