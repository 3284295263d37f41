"""Every figure of a page links to its full-size image (click to enlarge).

Sphinx links an image to its file only when the image is scaled
(``html_scaled_image_link``); a figure here is given ``width: 100%`` of the article,
which both makes it as wide as the article allows and has Sphinx add that link.
Gallery thumbnails keep their size: they already link to their example.
"""

from __future__ import annotations

from docutils import nodes

#: Where sphinx-gallery keeps thumbnails: images that link to their example instead.
THUMBNAILS = "/images/thumb/"


def widen(app, doctree, docname) -> None:
    for image in doctree.findall(nodes.image):
        uri = image.get("uri", "")
        if THUMBNAILS in "/" + uri or isinstance(image.parent, nodes.reference):
            continue
        if any(key in image for key in ("width", "height", "scale")):
            continue  # sized by its author: Sphinx links it already
        image["width"] = "100%"


def setup(app):
    app.connect("doctree-resolved", widen)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
