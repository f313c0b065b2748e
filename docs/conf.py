"""Sphinx configuration of the motionhyst documentation (``make docs``)."""

from __future__ import annotations

import inspect
import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import apigen  # noqa: E402

import motionhyst  # noqa: E402

project = "motionhyst"
author = "the motionhyst authors"
copyright = "2026, the motionhyst authors"
release = version = motionhyst.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "linkmodels",  # docs/linkmodels.py: the link models' tables from the registry
    "plants",  # docs/plants.py: the plants' table from the plant registry
]

exclude_patterns = ["_build", "_generated/**/*.md"]
templates_path = ["_templates"]
root_doc = "index"

autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

intersphinx_mapping: dict[str, tuple[str, None]] = {}

html_theme = "pydata_sphinx_theme"
html_title = f"motionhyst {version}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path = ["_static"]
html_css_files = ["custom.css"]
html_sidebars = {"equations": [], "index": [], "examples/index": []}  # pages without sections



def _equation_links_resolve(app, env, node, contnode):
    """Every name on the equations page must link: a broken one is a warning, so -W fails."""
    if node.get("refdomain") == "py" and node.get("refdoc") == "equations":
        from sphinx.util import logging

        logging.getLogger(__name__).warning(
            "equations page: %s does not resolve to a documented name", node["reftarget"],
            location=node)


def _no_type_docstring_for_data(app, what, name, obj, options, lines):
    """A module constant without a doc comment shows no docstring (not its type's: ndarray's)."""
    if what not in ("data", "attribute") or not lines or isinstance(obj, str):
        return
    type_doc = (inspect.getdoc(type(obj)) or "").strip().splitlines()
    first = lines[0].strip()
    if first.startswith(type(obj).__name__ + "(") or (type_doc and first == type_doc[0]):
        lines.clear()


def setup(app):
    app.connect("missing-reference", _equation_links_resolve)
    app.connect("autodoc-process-docstring", _no_type_docstring_for_data, priority=400)


# Pages written from the package itself at every build (see apigen.py).
GENERATED = HERE / "_generated"
apigen.write_api(HERE / "api")
apigen.write_cli(HERE / "cli")
apigen.run_reproduce(GENERATED / "reproduce")
apigen.run_cli(GENERATED / "stability", ["stability", "examples/hunting.toml",
                                          "--figure", "OUT/hunting.png"])
apigen.write_examples(HERE.parent / "examples", HERE / "examples")
