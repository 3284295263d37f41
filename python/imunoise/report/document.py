"""The report as a document: a list of blocks (headings, paragraphs, tables,
figures) rendered both to Markdown (figures linked) and to one self-contained HTML
file (plain HTML + CSS, figures embedded as data URIs, no JavaScript)."""

from __future__ import annotations

import base64
import html as _html
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Doc"]


@dataclass
class Doc:
    """Blocks in reading order; paragraph text may hold `code` spans."""

    blocks: list = field(default_factory=list)

    def h(self, level: int, text: str) -> None:
        self.blocks.append(("h", level, text))

    def p(self, text: str) -> None:
        self.blocks.append(("p", text))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[str]], caption="", *,
              collapsed: bool = False) -> None:
        """A table; ``collapsed``: a long reference table (a full Allan table) the
        reader opens on demand (``<details>``, its caption the summary), so the
        body keeps the tables decisions are read from."""
        self.blocks.append(("table", list(header), [list(r) for r in rows], caption,
                            collapsed))

    def figure(self, png: Path, caption: str) -> None:
        self.blocks.append(("figure", png, caption))

    def contents(self) -> None:
        """The table of contents: a list of every level-2 heading, wherever they
        are added (before or after this block), each a link to its section."""
        self.blocks.append(("toc",))

    def _sections(self) -> list[str]:
        return [b[2] for b in self.blocks if b[0] == "h" and b[1] == 2]

    def markdown(self, out_dir: Path) -> str:
        """Markdown text; figures linked relative to ``out_dir``."""
        lines = []
        for b in self.blocks:
            if b[0] == "h":
                lines += ["#" * b[1] + " " + b[2], ""]
            elif b[0] == "p":
                lines += [b[1], ""]
            elif b[0] == "toc":
                lines += ["**Contents**", ""]
                lines += [f"- [{t}](#{_md_slug(t)})" for t in self._sections()]
                lines.append("")
            elif b[0] == "table":
                _, header, rows, caption, collapsed = b
                if collapsed:
                    lines += ["<details>", f"<summary>{caption} ({len(rows)} rows)</summary>",
                              ""]
                elif caption:
                    lines += [f"*{caption}*", ""]
                lines.append("| " + " | ".join(header) + " |")
                lines.append("|" + "|".join("---" for _ in header) + "|")
                lines += ["| " + " | ".join(r) + " |" for r in rows]
                lines.append("")
                if collapsed:
                    lines += ["</details>", ""]
            elif b[0] == "figure":
                rel = b[1].relative_to(out_dir).as_posix()
                lines += [f"![{b[2]}]({rel})", "", f"*{b[2]}*", ""]
        return "\n".join(lines)

    def html(self, title: str) -> str:
        """One HTML page with the CSS inline and every figure embedded."""
        e = _html.escape
        body = []
        for b in self.blocks:
            if b[0] == "h":
                anchor = f' id="{_slug(b[2])}"' if b[1] == 2 else ""
                body.append(f"<h{b[1]}{anchor}>{e(b[2])}</h{b[1]}>")
            elif b[0] == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif b[0] == "toc":
                items = "".join(f'<li><a href="#{_slug(t)}">{e(t)}</a></li>'
                                for t in self._sections())
                body.append(f'<nav class="toc"><strong>Contents</strong><ol>{items}</ol></nav>')
            elif b[0] == "table":
                _, header, rows, caption, collapsed = b
                cap = f"<caption>{e(caption)}</caption>" if caption and not collapsed else ""
                # columns of words (quantity, verdict, remark) read left-aligned,
                # columns of numbers right-aligned
                cells = [[r[i] for r in rows if i < len(r) and r[i] not in _NEUTRAL]
                         for i in range(len(header))]
                left = [i > 0 and bool(c) and not any(_NUMERIC.match(v) for v in c)
                        for i, c in enumerate(cells)]
                cls = [' class="l"' if flag else "" for flag in left]
                th = "".join(f"<th{cls[i]}>{e(h)}</th>" for i, h in enumerate(header))
                trs = "".join(
                    "<tr>" + "".join(f"<td{cls[i] if i < len(cls) else ''}>{e(c)}</td>"
                                     for i, c in enumerate(r)) + "</tr>" for r in rows
                )
                # A short table is kept on one printed page; a long one flows
                # across pages with its header repeated.
                keep = " keep" if len(rows) <= _KEEP_TOGETHER_ROWS else ""
                table = (f'<div class="tw{keep}"><table>{cap}<thead><tr>{th}</tr></thead>'
                         f"<tbody>{trs}</tbody></table></div>")
                if collapsed:
                    table = (f"<details><summary>{e(caption)} ({len(rows)} rows)</summary>"
                             f"{table}</details>")
                body.append(table)
            elif b[0] == "figure":
                data = base64.b64encode(b[1].read_bytes()).decode("ascii")
                body.append(
                    f'<figure><img src="data:image/png;base64,{data}" alt="{e(b[2])}">'
                    f"<figcaption>{e(b[2])}</figcaption></figure>"
                )
        return _HTML.format(title=e(title), css=_CSS, body="\n".join(body))


