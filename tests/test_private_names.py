"""A private name stays in its module: no ``from motionhyst.x import _y`` in another module.

A name starting with ``_`` is free to change with its module; another module that
imports it ties the two together unseen (issue 20).  What another module needs is
public in its home module.  A private *module* (``hysteresis/_kernels.py``) is
private to its subpackage: only modules of the same subpackage import it.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _subpackage(module: str) -> str:
    """``motionhyst.hysteresis`` for ``motionhyst.hysteresis._kernels``, ``motionhyst`` for a
    top-level module."""
    parts = module.split(".")
    return ".".join(parts[:2]) if len(parts) > 2 else parts[0]


def _imports() -> list[tuple[str, int, str, str]]:
    """``(file, line, importing module, imported dotted name)`` of every motionhyst import."""
    out = []
    for path in sorted(SRC.rglob("*.py")):
        here = _module_name(path)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module \
                    and node.module.split(".")[0] == "motionhyst":
                out += [(str(path.relative_to(SRC)), node.lineno, here, f"{node.module}.{a.name}")
                        for a in node.names]
            elif isinstance(node, ast.Import):
                out += [(str(path.relative_to(SRC)), node.lineno, here, a.name)
                        for a in node.names if a.name.split(".")[0] == "motionhyst"]
    return out


def _private(part: str) -> bool:
    return part.startswith("_") and not (part.startswith("__") and part.endswith("__"))


def test_the_scan_sees_the_package():
    assert len(_imports()) > 100


def test_no_private_name_is_imported_from_another_module():
    bad = [f"{f}:{line}: {name}" for f, line, here, name in _imports()
           if _private(name.rsplit(".", 1)[1]) and name.rsplit(".", 1)[0] != here]
    assert not bad, "private names imported from another module:\n" + "\n".join(bad)


def test_private_modules_are_imported_inside_their_subpackage_only():
    bad = []
    for f, line, here, name in _imports():
        parts = name.split(".")[:-1]  # the module imported from (or the parent of an import)
        for i, part in enumerate(parts):
            if _private(part):
                owner = ".".join(parts[:i])  # the package the private module belongs to
                if not (here == owner or here.startswith(owner + ".")):
                    bad.append(f"{f}:{line}: {name}")
                break
    assert not bad, "private modules imported from another subpackage:\n" + "\n".join(bad)
