"""Scans in a study: the output ``scan`` (the moving average and moving standard deviation of
a scan's error, as ``motionhyst scan`` grades it) and its settings, a ``[scan]`` table and
axes ``scan.length``, ``scan.speed``, ``scan.a_max``, ``scan.j_max``, ``scan.s_max``,
``scan.window`` and ``scan.compensation``::

    scenario = "scan.toml"
    outputs = ["scan"]
    [scan]
    length = 0.01
    a_max = 2.0
    j_max = 50.0
    s_max = 1000.0
    [axes]
    "scan.speed" = [0.05, 0.1, 0.2]
    "scan.compensation" = ["none", "model"]

A point's scan is the command's with the same options (:data:`SCAN_DEFAULTS` are its
defaults): a fourth-order setpoint from rest after :data:`LEAD_IN`, the loop of the point's
scenario keys with the compensation of the point, and the largest ``|MA|`` and ``MSD`` over
the constant-velocity phases, the peak error and the settling time
(:func:`motionhyst.scan.scanning.run_scan`).  The reference's ``amplitude`` and
``frequency_hz`` do not enter a scan.
"""

from __future__ import annotations

import math

__all__ = ["COMPENSATIONS", "LEAD_IN", "SCAN_AXES", "SCAN_DEFAULTS", "scan_settings"]

LEAD_IN = 0.01
"""Rest before the setpoint starts [s] (``motionhyst scan``'s)."""

COMPENSATIONS = ("none", "model", "ilc", "basis")
"""The values of ``scan.compensation`` (``motionhyst scan --compensation``)."""

SCAN_AXES = ("scan.length", "scan.speed", "scan.a_max", "scan.j_max", "scan.s_max",
             "scan.window", "scan.compensation")
"""The scan's settings a study may sweep as axes."""

REQUIRED = ("length", "speed", "a_max", "j_max", "s_max")

SCAN_DEFAULTS: dict = {
    "window": 0.01, "compensation": "none", "point_to_point": False, "back_and_forth": False,
    "dwell": 0.0, "rate_hz": None, "tail": 0.05, "settle_tolerance": 1e-9, "feedforward": None,
    "ilc_trials": 10, "ilc_gain": 1.0, "ilc_cutoff": 300.0, "ilc_order": 2, "basis_trials": 4}
"""The settings of a ``[scan]`` table not given, as ``motionhyst scan``'s defaults (``window``
[s], ``tail`` [s], ``settle_tolerance`` [m], ``rate_hz`` the controller rate or None, ...;
``feedforward`` None: the terms the command runs without ``--feedforward``)."""

_POSITIVE = ("length", "speed", "a_max", "j_max", "s_max", "window", "settle_tolerance",
             "ilc_cutoff", "rate_hz")
_NONNEGATIVE = ("dwell", "tail")
_WHOLE = ("ilc_trials", "ilc_order", "basis_trials")


def _number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def check_scan_value(key: str, value, where: str) -> None:
    """Raise ``ValueError`` naming `where` if `value` is not a valid scan setting `key`.

    Parameters
    ----------
    key : str
        The setting (``"speed"``, ``"compensation"``, ...).
    value : object
        Its value.
    where : str
        The key as the file names it, for the message.

    Examples
    --------
    >>> check_scan_value("speed", 0.1, "[scan] 'speed'")
    >>> check_scan_value("compensation", "learned", "[scan] 'compensation'")
    Traceback (most recent call last):
    ...
    ValueError: [scan] 'compensation': give one of none, model, ilc, basis, got 'learned'
    """
    if key in _POSITIVE:
        ok, what = _number(value) and value > 0, "a number > 0"
    elif key in _NONNEGATIVE:
        ok, what = _number(value) and value >= 0, "a number >= 0"
    elif key in _WHOLE:
        ok, what = (isinstance(value, int) and not isinstance(value, bool)
                    and 1 <= value <= 1000), "a whole number from 1 to 1000"
    elif key == "ilc_gain":
        ok, what = _number(value) and 0 < value < 2, "a number in (0, 2)"
    elif key in ("point_to_point", "back_and_forth"):
        ok, what = isinstance(value, bool), "true or false"
    elif key == "compensation":
        ok, what = value in COMPENSATIONS, f"one of {', '.join(COMPENSATIONS)}"
    elif key == "feedforward":
        from motionhyst.scan.terms import TERMS

        ok = (isinstance(value, list) and all(t in TERMS for t in value)
              and len(set(value)) == len(value))
        what = f"a list of distinct terms among {', '.join(TERMS)}"
    else:
        raise ValueError(f"{where}: unknown setting (a scan has {', '.join(SCAN_DEFAULTS)} "
                         f"and {', '.join(REQUIRED)})")
    if not ok:
        raise ValueError(f"{where}: give {what}, got {value!r}")


