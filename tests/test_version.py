"""One version (#28): Cargo.toml's, which maturin writes into the wheel's metadata and the
compiled core carries as ``imunoise.__version__``; ``imunoise --version`` prints it.
(tools/check_wheel.py checks the built wheel's metadata against both.)"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import imunoise
import pytest
from imunoise import cli

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
#: Semantic versioning 2.0.0 (a pre-release and build suffix allowed).
SEMVER = re.compile(r"^(0|[1-9]\d*)\.(0|[1-9]\d*)\.(0|[1-9]\d*)"
                    r"(-[0-9A-Za-z.-]+)?(\+[0-9A-Za-z.-]+)?$")


def test_version_is_cargo_tomls_and_semantic():
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text())["package"]["version"]
    assert imunoise.__version__ == cargo
    assert SEMVER.match(imunoise.__version__)


def test_pyproject_takes_the_version_from_cargo():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert "version" not in project and "version" in project["dynamic"]


def test_cli_version_is_the_package_version(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"imunoise {imunoise.__version__}"


def test_changelog_has_an_unreleased_section_and_this_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in text
    released = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", text, re.M)
    assert released and all(SEMVER.match(v) for v in released)
    assert imunoise.__version__ in released
