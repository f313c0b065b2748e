"""The layering of docs/architecture.rst: imports between subpackages go down, never up.

Each subpackage (or top-level module) has a layer; a module imports from its own
subpackage and from lower layers only, so there is no circle between subpackages and no
arrow back up, not even inside a function: a result draws itself with its own subpackage's
``figures`` module and :mod:`motionhyst.core.plotting` (imported inside its ``plot`` method,
so that computing never loads matplotlib); :mod:`motionhyst.present` holds the paper's
figures and the report, above everything they draw.
Inside a subpackage, too, no two modules import each other, however indirectly: every
import counts (at the top, inside a function, or for type checking only).  And a module
holds one concept: none is longer than :data:`MAX_LINES`.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

LAYERS = [("core",), ("io",), ("hysteresis",), ("plants",), ("controllers",),
          ("analysis", "time"), ("scan", "identify"), ("scenario",), ("study",), ("present",),
          ("cli",), ("entry",)]
LAYER = {part: i for i, parts in enumerate(LAYERS) for part in parts}

#: The longest a module may be; a longer one holds more than one concept: split it.
MAX_LINES = 900


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


def _modules() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its own name)."""
    found = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).with_suffix("")
        found[".".join(rel.parts[:-1] if rel.parts[-1] == "__init__" else rel.parts)] = path
    return found


def _module_graph() -> dict[str, set[str]]:
    """``{module: modules it imports}``; ``from pkg import mod`` is an import of ``pkg.mod``.

    The package's own ``__init__`` is left out: it imports nothing at run time (its
    names load on first use) and the old module paths it keeps name every module.
    """
    modules = _modules()
    graph: dict[str, set[str]] = {m: set() for m in modules if m != "motionhyst"}
    for module in graph:
        for node in ast.walk(ast.parse(modules[module].read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                targets = [f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in modules
                           else node.module for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            graph[module] |= {t for t in targets if t in graph and t != module}
    return graph


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    circles = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while group[-1:] != [v]:
                group.append(stack.pop())
            if len(group) > 1:
                circles.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return circles


def test_the_circle_finder_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _circles(graph) == [["a", "b", "c"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_no_two_modules_import_each_other():
    circles = _circles(_module_graph())
    assert not circles, "modules in a circle of imports (move what they share down):\n" + (
        "\n".join(" <-> ".join(c) for c in circles))


def test_no_module_is_longer_than_the_limit():
    long = {str(path.relative_to(SRC)): n for path in SRC.rglob("*.py")
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines (split them by concept): {long}"


def test_every_subpackage_has_a_layer():
    parts = {_part(m) for _, m, _, _ in _imports()} - {""}
    assert parts <= set(LAYER), f"give these a layer in LAYERS: {sorted(parts - set(LAYER))}"


def test_imports_go_down():
    up = []
    for where, module, imported, function in _imports():
        here, there = _part(module), _part(imported)
        if here == "" or here == there:
            continue
        if LAYER[there] >= LAYER[here]:
            up.append(f"{where}: {module} imports {imported}"
                      + (f" (in {function})" if function else ""))
    assert not up, "imports that go up or sideways:\n" + "\n".join(up)
