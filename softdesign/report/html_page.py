"""The report page: one HTML file with inline CSS that shows the images kept beside it.

Nothing is fetched from the network (no scripts, fonts or style sheets from
elsewhere); every image is a relative link to a file in the same folder.
Every text is HTML-escaped.  Key figures carry ``data-pointer`` (the JSON
pointer into ``manifest.json``) and ``data-value`` (the exact JSON value) on
their value cell.  The page holds no date or time: the same build gives the
same bytes.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from html import escape
from typing import Any

from softdesign.report.plotting import Picture
from softdesign.report.tables import Check, KeyFigure, format_value

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 1.5em auto;
       max-width: 1240px; padding: 0 1em; color: #222; line-height: 1.4; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.8em; }
nav a { margin-right: 1em; } figure { margin: 1em 0; } img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption, .note { color: #555; font-size: 0.92em; } .note { margin: 0.4em 0; }
table { border-collapse: collapse; margin: 0.8em 0 1.4em; font-size: 0.9em; }
th, td { border: 1px solid #ddd; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f4f4f4; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.hash { font-family: ui-monospace, Menlo, Consolas, monospace; font-size: 0.85em; word-break: break-all; }
td.pass { color: #1a7f37; font-weight: 600; } td.fail { color: #c62828; font-weight: 600; }
caption { text-align: left; font-weight: 600; padding-bottom: 0.3em; }
.banner { border: 3px solid #c62828; background: #fdecea; color: #8e0000; padding: 0.6em 1em; margin: 1em 0;
          font-size: 1.05em; } .banner h2 { border: 0; margin: 0 0 0.3em; color: #c62828; }
.allclear { border: 2px solid #1a7f37; background: #e9f7ee; padding: 0.5em 1em; margin: 1em 0; }
details { margin: 0.4em 0 1.2em; } summary { cursor: pointer; color: #333; }
.verdict { padding: 0.6em 1em; margin: 1em 0 0.4em; border: 3px solid; } .verdict .headline { font-size: 1.25em;
           font-weight: 700; margin: 0.1em 0 0.3em; } .verdict ul { margin: 0.2em 0; }
.verdict.ok { border-color: #1a7f37; background: #e9f7ee; } .verdict.bad { border-color: #c62828; background: #fdecea; }
.verdict.bad .headline { color: #8e0000; } .verdict.open { border-color: #9a6700; background: #fff8e1; }
.tally { color: #555; margin: 0.2em 0 1em; }
"""


@dataclass(frozen=True)
class Cell:
    """One table cell: its text, a CSS class and extra attributes (name, value)."""

    text: str
    css: str = ""
    attributes: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Table:
    """A captioned table of cells."""

    caption: str
    header: tuple[str, ...]
    rows: Sequence[tuple[Cell, ...]]
    folded: str = ""  #: when set, the table is folded away in a <details> with this summary text


@dataclass(frozen=True)
class Section:
    """One numbered part of the page."""

    anchor: str
    title: str
    notes: list[str] = field(default_factory=list)
    pictures: list[Picture] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    embeds: list[str] = field(default_factory=list)  #: HTML fragments made by the package (never user text)


def key_figure_table(figures: list[KeyFigure]) -> Table:
    """Key figures with their exact value and manifest pointer on the value cell."""
    rows = []
    for f in figures:
        numeric = isinstance(f.value, (int, float)) and not isinstance(f.value, bool)
        exact = json.dumps(f.value, allow_nan=False)
        trace = (("data-pointer", f.pointer), ("data-value", exact))
        value = Cell(format_value(f.value), "num" if numeric else "", trace)
        rows.append((Cell(f.label), value, Cell(f.unit), Cell(f.pointer, "hash")))
    return Table("Key figures of manifest.json", ("figure", "value", "unit", "where in manifest.json"), rows)


CHECK_HEADER = ("subject", "check", "found", "required", "status")


def check_table(checks: list[Check]) -> Table:
    """Every check with its status, failures first (in their order), then the passed ones."""
    ordered = [c for c in checks if not c.passed] + [c for c in checks if c.passed]
    rows = [
        (Cell(c.subject), Cell(c.name), Cell(c.found), Cell(c.required),
         Cell("pass", "pass") if c.passed else Cell("FAIL", "fail"))
        for c in ordered
    ]
    passed = sum(c.passed for c in checks)
    return Table(f"Checks: {passed} of {len(checks)} passed", CHECK_HEADER, rows)


