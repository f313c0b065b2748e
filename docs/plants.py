"""Sphinx extension: the plants' table, written from the plant registry at build time.

Every plant registered in :data:`motionhyst.plants.registry.PLANTS` appears with the name
a scenario's ``[stage] type`` uses, its class and its
:class:`~motionhyst.plants.registry.PlantParameter` list (unit, default, range, meaning).
A plant added to the registry is documented by the next build.

Directive
    ``.. plants::``
        One table of all plants: ``type =``, what it is, parameters, outputs.
"""

from __future__ import annotations

import inspect
from typing import Any

from linkmodels import _directive, documented_name, first_line


def plants() -> dict[str, Any]:
    """The registry, ``{name: plant class}`` in registration order."""
    from motionhyst.plants.registry import PLANTS, stage_types

    stage_types()  # every plant module imported, so registered
    return dict(PLANTS)


def source_files() -> list[str]:
    """Files whose change changes the table: the registry and each plant's file."""
    from motionhyst.plants import registry

    return sorted({inspect.getfile(registry), *(inspect.getfile(c) for c in plants().values())})


def _parameters(cls: Any) -> str:
    if not cls.parameters:
        return "none: built from data (see the class)"
    parts = []
    for p in cls.parameters:
        default = "" if p.required else f", default ``{p.default:g}``"
        parts.append(f"``{p.name}`` [{p.unit}] {p.range}{default}: {p.help}")
    return "; ".join(parts)


def table() -> list[str]:
    """reST of the table of all plants."""
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 16 30 40 14", "",
             "   * - ``type =``", "     - what it is", "     - parameters",
             "     - measured position"]
    for name, cls in plants().items():
        where = "``[stage]``" if cls.parameters else "not a ``[stage]``"
        lines += [f"   * - ``{name}`` ({where})",
                  f"     - {first_line(cls)} (:class:`{documented_name(cls)}`)",
                  f"     - {_parameters(cls)}",
                  f"     - {', '.join(f'``{o}``' for o in cls.outputs)}"]
    return lines


def setup(app: Any) -> dict[str, Any]:
    app.add_directive("plants", _directive(table, titles=False, files=source_files))
    return {"parallel_read_safe": True, "parallel_write_safe": True}
