"""The report's folder: refused when it is someone else's, stale figures removed."""

import json
import os

import imunoise
import numpy as np
import pytest
from imunoise import report
from imunoise.cli import main
from imunoise.report.folder import MANIFEST

FS = 40.0


def _still(n=2400, seed=0):
    rng = np.random.default_rng(seed)
    return imunoise.ImuLog.from_arrays(
        FS, gyro=rng.normal(0, 1e-3, (n, 3)),
        accel=rng.normal(0, 0.01, (n, 3)) + [0.0, 0.0, -9.81], source="<still>")


def test_a_folder_that_is_not_a_report_needs_force(tmp_path, capsys):
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("mine")
    log = tmp_path / "still.csv"
    x = _still()
    np.savetxt(log, np.column_stack([np.arange(len(x)) / FS, x.gyro, x.accel]), delimiter=",",
               header="time,gx,gy,gz,ax,ay,az", comments="")
    assert main(["report", str(log), "-o", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--force" in err[0]
    assert sorted(p.name for p in out.iterdir()) == ["chapter1.tex"]
    with pytest.raises(ValueError, match="not a report"):
        report.build(x, out_dir=out, progress=False)


def test_a_report_replaces_its_own_files_removes_stale_ones_and_keeps_others(tmp_path):
    out = tmp_path / "rep"
    old = os.umask(0o022)
    try:
        first = report.build(_still(), out_dir=out, spec=None, progress=False)
    finally:
        os.umask(old)
    listed = json.loads((out / MANIFEST).read_text())["files"]
    assert "report.html" in listed and "figures/adev_gyro.png" in listed
    assert (out / "noise.json").stat().st_mode & 0o777 == 0o644  # was 0600
    # an earlier report's figure that this report does not draw, and a user's note
    (out / "figures" / "old_section.png").write_bytes(b"png")
    (out / MANIFEST).write_text(json.dumps({"imunoise_report": 1,
                                            "files": [*listed, "figures/old_section.png",
                                                      "../outside.txt"]}))
    (tmp_path / "outside.txt").write_text("not the report's")
    (out / "notes.txt").write_text("mine")
    second = report.build(_still(seed=1), out_dir=out, spec=None, progress=False)
    assert not (out / "figures" / "old_section.png").exists()
    assert (tmp_path / "outside.txt").exists()  # the manifest cannot reach outside
    assert (out / "notes.txt").read_text() == "mine"
    assert {p.name for p in second.figures} == {p.name for p in first.figures}
    assert not [p for p in out.rglob(".*") if p.name != MANIFEST]


def test_a_report_that_fails_to_read_its_log_creates_nothing(tmp_path, capsys):
    out = tmp_path / "never"
    assert main(["report", str(tmp_path / "missing.txt"), "-o", str(out)]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not out.exists()
