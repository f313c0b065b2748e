"""A link whose parameters vary along the stroke: a table of scales over the position.

A cable slab bends at another place as the stage moves, so its stiffness and
slip force change along a long stroke.  The link here is a base model (any
link with a time-domain update) whose parameters are scaled at the position
``x`` by factors interpolated linearly in a table ``(x_i, s_i)`` (held beyond
its ends)::

    p(x) = p_base s_p(x)

The elements keep their state (for a stop operator, its force) when the
parameters change: a Jenkins element follows ``dw = k(x) dx`` while ``|w| <
fc(x)`` and slips at ``w = +-fc(x)``.  The time runs update the parameters
between pieces of the run over which the position stays within one
:data:`STEPS_PER_INTERVAL`-th of the table's spacing, at the piece's mean
position (the setpoint's in a closed loop: the stage's within the tracking
error).
"""

from __future__ import annotations

from functools import lru_cache
from itertools import pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.stepping import GL_T, GL_W, Stepping, open_loop_chunk

__all__ = ["STEPS_PER_INTERVAL", "AlongStroke"]

#: Parameter updates of a time run per interval of the table (the parameters are held over
#: the samples within one such step of the position).
STEPS_PER_INTERVAL = 64


class AlongStroke(Hysteresis):
    """The link `base` with its parameters scaled along the stroke.

    Parameters
    ----------
    base : Hysteresis
        The link at scale 1 (a model with a time-domain update).
    position : array_like
        Increasing positions ``x_i`` of the table [m], at least two.
    scales : dict
        For each parameter of `base` that varies, its scale at each position
        (positive; a parameter not named keeps scale 1).

    Examples
    --------
    A Jenkins link whose slip force falls from 60 to 40 mN over 0.1 m:

    >>> from motionhyst import Jenkins
    >>> link = AlongStroke(Jenkins(20.0, 0.05), [0.0, 0.1], {"fc": [1.2, 0.8]})
    >>> round(link.at(0.05).fc, 6), round(link.at(0.2).fc, 6)
    (0.05, 0.04)
    >>> w = link.response(np.linspace(0.0, 0.1, 1001))          # slipping forward
    >>> round(float(w[-1]), 6)
    0.04
    """

    name = "along-stroke"

    def __init__(self, base: Hysteresis, position: ArrayLike, scales: dict) -> None:
        if isinstance(base, AlongStroke):
            raise ValueError("the base of a link along the stroke is a link model")
        self.base = base
        self.position = np.asarray(position, dtype=float)
        x = self.position
        if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)) or np.any(np.diff(x) <= 0):
            raise ValueError("the positions along the stroke must be at least two finite, "
                             "increasing values")
        names = [p.name for p in base.parameters]
        self.scales: dict[str, NDArray[np.float64]] = {}
        for name, values in scales.items():
            if name not in names:
                raise ValueError(f"{name!r} is not a parameter of the {base.name} model "
                                 f"({', '.join(names)})")
            v = np.asarray(values, dtype=float)
            if v.shape != x.shape or not np.all(np.isfinite(v)) or np.any(v <= 0):
                raise ValueError(f"the scales of {name} must be {x.size} positive values, one "
                                 "per position")
            self.scales[name] = v
        self.rate_independent = base.rate_independent
        self.parameters = base.parameters
        base.time_stepping()  # a model without a time-domain update is refused here

    def __repr__(self) -> str:
        return (f"AlongStroke({self.base!r}, position={self.position.tolist()}, "
                f"scales={ {k: v.tolist() for k, v in self.scales.items()} })")

    def scale_at(self, x: float) -> dict[str, float]:
        """Each varying parameter's scale at position `x` (held beyond the table).

        Parameters
        ----------
        x : float
            Position [m].
        """
        return {k: float(np.interp(x, self.position, v)) for k, v in self.scales.items()}

    def at(self, x: float) -> Hysteresis:
        """The base model with its parameters at position `x`.

        Parameters
        ----------
        x : float
            Position [m].
        """
        return _scaled(self.base, tuple(sorted(self.scale_at(x).items())))

    def with_base(self, base: Hysteresis) -> AlongStroke:
        """The same table of scales around another base model.

        Parameters
        ----------
        base : Hysteresis
            The new base (same model).
        """
        return AlongStroke(base, self.position, self.scales)

    def shifted(self, x0: float) -> AlongStroke:
        """The link seen from a stroke position `x0`: position 0 here is `x0` on the table.

        Parameters
        ----------
        x0 : float
            Where on the stroke the motion starts [m].
        """
        return AlongStroke(self.base, self.position - float(x0), self.scales)

    @property
    def initial_stiffness(self) -> float:
        """The largest initial stiffness along the table [N/m]."""
        return max(self.at(x).initial_stiffness for x in self.position)

    def describing_function(self, A, omega=None):
        """Not defined: the link's parameters change with the position.

        Parameters
        ----------
        A, omega : array_like
            Amplitude and frequency (unused).
        """
        raise ValueError("a link that varies along the stroke has no describing function: "
                         "run it in time (simulate, scan)")

    def time_stepping(self) -> Stepping:
        """The elements at the start of the table's first position (the runs update them)."""
        return self.at(self.position[0]).time_stepping()

    def stepping_params(self, x: float) -> NDArray[np.float64]:
        """The elements' parameter rows at position `x` (:class:`~.stepping.Stepping`).

        Parameters
        ----------
        x : float
            Position [m].
        """
        return self.at(x).time_stepping().params

    def pieces(self, x: ArrayLike) -> list[tuple[int, int]]:
        """Index ranges ``[i0, i1)`` of `x` within one :data:`STEPS_PER_INTERVAL`-th of the
        table's smallest spacing: a time run holds the parameters over each.

        Parameters
        ----------
        x : array_like
            Positions [m].
        """
        x = np.asarray(x, dtype=float)
        if x.size == 0:
            return []
        dx = float(np.min(np.diff(self.position))) / STEPS_PER_INTERVAL
        cell = np.floor((x - self.position[0]) / dx)
        breaks = np.flatnonzero(np.diff(cell)) + 1
        edges = [0, *breaks.tolist(), x.size]
        return list(pairwise(edges))

    def response(self, x: ArrayLike, w0: float = 0.0) -> NDArray[np.float64]:
        """Force for the displacement samples `x` from rest, the parameters updated between
        :meth:`pieces` at each one's mean position.

        Parameters
        ----------
        x : array_like
            Displacement samples [m] (positions on the table).
        w0 : float
            Must be 0: the link starts at rest.
        """
        if w0 != 0.0:
            raise ValueError("a link along the stroke starts at rest (w0 = 0)")
        x = np.ascontiguousarray(x, dtype=float)
        st = self.at(float(x[0]) if x.size else 0.0).time_stepping()
        s = np.ascontiguousarray(st.state0, dtype=float).copy()
        s_prev, scalars = s.copy(), np.zeros(2)
        out = np.empty(x.size)
        for i0, i1 in self.pieces(x):
            piece = x[i0:i1]
            params = np.ascontiguousarray(self.stepping_params(float(np.mean(piece))))
            out[i0:i1] = open_loop_chunk(st.codes, params, s, s_prev, scalars,
                                                 np.ascontiguousarray(piece), 0.0, i0, GL_T,
                                                 GL_W)
        return out

    def to_dict(self) -> dict:
        """The base model's parameters and the table (key ``along``)."""
        return {**self.base.to_dict(), "along": {"position": self.position.tolist(),
                                                 **{k: v.tolist() for k, v in
                                                    self.scales.items()}}}


@lru_cache(maxsize=4096)
def _scaled_cached(cls, items: tuple, scales: tuple) -> Hysteresis:
    kw = dict(items)
    for name, s in scales:
        v = kw[name]
        kw[name] = tuple(x * s for x in v) if isinstance(v, tuple) else v * s
    return cls(**{k: list(v) if isinstance(v, tuple) else v for k, v in kw.items()})


def _scaled(base: Hysteresis, scales: tuple) -> Hysteresis:
    d = base.to_dict()
    items = tuple((p.name, tuple(d[p.name]) if isinstance(d[p.name], list) else d[p.name])
                  for p in base.parameters)
    return _scaled_cached(type(base), items, scales)
