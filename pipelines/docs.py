"""Write docs/case-file.md and docs/commands.md from the code (softdesign/cli/reference.py): `python pipelines/docs.py`.

`--check` writes nothing and exits 1 when a page differs from what the code gives (the tests run the same check).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"


def pages() -> dict[Path, str]:
    """Each reference page's path and its text, as the code gives them now."""
    import typer

    from softdesign.cli import app
    from softdesign.cli.reference import case_reference_markdown, command_reference_markdown
    from softdesign.config import Case

    return {DOCS / "case-file.md": case_reference_markdown(Case),
            DOCS / "commands.md": command_reference_markdown(typer.main.get_command(app))}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--check", action="store_true", help="compare only; exit 1 when a page is out of date")
    args = parser.parse_args()
    stale = []
    for path, text in pages().items():
        if path.is_file() and path.read_text(encoding="utf-8") == text:
            continue
        stale.append(path)
        if not args.check:
            path.parent.mkdir(exist_ok=True)
            path.write_text(text, encoding="utf-8")
            print(f"wrote {path.relative_to(REPO)}")
    if args.check and stale:
        print("out of date: " + ", ".join(str(p.relative_to(REPO)) for p in stale) + "; run python pipelines/docs.py",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
