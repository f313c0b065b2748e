"""The layering of docs/architecture.rst: imports between subpackages go down, never up.

Each subpackage (or top-level module) has a layer; a module imports from its own
subpackage and from lower layers only, so there is no circle between subpackages and no
arrow back up.  The one arrow up on purpose: a result's ``plot`` method imports
:mod:`motionhyst.present` inside itself, so that computing never loads matplotlib.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

LAYERS = [("core", "io"), ("hysteresis",), ("plants", "controllers"), ("loop",),
          ("analysis", "time"), ("scan", "identify"), ("scenario",), ("study",), ("present",),
          ("cli",)]
LAYER = {part: i for i, parts in enumerate(LAYERS) for part in parts}


def _part(module: str) -> str:
    """``analysis`` for ``motionhyst.analysis.steady``; the package itself is ``""``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _imports():
    """``(file:line, importing module, imported module, enclosing function or None)``."""
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).with_suffix("")
        module = ".".join(rel.parts[:-1] if rel.parts[-1] == "__init__" else rel.parts)
        tree = ast.parse(path.read_text(encoding="utf-8"))
        enclosing: dict[int, str] = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                for inner in ast.walk(node):
                    if inner is not node:
                        enclosing[id(inner)] = node.name  # the innermost function wins
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            for name in names:
                if name.startswith("motionhyst."):
                    yield (f"{rel}.py:{node.lineno}", module, name, enclosing.get(id(node)))


def test_every_subpackage_has_a_layer():
    parts = {_part(m) for _, m, _, _ in _imports()} - {""}
    assert parts <= set(LAYER), f"give these a layer in LAYERS: {sorted(parts - set(LAYER))}"


def test_imports_go_down():
    up = []
    for where, module, imported, function in _imports():
        here, there = _part(module), _part(imported)
        if here == "" or here == there:
            continue
        if there == "present" and function == "plot":
            continue  # a result draws itself: present is imported only when it does
        if LAYER[there] >= LAYER[here]:
            up.append(f"{where}: {module} imports {imported}"
                      + (f" (in {function})" if function else ""))
    assert not up, "imports that go up or sideways:\n" + "\n".join(up)
