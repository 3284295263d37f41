"""A sphinx-gallery image scraper for imunoise's figures.

``imunoise.plot`` returns :class:`matplotlib.figure.Figure` objects that pyplot does
not track (a library must not open windows or keep figures alive), so the stock
matplotlib scraper, which asks pyplot, sees none. This one saves every Figure that a
code block of the example left in a variable (alone or in a list or tuple) and that an
earlier block of the same example had not shown yet.

Each is written as a plain ``image`` directive, as wide as the article (at least
:data:`MIN_WIDTH_PX` pixels of image behind it) and so linked by Sphinx to the full-size
file: click to enlarge. Its alternative text is the figure's title.
"""

from __future__ import annotations

import math
import os
from pathlib import PurePosixPath

#: Resolution of the saved figures, dots per inch of the figure's own size.
DPI = 110
#: Fewest pixels across a saved figure: the article shows it at least this wide at
#: 1280 px (docs/_static/figures.css), and a narrower image would be stretched.
MIN_WIDTH_PX = 800

#: The figures already shown, for the example being run (the figures themselves, so
#: that a freed figure's id reused by a new one is not mistaken for it).
_shown: dict[str, list] = {}


def _figures(value):
    from matplotlib.figure import Figure

    if isinstance(value, Figure):
        yield value
    elif isinstance(value, (list, tuple)):
        for item in value:
            if isinstance(item, Figure):
                yield item


def scrape(block, block_vars, gallery_conf, **kwargs) -> str:
    source = str(block_vars["src_file"])
    for other in [s for s in _shown if s != source]:
        del _shown[other]  # a new example: let the previous one's figures go
    shown = _shown.setdefault(source, [])
    new = []
    for value in list(block_vars["example_globals"].values()):
        for fig in _figures(value):
            if not any(fig is f for f in shown + new):
                new.append(fig)
    rst = []
    for fig, path in zip(new, block_vars["image_path_iterator"], strict=False):
        fig.savefig(path, dpi=max(DPI, math.ceil(MIN_WIDTH_PX / fig.get_figwidth())))
        where = PurePosixPath(os.path.relpath(path, gallery_conf["src_dir"]))
        rst.append(f"\n.. image:: /{where}\n   :alt: {_title(fig)}\n"
                   "   :class: sphx-glr-single-img\n   :width: 100%\n")
    shown.extend(new)
    return "".join(rst) + ("\n" if rst else "")


def _title(fig) -> str:
    """The figure's title, or its first panel's, as one line of text."""
    texts = [fig._suptitle.get_text() if fig._suptitle is not None else ""]
    texts += [ax.get_title() for ax in fig.axes]
    return " ".join(next((t for t in texts if t.strip()), "figure").split())
