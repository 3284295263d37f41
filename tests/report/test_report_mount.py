"""The report's "Sensors on one mount": with the logs of other sensors on the long log's
mount (``mount=`` / ``--mount``), each sensor's own Allan deviation beside its plain one,
the alignment's losses and the negative-variance taus in words; absent for one log."""

from __future__ import annotations

import re

import imunoise
import numpy as np
import pytest
from helpers.mount import mount_logs
from imunoise import report
from imunoise.cli import main
from imunoise.report.formatting import format_number

FS = 20.0
N = 24_000  # 20 min
TITLE = "Sensors on one mount"


def _logs(white=(0.01, 0.02, 1e-7), **kw):
    return mount_logs(N, FS, white, starts=(200, 0, 450), ends=(N, N - 300, N - 100),
                      clock_offsets=(0.0, 0.0, 0.0), jitter=0.2, seed=21, **kw)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    long, *others = _logs()
    rep = report.build(long, None, tmp_path_factory.mktemp("mount"), spec=None,
                       progress=False, mount=others)
    return rep, rep.markdown.read_text()


def _section(md: str) -> str:
    start = re.search(rf"^## \d+\. {TITLE}$", md, re.M)
    assert start, "no mount section"
    end = md.find("\n## ", start.end())
    return md[start.end():end]


def test_the_section_compares_own_and_plain_and_counts_the_losses(built):
    rep, md = built
    text = _section(md)
    result = rep.own_noise["gyro"]
    assert result.method == "three-cornered hat" and "three-cornered hat" in text
    al = result.aligned
    assert list(al.before) == [250, 450, 0] and list(al.after) == [300, 0, 200]
    assert f"{al.n_samples} samples" in text and al.n_samples == N - 750
    # the alignment table: one row per log with its cut counts
    assert re.search(r"\| long \(<sensor 0>\) \| 0 \| .* \| 250 \| 300 \| 0 \| 0 \|", text)
    # the per-tau table: plain and own of the first tau, as the API gives them
    row = next(line for line in text.splitlines()
               if line.startswith(f"| {format_number(result.taus[0])} |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == format_number(result.plain[0].dev[0, 0])
    assert cells[2] == format_number(result.own[0].dev[0, 0])
    # the long and mount 1 gyros: their own noise, white within 15 % at 1 s
    own = [np.reshape(r.dev, (len(result.taus), -1)) for r in result.own]
    i = int(np.argmin(np.abs(result.taus - 1.0)))
    np.testing.assert_allclose(own[0][i], 0.01 / np.sqrt(result.taus[i]), rtol=0.15)
    np.testing.assert_allclose(own[1][i], 0.02 / np.sqrt(result.taus[i]), rtol=0.15)
    assert any(p.name == "mount_gyro.png" for p in rep.figures)
    # the report's logs are the logs as read, not their aligned copies
    assert [len(log) for log in rep.logs] == [N - 200, N - 300, N - 550]


def test_negative_variances_are_stated_with_their_taus(built):
    rep, md = built
    text = _section(md)
    result = rep.own_noise["gyro"]
    assert result.negative[2].any() and not result.negative[0].any()
    said = re.search(r"\*\*Negative own variance\*\*, mount 2 \(<sensor 2>\): (.*)\. There",
                     text)
    assert said, text
    first = np.flatnonzero(np.reshape(result.negative[2], (len(result.taus), -1))[:, 0])
    listed = said.group(1).split(";")[0]
    assert listed.startswith("X at τ = ")
    assert [format_number(result.taus[k]) for k in first] == listed[len("X at τ = "):-2].split(
        ", ")
    assert "< " in text and "mount 1 (<sensor 1>)" not in text.split("**Negative")[1][:40]


def test_one_log_has_no_mount_section(tmp_path):
    rep = report.build(_logs()[0], None, tmp_path, spec=None, progress=False)
    assert TITLE not in rep.markdown.read_text() and rep.own_noise == {}


def test_the_command_line_takes_the_mount_logs(tmp_path, capsys):
    logs = mount_logs(6000, FS, (0.01, 0.02), starts=(0, 100), ends=(6000, 5900), seed=5,
                      clock_offsets=(1.0, 1.0))
    paths = [str(tmp_path / f"s{i}.bin") for i in range(2)]
    for log, path in zip(logs, paths, strict=True):
        imunoise.write_vn_binary(log, path=path)
    out = tmp_path / "out"
    assert main(["report", paths[0], "--mount", paths[1], "-o", str(out), "--spec", "none"]) == 0
    text = _section((out / "report.md").read_text())
    assert "Groslambert covariance" in text and "s1.bin" in text
    with pytest.raises(imunoise.ImunoiseValueError, match="mount must hold one or two logs"):
        report.build(paths[0], None, tmp_path / "x", mount=[paths[1]] * 3, progress=False)
    assert main(["report", paths[0], "--mount", paths[1], paths[1], paths[1], "-o",
                 str(tmp_path / "y")]) == 2
    assert "mount must hold one or two logs" in capsys.readouterr().err
