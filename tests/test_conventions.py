"""imunoise's own warning kinds: every warning is an ImunoiseWarning, so one filter
silences them all and nothing else; every call site names its kind."""

from __future__ import annotations

import ast
import warnings
from pathlib import Path

import imunoise
import numpy as np
import pytest
from imunoise import errors

PACKAGE = Path(imunoise.__file__).parent


def test_one_filter_silences_every_imunoise_warning_and_nothing_else(tmp_path):
    log = tmp_path / "x.csv"
    np.savetxt(log, np.random.default_rng(0).normal(size=(500, 3)), delimiter=",",
               header="gyro_x,gyro_y,gyro_z", comments="")
    x = np.random.default_rng(1).normal(size=2000)
    x[100:120] = np.nan
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        warnings.filterwarnings("ignore", category=imunoise.ImunoiseWarning)
        imunoise.read(log)                  # no fs: assumed
        imunoise.adev(x, 10.0, gaps="splice")  # gaps
        warnings.warn("someone else's", UserWarning, stacklevel=1)
    assert [str(w.message) for w in seen] == ["someone else's"]
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        imunoise.read(log)
        imunoise.adev(x, 10.0, gaps="splice")
    kinds = {w.category for w in seen}
    assert imunoise.AssumptionWarning in kinds and imunoise.GapWarning in kinds
    assert all(issubclass(k, imunoise.ImunoiseWarning) for k in kinds)


def test_the_kinds_keep_their_builtin_bases():
    assert issubclass(imunoise.CoverageWarning, RuntimeWarning)
    assert issubclass(imunoise.ImunoiseDeprecationWarning, DeprecationWarning)
    assert issubclass(imunoise.ImunoiseWarning, UserWarning)
    for cls in (imunoise.ParseError, imunoise.ImunoiseValueError):
        assert issubclass(cls, ValueError) and issubclass(cls, imunoise.ImunoiseError)
    assert issubclass(imunoise.ImunoiseTypeError, TypeError)


def _warn_calls():
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.relative_to(PACKAGE).as_posix() == "_support/warn.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr == "warn"
                    and isinstance(node.func.value, ast.Name)
                    and node.func.value.id in ("warnings", "_warn")):
                yield path, node


@pytest.mark.parametrize("builtin", ["UserWarning", "RuntimeWarning", "DeprecationWarning"])
def test_no_call_site_names_a_builtin_kind(builtin):
    """A site passes one of imunoise.errors' kinds (or forwards a caught warning's)."""
    bad = []
    for path, node in _warn_calls():
        names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        if builtin in names:
            bad.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not bad, bad


def test_direct_warnings_name_an_imunoise_kind():
    """warnings.warn (not _warn.warn, which maps built-in kinds) must name one."""
    kinds = set(errors.__all__)
    for path, node in _warn_calls():
        if node.func.value.id != "warnings":
            continue
        category = node.args[1] if len(node.args) > 1 else next(
            (k.value for k in node.keywords if k.arg == "category"), None)
        assert isinstance(category, ast.Name) and category.id in kinds, (
            f"{path.relative_to(PACKAGE)}:{node.lineno}")


@pytest.mark.parametrize("call", [
    lambda: imunoise.adev(np.ones(100), -1.0),                      # Python's check
    lambda: imunoise.adev(np.ones(100), 1.0, taus="fortnightly"),  # Python's check
    lambda: imunoise._core.simd.force("avx1024"),                  # the Rust binding's
    lambda: imunoise.fit(np.ones(3)),                              # a wrong type
    lambda: imunoise.read(b"no imu here\n1,2\n"),                  # a reader's
])
def test_one_except_catches_every_imunoise_error(call):
    with pytest.raises(imunoise.ImunoiseError) as caught:
        call()
    assert isinstance(caught.value, ValueError | TypeError)


def test_no_module_raises_a_bare_builtin_error():
    """Every raise site names an imunoise class (a test, not a convention on trust)."""
    bad = []
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and node.exc is not None:
                exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
                if isinstance(exc, ast.Name) and exc.id in ("ValueError", "TypeError"):
                    bad.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not bad, bad