#: A cell that reads as a number: "1.2", "(3.4 ± 0.1)e-3", "−5", "< 10", "typ. 0.2".
_NUMERIC = re.compile(r"^(typ\.\s*)?[(<>~−-]?\s*[\d.]")

#: Cells that say nothing about their column's kind.
_NEUTRAL = frozenset({"", "—", "not resolved"})

#: Tables with at most this many rows are not split across printed pages.
_KEEP_TOGETHER_ROWS = 20


def _slug(heading: str) -> str:
    """``"4. Attitude (yaw, pitch, roll)"`` -> ``"attitude-yaw-pitch-roll"``: a
    section's anchor, so report.html#allan-deviation links to it."""
    words = re.findall(r"[a-z]+", heading.lower())
    return "-".join(words) or "section"


def _md_slug(heading: str) -> str:
    """The anchor GitHub (and most Markdown renderers) give a heading:
    ``"4. Attitude (yaw, pitch, roll)"`` -> ``"4-attitude-yaw-pitch-roll"``."""
    kept = re.sub(r"[^\w\- ]", "", heading.lower())
    return kept.replace(" ", "-")


def _inline(text: str) -> str:
    """Escape, turn `code` spans into <code>, **bold** into <strong> and
    ``[text](https://…)`` links into <a>."""
    parts = _html.escape(text, quote=False).split("`")
    out = "".join(f"<code>{p}</code>" if i % 2 else _LINK.sub(
        r'<a href="\2">\1</a>', _BOLD.sub(r"<strong>\1</strong>", p))
        for i, p in enumerate(parts))
    return out


_LINK = re.compile(r"\[([^\]]+)\]\((https?://[^)\s]+)\)")
_BOLD = re.compile(r"\*\*(.+?)\*\*")


_CSS = """
:root{--fg:#1d2330;--mut:#5b6475;--bd:#d9dee7;--bg:#fff;--hd:#f3f5f9;--ac:#1f5fbf}
*{box-sizing:border-box}
body{font:15px/1.55 -apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;color:var(--fg);
background:var(--bg);max-width:1100px;margin:2rem auto;padding:0 1.25rem}
h1{font-size:1.9rem;margin:.2rem 0 .6rem;border-bottom:3px solid var(--ac);padding-bottom:.4rem}
h2{font-size:1.35rem;margin-top:2.4rem;border-bottom:1px solid var(--bd);padding-bottom:.25rem}
h3{font-size:1.1rem;margin-top:1.6rem;color:var(--mut)}
p{margin:.5rem 0 .9rem}
code{font:13px/1.4 ui-monospace,SFMono-Regular,Menlo,Consolas,monospace;background:var(--hd);
padding:.05rem .3rem;border-radius:3px}
.tw{overflow-x:auto;margin:.6rem 0 1.2rem}
table{border-collapse:collapse;font-size:13px;font-variant-numeric:tabular-nums}
caption{caption-side:top;text-align:left;color:var(--mut);font-style:italic;padding:.2rem 0}
th,td{border:1px solid var(--bd);padding:.3rem .45rem;text-align:right;white-space:nowrap}
th{white-space:normal;vertical-align:bottom}
details{margin:.4rem 0 1rem}
summary{cursor:pointer;color:var(--mut);font-style:italic}
th{background:var(--hd);font-weight:600}
td:first-child,th:first-child,td.l,th.l{text-align:left}
tbody tr:nth-child(even){background:#fafbfd}
nav.toc{background:var(--hd);border:1px solid var(--bd);border-radius:4px;
padding:.5rem 1rem;margin:1rem 0 1.4rem;display:inline-block}
nav.toc ol{list-style:none;margin:.3rem 0 0;padding:0;columns:2;column-gap:2.5rem}
nav.toc li{padding:.1rem 0;break-inside:avoid}
nav.toc a{color:var(--ac);text-decoration:none}
nav.toc a:hover{text-decoration:underline}
figure{margin:1rem 0 1.6rem}
img{max-width:100%;height:auto;border:1px solid var(--bd);border-radius:4px}
figcaption{color:var(--mut);font-size:13px;margin-top:.3rem}
footer{margin-top:3rem;color:var(--mut);font-size:12px;border-top:1px solid var(--bd);
padding-top:.6rem}
@media print{
body{max-width:none;margin:0;padding:0;font-size:11pt}
h2,h3{break-after:avoid}
figure,caption,tr,.keep{break-inside:avoid}
thead{display:table-header-group}
img{max-height:24cm;width:auto;max-width:100%}
.tw{overflow:visible}
table{font-size:8pt}
th,td{white-space:normal;padding:.15rem .3rem}
}
"""

_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title><style>{css}</style></head>
<body>
{body}
</body></html>
"""
