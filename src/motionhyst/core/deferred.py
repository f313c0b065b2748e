"""python-control imported without the plotting and statistics modules a computation never uses.

``import control`` loads, besides its systems, matplotlib's pyplot and axisartist (for its
plots and the grids of its pole-zero maps, :mod:`control.grid`) and scipy.stats (for the
peak finding of scipy.signal, :func:`scipy.stats.scoreatpercentile`): about half of the CPU
time of the import (0.7 of 1.6 s), which a command that refuses its input once its loop is
built (a loop that hunts, a fitted plant that makes the loop unstable) would spend for
nothing.  While python-control is imported, each of these modules is a stand-in
(:class:`Deferred`) that imports the real module at the first use of one of its names, so
that a plot or a peak search of python-control's still works: it imports them then.

A name of a stand-in that is not among the ones it forwards (:data:`DEFERRED`; another
version of python-control or scipy) imports the real module at once: the import is then as
slow as before, never wrong.

Examples
--------
>>> import sys
>>> from motionhyst.core.deferred import Deferred
>>> stats = Deferred("scipy.stats", ("scoreatpercentile",))
>>> score = stats.scoreatpercentile        # nothing imported yet
>>> float(score([1.0, 2.0, 3.0, 4.0], 50))  # the real function, imported at its first call
2.5
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
from collections.abc import Sequence
from typing import Any

__all__ = ["DEFERRED", "Deferred", "defer_control_extras"]

DEFERRED: dict[str, tuple[str, ...] | None] = {
    "matplotlib": None,                             # used inside python-control's functions only
    "matplotlib.pyplot": None,
    "matplotlib.transforms": None,
    "control.grid": ("nogrid", "sgrid", "zgrid"),   # what control.pzmap imports from it
    "scipy.stats": ("scoreatpercentile",),          # what scipy.signal._peak_finding imports
    "scipy.ndimage": ("convolve1d",),               # what scipy.signal._savitzky_golay imports
}
"""The modules deferred while python-control is imported, and the names each forwards to its
real module (None: every name, which its importers read only when they run)."""


def _real(name: str) -> types.ModuleType:
    """The real module `name`, imported now if only its stand-in was."""
    if isinstance(sys.modules.get(name), Deferred):
        del sys.modules[name]
    return importlib.import_module(name)


class Deferred(types.ModuleType):
    """A stand-in for the module `name` that imports it at the first use of one of its names.

    Parameters
    ----------
    name : str
        The module's full name.
    names : sequence of str or None
        The functions it forwards without importing the module until they are called
        (``from module import name`` takes them); any other name imports the module at once.
        None: every name is read from the real module, imported at its first read.

    Examples
    --------
    >>> from motionhyst.core.deferred import Deferred
    >>> fractions = Deferred("fractions", None)
    >>> fractions.Fraction(1, 3) + fractions.Fraction(1, 6)
    Fraction(1, 2)
    """

    def __init__(self, name: str, names: Sequence[str] | None) -> None:
        super().__init__(name)
        self.__dict__["_forwarded"] = None if names is None else frozenset(names)

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__"):  # the import system's questions: a plain module's answers
            raise AttributeError(attr)
        name = self.__name__
        forwarded = self.__dict__["_forwarded"]
        if forwarded is None or attr not in forwarded:
            sub = sys.modules.get(f"{name}.{attr}")
            if isinstance(sub, Deferred):  # ``import package.module``: its stand-in
                return sub
            real = _real(name)
            try:
                return getattr(real, attr)
            except AttributeError:
                if not hasattr(real, "__path__"):
                    raise
                return importlib.import_module(f"{name}.{attr}")  # a module not imported yet

        def forward(*args: Any, **kwargs: Any) -> Any:
            return getattr(_real(name), attr)(*args, **kwargs)

        forward.__name__ = forward.__qualname__ = attr
        return forward


class _DeferringLoader(importlib.abc.Loader):
    """python-control's own loader, run with :data:`DEFERRED` standing in."""

    def __init__(self, loader: importlib.abc.Loader) -> None:
        self.loader = loader

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return self.loader.create_module(spec)

    def exec_module(self, module: types.ModuleType) -> None:
        module.__loader__ = module.__spec__.loader = self.loader  # as a plain import leaves it
        standing_in = {name: Deferred(name, names) for name, names in DEFERRED.items()
                       if name not in sys.modules}
        sys.modules.update(standing_in)
        try:
            self.loader.exec_module(module)
        finally:
            for name, stand_in in standing_in.items():
                if sys.modules.get(name) is stand_in:
                    del sys.modules[name]  # the next import of it is the real one


class _ControlFinder(importlib.abc.MetaPathFinder):
    """Finds ``control`` as the path does, with :class:`_DeferringLoader`; once."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None
                  ) -> importlib.machinery.ModuleSpec | None:
        if fullname != "control":
            return None
        sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is None or spec.loader is None:
            return spec
        spec.loader = _DeferringLoader(spec.loader)
        return spec


def defer_control_extras() -> None:
    """Have the next ``import control`` of this process defer :data:`DEFERRED`.

    Does nothing once python-control is imported (or its import is already set so).

    Examples
    --------
    >>> from motionhyst.core.deferred import defer_control_extras
    >>> defer_control_extras()
    >>> import control
    >>> control.tf([1.0], [1.0, 1.0]).poles()
    array([-1.+0.j])
    """
    if "control" in sys.modules or any(isinstance(f, _ControlFinder) for f in sys.meta_path):
        return
    sys.meta_path.insert(0, _ControlFinder())
