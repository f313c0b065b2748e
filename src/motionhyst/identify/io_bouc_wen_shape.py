"""The search layout of a Bouc-Wen link on the quasi-static plant (:class:`BoucWenShape`).

The link's force depends on ``beta / fc^n`` and ``gamma / fc^n`` only; the layout fixes the
force scale ``fc`` and searches ``k``, ``beta + gamma`` and ``beta - gamma >= 0`` (and
``n - 1 >= 0`` when the exponent is estimated), for
:mod:`~motionhyst.identify.io_quasi_static`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.hysteresis import BoucWen, Hysteresis
from motionhyst.hysteresis.registry import Parameter
from motionhyst.identify.io_elements import LinkLayout

__all__: list[str] = []  # the search's internals, for the identification modules


#: The search's shape values of a Bouc-Wen link (:class:`BoucWenShape`)
SHAPE_SUM = Parameter("beta+gamma", "", "beta + gamma at the force scale fc", None, "finite")
SHAPE_DIFFERENCE = Parameter("beta-gamma", "", "beta - gamma at the force scale fc", None,
                             "nonnegative")
EXPONENT_EXCESS = Parameter("n-1", "", "the exponent n less 1", None, "nonnegative")
#: Where an estimated exponent starts (``n = 2``: exact steps)
EXPONENT_START = 2.0


@dataclass
class BoucWenShape(LinkLayout):
    """A Bouc-Wen link's search layout: ``k``, ``beta + gamma`` and ``beta - gamma >= 0``
    at a fixed force scale ``fc``, and ``n - 1 >= 0`` unless the exponent is fixed.

    Only ``beta / fc^n`` and ``gamma / fc^n`` enter the link's force (eq. 2 of
    :class:`~motionhyst.hysteresis.BoucWen`), so a search of ``fc, beta, gamma`` has a
    direction that changes nothing, and ``beta >= gamma`` is a wall of the model's accepted
    set on which many links lie (``beta = gamma``: unloading as stiff as the initial
    stiffness), where a forward difference steps out of it: such a search stalls there
    (measured: a link of 1e6 N/m fitted to 25 N RMS on 15 N of noise).  Here the fixed
    scale removes the first, and ``beta - gamma`` is a bound of the search (stepped along,
    not across).  :meth:`normalised` gives the result as the link is written:
    ``beta + gamma = 1`` (``fc`` the saturation force) when it has an ultimate force.
    """

    fc: float = 1.0
    n: float | None = 1.0

    @classmethod
    def of_exponent(cls, n: float | None) -> BoucWenShape:
        """The layout of a Bouc-Wen link of exponent `n` (None: estimated; the force scale
        set later)."""
        entries = [(BoucWen.parameters[0], -1), (SHAPE_SUM, -1), (SHAPE_DIFFERENCE, -1)]
        if n is None:
            entries.append((EXPONENT_EXCESS, -1))
        return cls(BoucWen, entries, {} if n is None else {"n": float(n)},
                   n=None if n is None else float(n))

    def exponent(self, v: NDArray[np.float64] | None = None) -> float:
        """The exponent: fixed, or of the values `v` (its start without them)."""
        if self.n is not None:
            return self.n
        return EXPONENT_START if v is None else 1.0 + float(v[3])

    def shape(self, force: float, beta: float, gamma: float) -> NDArray[np.float64]:
        """``beta + gamma, beta - gamma`` at this layout's scale of the link whose force
        scale is `force` with shape `beta`, `gamma` (and ``n - 1`` at its start if
        estimated)."""
        r = (self.fc / force) ** self.exponent()
        tail = [] if self.n is not None else [EXPONENT_START - 1.0]
        return np.array([(beta + gamma) * r, (beta - gamma) * r, *tail])

    def build(self, v: NDArray[np.float64]) -> Hysteresis:
        return BoucWen(k=float(v[0]), fc=self.fc, n=self.exponent(v),
                       beta=0.5 * float(v[1] + v[2]), gamma=0.5 * float(v[1] - v[2]))

    def start(self, k_link: float, y_scale: float, v_scale: float, c: float,
              slip: float = 1.0) -> NDArray[np.float64]:
        """As :meth:`LinkLayout.start`: the link's force scale at ``0.5 y_scale`` times its
        stiffness, times `slip`, ``beta = 0.6, gamma = 0.4``."""
        return np.concatenate([[k_link], self.shape(k_link * 0.5 * y_scale * slip, 0.6, 0.4)])

    def normalised(self, names: list[str], values: NDArray[np.float64],
                   cov: NDArray[np.float64]):
        """The estimates `values` of `names` (the search's) and their covariance `cov`, with
        ``link.fc, link.beta, link.gamma`` (and ``link.n``) for the shape values:
        ``beta + gamma = 1`` when it is positive (scale ``fc (beta + gamma)^(-1/n)``), else
        at the search's scale; the covariance by the derivatives of that map.  Returns
        names, values, covariance, the link."""
        i, j = names.index("link.beta+gamma"), names.index("link.beta-gamma")
        e = names.index("link.n-1") if self.n is None else None
        ssum, diff = float(values[i]), float(values[j])
        n = self.n if e is None else 1.0 + float(values[e])
        if ssum > 0.0:
            fc = self.fc * ssum ** (-1.0 / n)
            beta, gamma = 0.5 + 0.5 * diff / ssum, 0.5 - 0.5 * diff / ssum
            d = np.array([[-fc / (n * ssum), 0.0, fc * math.log(ssum) / n ** 2],
                          [-0.5 * diff / ssum ** 2, 0.5 / ssum, 0.0],
                          [0.5 * diff / ssum ** 2, -0.5 / ssum, 0.0]])
        else:
            fc, beta, gamma = self.fc, 0.5 * (ssum + diff), 0.5 * (ssum - diff)
            d = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, -0.5, 0.0]])
        shape = [i, j] + ([] if e is None else [e])
        keep = [m for m in range(len(names)) if m not in shape]
        at = sum(m < min(shape) for m in keep)
        new = ["link.fc", "link.beta", "link.gamma"] + ([] if e is None else ["link.n"])
        out_names = [names[m] for m in keep]
        out_names[at:at] = new
        T = np.zeros((len(out_names), len(names)))
        for row, m in enumerate(keep):
            T[row + (len(new) if row >= at else 0), m] = 1.0
        T[at:at + 3, shape] = d[:, :len(shape)]
        if e is not None:
            T[at + 3, e] = 1.0
        out = np.zeros(len(out_names))
        out[[r for r in range(len(out_names)) if not at <= r < at + len(new)]] = values[keep]
        out[at:at + len(new)] = [fc, beta, gamma, n][:len(new)]
        unknown = np.isnan(cov)  # undetermined: so is what depends on it
        cov_out = T @ np.where(unknown, 0.0, cov) @ T.T
        cov_out[(np.abs(T) @ unknown @ np.abs(T).T) > 0] = np.nan
        return out_names, out, cov_out, BoucWen(k=float(values[names.index("link.k")]),
                                                fc=fc, n=n, beta=beta, gamma=gamma)