def compact_check_tables(checks: list[Check]) -> list[Table]:
    """The checks in at most three tables: the failures (when any), one row per kind of check with its tally,
    and every passed check (a row each: subject, figure found, limit) folded away in a <details>."""
    failed = [c for c in checks if not c.passed]
    passed = [c for c in checks if c.passed]
    tables = []
    if failed:
        rows = check_table(failed).rows
        tables.append(Table(f"Checks FAILED: {len(failed)} of {len(checks)}", CHECK_HEADER, rows))
    kinds: dict[str, list[Check]] = {}
    for c in checks:
        kinds.setdefault(c.name, []).append(c)
    tally = [(Cell(name), Cell(str(sum(c.passed for c in group)), "num"), Cell(str(len(group)), "num"),
              Cell("all passed", "pass") if all(c.passed for c in group) else Cell("some failed", "fail"))
             for name, group in kinds.items()]
    tables.append(Table(f"Checks: {len(passed)} of {len(checks)} passed", ("check", "passed", "of", ""), tally))
    if passed:
        tables.append(Table(f"The {len(passed)} passed checks", CHECK_HEADER, check_table(passed).rows,
                            folded=f"every passed check, one row each ({len(passed)})"))
    return tables


def plain_table(
    caption: str, header: tuple[str, ...], rows: Sequence[tuple[str, ...]], css: tuple[str, ...] = ()
) -> Table:
    """A table of plain texts; ``css`` gives a class per column."""
    classes = css or ("",) * len(header)
    return Table(caption, header, [tuple(Cell(text, c) for text, c in zip(row, classes, strict=True)) for row in rows])


def _attributes(pairs: tuple[tuple[str, str], ...]) -> str:
    return "".join(f' {name}="{escape(value, quote=True)}"' for name, value in pairs)


def _table_html(table: Table) -> str:
    head = "".join(f"<th>{escape(h)}</th>" for h in table.header)
    body = []
    for row in table.rows:
        cells = "".join(
            f"<td{_attributes(((('class', c.css),) if c.css else ()) + c.attributes)}>{escape(c.text)}</td>"
            for c in row
        )
        body.append(f"<tr>{cells}</tr>")
    html = f"<table><caption>{escape(table.caption)}</caption>\n<tr>{head}</tr>\n" + "\n".join(body) + "\n</table>"
    return f"<details><summary>{escape(table.folded)}</summary>\n{html}\n</details>" if table.folded else html


def table_html(table: Table) -> str:
    """One table (folded in a <details> when ``table.folded``) as HTML."""
    return _table_html(table)


def _picture_html(p: Picture) -> str:
    return (
        f'<figure><img src="{escape(p.name, quote=True)}" width="{p.size[0]}" height="{p.size[1]}" '
        f'alt="{escape(p.title, quote=True)}">\n<figcaption>{escape(p.caption)}</figcaption></figure>'
    )


def _section_html(number: int, section: Section) -> str:
    parts = [f'<section id="{escape(section.anchor, quote=True)}">', f"<h2>{number} {escape(section.title)}</h2>"]
    parts += [f'<p class="note">{escape(note)}</p>' for note in section.notes]
    for picture in section.pictures:
        parts += [f"<h3>{escape(picture.title)}</h3>", _picture_html(picture)]
    parts += section.embeds
    parts += [_table_html(t) for t in section.tables]
    return "\n".join(parts + ["</section>"])


def banner_html(warnings: Sequence[str], notes: Sequence[str] = ()) -> str:
    """Every warning in one box at the top that cannot be missed, or a plain line that there are none; then the
    notes (what was done on the way), folded."""
    if not warnings:
        html = '<p class="allclear" id="warnings">No warnings.</p>'
    else:
        items = "".join(f"<li>{escape(w)}</li>" for w in warnings)
        html = (f'<div class="banner" id="warnings" role="alert"><h2>{len(warnings)} warning(s)</h2>'
                f"<ul>{items}</ul></div>")
    if notes:
        items = "".join(f"<li>{escape(n)}</li>" for n in notes)
        html += f'<details class="notes" id="notes"><summary>{len(notes)} note(s)</summary><ul>{items}</ul></details>'
    return html


def render_page(title: str, summary: list[str], sections: list[Section], top: str = "") -> str:
    """The whole page as text; ``top`` (HTML made by the package: banner, summary table) follows the summary lines."""
    nav = " ".join(
        f'<a href="#{escape(s.anchor, quote=True)}">{k} {escape(s.title)}</a>' for k, s in enumerate(sections, 1)
    )
    body = "\n".join(_section_html(k, s) for k, s in enumerate(sections, 1))
    lines = "".join(f"<p>{escape(line)}</p>" for line in summary)
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">\n<title>{escape(title)}</title>\n'
        f"<style>{STYLE}</style>\n</head>\n<body>\n<h1>{escape(title)}</h1>\n{lines}\n{top}<nav>{nav}</nav>\n{body}\n"
        "</body>\n</html>\n"
    )


def referenced_files(page: str) -> list[str]:
    """Every ``src`` and ``href`` value of the page except in-page anchors (for checks and tests)."""
    from html.parser import HTMLParser

    found: list[str] = []

    class _Links(HTMLParser):
        def handle_starttag(self, tag: str, attrs: list[tuple[str, Any]]) -> None:
            found.extend(v for k, v in attrs if k in ("src", "href") and v and not v.startswith("#"))

    _Links().feed(page)
    return found
