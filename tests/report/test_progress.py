"""The one progress display: shown only when asked, or when stderr is a terminal."""

from imunoise._progress import Progress, byte_bar, wanted


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


def test_total_can_shrink_to_the_steps_that_apply(capsys):
    # the report sets it once it knows which sections the logs have: no empty steps
    with Progress(True, total=9, leave=True) as bar:
        bar.set_total(2)
        bar.step("one")
        bar.step("two")
    err = capsys.readouterr().err
    assert "2/2" in err and "/9" not in err.rsplit("\r", 1)[-1]
