"""Keep the pictures of the report in docs/report.md current: build the report of the bundled
VN-100 capture (and of a simulated 20-minute still log, for the warm-up and the
dynamic Allan deviation, which need a longer record) and copy some of its figures
into docs/img/.

    python3 tools/report_figures.py            # writes docs/img/report-*.png
    python3 tools/report_figures.py -o DIR

The PNGs are reduced to a 256-colour palette (Pillow) to keep the repository small;
the figures themselves are exactly those the report embeds.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: (which report, figure name) -> file under docs/img/
FIGURES = {
    ("bundled", "adev_gyro"): "report-allan-gyro.png",
    ("bundled", "psd_gyro"): "report-psd-gyro.png",
    ("bundled", "hist_gyro"): "report-histogram-gyro.png",
    ("bundled", "events_gyro"): "report-events-gyro.png",
    ("simulated", "dadev_gyro"): "report-dynamic-allan-gyro.png",
    ("simulated", "warmup"): "report-warmup.png",
}
#: Length of the simulated still log: just over the warm-up section's 20 minutes.
SIMULATED_HOURS = 0.34


def build_reports(work: Path) -> dict[str, Path]:
    """Figure folders of the two reports."""
    sys.path.insert(0, str(ROOT / "python"))
    import imunoise
    from imunoise import report
    from imunoise._simulation.log import still_log
    from imunoise.cli import bundled_log

    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        logs = {"bundled": imunoise.read(bundled_log(), fs=40.0),
                "simulated": still_log(SIMULATED_HOURS, 40.0, spec="vn100", seed=0)}
        for name, log in logs.items():
            rep = report.build(log, None, work / name, progress=False)
            out[name] = rep.out_dir / "figures"
    return out


def copy_small(src: Path, dst: Path) -> None:
    """``src`` to ``dst``, as a 256-colour palette PNG when Pillow is there."""
    try:
        from PIL import Image
    except ImportError:
        shutil.copyfile(src, dst)
        return
    with Image.open(src) as img:
        img.convert("RGB").quantize(256).save(dst, optimize=True)


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("-o", "--out", type=Path, default=ROOT / "docs" / "img")
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="imunoise-figures-") as tmp:
        folders = build_reports(Path(tmp))
        for (which, figure), name in FIGURES.items():
            dst = args.out / name
            copy_small(folders[which] / f"{figure}.png", dst)
            print(dst)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
