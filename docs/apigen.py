"""Pages of the documentation written at build time from the package itself.

The API reference lists every public name through autosummary, so a name added
to a module's ``__all__`` appears without editing the documentation; the
command-line reference is the parser's own help; the examples page runs every
script under ``examples/`` and shows its figures.  :func:`public_api` is also
what ``tests/test_docs.py`` checks the package against.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

PACKAGE = "motionhyst"


def public_modules() -> list[str]:
    """Dotted names of the package's public modules: no part of the name starts with ``_``."""
    pkg = importlib.import_module(PACKAGE)
    names = [PACKAGE]
    for info in pkgutil.walk_packages(pkg.__path__, prefix=PACKAGE + "."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return sorted(names)


def module_public_names(module: ModuleType) -> list[str]:
    """A module's public names: its ``__all__``, else the functions and classes it defines."""
    if hasattr(module, "__all__"):
        return list(module.__all__)
    return sorted(
        name for name, obj in vars(module).items()
        if not name.startswith("_")
        and (inspect.isclass(obj) or inspect.isfunction(obj))
        and getattr(obj, "__module__", None) == module.__name__
    )


def _home(obj: object, fallback: str, modules: list[str]) -> str:
    """The public module an object belongs to: the deepest public module its own module is in."""
    own = getattr(obj, "__module__", None) or fallback
    best = PACKAGE
    for mod in modules:
        if mod != PACKAGE and (own == mod or own.startswith(mod + ".")) and len(mod) > len(best):
            best = mod
    return best if best != PACKAGE else fallback


def public_api() -> dict[str, list[str]]:
    """Every public name, as ``{public module: [dotted names documented in its section]}``.

    Each object is documented once, under its shortest public spelling: a name in
    ``motionhyst.__all__`` as ``motionhyst.X``, in the section of the module that
    defines it; other names under their module.  Modules whose every public name
    is documented elsewhere keep an empty list (their section only links).
    """
    modules = public_modules()
    seen: dict[int, str] = {}
    api: dict[str, list[str]] = {mod: [] for mod in modules if mod != PACKAGE}
    order = [PACKAGE] + [m for m in modules if m != PACKAGE]
    order.sort(key=lambda m: (m.count("."), m))  # shallow spellings first
    for mod_name in order:
        module = importlib.import_module(mod_name)
        for name in module_public_names(module):
            obj = getattr(module, name)
            if id(obj) in seen:
                continue
            dotted = f"{mod_name}.{name}"
            seen[id(obj)] = dotted
            home = _home(obj, mod_name, modules) if mod_name == PACKAGE else mod_name
            api.setdefault(home, []).append(dotted)
    return api


def _shadowed(mod_name: str) -> bool:
    """Whether the package attribute of a module's name is another object.

    An old module path that moved (``motionhyst.simulate``, see ``motionhyst._MOVED``) may be
    shadowed by an exported function of the same name; the function's page owns the name.
    """
    parent, _, last = mod_name.rpartition(".")
    return getattr(importlib.import_module(parent), last) is not importlib.import_module(mod_name)


def write_api(dest: Path) -> int:
    """Write ``dest/index.rst``: one section per public module, an autosummary of its names.

    Returns the number of names listed.
    """
    api = public_api()
    lines = [
        ".. This page is written by docs/apigen.py at every build; do not edit.",
        "",
        "API reference",
        "=============",
        "",
        "Every public name of :mod:`motionhyst`, by the module that defines it.  The names",
        "exported at the top level are spelled ``motionhyst.X`` (``from motionhyst import X``);",
        "the others are imported from their module.  The paper's equations are mapped to these",
        "names on :doc:`/equations`.",
        "",
        ".. automodule:: motionhyst",
        "   :no-members:",
        "",
    ]
    count = 0
    for mod_name in sorted(api):
        module = importlib.import_module(mod_name)
        title = f"``{mod_name}``"
        lines += [title, "-" * len(title), "", f".. automodule:: {mod_name}", "   :no-members:"]
        if _shadowed(mod_name):  # the name is the function's: the module gets no target
            lines.append("   :no-index:")
        lines.append("")
        names = api[mod_name]
        if names:
            # relative to the package, so that the table reads Jenkins, quasilinear.mismatch
            lines += [f".. currentmodule:: {PACKAGE}", "", ".. autosummary::",
                      "   :toctree: generated", "   :nosignatures:", ""]
            lines += [f"   {n.removeprefix(PACKAGE + '.')}" for n in names]
            lines.append("")
            count += len(names)
        elif module_public_names(module):
            lines += ["Its public names are documented above under their shorter spelling.", ""]
    dest.mkdir(parents=True, exist_ok=True)
    shutil.rmtree(dest / "generated", ignore_errors=True)  # stubs of names since removed
    _write_if_changed(dest / "index.rst", "\n".join(lines) + "\n")
    return count


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:  # argparse keeps its subparsers here only
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def write_cli(dest: Path) -> None:
    """Write ``dest/index.rst``: ``motionhyst --help`` and every command's ``--help``."""
    from motionhyst.cli import build_parser

    parser = build_parser()
    lines = [".. This page is written by docs/apigen.py at every build; do not edit.", "",
             "Command reference", "=================", "",
             "The help of ``motionhyst`` and of each of its commands, as the installed version "
             "prints it.", "", ".. code-block:: text", ""]
    lines += ["   " + ln for ln in parser.format_help().splitlines()]
    lines.append("")
    for name, sub in _subcommands(parser).items():
        title = f"``motionhyst {name}``"
        lines += [title, "-" * len(title), "", ".. code-block:: text", ""]
        lines += ["   " + ln if ln else "" for ln in sub.format_help().splitlines()]
        lines.append("")
    dest.mkdir(parents=True, exist_ok=True)
    _write_if_changed(dest / "index.rst", "\n".join(lines) + "\n")


def write_examples(examples: Path, dest: Path, run: Callable[[Path, Path], None] | None = None
                   ) -> list[str]:
    """Run every ``examples/*.py`` into ``dest/<name>/`` and write a page showing code and figures.

    Each example takes its output folder as its only argument.  Returns the names.
    """
    run = run or _run_example
    names = []
    lines = [".. This page is written by docs/apigen.py at every build; do not edit.", "",
             "Examples", "========", "",
             "The scripts under ``examples/`` of the repository, run when this page was built; "
             "each takes an output folder as its only argument "
             "(``python examples/NAME.py OUT_DIR``).  The scenario they start from, the "
             "paper's Table I, is ``examples/paper.toml``:", "",
             ".. literalinclude:: ../../examples/paper.toml", "   :language: toml", ""]
    for script in sorted(examples.glob("*.py")):
        name = script.stem
        out = dest / name
        out.mkdir(parents=True, exist_ok=True)
        printed = run(script, out)
        doc = _module_docstring(script)
        title = f"``{script.name}``"
        lines += [title, "-" * len(title), ""]
        lines += [*doc.splitlines(), ""]
        if printed:
            lines += ["What it prints:", "", ".. code-block:: text", ""]
            lines += ["   " + ln if ln else "" for ln in printed.splitlines()]
            lines.append("")
        for png in sorted(out.rglob("*.png")):
            rel = png.relative_to(dest).as_posix()
            lines += [f".. figure:: {rel}", "   :width: 90%", "", f"   ``{png.name}``", ""]
        lines += [".. literalinclude:: " + f"../../examples/{script.name}",
                  "   :language: python", "   :caption: " + script.name, ""]
        names.append(name)
    dest.mkdir(parents=True, exist_ok=True)
    _write_if_changed(dest / "index.rst", "\n".join(lines) + "\n")
    return names


def _module_docstring(script: Path) -> str:
    import ast

    return ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))) or ""


