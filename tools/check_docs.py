"""Build the documentation site warning-free and check that nothing public lacks a page.

    python3 tools/check_docs.py          # what `python3 tools/check.py docs` runs

Runs Sphinx (warnings are errors; every warning is listed before the build fails),
which executes the gallery and generates a page per public name and per CLI subcommand
(docs/_ext/refpages.py); then checks that the HTML of each of those pages, and of each
gallery example, was written, and that a reader can use its figures and links:

- every figure image is at least 800 px wide and its ``<img>`` links to the full-size
  file (click to enlarge);
- every relative link of every page leads to a file of the site (a user with the wheel
  has no ``rust/`` or ``benches/`` folder to follow a link into);
- with Chromium on PATH, each page of the user guide and the gallery drawn in a 1280 px
  window: its figures at least 800 px wide, the right-hand contents inside the window
  (no entry cut at its edge), every code block either wrapped or scrollable (never cut
  off). Without Chromium this part is skipped with a note.

Output: docs/_build/html/index.html.
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
HTML = DOCS / "_build" / "html"


def expected_pages() -> list[Path]:
    """The HTML every build must contain: API, CLI and gallery pages."""
    sys.path.insert(0, str(DOCS / "_ext"))
    import refpages

    objects = refpages.public_objects()
    pages = [HTML / refpages.API_DIR / f"{refpages.page_name(n)}.html" for n in objects]
    pages += [HTML / refpages.CLI_DIR / f"{name}.html"
              for name in refpages.subcommands(refpages.cli_parser())]
    pages += [HTML / "auto_examples" / f"{p.stem}.html"
              for p in sorted((DOCS / "gallery").glob("plot_*.py"))]
    return pages


#: Fewest pixels across a figure, in its file and as drawn in a LAYOUT_WIDTH window.
MIN_FIGURE_PX = 800
#: Window width of the layout check: a laptop's.
LAYOUT_WIDTH = 1280
#: Generated pages that hold no figure of ours and only theme links.
SKIPPED_PAGES = ("genindex.html", "search.html", "py-modindex.html")
ANCHOR = re.compile(r'<a\b[^>]*\bhref="([^"]*)"[^>]*>', re.S)
IMAGE = re.compile(r'<img\b[^>]*\bsrc="([^"]*)"[^>]*>', re.S)
LINKED_IMAGE = re.compile(r'<a\b[^>]*\bhref="([^"]*)"[^>]*>\s*<img\b[^>]*\bsrc="([^"]*)"', re.S)


def pages() -> list[Path]:
    return sorted(p for p in HTML.rglob("*.html")
                  if "_static" not in p.parts and p.name not in SKIPPED_PAGES)


def is_figure(src: str) -> bool:
    """An image of the article (not a theme icon, not a gallery thumbnail)."""
    return "_images/" in src and "_thumb" not in src


def figure_problems() -> list[str]:
    """Figures narrower than MIN_FIGURE_PX, or not linked to their full-size file."""
    from PIL import Image

    problems = []
    for png in sorted((HTML / "_images").glob("*.png")):
        if "_thumb" in png.name:
            continue
        with Image.open(png) as img:
            if img.width < MIN_FIGURE_PX:
                problems.append(f"_images/{png.name} is {img.width} px wide "
                                f"(at least {MIN_FIGURE_PX})")
    for page in pages():
        text = page.read_text(encoding="utf-8")
        linked = {src for href, src in LINKED_IMAGE.findall(text) if href == src}
        for src in IMAGE.findall(text):
            if is_figure(src) and src not in linked:
                problems.append(f"{page.relative_to(HTML)}: {src} does not link to itself "
                                "(click to enlarge)")
    return problems


def link_problems() -> list[str]:
    """Relative links that lead to no file of the built site."""
    problems = []
    for page in pages():
        for href in ANCHOR.findall(page.read_text(encoding="utf-8")):
            href = html.unescape(href)
            if not href or re.match(r"[a-z][a-z0-9+.-]*:", href) or href.startswith("#"):
                continue  # another site, mail, or this page
            target = (page.parent / href.split("#")[0].split("?")[0]).resolve()
            if not target.exists() or HTML.resolve() not in target.parents:
                problems.append(f"{page.relative_to(HTML)}: link {href!r} leads to no page "
                                "of the site")
    return problems


#: Measures the page as drawn and appends the numbers to it as JSON.
PROBE = """<script>
window.addEventListener('load', () => setTimeout(() => {
  const vw = document.documentElement.clientWidth;
  const box = e => e.getBoundingClientRect();
  const toc = document.querySelector('.bd-sidebar-secondary');
  const shown = toc && getComputedStyle(toc).display !== 'none';
  const out = {
    vw,
    figures: [...document.querySelectorAll('article img')]
      .filter(i => i.getAttribute('src').includes('_images/') &&
                   !i.getAttribute('src').includes('_thumb'))
      .map(i => [i.getAttribute('src'), Math.round(box(i).width)]),
    toc: shown ? [Math.round(box(toc).right), toc.scrollWidth - toc.clientWidth,
                  ...[...toc.querySelectorAll('a')].map(a => Math.round(box(a).right))] : [],
    code: [...document.querySelectorAll('article pre')].filter(p => {
      const style = getComputedStyle(p), parent = getComputedStyle(p.parentElement);
      const scrolls = ['auto', 'scroll'].includes(style.overflowX) ||
                      ['auto', 'scroll'].includes(parent.overflowX);
      return p.scrollWidth > p.clientWidth + 1 && !scrolls;
    }).map(p => p.textContent.slice(0, 60)),
  };
  const el = document.createElement('pre');
  el.id = 'imunoise-layout';
  el.textContent = JSON.stringify(out);
  document.body.appendChild(el);
}, 200));
</script>"""


def layout_problems(browser: str) -> list[str]:
    """The user guide's and the gallery's pages, drawn by headless Chromium
    LAYOUT_WIDTH px wide (the generated API and CLI pages share their layout)."""
    problems = []
    drawn = [p for p in pages() if p.parent in (HTML, HTML / "auto_examples")]
    # two Chromiums at a time: the check waits on the browser, not on Python
    with ThreadPoolExecutor(max_workers=2) as pool:
        for found in pool.map(lambda page: _layout(browser, page), drawn):
            problems += found
    print(f"layout: {len(drawn)} pages drawn at {LAYOUT_WIDTH} px")
    return problems


def _layout(browser: str, page: Path) -> list[str]:
    """The layout problems of one page."""
    problems = []
    name = page.relative_to(HTML)
    # the probe is a copy beside the page, so that its relative links still resolve
    with tempfile.NamedTemporaryFile("w", suffix=".html", dir=page.parent,
                                     encoding="utf-8", delete=False) as probe:
        probe.write(page.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"))
    try:
        dom = subprocess.run(
            [browser, "--headless=new", "--no-sandbox", "--disable-gpu",
             "--hide-scrollbars", f"--window-size={LAYOUT_WIDTH},900",
             "--virtual-time-budget=10000", "--dump-dom", Path(probe.name).as_uri()],
            capture_output=True, text=True, timeout=180).stdout
    finally:
        Path(probe.name).unlink()
    found = re.search(r'<pre id="imunoise-layout">(.*?)</pre>', dom, re.S)
    if found is None:
        return [f"{name}: Chromium drew no layout to measure"]
    seen = json.loads(html.unescape(found.group(1)))
    for src, width in seen["figures"]:
        if width < MIN_FIGURE_PX:
            problems.append(f"{name}: {src} drawn {width} px wide at {LAYOUT_WIDTH} px "
                            f"(at least {MIN_FIGURE_PX})")
    if seen["toc"] and (max(seen["toc"][:1] + seen["toc"][2:]) > seen["vw"]
                        or seen["toc"][1] > 0):
        problems.append(f"{name}: the right-hand contents are cut at {LAYOUT_WIDTH} px")
    for text in seen["code"]:
        problems.append(f"{name}: a code line is cut off, neither wrapped nor "
                        f"scrollable: {text!r}")
    return problems


#: The modules the docs extra installs (pyproject.toml).
NEEDED = ("sphinx", "numpydoc", "pydata_sphinx_theme", "myst_parser", "sphinx_gallery")


def main() -> int:
    import importlib.util

    missing_modules = [m for m in NEEDED if importlib.util.find_spec(m) is None]
    if missing_modules:
        print(f"check_docs: {', '.join(missing_modules)} not installed; "
              "install the docs extra: python3 -m pip install -e '.[docs]'", file=sys.stderr)
        return 2
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
               str(DOCS), str(HTML)]
    print(f"$ {' '.join(command)}", flush=True)
    code = subprocess.call(command, cwd=ROOT)
    if code:
        return code
    missing = [p for p in expected_pages() if not p.exists()]
    for page in missing:
        print(f"check_docs: no page {page.relative_to(ROOT)}", file=sys.stderr)
    # every gallery example draws: a page without a figure lost its scraper
    blank = [p for p in (HTML / "auto_examples").glob("plot_*.html")
             if (DOCS / "gallery" / f"{p.stem}.py").exists() and "<img" not in p.read_text()]
    for page in blank:
        print(f"check_docs: no figure on {page.relative_to(ROOT)}", file=sys.stderr)
    problems = figure_problems() + link_problems()
    browser = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")
                    if shutil.which(b)), None)
    if browser:
        problems += layout_problems(browser)
    else:
        print("check_docs: no Chromium on PATH: the layout at 1280 px is not checked")
    for problem in problems:
        print(f"check_docs: {problem}", file=sys.stderr)
    if missing or blank or problems:
        return 1
    print(f"docs: {HTML.relative_to(ROOT) / 'index.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
