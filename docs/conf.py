"""Sphinx configuration of the imunoise documentation site.

Build: ``python3 tools/check.py docs`` (warnings are errors), or
``python3 -m sphinx -W --keep-going -b html docs docs/_build/html``.
Needs the ``docs`` extra (``pip install -e ".[docs]"``) and an importable imunoise.
"""

from __future__ import annotations

import os
import sys
import urllib.request
from pathlib import Path

import imunoise

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

project = "imunoise"
author = "the imunoise authors"
copyright = "the imunoise authors, MIT licence"
release = imunoise.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "refpages",  # docs/_ext: a page per public name and per CLI subcommand
    "figlinks",  # docs/_ext: figures as wide as the article, linked to the full image
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "gallery/README.txt", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip"]
# The user-guide pages were written for GitHub: their headings may skip a level.
suppress_warnings = ["myst.header"]
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# -- API reference ---------------------------------------------------------------------
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autodoc_member_order = "bysource"
# Signatures show defaults as written (confidence=ONE_SIGMA), not as 0.6826894921370859.
autodoc_preserve_defaults = True
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# -- gallery ---------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"plot_",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "capture_repr": ("_repr_html_", "__repr__"),
    "image_scrapers": ("matplotlib", "figscraper.scrape"),  # docs/_ext: imunoise.plot figures
    "download_all_examples": False,
    "remove_config_comments": True,
    "reference_url": {"imunoise": None},
    "min_reported_time": 0,
}

# -- cross-references to numpy, scipy, matplotlib --------------------------------------
# Intersphinx needs each project's objects.inv. They are fetched once into
# docs/_build/intersphinx/ and read from there afterwards; one that cannot be fetched
# (offline, no proxy) is left out with a note, never a warning: the build must not
# depend on the network. IMUNOISE_DOCS_OFFLINE=1 skips fetching altogether.
INVENTORIES = {
    "python": "https://docs.python.org/3/",
    "numpy": "https://numpy.org/doc/stable/",
    "scipy": "https://docs.scipy.org/doc/scipy/",
    "matplotlib": "https://matplotlib.org/stable/",
}
INVENTORY_CACHE = HERE / "_build" / "intersphinx"


def _cached_inventories() -> dict[str, tuple[str, str]]:
    found = {}
    offline = os.environ.get("IMUNOISE_DOCS_OFFLINE") == "1"
    INVENTORY_CACHE.mkdir(parents=True, exist_ok=True)
    for name, url in INVENTORIES.items():
        local = INVENTORY_CACHE / f"{name}.inv"
        if not local.exists() and not offline:
            try:
                with urllib.request.urlopen(url + "objects.inv", timeout=5) as response:
                    data = response.read()
                tmp = local.with_suffix(".part")
                tmp.write_bytes(data)
                tmp.replace(local)
            except (OSError, ValueError) as exc:
                print(f"intersphinx: {name} inventory not fetched ({exc}); "
                      "its cross-references are plain text")
        if local.exists():
            found[name] = (url, str(local))
    return found


intersphinx_mapping = _cached_inventories()

# -- HTML ------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"imunoise {release}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_static_path = ["_static"]
html_css_files = ["figures.css"]  # sidebars narrow enough for 800 px figures at 1280 px
html_show_sourcelink = False