def scan_settings(table: dict | None, axes: dict) -> dict:
    """The scan's settings of a study: its ``[scan]`` `table` over :data:`SCAN_DEFAULTS`,
    checked, with the settings its ``scan.*`` `axes` sweep left out.

    Parameters
    ----------
    table : dict or None
        The study file's ``[scan]``.
    axes : dict
        The study's axes (their ``scan.*`` keys are settings too).

    Returns
    -------
    dict
        Every setting but the swept ones.

    Raises
    ------
    ValueError
        One line naming the key: an unknown or invalid setting, a required one (``length``,
        ``speed``, ``a_max``, ``j_max``, ``s_max``) neither in the table nor an axis.

    Examples
    --------
    >>> s = scan_settings({"length": 0.01, "a_max": 2.0, "j_max": 50.0, "s_max": 1e3},
    ...                   {"scan.speed": [0.05, 0.1]})
    >>> s["length"], s["window"], "speed" in s
    (0.01, 0.01, False)
    """
    table = dict(table or {})
    out = dict(SCAN_DEFAULTS)
    for key, value in table.items():
        check_scan_value(key, value, f"[scan] {key!r}")
        out[key] = value
    swept = {k[5:] for k in axes if k.startswith("scan.")}
    for key in REQUIRED:
        if key not in out and key not in swept:
            raise ValueError(f"[scan] {key!r}: missing (give it here or as the axis "
                             f"\"scan.{key}\")")
    for key in swept:
        if key in table:
            raise ValueError(f"[scan] {key!r}: also the axis \"scan.{key}\"; give one")
        out.pop(key, None)
    if out["point_to_point"] and (out["back_and_forth"] or out["dwell"]):
        raise ValueError("[scan]: back_and_forth and dwell apply to scans, not to "
                         "point_to_point")
    return out


def run_point_scan(loop, settings: dict, unset: tuple[str, ...] = ()) -> dict:
    """The output ``scan`` of one point: ``ma_max``, ``msd_max``, ``peak_error`` [m] and
    ``settling_time_s`` [s] (NaN where the command prints none) of the scan of `settings` on
    `loop`, as ``motionhyst scan`` computes them.

    Parameters
    ----------
    loop : Loop
        The point's loop.
    settings : dict
        Every setting (:func:`scan_settings` and the point's ``scan.*`` values).
    unset : tuple of str
        The stage terms (``jerk``, ``snap``) the scenario's ``[feedforward]`` leaves unset.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> s = scan_settings({"length": 0.005, "speed": 0.05, "a_max": 2.0, "j_max": 50.0,
    ...                    "s_max": 1e3, "window": 0.05}, {})
    >>> out = run_point_scan(default_scenario().loop(), s)
    >>> round(out["ma_max"] / (0.05 / 6.2e6), 2)        # slipping link: e = fc / C(0)
    1.0
    """
    from motionhyst.scan.ilc import ILCFilters
    from motionhyst.scan.profiles import point_to_point, scan
    from motionhyst.scan.scanning import run_scan
    from motionhyst.scan.terms import scan_terms

    s = settings
    if s["point_to_point"]:
        profile = point_to_point(s["length"], s["speed"], s["a_max"], s["j_max"], s["s_max"],
                                 rate_hz=s["rate_hz"], start=LEAD_IN)
    else:
        profile = scan(s["length"], s["speed"], s["a_max"], s["j_max"], s["s_max"],
                       back_and_forth=s["back_and_forth"], dwell=s["dwell"],
                       rate_hz=s["rate_hz"], start=LEAD_IN)
    terms = s["feedforward"] if s["feedforward"] is not None else scan_terms(loop, unset)
    res = run_scan(loop, profile, s["window"], [s["compensation"]], s["ilc_trials"],
                   ILCFilters(s["ilc_gain"], s["ilc_cutoff"], s["ilc_order"]), None,
                   s["settle_tolerance"], s["tail"], feedforward=terms,
                   basis_trials=s["basis_trials"], without_link=False)
    r = res.runs[0]
    return {name: math.nan if getattr(r, name) is None else float(getattr(r, name))
            for name in ("ma_max", "msd_max", "peak_error", "settling_time_s")}
