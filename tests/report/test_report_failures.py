"""A report that fails or is interrupted leaves no skeleton; a wrong spec is found
before any work; datasheet names do not hide behind folders."""

from __future__ import annotations

import json

import imunoise
import numpy as np
import pytest
from imunoise import datasheet, report
from imunoise.cli import main
from imunoise.report import folder

# a 100-s log resolves no rate random walk: not what these tests look at
pytestmark = pytest.mark.filterwarnings("ignore:the .* model has no resolved K")


def _small_log():
    rng = np.random.default_rng(7)
    n = 4000
    return imunoise.ImuLog.from_arrays(
        40.0, gyro=np.round(rng.normal(0, 1e-3, (n, 3)), 6),
        accel=np.round(rng.normal(0, 0.01, (n, 3)) + [0, 0, -9.81], 3),
        source="<test arrays>")


@pytest.fixture
def fail_at_the_end(monkeypatch):
    """The report fails after every figure was written, as late as it can."""
    def boom(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(folder, "settle", boom)


def test_a_failed_report_into_a_new_folder_leaves_nothing(tmp_path, fail_at_the_end):
    out = tmp_path / "new" / "report"
    with pytest.raises(KeyboardInterrupt):
        report.build(_small_log(), out_dir=out, spec=None, progress=False)
    # before: the folder, its manifest and figures/ with the figures made so far
    assert not (tmp_path / "new").exists()
    assert list(tmp_path.iterdir()) == []


def test_a_failed_report_into_a_users_folder_removes_only_its_own_files(
        tmp_path, fail_at_the_end):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    with pytest.raises(KeyboardInterrupt):
        report.build(_small_log(), out_dir=out, spec=None, progress=False, force=True)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_a_failed_update_of_a_report_keeps_the_previous_one(tmp_path, monkeypatch):
    out = tmp_path / "rep"
    report.build(_small_log(), out_dir=out, spec=None, progress=False)
    listed = json.loads((out / folder.MANIFEST).read_text())["files"]

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(folder, "settle", boom)
    with pytest.raises(RuntimeError):
        report.build(_small_log(), out_dir=out, spec=None, progress=False)
    assert json.loads((out / folder.MANIFEST).read_text())["files"] == listed
    assert all((out / name).is_file() for name in listed)


def test_report_checks_the_spec_before_reading_the_logs(tmp_path, capsys):
    out = tmp_path / "r"
    # the log does not exist: the spec's error comes first, so nothing was read
    code = main(["report", str(tmp_path / "missing.txt"), "--spec",
                 str(tmp_path / "nonexistent.toml"), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip() == (f"imunoise: error: spec file "
                           f"'{tmp_path / 'nonexistent.toml'}' does not exist")
    assert not out.exists()


def test_a_folder_named_like_a_datasheet_does_not_hide_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "vn100").mkdir()
    assert datasheet.load_spec("vn100").name == datasheet.load_spec("VN100").name
    assert main(["plan", "--spec", "vn100", "--sensor", "gyro"]) == 0
    assert "VN-100 gyro" in capsys.readouterr().out


def test_a_file_named_like_a_datasheet_is_read(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "vn100").write_text(
        'name = "bench unit"\n[[gyro]]\nterm = "N"\nvalue = 0.2\nunit = "deg/sqrt(h)"\n')
    assert datasheet.load_spec("vn100").name == "bench unit"


@pytest.mark.parametrize(("spec", "message"), [
    ("nope", "spec must be one of ['vn100'] or a .toml path; got 'nope'"),
    ("vn100.toml", "spec file 'vn100.toml' does not exist"),
    ("folder.toml", "spec file 'folder.toml' is not a file"),
])
def test_spec_errors_name_the_spec(tmp_path, monkeypatch, spec, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.toml").mkdir()
    with pytest.raises(ValueError) as exc:
        datasheet.load_spec(spec)
    assert str(exc.value) == message
