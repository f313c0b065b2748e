"""``make docs``'s link check (``docs/checklinks.py``) finds a missing page and a missing anchor."""

from __future__ import annotations

import importlib.util
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent / "docs"


def _checklinks():
    spec = importlib.util.spec_from_file_location("checklinks", DOCS / "checklinks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_broken_pages_and_anchors_are_found(tmp_path):
    (tmp_path / "a.html").write_text(
        '<a id="top-of-a" href="b.html#here">b</a><a href="b.html#gone">b</a>'
        '<a href="missing.html">m</a><a href="#top-of-a">self</a><a href="https://x.org">x</a>')
    (tmp_path / "b.html").write_text('<p id="here">b</p><img src="fig.png">')
    (tmp_path / "fig.png").write_bytes(b"")
    broken, internal, external = _checklinks().check(tmp_path)
    assert sorted(broken) == ["a.html: b.html#gone: no such anchor",
                              "a.html: missing.html: no such file"]
    assert (internal, external) == (5, 1)
