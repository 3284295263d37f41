"""Build the documentation site warning-free and check that nothing public lacks a page.

    python3 tools/check_docs.py          # what `python3 tools/check.py docs` runs

Runs Sphinx (warnings are errors; every warning is listed before the build fails),
which executes the gallery and generates a page per public name and per CLI subcommand
(docs/_ext/refpages.py); then checks that the HTML of each of those pages, and of each
gallery example, was written. Output: docs/_build/html/index.html.
"""

from __future__ import annotations

import subprocess
import sys
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
    if missing or blank:
        return 1
    print(f"docs: {HTML.relative_to(ROOT) / 'index.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
