"""Every public callable documents its parameters (as python-control's docstrings test).

A public callable is a function or class named in a public module's
``__all__`` (the names the API reference lists, ``docs/apigen.py``) and every
public method those classes define.  Each parameter of its signature (``self``,
``*args`` and ``**kwargs`` aside) must be named in the numpydoc ``Parameters``
section of its docstring; for a class, of the class docstring (a dataclass may
document its fields under ``Attributes`` instead, as its results do), and a
documented name must be a parameter (no stale entries).  A class whose
constructor is inherited from outside the package is not checked.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
from dataclasses import is_dataclass
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parent.parent / "docs"
PACKAGE = "motionhyst"
SECTION = re.compile(r"^(\w[\w ]*)\n-{3,}\n", re.M)


def _apigen():
    spec = importlib.util.spec_from_file_location("apigen", DOCS / "apigen.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def sections(doc: str) -> dict[str, str]:
    """The numpydoc sections of `doc`, ``{title: text}``.

    >>> sections("One line.\\n\\nParameters\\n----------\\nx : float\\n    A value.\\n")
    {'Parameters': 'x : float\\n    A value.\\n'}
    """
    heads = list(SECTION.finditer(doc))
    out: dict[str, str] = {}
    for i, m in enumerate(heads):
        end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
        out[m.group(1)] = out.get(m.group(1), "") + doc[m.end():end]
    return out


def documented_names(text: str) -> set[str]:
    """The names a numpydoc parameter list documents (``a, b : float`` names two).

    >>> sorted(documented_names("x, y : float\\n    Values.\\n**kwargs\\n    Passed on.\\n"))
    ['kwargs', 'x', 'y']
    """
    names = set()
    for line in text.splitlines():
        if line and not line[0].isspace():
            head = line.split(" : ")[0].strip().rstrip(":")
            names.update(n.strip().lstrip("*") for n in head.split(",") if n.strip())
    return names


def parameters(obj) -> list[str] | None:
    """The named parameters of `obj`'s signature; None where it has none Python can read."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    return [p.name for p in sig.parameters.values()
            if p.name not in ("self", "cls")
            and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def _own_constructor(cls: type) -> bool:
    """True if the package defines the constructor the signature of `cls` comes from."""
    for base in cls.__mro__:
        if "__init__" in vars(base) or "__new__" in vars(base):
            return base.__module__.startswith(PACKAGE + ".") or base.__module__ == PACKAGE
    return False


def public_callables() -> list[tuple[str, object]]:
    """``(dotted name, callable)`` of every public function, class and public method, once."""
    gen = _apigen()
    seen: set[int] = set()
    out = []
    for mod_name in gen.public_modules():
        module = importlib.import_module(mod_name)
        for name in gen.module_public_names(module):
            obj = getattr(module, name)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)) or id(obj) in seen:
                continue
            seen.add(id(obj))
            out.append((f"{mod_name}.{name}", obj))
            if inspect.isclass(obj):
                for attr, member in vars(obj).items():
                    if isinstance(member, staticmethod | classmethod):
                        member = member.__func__
                    if (not attr.startswith("_") and inspect.isfunction(member)
                            and id(member) not in seen):
                        seen.add(id(member))
                        out.append((f"{mod_name}.{name}.{attr}", member))
    return out


def undocumented(obj) -> tuple[list[str], list[str]]:
    """``(parameters not documented, documented names that are no parameter)`` of `obj`."""
    names = parameters(obj)
    if names is None or (inspect.isclass(obj) and not _own_constructor(obj)):
        return [], []
    parts = sections(inspect.getdoc(obj) or "")
    text = parts.get("Parameters", "")
    if inspect.isclass(obj) and is_dataclass(obj):
        text += parts.get("Attributes", "")
    if inspect.isclass(obj) and "__init__" in vars(obj):
        own = inspect.cleandoc(vars(obj)["__init__"].__doc__ or "")  # not a base's docstring
        text += sections(own).get("Parameters", "")
    got = documented_names(text)
    missing = [n for n in names if n not in got]
    takes_more = any(p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
                     for p in inspect.signature(obj).parameters.values())
    stale = ([] if takes_more or (inspect.isclass(obj) and is_dataclass(obj))
             else sorted(got - set(names)))
    return missing, stale


CALLABLES = [(name, obj) for name, obj in public_callables() if parameters(obj)]


def test_the_package_has_public_callables_with_parameters():
    assert len(CALLABLES) > 100


@pytest.mark.parametrize(("name", "obj"), CALLABLES, ids=[n for n, _ in CALLABLES])
def test_parameters_are_documented(name, obj):
    missing, stale = undocumented(obj)
    assert not missing, f"{name}: parameters without an entry in 'Parameters': {missing}"
    assert not stale, f"{name}: 'Parameters' names what the signature lacks: {stale}"
