"""The documentation's reference pages (#28): every public name of ``imunoise.__all__``
and every CLI subcommand gets a page, generated from the package itself; the gallery
draws every figure the report draws."""

from __future__ import annotations

import argparse
import importlib.util
import re
import sys
from pathlib import Path

import imunoise
import pytest
from imunoise import cli

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def refpages():
    spec = importlib.util.spec_from_file_location("refpages", DOCS / "_ext" / "refpages.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["refpages"] = module
    spec.loader.exec_module(module)
    yield module
    del sys.modules["refpages"]


@pytest.fixture(scope="module")
def pages(refpages, tmp_path_factory):
    source = tmp_path_factory.mktemp("docs")
    (source / "api").mkdir()
    (source / "api" / "removed_name.rst").write_text("stale")
    refpages.write_pages(source)
    return source


def _parser_commands() -> set[str]:
    parser = cli._build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return set(sub.choices)


def test_every_public_name_has_an_api_page(refpages, pages):
    index = (pages / "api" / "index.rst").read_text()
    for name in imunoise.__all__:
        page = pages / "api" / f"{refpages.page_name(name)}.rst"
        text = page.read_text()
        assert text.startswith(f"imunoise.{name}\n"), name
        directive = re.search(r"^\.\. (auto\w+|py:data)::\s+(\S+)", text, re.M)
        assert directive and directive.group(2).endswith(name), (name, text)
        assert f"<{refpages.page_name(name)}>" in index, name
    assert not (pages / "api" / "removed_name.rst").exists()  # stale pages go


def test_api_pages_use_the_directive_of_their_kind(pages):
    assert ".. autofunction:: adev" in (pages / "api" / "adev.rst").read_text()
    assert ".. autoclass:: NoiseModel" in (pages / "api" / "NoiseModel.rst").read_text()
    assert ".. autoexception:: ParseError" in (pages / "api" / "ParseError.rst").read_text()
    assert ".. automodule:: imunoise.plot" in (pages / "api" / "plot.rst").read_text()
    version = (pages / "api" / "version.rst").read_text()
    assert f":value: {imunoise.__version__!r}" in version


def test_every_subcommand_has_a_cli_page(refpages, pages):
    commands = _parser_commands()
    assert {"report", "adev", "fit", "demo"} <= commands
    written = {p.stem for p in (pages / "cli").glob("*.rst")} - {"index"}
    assert written == commands
    index = (pages / "cli" / "index.rst").read_text()
    for name in commands:
        assert f":doc:`{name}`" in index
        text = (pages / "cli" / f"{name}.rst").read_text()
        assert text.startswith(f"imunoise {name}\n")
        assert f".. program:: imunoise {name}" in text


def test_cli_pages_list_every_option_with_its_help(pages):
    parser = cli._build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    fit = (pages / "cli" / "fit.rst").read_text()
    for action in sub.choices["fit"]._actions:
        for option in action.option_strings:
            assert re.search(rf"^\.\. option:: .*{re.escape(option)}\b", fit, re.M), option
    assert ".. option:: --bootstrap REPLICATES" in fit
    assert "parametric bootstrap" in fit
    # %(default)s is expanded, reST specials escaped
    report = (pages / "cli" / "report.rst").read_text()
    assert "(default: imunoise-report)" in report
    assert "%(default)" not in report


def test_escape_keeps_text_literal(refpages):
    assert refpages._escape("a_b *c* `d` |e| \\") == r"a\_b \*c\* \`d\` \|e\| \\"


def test_gallery_draws_every_figure_of_the_report():
    drawn = set()
    for path in (ROOT / "python" / "imunoise" / "report").glob("*.py"):
        drawn |= set(re.findall(r"\bplot\.(\w+)\(", path.read_text()))
    drawn -= {"save", "style", "plain_ticks"}  # not figures
    assert {"allan", "histograms", "time_series"} <= drawn
    gallery = "".join(p.read_text() for p in (DOCS / "gallery").glob("plot_*.py"))
    shown = set(re.findall(r"\bplot\.(\w+)\(", gallery))
    assert drawn <= shown, f"the gallery does not draw {sorted(drawn - shown)}"
