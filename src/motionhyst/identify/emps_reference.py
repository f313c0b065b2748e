"""The EMPS benchmark's reference models: inverse dynamics (IDIM-LS), symmetric and asymmetric.

A. Janot, M. Gautier and M. Brunot, "Data Set and Reference Models of EMPS",
Workshop on Nonlinear System Identification Benchmarks, Eindhoven, 2019.  The
benchmark's reference model is a mass with viscous and Coulomb friction and a force
offset ``OF`` identified by inverse dynamics and least squares (IDIM-LS):

.. math::

    M \\ddot q = F - F_v \\dot q - F_c \\operatorname{sign}(\\dot q) - OF;

its description's section 4.2 gives the same method with asymmetric friction, eq. (12),
viscous and Coulomb coefficients by direction and no offset (the screw's mechanical fatigue):

.. math::

    M \\ddot q = F - F_v^+ 0^+(\\dot q) - F_c^+ \\operatorname{sign}(0^+(\\dot q))
    - F_v^- 0^-(\\dot q) - F_c^- \\operatorname{sign}(0^-(\\dot q)),

``0+(q') = max(q', 0)``, ``0-(q') = min(q', 0)``.  Here: their published parameters, the
models as open-loop systems (:func:`reference_system`), eq. (12) by one linear solve
(:func:`asymmetric_inverse_dynamics`), and the constant offset a model with friction by
direction amounts to (:func:`equivalent_offset`).
"""

from __future__ import annotations

import numpy as np

from motionhyst.identify.input_output import IORecord

__all__ = ["PUBLISHED", "REFERENCE_ASYMMETRIC", "REFERENCE_MODEL", "asymmetric_inverse_dynamics",
           "equivalent_offset", "reference_system"]

REFERENCE_MODEL = {"m": 95.1089, "c": 203.5034, "fc": 20.3935, "offset": -3.1648}
"""The benchmark's IDIM-LS model: M [kg], Fv [N s/m], Fc [N], OF [N]."""
REFERENCE_ASYMMETRIC = {"m": 95.1540, "c_pos": 166.7061, "fc_pos": 20.1440, "c_neg": 240.4236,
                        "fc_neg": 20.6277}
"""The benchmark's IDIM-LS model with asymmetric friction (its description's eq. 12, section
4.2): ``M q'' = F - Fv+ 0+(q') - Fc+ sign(0+(q')) - Fv- 0-(q') - Fc- sign(0-(q'))``, no offset:
M [kg], Fv+, Fv- [N s/m], Fc+, Fc- [N]."""
PUBLISHED: tuple[tuple[str, float | None, float], ...] = (
    ("dynoNet (neural, black box; Forgione and Piga 2021)", 2.64, 96.8),
    ("IDIM-LS reference model, simulated open loop from rest with its offset", 9.2, 88.8),
    ("best linear model (as cited by dynoNet)", None, 25.4),
)
"""Published simulation results on the test record: (method, RMSE [mm] or None, fit [%])."""


def reference_system(parameters: dict | None = None):
    """The IDIM-LS reference model as an open-loop system (a mass-damper with Coulomb friction).

    Parameters
    ----------
    parameters : dict, optional
        ``m, c, fc, offset`` (default :data:`REFERENCE_MODEL`, the published ones), or the
        asymmetric model's ``m, c_pos, c_neg, fc_pos, fc_neg`` (:data:`REFERENCE_ASYMMETRIC`:
        the stage's viscous friction by direction, the Coulomb link's force by direction,
        no offset).

    Examples
    --------
    >>> sys = reference_system()
    >>> sys.plant.m, sys.hysteresis.fc
    (95.1089, 20.3935)
    >>> sys = reference_system(REFERENCE_ASYMMETRIC)
    >>> round(sys.plant.c_pos, 4), round(sys.plant.c_neg, 4), sys.hysteresis.fc_neg
    (166.7061, 240.4236, 20.6277)
    """
    from motionhyst.hysteresis import Coulomb
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    r = REFERENCE_MODEL if parameters is None else parameters
    if "c_pos" in r:
        return OpenLoop(MassDamper.by_direction(r["m"], r["c_pos"], r["c_neg"]),
                        Coulomb(fc_pos=r["fc_pos"], fc_neg=r["fc_neg"]))
    return OpenLoop(MassDamper(r["m"], r["c"], force_offset=-r["offset"]), Coulomb(fc=r["fc"]))


