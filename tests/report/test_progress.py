"""The one progress display: shown only when asked, or when stderr is a terminal."""

import sys
import warnings

from imunoise._support.progress import Progress, byte_bar, wanted


def test_step_bar_only_when_asked(capsys):
    with Progress(True, total=2) as bar:
        bar.step("one")
    assert "one" in capsys.readouterr().err
    with Progress(None, total=2) as quiet:  # stderr is not a terminal under pytest
        quiet.step("two")
        assert not quiet.shown and quiet.bytes("reading") is None
    assert capsys.readouterr().err == ""
    assert wanted(True) and not wanted(False) and not wanted(None)


def test_byte_bar_closes_itself(capsys):
    update = byte_bar("reading x")
    update(50, 100)
    update(100, 100)
    assert "reading x" in capsys.readouterr().err


def _lines_with(err: str, word: str) -> list[str]:
    """The pieces of stderr (split at newlines and carriage returns) holding ``word``."""
    return [piece for line in err.split("\n") for piece in line.split("\r") if word in piece]


def test_warnings_print_above_the_bar_not_inside_it(capsys, monkeypatch):
    # --progress into a pipe: the bar's line and a warning used to share one line. The
    # warnings are shown as the CLI shows them (one line each), not recorded by pytest.
    def one_line(message, category, filename, lineno, file=None, line=None):
        print(f"imunoise: warning: {message}", file=file or sys.stderr)

    monkeypatch.setattr(warnings, "showwarning", one_line)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        with Progress(True, total=3, leave=True) as bar:
            bar.step("one")
            warnings.warn("something odd", UserWarning, stacklevel=1)
            bar.step("two")
            update = byte_bar("reading x")
            update(10, 100)
            warnings.warn("while reading", UserWarning, stacklevel=1)
            update(100, 100)
    err = capsys.readouterr().err
    for word in ("something odd", "while reading"):
        pieces = _lines_with(err, word)
        assert pieces and all("%|" not in p and "it/s" not in p for p in pieces), pieces
    # the bars hand the warnings back when they close
    assert warnings.showwarning is one_line


def test_report_bar_total_never_changes(tmp_path, capsys):
    """The report counts the sections that apply before its bar starts (it went from
    14 to 12 steps mid-run)."""
    import re
    from importlib import resources

    from imunoise import report

    log = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
    report.build(str(log), None, tmp_path / "r", fs=40.0, progress=True)
    err = capsys.readouterr().err
    totals = {int(t) for t in re.findall(r"\d+/(\d+) \[", err)}
    assert len(totals) == 1, totals
