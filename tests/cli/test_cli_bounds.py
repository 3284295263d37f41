"""Every numeric option of the command line is bounded: NaN, infinities, 1e300 and
the like are refused while the arguments are parsed, with one line that names the
option, its bound and the value, and exit status 2."""

from __future__ import annotations

import argparse

import pytest
from imunoise.cli import _build_parser, main

#: Commands whose options another part of the code bounds (the recorder and the
#: emulator check theirs against the sensor's limits).
ELSEWHERE = {"record", "emulate"}


def _subparsers():
    parser = _build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def _numeric_options():
    """(command, option, nargs) of every option whose value is a number."""
    out = []
    for name, p in _subparsers().items():
        if name in ELSEWHERE:
            continue
        for a in p._actions:
            if not a.option_strings or a.type is None:
                continue
            try:
                a.type("1")
            except (argparse.ArgumentTypeError, ValueError, TypeError):
                continue  # not a number (CHANNEL=COLS, ...)
            if a.type is str:
                continue
            out.append((name, a.option_strings[-1], a.nargs))
    return out


def _argv(command: str, option: str, nargs, value: str) -> list[str]:
    """A command line that parses but for ``option value``."""
    p = _subparsers()[command]
    argv = [command]
    for a in p._actions:
        if not a.option_strings and a.nargs != "?":
            argv.append("x")
        elif a.required and a.option_strings:
            argv += [a.option_strings[-1], "out.csv"]
    if isinstance(nargs, int):
        return argv + [option] + [value] * nargs
    return argv + [f"{option}={value}"]  # "-1" after a space would be an option


NUMERIC = _numeric_options()


def test_every_numeric_option_has_a_bounded_type():
    plain = [(c, o) for c, o, _ in NUMERIC
             for a in _subparsers()[c]._actions if o in a.option_strings
             and not a.choices  # choices bound it
             and (a.type in (int, float) or a.type.__name__ == "_positive_float")]
    assert not plain, f"options without an upper bound: {plain}"
    assert ("plan", "--fs", None) in NUMERIC and ("psd", "--bins", None) in NUMERIC


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e300", "-1e300", "-1",
                                   "9" * 40])
@pytest.mark.parametrize(("command", "option", "nargs"), NUMERIC,
                         ids=[f"{c} {o}" for c, o, _ in NUMERIC])
def test_out_of_bound_values_are_one_line_errors(command, option, nargs, value, capsys,
                                                 tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # should a value pass, its command writes here
    if isinstance(nargs, int) and value.startswith("-"):
        pytest.skip("argparse takes a leading '-' of a multi-value option for an option")
    code = main(_argv(command, option, nargs, value))
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"imunoise: error: argument {option}"), err
    assert repr(value) in lines[0] or f"invalid choice: {value}" in lines[0], err
    assert "invalid parse value" not in err, err  # the type failed inside itself


@pytest.mark.parametrize(("argv", "message"), [
    # each overflowed or ran out of memory past the parser before
    (["plan", "--fs", "1e300"], "argument --fs: must be in [0.001, 1e+06] Hz; got '1e300'"),
    (["plan", "--fs", "1e-300"], "argument --fs: must be in [0.001, 1e+06] Hz"),
    (["dadev", "x", "--step", "1e300"], "argument --step: must be in (0, 1e+09] s"),
    (["psd", "x", "--bins", "1000000000000"], "argument --bins: must be in [1, 1000]"),
    (["convert", "x", "-o", "y.npy", "--chunk-mb", "1e300"],
     "argument --chunk-mb: must be in [0.01, 65536] MB"),
    (["simulate", "-o", "x.txt", "--seed", "-1"], "argument --seed: must be in [0, "),
    (["plan", "--confidence", "1"], "argument --confidence: must be in (0, 1); got '1'"),
    (["fit", "x", "--bootstrap", "1e3"], "argument --bootstrap: expected an integer"),
])
def test_named_bounds(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err, err


def test_values_inside_the_bounds_still_run(capsys):
    assert main(["plan", "--fs", "1e6", "--sensor", "gyro"]) == 0
    assert "plan VectorNav VN-100 gyro" in capsys.readouterr().out


def test_bootstrap_bound_of_the_log_names_the_option(capsys):
    from imunoise.cli import bundled_log

    # 13,223 samples: at most 15,125 replicates, said before any analysis
    assert main(["fit", str(bundled_log()), "--fs", "40", "--bootstrap", "20000"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == ("imunoise: error: --bootstrap must be at most 15,125 replicates "
                           "for this log's 13,223 samples (at most 200,000,000 simulated "
                           "samples are held at once); got 20,000")
