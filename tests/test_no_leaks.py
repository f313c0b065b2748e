"""Tests and examples leave the interpreter as they found it (review B17 L3, L5): no test
puts a folder on ``sys.path`` for the rest of the session (pytest's own import of the tests'
folder, or ``monkeypatch.syspath_prepend``, is how a test imports a sibling), and no example
of a docstring swaps ``sys.stderr`` or ``sys.stdout`` by assignment (an example that fails
between the swap and its undoing left the session's stderr pointing at a doctest's buffer;
``contextlib.redirect_stderr`` undoes it whatever happens).
"""

from __future__ import annotations

import ast
import doctest
from pathlib import Path

import motionhyst

TESTS = Path(__file__).resolve().parent


def _path_changes(tree: ast.AST) -> list[int]:
    """Lines of `tree` that change ``sys.path`` in place or rebind it (code, not text: a child
    process's script in a string is its own interpreter)."""
    def is_sys_path(node) -> bool:
        return (isinstance(node, ast.Attribute) and node.attr == "path"
                and isinstance(node.value, ast.Name) and node.value.id == "sys")

    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            found = is_sys_path(node.func.value)  # sys.path.insert(...), .append, .extend, ...
        elif isinstance(node, (ast.Assign, ast.AugAssign)):
            found = any(is_sys_path(t) for t in (
                node.targets if isinstance(node, ast.Assign) else [node.target]))
        else:
            found = False
        if found:
            lines.append(node.lineno)
    return sorted(lines)


def test_no_test_changes_sys_path():
    """main: test_identify_budget put the tests' folder on sys.path three times, for good."""
    found = {}
    for path in sorted(TESTS.glob("*.py")):
        lines = _path_changes(ast.parse(path.read_text(), str(path)))
        if lines:
            found[path.name] = lines
    assert found == {}


def test_the_check_finds_a_change_of_sys_path():
    code = "import sys\nsys.path.insert(0, 'x')\nsys.path = []\nscript = 'sys.path.append(1)'\n"
    assert _path_changes(ast.parse(code)) == [2, 3]


def _swaps(docstring: str) -> list[str]:
    """The examples of `docstring` that assign ``sys.stderr`` or ``sys.stdout``."""
    out = []
    for example in doctest.DocTestParser().get_examples(docstring or ""):
        try:
            tree = ast.parse(example.source)
        except SyntaxError:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign) and any(
                    isinstance(t, ast.Attribute) and t.attr in ("stderr", "stdout")
                    and isinstance(t.value, ast.Name) and t.value.id == "sys"
                    for t in node.targets):
                out.append(example.source.strip())
    return out


def test_no_example_swaps_the_standard_streams():
    """main: three examples of motionhyst.cli._common set sys.stderr = sys.stdout and back to
    sys.__stderr__ (not even the stream they found)."""
    found = {}
    root = Path(motionhyst.__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef,
                                 ast.AsyncFunctionDef)):
                swaps = _swaps(ast.get_docstring(node, clean=True) or "")
                if swaps:
                    found[f"{path.relative_to(root)}:{getattr(node, 'name', '')}"] = swaps
    assert found == {}


def test_the_check_finds_a_swap():
    text = ">>> import sys\n>>> sys.stderr = sys.stdout\n>>> print(1)\n1\n"
    assert _swaps(text) == ["sys.stderr = sys.stdout"]