def asymmetric_inverse_dynamics(record: IORecord) -> dict[str, float]:
    """The benchmark's asymmetric IDIM-LS model (:data:`REFERENCE_ASYMMETRIC`'s, eq. 12) of a
    record: one linear least-squares solve.

    ``F = M q'' + Fv+ 0+(q') + Fc+ [q' > 0] + Fv- 0-(q') - Fc- [q' < 0]``, the rates from
    :func:`~motionhyst.identify.io_start.equation_rows`' Savitzky-Golay filter; no offset
    (a constant force while the axis moves is the difference of ``Fc+`` and ``Fc-``).

    Parameters
    ----------
    record : IORecord
        Time [s], force [N], position [m].

    Returns
    -------
    dict
        ``m, c_pos, c_neg, fc_pos, fc_neg`` [kg, N s/m, N].

    Examples
    --------
    >>> t = np.arange(4000) / 1000.0
    >>> y = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(6 * np.pi * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = (95 * np.gradient(v, t, edge_order=2) + 160 * np.maximum(v, 0) + 20 * (v > 0)
    ...      + 240 * np.minimum(v, 0) - 21.0 * (v < 0))
    >>> {k: round(x) for k, x in asymmetric_inverse_dynamics(IORecord(t, u, y)).items()}
    {'m': 95, 'c_pos': 160, 'c_neg': 240, 'fc_pos': 20, 'fc_neg': 21}
    """
    from motionhyst.identify.io_start import equation_rows

    (rows,), (u,) = equation_rows([record], floating=True, asymmetric=True)
    A = np.column_stack([rows[:, :3], (rows[:, 1] > 0) * 1.0, (rows[:, 2] < 0) * -1.0])
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    x = np.linalg.lstsq(A / scale, u, rcond=None)[0] / scale
    return dict(zip(("m", "c_pos", "c_neg", "fc_pos", "fc_neg"), map(float, x), strict=True))


def equivalent_offset(parameters: dict, record: IORecord) -> float:
    """The constant force offset ``OF`` that a model's offset amounts to on a record's motion.

    The benchmark's reference model has one viscous coefficient and a constant
    offset.  With viscous friction by direction (``c + c_pos`` forward,
    ``c + c_neg`` backward: the Coulomb link's own; or the stage's ``c +
    c_skew`` forward, ``c - c_skew`` backward) the friction's viscous force is
    ``(c + (c_pos + c_neg)/2) q' + d |q'|``, ``d = c_skew + (c_pos - c_neg)/2``:
    its even part acts as an offset that follows the speed, and on a motion
    whose mean speed is ``mean |q'|`` it is the constant offset ``d mean |q'|``; a drifting
    offset ``OF + rate t`` is ``OF + rate mean(t)`` on average.  Their sum is
    what the reference model's ``OF`` is fitted to (EMPS, viscous friction by
    direction: ``OF`` +0.11 N and ``(c_pos - c_neg)/2 mean |q'|`` = -3.0 N
    against the published -3.16 N).

    Parameters
    ----------
    parameters : dict
        ``offset`` [N] and optionally ``c_pos``, ``c_neg``, ``c_skew`` [N s/m],
        ``drift`` [N/s] (as :class:`~motionhyst.identify.emps.EMPSModel` holds them), or
        Coulomb forces by direction ``fc_pos``, ``fc_neg`` [N] (:data:`REFERENCE_ASYMMETRIC`:
        ``(fc_pos - fc_neg) / 2`` is an offset while the axis moves).
    record : IORecord
        The record whose motion the model was identified on (its velocity is
        the measured position's gradient).

    Returns
    -------
    float
        ``OF + (fc_pos - fc_neg)/2 + rate mean(t) + d mean |q'|`` [N].

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(2001) / 1000.0
    >>> rec = IORecord(t, np.zeros_like(t), 0.05 * np.sin(np.pi * t))  # mean |q'| = 0.1 m/s
    >>> round(equivalent_offset({"offset": 0.1, "c_neg": 76.0}, rec), 2)
    -3.7
    >>> round(equivalent_offset({"offset": -3.0, "drift": -0.02}, rec), 2)  # mean t = 1 s
    -3.02
    >>> round(equivalent_offset({"offset": 0.1, "c_skew": -38.0}, rec), 2)
    -3.7
    >>> round(equivalent_offset({"c_pos": 160.0, "c_neg": 236.0, "fc_pos": 20.0,
    ...                          "fc_neg": 20.2}, rec), 2)
    -3.9
    """
    v = np.gradient(record.y, record.t)
    offset = parameters.get("offset", 0.0)
    if "fc_pos" in parameters:  # Coulomb forces by direction: their difference while moving
        offset += 0.5 * (parameters["fc_pos"] - parameters["fc_neg"])
    even = (parameters.get("c_skew", 0.0)
            + 0.5 * (parameters.get("c_pos", 0.0) - parameters.get("c_neg", 0.0)))
    return float(offset + parameters.get("drift", 0.0) * np.mean(record.t)
                 + even * np.mean(np.abs(v)))