def _run_example(script: Path, out: Path) -> str:
    proc = subprocess.run([sys.executable, str(script), str(out)], capture_output=True,
                          text=True, cwd=out, env=_env(), check=False, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"{script.name} failed:\n{proc.stderr}")
    return proc.stdout


def run_reproduce(out: Path) -> None:
    """``motionhyst reproduce --out OUT --quiet``: the report and figures the outputs page shows.

    `out` is the build's own folder: emptied first, so every build shows a fresh run.
    """
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    code = "import sys; from motionhyst.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", code, "reproduce", "--out", str(out), "--quiet"],
                          capture_output=True, text=True, env=_env(), check=False, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"motionhyst reproduce failed:\n{proc.stderr}")


def run_cli(out: Path, args: list[str]) -> None:
    """``motionhyst ARGS`` run in the build's folder `out` (emptied first): a guide's figure.

    Relative paths in `args` are taken from the repository's top (``examples/...``) and
    from `out` for the files the command writes (give those as ``OUT/name``).
    """
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    top = Path(__file__).resolve().parent.parent
    args = [a.replace("OUT/", f"{out}/") for a in args]
    code = "import sys; from motionhyst.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=_env(), cwd=top, check=False, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"motionhyst {' '.join(args)} failed:\n{proc.stderr}")


def _env() -> dict[str, str]:
    import os

    return {**os.environ, "MPLBACKEND": "Agg"}


def _write_if_changed(path: Path, text: str) -> None:
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
