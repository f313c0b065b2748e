"""Check every link inside the built HTML site: the page it names exists, and so does its anchor.

``make docs`` runs it after the HTML build (``python docs/checklinks.py docs/_build/html``).
Links out of the site (``http:``, ``https:``, ``mailto:``) are counted but not fetched: the
build machines have no network.  The theme's assets (``_static/``) and the highlighted source
pages (``_modules/``, whose back-links Sphinx's viewcode writes) are not checked.  Exit 1
with one line per broken link.
"""

from __future__ import annotations

import re
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

SKIPPED = ("_static", "_modules")
"""Folders of the site whose pages are not checked (their links, not links to them)."""


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("name"):
            self.ids.add(a["name"])
        for key in ("href", "src"):
            if tag in ("a", "img", "link", "script") and a.get(key):
                self.links.append(a[key])


def check(site: Path) -> tuple[list[str], int, int]:
    """``(broken links, internal links checked, external links skipped)`` of the site."""
    pages: dict[Path, _Page] = {}
    for path in sorted(site.rglob("*.html")):
        page = _Page()
        page.feed(path.read_text(encoding="utf-8", errors="replace"))
        pages[path.resolve()] = page
    broken, internal, external = [], 0, 0
    for path, page in pages.items():
        if path.relative_to(site.resolve()).parts[0] in SKIPPED:
            continue
        for link in page.links:
            parts = urlsplit(link)
            if parts.scheme or link.startswith("//"):
                external += 1
                continue
            internal += 1
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if not target.exists():
                broken.append(f"{path.relative_to(site.resolve())}: {link}: no such file")
            elif parts.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else set()
                if unquote(parts.fragment) not in ids and not re.fullmatch(r"top", parts.fragment):
                    broken.append(f"{path.relative_to(site.resolve())}: {link}: no such anchor")
    return broken, internal, external


def main(argv: list[str]) -> int:
    site = Path(argv[1] if len(argv) > 1 else "docs/_build/html")
    broken, internal, external = check(site)
    for line in broken:
        print(f"broken link: {line}", file=sys.stderr)
    print(f"links: {internal} inside the site checked, {len(broken)} broken; "
          f"{external} outside it not fetched (no network)")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
