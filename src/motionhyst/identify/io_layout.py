"""How a registered link model's parameters enter an input-output search.

The element links' search (:mod:`~motionhyst.identify.io_elements`) and the quasi-static
plant's (:mod:`~motionhyst.identify.io_quasi_static`) take a link's parameters as
:class:`LinkLayout` lays them out: which are searched as logarithms, their scales and starts
by unit, the ones fixed (a spring or damper in parallel with the stage's), and a mass-damper's
viscous friction by direction (:data:`SKEW`) searched with them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.hysteresis import Hysteresis, Parameter

__all__: list[str] = []  # the search's internals, for the identification modules

#: Start values and search scales by the parameter's unit (registry.Parameter.unit)
STIFFNESS_UNIT, FORCE_UNIT, DAMPING_UNIT, VELOCITY_UNIT, LENGTH_UNIT = (
    "N/m", "N", "N s/m", "m/s", "m")
_STIFFNESS, _FORCE, _DAMPING, _VELOCITY, _LENGTH = (
    STIFFNESS_UNIT, FORCE_UNIT, DAMPING_UNIT, VELOCITY_UNIT, LENGTH_UNIT)


@dataclass
class LinkLayout:
    """How a registered link model's parameters enter the search.

    Built from the model's :class:`~motionhyst.hysteresis.registry.Parameter`
    list alone, so a newly registered model needs no edit here: each value
    (a list parameter gives `n` values) is estimated, as a logarithm when it
    must be positive, linearly (scaled, bounded below by 0) when it may be 0;
    a parameter that only adds a spring or damper in parallel (``parallel``)
    is fixed at 0, since the stage's ``k`` or ``c`` holds the sum.  With `skew`
    the stage's viscous friction by direction (a mass-damper's ``c_skew``,
    :data:`SKEW`) is the last value: the link's :meth:`build` leaves it out.
    """

    cls: type
    entries: list[tuple[Parameter, int]]  # (parameter, number of values; -1: a scalar)
    fixed: dict[str, float]
    skew: bool = False

    @classmethod
    def of(cls, klass: type, n: int, faster: str | None = None,
           skew: bool = False) -> LinkLayout:
        """The layout of the link model `klass` (`n` values of a list parameter); `faster`:
        the Coulomb link's direction-dependent viscous friction, ``"c_pos"`` or ``"c_neg"``
        (the direction with more, estimated on top of the stage's ``c``; the other
        fixed at 0); `skew`: the stage's viscous friction by direction after the link's
        values."""
        entries, fixed = [], {}
        if faster is not None:
            form = {p.name: p for p in klass.forms[0].parameters}
            slower = "c_neg" if faster == "c_pos" else "c_pos"
            return cls(klass, [(klass.parameters[0], -1), (form[faster], -1)],
                       {slower: 0.0})
        for par in klass.parameters:
            if par.parallel:
                fixed[par.name] = 0.0
            elif par.many:  # a list: n values (none if the model's default is no element)
                entries.append((par, 0 if par.default == () else n))
            else:
                entries.append((par, -1))
        return cls(klass, entries, fixed, skew)

    def _values(self):
        for par, count in self.entries:
            if count < 0:
                yield par, None
            else:
                for i in range(count):
                    yield par, i
        if self.skew:
            yield SKEW, None

    @property
    def names(self) -> list[str]:
        """Names of the estimates, ``link.`` before the model's parameter names (the
        stage's ``c_skew`` as it is)."""
        return [SKEW.name if par is SKEW else
                f"link.{par.name}" if i is None else f"link.{par.name}[{i}]"
                for par, i in self._values()]

    @property
    def logarithmic(self) -> NDArray[np.bool_]:
        """True for the values searched as logarithms (those that must be positive)."""
        return np.array([par.kind == "positive" for par, _ in self._values()], dtype=bool)

    def build(self, v: NDArray[np.float64]) -> Hysteresis:
        """The link of the values `v` (in the order of :attr:`names`)."""
        kwargs: dict = dict(self.fixed)
        j = 0
        for par, count in self.entries:
            if count < 0:
                kwargs[par.name] = float(v[j])
                j += 1
            else:
                kwargs[par.name] = [float(x) for x in v[j:j + count]]
                j += count
        return self.cls(**kwargs)

    def scales(self, k: float, c: float, y_scale: float, v_scale: float
               ) -> NDArray[np.float64]:
        """Typical magnitude of each value, by its unit (for the linear ones' search)."""
        unit = {_STIFFNESS: k, _FORCE: k * y_scale, _DAMPING: c, _VELOCITY: v_scale,
                _LENGTH: y_scale}
        return np.array([unit.get(par.unit, 1.0) for par, _ in self._values()])

    def start(self, k_link: float, y_scale: float, v_scale: float, c: float,
              slip: float = 1.0) -> NDArray[np.float64]:
        """Start values: stiffness `k_link` slipping across the record's displacement range.

        The stiffness values share `k_link`; element ``i`` of a list slips at a
        displacement from ``0.05`` to ``2`` times `y_scale` (geometric), a
        scalar force at ``0.5 y_scale`` times the link's stiffness (a second
        force half as large again), all times `slip`; a velocity is ``0.1`` of
        `v_scale`, a damping `c`; a parameter with a default starts there.
        """
        values = list(self._values())
        n_stiff = sum(1 for par, _ in values if par.unit == _STIFFNESS)
        k_each = k_link / max(n_stiff, 1)
        n_list = max([count for _, count in self.entries] + [1])
        y_scale = y_scale * slip
        d_list = y_scale * np.geomspace(0.05, 2.0, n_list)
        n_len = sum(1 for par, i in values if par.unit == _LENGTH and i is None)
        d_len = y_scale * np.geomspace(0.05, 2.0, max(n_len, 1))
        out, n_force, j_len = [], 0, 0
        for par, i in values:
            if par.default not in (None, ()) and not par.many:
                out.append(float(par.default))  # type: ignore[arg-type]
            elif par.unit == _STIFFNESS:
                out.append(k_each)
            elif par.unit == _FORCE:
                if i is not None:
                    out.append(k_each * d_list[i])
                else:
                    out.append(k_link * 0.5 * y_scale * 1.5 ** n_force)
                    n_force += 1
            elif par.unit == _LENGTH:
                out.append(d_list[i] if i is not None else d_len[j_len])
                j_len += i is None
            elif par.unit == _VELOCITY:
                out.append(0.1 * v_scale)
            elif par.unit == _DAMPING:
                out.append(c)
            else:
                out.append(1.0)
        return np.array(out)


#: A mass-damper's viscous friction by direction, searched with a link's values
#: (:class:`~motionhyst.plants.mass_damper.MassDamper`'s ``c_skew``)
SKEW = Parameter("c_skew", _DAMPING, "half the difference of the stage's viscous friction "
                 "moving forward and backward", 0.0, "finite")
