"""Look at the HTML report as a reader does: headless Chromium screenshots of every
section at a laptop's size, and the report printed to PDF (pages as PNG).

    python3 tools/screenshot_report.py                      # imunoise demo, then shoot it
    python3 tools/screenshot_report.py out/report.html -o shots/

Needs Chromium (Debian: apt-get install chromium) and, for the PDF pages as PNG,
pdftoppm (apt-get install poppler-utils). Writes ``NN-<section>.png`` per section,
``report.pdf`` and ``report-page-N.png``; prints what it wrote. A reader then opens the
PNGs: text readable at 1366 px, no table cut at the right edge, no figure split
across PDF pages.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

LAPTOP = (1366, 768)
BROWSERS = ("chromium", "chromium-browser", "google-chrome")


def browser() -> str:
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    sys.exit("screenshot_report: no Chromium on PATH (apt-get install chromium)")


def chromium(exe: str, *args: str) -> None:
    command = [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               "--no-first-run", *args]
    subprocess.run(command, check=True, capture_output=True, timeout=120)


def shoot_sections(exe: str, html: Path, out: Path) -> list[Path]:
    """One PNG per section at the laptop's width. Headless Chromium paints only the
    first screenful of a page, so each section is cut into a page of its own (the
    report's head and CSS kept), drawn in a tall window, and the blank rest trimmed."""
    from PIL import Image, ImageChops

    text = html.read_text(encoding="utf-8")
    head, _, body = text.partition("<body>")
    parts = re.split(r'(?=<h2 id=")', body)
    width, height = LAPTOP
    written = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, part in enumerate(parts):
            anchor = re.match(r'<h2 id="([^"]+)"', part)
            name = anchor.group(1) if anchor else "top"
            page = Path(tmp) / f"{k:02d}.html"
            page.write_text(f"{head}<body>{part}</body></html>", encoding="utf-8")
            png = out / f"{k:02d}-{name}.png"
            chromium(exe, f"--window-size={width},{6 * height}", f"--screenshot={png}",
                     page.as_uri())
            with Image.open(png) as img:
                rgb = img.convert("RGB")
                box = ImageChops.difference(rgb, Image.new("RGB", rgb.size, "white")).getbbox()
                bottom = min(rgb.height, (box[3] if box else height) + 24)
                rgb.crop((0, 0, width, max(bottom, 200))).save(png)
            written.append(png)
    return written


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("html", nargs="?", type=Path, help="report.html (default: run imunoise demo)")
    p.add_argument("-o", "--out", type=Path, default=Path("report-screenshots"))
    args = p.parse_args(argv)
    exe = browser()
    html = args.html
    if html is None:
        demo = Path(tempfile.mkdtemp(prefix="imunoise-demo-"))
        subprocess.run([sys.executable, "-m", "imunoise.cli", "demo", "-o", str(demo),
                        "--no-progress"], check=True)
        html = demo / "report.html"
    html = html.resolve()
    args.out.mkdir(parents=True, exist_ok=True)
    written = [*shoot_sections(exe, html, args.out)]
    pdf = args.out / "report.pdf"
    chromium(exe, f"--print-to-pdf={pdf}", "--no-pdf-header-footer", html.as_uri())
    written.append(pdf)
    if shutil.which("pdftoppm"):
        subprocess.run(["pdftoppm", "-r", "45", "-png", str(pdf), str(args.out / "report-page")],
                       check=True)
        written += sorted(args.out.glob("report-page-*.png"))
    print("\n".join(str(w) for w in written))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
