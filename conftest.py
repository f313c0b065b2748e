"""Settings for every test, including the docstring examples collected from ``src/``.

The examples run in a fresh temporary folder each, so nothing they write lands in the
repository, and figures draw on the non-interactive Agg backend.
"""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(autouse=True)
def _doctest_in_tmp(request: pytest.FixtureRequest, tmp_path, monkeypatch) -> None:
    if isinstance(request.node, pytest.DoctestItem):
        monkeypatch.chdir(tmp_path)
