"""Sphinx extension: the link models' tables, written from the model registry at build time.

Every link model registered in :data:`motionhyst.hysteresis.registry.MODELS` appears on
the pages that list the models, with the name a scenario uses, its class, its
:class:`~motionhyst.hysteresis.registry.Parameter` list (unit, default, range, meaning)
and how its describing function is computed (the first line of the docstring of its
``describing_function``).  A model added to the registry is documented by the next build.

Directives
    ``.. link-models::``
        One table of all models: ``model =``, what it is, parameters, describing function.
    ``.. link-model-parameters::``
        One subsection per model with its parameters (and its other forms' parameters).

Substitutions (in every page)
    ``|link_model_classes|``
        The models' classes, linked, in registration order.
    ``|link_model_names|``
        The models' scenario names (``jenkins``, ...).
"""

from __future__ import annotations

import functools
import inspect
import re
from collections.abc import Callable
from typing import Any

RANGES = {"positive": "> 0", "nonnegative": ">= 0", "finite": "any"}


def models() -> dict[str, Any]:
    """The registry, ``{scenario name: model class}`` in registration order."""
    from motionhyst.hysteresis.registry import MODELS

    return dict(MODELS)


@functools.cache
def _documented() -> dict[int, str]:
    import importlib

    import apigen

    found = {}
    for names in apigen.public_api().values():
        for dotted in names:
            module, _, attr = dotted.rpartition(".")
            obj = getattr(importlib.import_module(module), attr, None)
            if obj is not None:
                found.setdefault(id(obj), dotted)
    return found


def documented_name(obj: object) -> str:
    """The dotted name under which the API reference documents `obj` (its shortest spelling)."""
    fallback = f"{obj.__module__}.{obj.__qualname__}"  # type: ignore[attr-defined]
    return _documented().get(id(obj), fallback)


def source_files() -> list[str]:
    """Files whose change changes the tables: the registry, its package, each model's file."""
    from motionhyst.hysteresis import registry

    files = {inspect.getfile(registry), inspect.getfile(registry).replace("registry.py",
                                                                          "__init__.py")}
    files.update(inspect.getfile(cls) for cls in models().values())
    return sorted(files)


def first_line(obj: object) -> str:
    """The first line of an object's docstring, without a trailing unit such as ``[N/m]``."""
    doc = (inspect.getdoc(obj) or "").strip().splitlines()
    line = doc[0].strip() if doc else ""
    return re.sub(r"\s*\[[^\]]*\]\.?$", ".", line)


def _default(p: Any) -> str:
    if p.default is None:
        return "required"
    if isinstance(p.default, tuple):
        return "none" if not p.default else "``[" + ", ".join(f"{v:g}" for v in p.default) + "]``"
    return f"``{p.default:g}``"


def _key(p: Any) -> str:
    return f"``{p.name} = [...]``" if p.many else f"``{p.name}``"


def _short_parameters(cls: Any) -> str:
    parts = []
    for p in cls.parameters:
        text = _key(p)
        if not p.required:
            text += " (none)" if p.default == () else f" ({_default(p).strip('`')})"
        parts.append(text)
    return ", ".join(parts)


def _dependence(cls: Any) -> str:
    if cls.rate_independent:
        return "rate-independent: ``D(A)``"
    return "rate-dependent: ``D(A, omega)``"


def summary_table() -> list[str]:
    """reST of the table of all models."""
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 14 30 30 26", "",
             "   * - ``model =``", "     - what it is", "     - parameters (default)",
             "     - describing function"]
    for name, cls in models().items():
        lines += [f"   * - ``{name}``",
                  f"     - {first_line(cls)} (:class:`{documented_name(cls)}`)",
                  f"     - {_short_parameters(cls)}; {_dependence(cls)}",
                  f"     - {first_line(cls.describing_function)}"]
    return lines


def _parameter_table(parameters: tuple, df_options: bool = True) -> list[str]:
    """reST of a parameter table; `df_options`: with the ``motionhyst df`` option column."""
    head = ["scenario key", "``motionhyst df``", "unit", "default", "range", "meaning"]
    widths = "16 16 10 12 12 34"
    if not df_options:
        head, widths = [head[0], *head[2:]], "20 12 14 14 40"
    lines = [".. list-table::", "   :header-rows: 1", f"   :widths: {widths}", "",
             f"   * - {head[0]}", *(f"     - {h}" for h in head[1:])]
    for p in parameters:
        option = "--" + p.name.replace("_", "-") + (" ..." if p.many else "")
        rng = RANGES[p.kind] + ("" if p.maximum is None else f", <= {p.maximum:g}") + (
            ", each" if p.many else "")
        cells = [_key(p), f"``{option}``", p.unit or "-", _default(p), rng, p.help]
        if not df_options:
            del cells[1]
        lines += [f"   * - {cells[0]}", *(f"     - {c}" for c in cells[1:])]
    return lines


def parameter_sections() -> list[str]:
    """reST of one subsection per model: its parameters and its other forms'."""
    lines: list[str] = []
    for name, cls in models().items():
        title = f"``{name}``"
        zeta = "; defines ``zeta = fc / (k A)`` (eq. 4)" if cls.defines_zeta else ""
        lines += [title, "~" * len(title), "",
                  f"{first_line(cls)}  Class :class:`{documented_name(cls)}`; "
                  f"{_dependence(cls)}{zeta}.", ""]
        if not cls.rate_independent:
            lines += ["``motionhyst df`` needs ``--frequency`` for this model.", ""]
        lines += [*_parameter_table(cls.parameters), ""]
        for form in getattr(cls, "forms", ()):
            keys = ", ".join(f"``{p.name}``" for p in form.parameters)
            lines += [f"Also accepted in a scenario, the {form.name} form: a ``[hysteresis]`` "
                      f"table with a key of it that the table above lacks ({keys}) is read in "
                      f"this form; in Python "
                      f":meth:`{documented_name(cls)}.{form.constructor}`.", ""]
            lines += [*_parameter_table(form.parameters, df_options=False), ""]
    return lines


def substitutions() -> str:
    """reST substitution definitions added to every page (``rst_prolog``)."""
    classes = ", ".join(f":class:`{documented_name(c)}`" for c in models().values())
    names = ", ".join(f"``{n}``" for n in models())
    return (f"\n.. |link_model_classes| replace:: {classes}\n"
            f".. |link_model_names| replace:: {names}\n")


def _add_substitutions(app: Any, config: Any) -> None:
    config.rst_prolog = (config.rst_prolog or "") + substitutions()


def _directive(write: Callable[[], list[str]], titles: bool,
               files: Callable[[], list[str]] = source_files) -> type:
    """A directive without content that parses the reST `write` returns in its place (read
    again when one of `files` changes)."""
    from docutils import nodes
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective
    from sphinx.util.nodes import nested_parse_with_titles

    class Generated(SphinxDirective):
        has_content = False

        def run(self) -> list[nodes.Node]:
            for path in files():  # the page is read again when a model changes
                self.env.note_dependency(path)
            source = self.get_source_info()[0]
            content = StringList(write(), source=f"{source} (written by linkmodels.py)")
            container = nodes.section() if titles else nodes.container()
            if titles:
                nested_parse_with_titles(self.state, content, container)
            else:
                self.state.nested_parse(content, self.content_offset, container)
            return list(container.children)

    return Generated


def setup(app: Any) -> dict[str, Any]:
    app.add_directive("link-models", _directive(summary_table, titles=False))
    app.add_directive("link-model-parameters", _directive(parameter_sections, titles=True))
    app.connect("config-inited", _add_substitutions)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
