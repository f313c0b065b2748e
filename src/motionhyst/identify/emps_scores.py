"""The EMPS benchmark's metric, and what a record's drift does to it.

:func:`score` is the benchmark's metric (A. Janot, M. Gautier and M. Brunot, "Data Set and
Reference Models of EMPS", Workshop on Nonlinear System Identification Benchmarks, Eindhoven,
2019): the position simulated from the force alone, its initial state set from the first
:data:`~motionhyst.identify.io_predict.INIT_WINDOW` samples, its RMS error in mm over the
samples after them.  :func:`own_offset_score` and :func:`period_drift` are diagnoses of the
record's force offset drifting, not scores: the benchmark's models may not look at the record
they are scored on.
"""

from __future__ import annotations

import numpy as np

from motionhyst.identify.emps_files import PERIOD
from motionhyst.identify.input_output import IORecord
from motionhyst.identify.io_predict import INIT_WINDOW, predict_from_window
from motionhyst.identify.io_start import inverse_dynamics

__all__ = ["own_offset_score", "period_drift", "score"]


def score(system, record: IORecord) -> tuple[dict, np.ndarray]:
    """The benchmark's metric of a model on a record, and the simulated position.

    The position is simulated from the force alone, the initial state set from
    the first :data:`INIT_WINDOW` samples
    (:func:`~motionhyst.identify.io_predict.predict_from_window`); the RMS error
    in mm and the fit in % count the samples from :data:`INIT_WINDOW` on.

    Parameters
    ----------
    system : OpenLoop
        The model (its plant's ``force_offset`` applied).
    record : IORecord
        Time [s], force [N] and measured position [m].

    Returns
    -------
    dict
        ``{"record": record.name, "rmse_mm": .., "fit_percent": ..}``.
    ndarray
        The simulated position [m].

    Examples
    --------
    The reference model scored on a record it made itself, shifted by 1 mm (the
    state set from the window takes the shift up):

    >>> import numpy as np
    >>> from motionhyst.identify.emps_reference import reference_system
    >>> ref = reference_system()
    >>> t = np.arange(3000) / 1000.0
    >>> u = 120.0 * np.sin(2 * np.pi * t)
    >>> y = ref.simulate(t, u).displacement
    >>> metric, _ = score(ref, IORecord(t, u, y + 1e-3, "shifted"))
    >>> metric["rmse_mm"] < 0.01, round(metric["fit_percent"], 1)
    (True, 100.0)
    """
    pred = predict_from_window(system, record.t, record.u, record.y, window=INIT_WINDOW)
    return ({"record": record.name, "rmse_mm": 1e3 * pred.rmse,
             "fit_percent": pred.fit_percent}, pred.displacement)


def own_offset_score(system, record: IORecord, span: float = 2.0) -> dict:
    """The model's score on a record with the force offset that suits the record best.

    The force offset ``OF`` alone is re-estimated on `record` (the plant
    receives ``F - OF``), everything else kept: the error left is the model's
    own, the rest of its score was the difference between the offset of the
    records it was identified from and this one's.  A diagnosis, not a score:
    the benchmark's models may not look at the record they are scored on.

    Parameters
    ----------
    system : OpenLoop
        The model (a plant with ``force_offset = -OF``).
    record : IORecord
        The record scored.
    span : float
        The offset is searched within this many newtons of the model's [N].

    Returns
    -------
    dict
        ``{"offset": OF [N], "rmse_mm": ..}``.

    Examples
    --------
    The reference model on its own record made with an offset 0.2 N larger:

    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> u = 120.0 * np.sin(2 * np.pi * t) + 40.0 * np.sin(5 * np.pi * t)
    >>> from motionhyst.identify.emps_reference import REFERENCE_MODEL, reference_system
    >>> shifted = reference_system(dict(REFERENCE_MODEL, offset=-2.9648))
    >>> y = shifted.simulate(t, u).displacement
    >>> own = own_offset_score(reference_system(), IORecord(t, u, y, "shifted"))
    >>> round(own["offset"], 3), own["rmse_mm"] < 0.01
    (-2.965, True)
    """
    from scipy.optimize import minimize_scalar

    plant = system.plant
    of = -plant.force_offset

    def rmse(offset: float) -> float:
        plant.force_offset = -offset
        try:
            return float(score(system, record)[0]["rmse_mm"])
        finally:
            plant.force_offset = -of

    sol = minimize_scalar(rmse, bounds=(of - span, of + span), method="bounded",
                          options={"xatol": 1e-3})
    return {"offset": float(sol.x), "rmse_mm": float(sol.fun)}


def period_drift(record: IORecord, period: int = PERIOD) -> list[dict]:
    """The inverse-dynamics (IDIM-LS) estimate of each period of a record, to see it drift.

    Each period (the last one if it holds at least half of one) is fitted
    alone by :func:`~motionhyst.identify.io_start.inverse_dynamics`, with one
    viscous friction and with one per direction.  On ``DATA_EMPS`` the force
    offset moves from -3.00 to -3.34 N over the four periods of the same motion;
    with viscous friction by direction the offset stays between -0.32 and -0.24 N and the
    forward viscous friction falls from 171 to 165 N s/m instead (the axis
    warming up, or a drift of the drive): a model identified on some periods
    misses the others by that much, whatever its friction law.

    Parameters
    ----------
    record : IORecord
        The record.
    period : int
        Samples per period.

    Returns
    -------
    list of dict
        ``{"period", "m", "offset", "c_pos", "c_neg", "offset_asymmetric"}`` per
        period (1-based), in [kg], [N], [N s/m].

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4000) / 1000.0
    >>> y = 0.05 * np.sin(2 * np.pi * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 95 * np.gradient(v, t, edge_order=2) + 200 * v + 20 * np.sign(v) - 3 - 0.2 * t
    >>> [round(d["offset"], 2) for d in period_drift(IORecord(t, u, y), 1000)]
    [-3.1, -3.3, -3.5, -3.7]
    """
    out = []
    for i in range(-(-record.t.size // period)):
        s = slice(i * period, min((i + 1) * period, record.t.size))
        if s.stop - s.start < period // 2:
            break
        piece = [IORecord(record.t[s], record.u[s], record.y[s], record.name)]
        sym = inverse_dynamics(piece, floating=True)
        asym = inverse_dynamics(piece, floating=True, asymmetric=True)
        out.append({"period": i + 1, "m": sym["m"], "offset": sym["u0"],
                    "c_pos": asym["c_pos"], "c_neg": asym["c_neg"],
                    "offset_asymmetric": asym["u0"]})
    return out
