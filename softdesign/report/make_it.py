"""The report's "make it" section: the fabrication sheet (``fabrication.md``) of the build, as HTML.

The lines are the sheet's own (:func:`softdesign.pipeline.fabrication_sheet.sheet_lines` of the manifest's
``metrics.fabrication``), so the page and ``fabrication.md`` say the same.  The sheet's Markdown is the small
subset it writes: headings, bullet and numbered lists, tables, paragraphs and ``code``.
"""

from __future__ import annotations

import re
from html import escape
from typing import Any

from softdesign.pipeline.fabrication_sheet import sheet_lines
from softdesign.report.html_page import Section


def make_it_section(manifest: dict[str, Any]) -> Section | None:
    """The section, or None for a build made before the sheet existed."""
    figures = manifest.get("metrics", {}).get("fabrication")
    if not isinstance(figures, dict) or "body_length_mm" not in figures:
        return None
    return Section("make-it", "Make it", embeds=[html_from_markdown(sheet_lines(figures)[1:])])


def _inline(text: str) -> str:
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", escape(text))


def html_from_markdown(lines: list[str]) -> str:
    """HTML of the sheet's Markdown subset (the first heading is the section's own title)."""
    out: list[str] = []
    block = ""  # the open block: "ul", "ol" or "table"
    for line in lines:
        kind = ("ul" if line.startswith("- ") else "ol" if re.match(r"\d+\. ", line)
                else "table" if line.startswith("|") else "")
        if kind != block and block:
            out.append(f"</{block}>")
        if kind and kind != block:
            out.append(f"<{kind}>")
        block = kind
        if kind == "table":
            cells = [c.strip() for c in line.strip("|").split("|")]
            if not all(set(c) <= {"-"} for c in cells):
                tag = "th" if out[-1] == "<table>" else "td"
                out.append("<tr>" + "".join(f"<{tag}>{_inline(c)}</{tag}>" for c in cells) + "</tr>")
        elif kind:
            out.append(f"<li>{_inline(line.split(' ', 1)[1])}</li>")
        elif line.startswith("## "):
            out.append(f"<h3>{_inline(line[3:])}</h3>")
        elif line.strip():
            out.append(f"<p>{_inline(line)}</p>")
    if block:
        out.append(f"</{block}>")
    return "\n".join(out)
