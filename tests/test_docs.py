"""The documentation covers the package: every public name, every equation, runnable code.

The API reference is generated from the packages' ``__all__`` (``docs/apigen.py``); these
tests check that what it generates names every public object, that each public function
and class carries an Examples section (run by ``--doctest-modules`` over ``src/``), that
the equations page maps eqs. (1)-(23) to names that exist, and that the README's Python
runs as written.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import io
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

import motionhyst

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
N_EQUATIONS = 23  # numbered equations of the paper


def _apigen() -> ModuleType:
    spec = importlib.util.spec_from_file_location("apigen", DOCS / "apigen.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _all_lists() -> dict[str, list[str]]:
    """``__all__`` of the package and of every public module or subpackage that has one."""
    lists = {"motionhyst": list(motionhyst.__all__)}
    for name in _apigen().public_modules():
        module = importlib.import_module(name)
        if name != "motionhyst" and hasattr(module, "__all__"):
            lists[name] = list(module.__all__)
    return lists


def _public_objects() -> list[tuple[str, object]]:
    out = []
    for mod_name, names in _all_lists().items():
        module = importlib.import_module(mod_name)
        out += [(f"{mod_name}.{n}", getattr(module, n)) for n in names]
    return out


PUBLIC = _public_objects()


def test_all_lists_name_existing_objects():
    for mod_name, names in _all_lists().items():
        module = importlib.import_module(mod_name)
        missing = [n for n in names if not hasattr(module, n)]
        assert not missing, f"{mod_name}.__all__ names what it lacks: {missing}"
        assert len(set(names)) == len(names), f"{mod_name}.__all__ repeats a name"


def test_every_public_name_is_in_the_api_reference(tmp_path):
    gen = _apigen()
    count = gen.write_api(tmp_path)
    page = (tmp_path / "index.rst").read_text()
    listed = {f"motionhyst.{ln.strip()}" for ln in page.splitlines()
              if ln.startswith("   ") and not ln.strip().startswith(":")
              and re.fullmatch(r"[\w.]+", ln.strip())}
    assert count == len(listed) > 0
    documented = {id(_resolve(n)) for n in listed}
    absent = [name for name, obj in PUBLIC if id(obj) not in documented]
    assert not absent, f"public names missing from the API reference: {absent}"
    # the top-level names are documented under their top-level spelling
    for name in motionhyst.__all__:
        assert f"motionhyst.{name}" in listed, name


def _has_examples(obj: object) -> bool:
    doc = inspect.getdoc(obj) or ""
    m = re.search(r"^Examples\n-{8,}\n(.*?)(?=^\S[^\n]*\n-{3,}\n|\Z)", doc, re.M | re.S)
    return bool(m) and ">>>" in m.group(1)


def _functions_and_classes() -> list[tuple[str, object]]:
    seen: set[int] = set()
    out = []
    for name, obj in PUBLIC:
        if (inspect.isclass(obj) or inspect.isfunction(obj)) and id(obj) not in seen:
            seen.add(id(obj))
            out.append((name, obj))
    return out


@pytest.mark.parametrize("name, obj", _functions_and_classes(),
                         ids=lambda v: v if isinstance(v, str) else "")
def test_public_function_or_class_has_an_examples_section(name, obj):
    """Run by ``--doctest-modules``; a name without one fails here."""
    assert _has_examples(obj), f"{name}: no numpydoc Examples section with >>> lines"


def _resolve(dotted: str) -> object:
    """The object a dotted name stands for, found as autosummary finds it.

    The longest importable module prefix first, then attributes: so
    ``motionhyst.simulate`` is the function and ``motionhyst.time.simulation.Simulation`` the
    class in its module.  A dataclass field, which is no class
    attribute, resolves to its class.
    """
    parts = dotted.split(".")
    for i in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        rest = parts[i:]
        for j, attr in enumerate(rest):
            if hasattr(obj, attr):
                obj = getattr(obj, attr)
            elif j == len(rest) - 1 and attr in getattr(obj, "__annotations__", {}):
                return obj
            else:
                break
        else:
            return obj
    if len(parts) == 1:
        return importlib.import_module(dotted)
    raise AttributeError(f"{dotted} does not resolve")


def test_equation_page_maps_every_equation_to_existing_names():
    text = (DOCS / "equations.rst").read_text()
    rows = re.findall(r"^   \* - \\?\((\d+)\)\n((?:     - .*\n|       .*\n)+)", text, re.M)
    assert [int(n) for n, _ in rows] == list(range(1, N_EQUATIONS + 1))
    for number, body in rows:
        cells = re.split(r"^     - ", body, flags=re.M)[1:]
        assert len(cells) == 3, f"eq. ({number}): expected what, module, names"
        module_cell = re.fullmatch(r":mod:`([\w.]+)`\s*", cells[1])
        assert module_cell, f"eq. ({number}): the module cell is one :mod: link"
        importlib.import_module(module_cell.group(1))
    targets = re.findall(r":(?:func|class|meth|attr|mod):`~?([\w.]+)`", text)
    assert len(targets) > N_EQUATIONS
    for target in targets:
        _resolve(target)


def _readme_python_blocks() -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(), re.M | re.S)


def test_readme_python_runs_as_written(tmp_path, monkeypatch):
    blocks = _readme_python_blocks()
    assert blocks, "the README has Python blocks"
    monkeypatch.chdir(tmp_path)
    for i, code in enumerate(blocks):
        exec(compile(code, f"README.md python block {i + 1}", "exec"), {"__name__": "readme"})
    assert list(tmp_path.iterdir()) == []  # the README's code writes nothing


@pytest.mark.parametrize("first", [
    "pass",
    "import motionhyst.time.simulation",
    "from motionhyst.time.simulation import Simulation",
    "import motionhyst.cli",
])
def test_top_level_simulate_is_the_function_in_any_import_order(first):
    code = (f"{first}\n"
            "from motionhyst import simulate, PointToPoint, load_reference_csv\n"
            "import motionhyst, inspect\n"
            "assert inspect.isfunction(simulate), simulate\n"
            "assert motionhyst.simulate is simulate\n"
            "assert inspect.isclass(PointToPoint) and callable(load_reference_csv)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr


def _docstrings() -> list[tuple[str, str]]:
    """Docstrings the API reference renders: public modules, names and their members."""
    gen = _apigen()
    out = []
    for mod_name in gen.public_modules():
        module = importlib.import_module(mod_name)
        out.append((mod_name, inspect.getdoc(module) or ""))
    for name, obj in PUBLIC:
        if inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member)
                                                 or isinstance(member, property | classmethod)):
                    out.append((f"{name}.{attr}", inspect.getdoc(member) or ""))
        if inspect.isclass(obj) or inspect.isfunction(obj):
            out.append((name, inspect.getdoc(obj) or ""))
    return out


def test_docstrings_are_valid_restructuredtext():
    """What breaks ``make docs -W`` at the docutils level (an unclosed ``literal``, a bare
    ``|x|`` read as a substitution), found without building the site.  Sphinx's own roles
    and directives are accepted as they are."""
    import docutils.core as docutils_core
    from docutils.parsers.rst import roles

    def generic_role(name, rawtext, text, lineno, inliner, options=None, content=None):
        return [], []

    for role in ("func", "class", "meth", "attr", "mod", "data", "obj", "exc", "doc", "ref",
                 "math", "term", "py:func", "py:class", "py:meth", "py:mod", "py:data"):
        roles.register_local_role(role, generic_role)
    problems = []
    for name, doc in _docstrings():
        report = io.StringIO()
        docutils_core.publish_doctree(doc, settings_overrides={
            "report_level": 2, "halt_level": 5, "warning_stream": report})
        messages = [ln for ln in report.getvalue().splitlines()
                    if ("WARNING" in ln or "ERROR" in ln or "SEVERE" in ln)
                    and "Unknown interpreted text role" not in ln
                    and 'Unknown directive type' not in ln]
        problems += [f"{name}: {m}" for m in messages]
    assert not problems, "\n".join(problems)


def _linkmodels(monkeypatch) -> ModuleType:
    monkeypatch.syspath_prepend(str(DOCS))  # it imports docs/apigen.py as Sphinx does
    spec = importlib.util.spec_from_file_location("linkmodels", DOCS / "linkmodels.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_model_tables_come_from_the_registry(monkeypatch):
    """The models page lists every registered model and each of its parameters, a model
    registered later included, with the class under its documented name."""
    from motionhyst.hysteresis import MODELS, Jenkins
    from motionhyst.hysteresis.registry import Parameter

    class Spring(Jenkins):
        """A linear spring, registered for this test only."""

        name = "spring-only"
        parameters = (Parameter("k_lin", "N/m", "stiffness of the spring"),)

    monkeypatch.setitem(MODELS, Spring.name, Spring)
    gen = _linkmodels(monkeypatch)
    table = "\n".join(gen.summary_table())
    sections = "\n".join(gen.parameter_sections())
    rows = re.findall(r"^   \* - ``([\w-]+)``$", table, re.M)
    assert rows == list(MODELS)
    for name, cls in MODELS.items():
        section = sections.split(f"``{name}``\n")[1].split("\n~~~")[0]
        for p in cls.parameters:
            assert f"``{p.name}" in section and p.help in section, (name, p.name)
        for form in getattr(cls, "forms", ()):
            assert all(f"``{p.name}``" in section for p in form.parameters), name
    assert "``--k-lin``" in sections and "stiffness of the spring" in sections
    assert ":class:`motionhyst.Jenkins`" in table  # the top-level spelling the API uses
    assert ":class:`motionhyst.MaxwellIwan`" in gen.substitutions()
    assert "Closed-form describing function" in table
