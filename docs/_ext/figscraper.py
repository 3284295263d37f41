"""A sphinx-gallery image scraper for imunoise's figures.

``imunoise.plot`` returns :class:`matplotlib.figure.Figure` objects that pyplot does
not track (a library must not open windows or keep figures alive), so the stock
matplotlib scraper, which asks pyplot, sees none. This one saves every Figure that a
code block of the example left in a variable (alone or in a list or tuple) and that an
earlier block of the same example had not shown yet.
"""

from __future__ import annotations

from pathlib import PurePosixPath

from sphinx_gallery.scrapers import figure_rst

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
        path = PurePosixPath(path)
        fig.savefig(path, dpi=110)
        rst.append(figure_rst([path], gallery_conf["src_dir"]))
    shown.extend(new)
    return "".join(rst)
