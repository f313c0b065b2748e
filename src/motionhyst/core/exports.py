"""A package's names imported from their modules on first use (PEP 562).

A package that re-exports the names of its modules imports them all when it is
imported, and with them the libraries they use.  :func:`lazy_exports` gives the
package's ``__getattr__`` and ``__dir__`` instead: a name is imported from its
module when it is first used, so importing the package, or one of its light
modules, imports nothing heavy.
"""

from __future__ import annotations

import importlib
import sys

TYPE_CHECKING = False  # typing's, without typing: ``import motionhyst`` runs before the command
if TYPE_CHECKING:      # can handle a signal (motionhyst.entry), so it imports next to nothing
    from collections.abc import Callable, Iterable, Mapping
    from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, exports: Mapping[str, Iterable[str]]
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of a package whose names load on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : mapping
        Module -> the names the package exports from it.

    Returns
    -------
    tuple
        ``(__getattr__, __dir__)``, to assign in the package's ``__init__``: a name
        is imported from its module at its first access and then kept in the
        package's namespace; an unknown name raises ``AttributeError``.

    Examples
    --------
    >>> import sys, types
    >>> from motionhyst.core.exports import lazy_exports
    >>> pkg = types.ModuleType("pkg")
    >>> sys.modules["pkg"] = pkg
    >>> pkg.__getattr__, pkg.__dir__ = lazy_exports("pkg", {"json": ["dumps"]})
    >>> pkg.dumps([1])
    '[1]'
    >>> "dumps" in vars(pkg)   # kept: the next access is an ordinary attribute
    True
    >>> del sys.modules["pkg"]
    """
    where = {name: module for module, names in exports.items() for name in names}

    def __getattr__(name: str) -> Any:
        """Import an exported name from its module on first access (PEP 562)."""
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        namespace = vars(sys.modules[package])
        return sorted(set(namespace) | set(namespace.get("__all__", ())))

    return __getattr__, __dir__
