"""Offsets and initial states estimated with an input-output model.

Measured records carry offsets and do not start at rest: the force a drive
reports is off by a constant (EMPS: -3.2 N, 2 % of its peak), the encoder's
zero is anywhere, and a record cut from a run starts moving.  A model fitted
without them takes the bias for dynamics (EMPS: a force offset read as 182 kg
of inertia instead of 95 kg).  They are estimated with the model's parameters
as offsets of the measured signals:

.. math::

    \\hat y(t) = y_{model}(t;\\; u - u_0,\\; x(t_0)) + y_0,

``u_0`` (``input_offset`` [N]: the plant receives ``u - u_0``; the EMPS
benchmark's ``OF``) common to the records (with ``drift``, ``u_0 + u_1 t``: the
offset drifting at ``input_drift`` [N/s] over the records' own time ``t``, a
machine warming up), ``y_0`` (``output_offset`` [m])
and the initial state ``x(t_0)`` (the stage moving as one body at ``v0``
[m/s], displaced by ``y0`` [m] where a spring holds it) one per record.  On
a floating stage (no spring to the ground) the output offset and the initial
position are the same thing: only the offset is estimated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["OFFSET_CHOICES", "Extras", "initial_state"]

#: ``offset`` choices of :func:`~motionhyst.identify.input_output.identify_io` (``--offset``)
OFFSET_CHOICES = ("auto", "none", "input", "output", "both")


@dataclass(frozen=True)
class Extras:
    """Which offsets and initial states are estimated, and their names and scales.

    Parameters
    ----------
    input_offset, output_offset : bool
        Estimate the force offset (one) and the position offsets (one per record).
    initial : tuple of str
        The initial state's estimates per record: ``()`` (from rest), ``("v0",)``
        (a floating stage) or ``("y0", "v0")``.
    n_records : int
        Number of records.
    input_drift : bool
        Estimate the force offset's drift in time (one, with the force offset).

    Examples
    --------
    >>> ex = Extras.choose("auto", floating=True, periodic=False, from_rest=False,
    ...                    n_records=2)
    >>> ex.names
    ['input_offset', 'output_offset[0]', 'output_offset[1]', 'v0[0]', 'v0[1]']
    >>> Extras.choose("none", floating=False, periodic=False, from_rest=True,
    ...               n_records=1).names
    []
    >>> Extras.choose("auto", floating=True, periodic=False, from_rest=False, n_records=1,
    ...               window=True, drift=True).names
    ['input_offset', 'input_drift']
    """

    input_offset: bool
    output_offset: bool
    initial: tuple[str, ...]
    n_records: int
    input_drift: bool = False

    @classmethod
    def choose(cls, offset: str, *, floating: bool, periodic: bool, from_rest: bool,
               n_records: int, window: bool = False, drift: bool = False) -> Extras:
        """What to estimate for the `offset` choice (:data:`OFFSET_CHOICES`).

        ``auto`` is what records can tell apart: ``both`` for a floating stage's
        records from a start (a force offset makes it drift), nothing for its
        periodic ones (compared without their means, and a force offset would
        make it drift), the output offset for a stage on a spring (a force
        offset only moves it by ``u0 / k``: the same as a position offset but
        for the link's nonlinearity).  Periodic records have no initial state;
        `from_rest` fixes it at rest.  With `window` each record's initial state (and a
        floating stage's position offset, the same thing) is set from its first samples
        as the fit runs (:func:`~motionhyst.identify.io_predict.state_from_window`):
        only the force offset is estimated (``auto`` or ``input``, on a floating
        stage; nothing on a stage held by a spring).

        Parameters
        ----------
        offset : str
            One of :data:`OFFSET_CHOICES`.
        floating : bool
            No spring holds the stage to the ground.
        periodic : bool
            The records are periods of a steady state.
        from_rest : bool
            The records start at rest (no initial state estimated).
        n_records : int
            Number of records.
        window : bool
            The records' states are set from their first samples.
        drift : bool
            The force offset drifts in time: its rate is estimated with it (records
            from a start whose force offset is estimated).

        Returns
        -------
        Extras

        Raises
        ------
        ValueError
            An unknown choice; a window on periodic records or with `from_rest`, or
            with an offset it would leave unestimated (``output`` or ``both``; ``input``
            on a stage held by a spring); a drift without a force offset or on periodic
            records.
        """
        if offset not in OFFSET_CHOICES:
            raise ValueError(f"unknown offset choice {offset!r}; expected one of "
                             f"{', '.join(OFFSET_CHOICES)}")
        if drift:
            if periodic:
                raise ValueError("a drifting force offset repeats no period: not with "
                                 "periodic records")
            out = cls.choose(offset, floating=floating, periodic=False, from_rest=from_rest,
                             n_records=n_records, window=window)
            if not out.input_offset:
                raise ValueError("the force offset's drift is estimated with the force "
                                 "offset: offset 'auto', 'input' or 'both' on a floating "
                                 "stage")
            return cls(True, out.output_offset, out.initial, out.n_records, True)
        if window:
            if periodic or from_rest:
                raise ValueError("an initialisation window sets the state of records from a "
                                 "start: not with periodic records or from rest")
            if offset in ("output", "both"):
                raise ValueError(f"offset {offset!r} with an initialisation window: the window "
                                 f"sets each record's position (a floating stage's position "
                                 f"offset) from its first samples; choose 'auto' or 'input' "
                                 f"(the force offset), or no window")
            if offset == "input" and not floating:
                raise ValueError("offset 'input' with an initialisation window: the force "
                                 "offset is estimated with a window on a floating stage only; "
                                 "choose 'auto' or 'none', or no window")
            return cls(floating and offset in ("auto", "input"), False, (), int(n_records))
        if offset == "auto":  # what the records can tell apart
            offset = "both" if floating and not periodic else "none" if floating else "output"
        if periodic and floating and offset != "none":
            raise ValueError("periodic records of a floating stage are compared without "
                             "their means and a force offset makes it drift: use --offset none")
        initial: tuple[str, ...] = ()
        if not (periodic or from_rest):
            initial = ("v0",) if floating else ("y0", "v0")
        return cls(offset in ("input", "both"), offset in ("output", "both"), initial,
                   int(n_records))

    def _per_record(self, base: str) -> list[str]:
        return [base] if self.n_records == 1 else [f"{base}[{i}]"
                                                    for i in range(self.n_records)]

    @property
    def names(self) -> list[str]:
        """Names of the estimates, in the search vector's order."""
        out = ["input_offset"] if self.input_offset else []
        if self.input_drift:
            out.append("input_drift")
        if self.output_offset:
            out += self._per_record("output_offset")
        for what in self.initial:
            out += self._per_record(what)
        return out

    @property
    def size(self) -> int:
        """Number of estimates."""
        return len(self.names)

    def scales(self, u_scale: float, y_scale: float, v_scale: float, t_scale: float = 1.0
               ) -> NDArray[np.float64]:
        """Typical size of each estimate: the force's, the output's or its rate's RMS.

        Parameters
        ----------
        u_scale, y_scale, v_scale : float
            Sizes of a force [N], a position [m] and a velocity [m/s].
        t_scale : float
            The records' duration [s]: a drift's size is ``u_scale / t_scale``.

        Returns
        -------
        ndarray
            One size per name of :attr:`names`.
        """
        unit = {"input_offset": u_scale, "output_offset": y_scale, "y0": y_scale,
                "v0": v_scale, "input_drift": u_scale / t_scale}
        return np.array([unit[name.split("[")[0]] for name in self.names])

    def split(self, e: NDArray[np.float64]) -> tuple[float, NDArray[np.float64],
                                                      NDArray[np.float64]]:
        """The force offset, the records' position offsets and their initial states
        ``(n_records, len(initial))`` from the estimates `e`.

        Parameters
        ----------
        e : ndarray
            The estimates, in the order of :attr:`names`.

        Returns
        -------
        tuple
            ``(u0, y0, init)``.
        """
        j = int(self.input_offset) + int(self.input_drift)
        u0 = float(e[0]) if self.input_offset else 0.0
        y0 = np.zeros(self.n_records)
        if self.output_offset:
            y0 = np.asarray(e[j:j + self.n_records], dtype=float)
            j += self.n_records
        init = np.zeros((self.n_records, len(self.initial)))
        for a in range(len(self.initial)):
            init[:, a] = e[j:j + self.n_records]
            j += self.n_records
        return u0, y0, init

    def drift(self, e: NDArray[np.float64]) -> float:
        """The force offset's drift [N/s] from the estimates `e` (0 when not estimated).

        Parameters
        ----------
        e : ndarray
            The estimates, in the order of :attr:`names`.

        Returns
        -------
        float
        """
        return float(e[1]) if self.input_drift else 0.0

    def columns_of_record(self, i: int) -> list[int]:
        """Indices (into :attr:`names`) of the estimates that move record `i` alone.

        Parameters
        ----------
        i : int
            The record's index.

        Returns
        -------
        list of int
        """
        j = int(self.input_offset) + int(self.input_drift)
        out = []
        if self.output_offset:
            out.append(j + i)
            j += self.n_records
        for _ in self.initial:
            out.append(j + i)
            j += self.n_records
        return out


def initial_state(n: int, initial: tuple[str, ...], values: NDArray[np.float64]
                  ) -> NDArray[np.float64] | None:
    """The plant's state ``(q, q')`` of `n` coordinates moving as one body.

    Parameters
    ----------
    n : int
        Coordinates of the plant.
    initial : tuple of str
        ``()``, ``("v0",)`` or ``("y0", "v0")``.
    values : ndarray
        Their values.

    Returns
    -------
    ndarray or None
        None for a start at rest.

    Examples
    --------
    >>> initial_state(2, ("y0", "v0"), np.array([1e-3, 0.02])).tolist()
    [0.001, 0.001, 0.02, 0.02]
    """
    if not initial:
        return None
    x = np.zeros(2 * n)
    for name, value in zip(initial, values, strict=True):
        if name == "y0":
            x[:n] = value
        else:
            x[n:] = value
    return x
