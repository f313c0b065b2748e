"""Friction links of a positioning axis, in the spellings their search takes.

On a mass-damper (a positioning axis: a mass on guides, no spring to the ground)
the link is the axis's friction, and a friction force is bounded by its sliding
level.  Two registered links need another spelling of their parameters for the
search to keep to that (the element links' search,
:func:`~motionhyst.identify.io_elements.identify_elements_io`, takes any class
with the registry's ``parameters`` whose call returns the link):

- the Bouc-Wen link (:func:`bouc_wen_friction`): its hysteretic force alone,
  ``beta + gamma = 1`` so that ``fc`` is its sliding force;
- the LuGre link (:func:`lugre_stribeck`): the static force at least the Coulomb
  one, ``fs = fc + stribeck`` with ``stribeck >= 0`` (Canudas de Wit et al. 1995), its
  bristles between a presliding the records would see and a stuck mode they resolve.

Every friction link's limit is the rigid slider, the Coulomb link: a Jenkins link whose
stiffness the records do not resolve is that limit
(:func:`~motionhyst.identify.rigid_limit.unresolved_stiffness`).

Without them a search on a measured axis ends outside the models' meaning (EMPS:
a LuGre ``fc`` of 2.2e6 N against ``fs`` 23 N with ``vs`` 40 m/s, its Stribeck
curve a quadratic viscous term in place of ``c``, and the mass 70.9 kg for 95.1).
"""

from __future__ import annotations

import math

import numpy as np

from motionhyst.hysteresis import BoucWen, LuGre, Parameter
from motionhyst.identify.io_records import IORecord

__all__ = ["PRESLIDING_BOUND", "PRESLIDING_SHARE", "STUCK_MODE_SAMPLES", "VS_SHARE",
           "bouc_wen_friction", "lugre_stribeck", "presliding_note"]


def bouc_wen_friction(nu: float) -> type:
    """The Bouc-Wen link as a positioning axis's friction, in the spelling its search takes.

    On a mass-damper nothing holds the stage but the link, and its force is the
    normalised model's hysteretic force alone, eq. (2) of
    :class:`~motionhyst.hysteresis.BoucWen`: the general form's linear share is a
    spring to the ground, which a positioning axis does not have.  A friction force is
    bounded: ``beta + gamma > 0``, normalised to ``beta + gamma = 1`` so that ``fc``
    is the force the link saturates at when sliding (the friction force; only
    ``beta / fc^n`` and ``gamma / fc^n`` enter eq. (2), so ``fc`` and the two shape
    parameters are not determined together otherwise).  Searched: ``k``, ``fc`` and the
    dissipation ``d = beta - gamma >= 0`` (``beta = (1 + d) / 2``, ``gamma = (1 - d) / 2``:
    ``d = 0`` unloads at ``k``, larger ``d`` stiffer, the loops' area growing with it); the
    exponent ``n`` is fixed at `nu`.

    Parameters
    ----------
    nu : float
        The exponent ``n >= 1``.

    Returns
    -------
    type
        A class with the registry's ``parameters`` (``k``, ``fc``, ``dissipation``) whose
        call returns the :class:`~motionhyst.hysteresis.BoucWen` link.

    Examples
    --------
    >>> link = bouc_wen_friction(1.0)(k=2e5, fc=20.0, dissipation=0.5)
    >>> link.beta, link.gamma, link.n
    (0.75, 0.25, 1.0)
    """
    if not (math.isfinite(nu) and nu >= 1.0):
        raise ValueError(f"the Bouc-Wen exponent must be >= 1, got {nu!r}")

    class BoucWenFriction:
        """The Bouc-Wen friction link of :func:`bouc_wen_friction` (its search's spelling)."""

        name = BoucWen.name
        parameters = (Parameter("k", "N/m", "initial stiffness k"),
                      Parameter("fc", "N", "friction force f_c (beta + gamma = 1)"),
                      Parameter("dissipation", "", "beta - gamma >= 0", 1.0, "nonnegative"))

        def __new__(cls, k: float, fc: float, dissipation: float) -> BoucWen:  # type: ignore[misc]
            return BoucWen(k=k, fc=fc, n=nu, beta=0.5 * (1.0 + dissipation),
                           gamma=0.5 * (1.0 - dissipation))

    return BoucWenFriction


PRESLIDING_BOUND = 1e-3
"""The LuGre link's search keeps its presliding displacement ``fc / sigma0`` at most this share of
the records' stroke (bristles are stiff: a friction's presliding is micrometres)."""

VS_SHARE = 1e-3
"""The LuGre link's search keeps ``vs`` at least the records' velocity resolution: their position
quantum times the sampling rate, and at least this share of their largest speed."""


def lugre_stribeck(records: list[IORecord]) -> type:
    """The LuGre link as a positioning axis's friction, in the spelling its search takes.

    The Stribeck effect: the friction force falls from the static ``fs`` at rest to the
    Coulomb ``fc`` when sliding, ``g(v) = fc + (fs - fc) exp(-(v / vs)^2)``, so ``fs >=
    fc``: searched as ``fc`` and ``stribeck = fs - fc >= 0``.  With ``fs < fc`` and ``vs``
    above the record's speeds the curve is ``fs + (fc - fs) (v / vs)^2``, a quadratic
    viscous force that takes the stage's damper's place (EMPS: 70.9 kg).  The bristles are
    the contacts' micro-deflection before sliding, between two bounds the records set:
    stiff enough that the presliding ``fc / sigma0`` is at most ``P`` =
    :data:`PRESLIDING_BOUND` times the records' stroke (softer, they are a spring and damper
    in the link: EMPS 86.6 kg with 2 cm of presliding), and soft enough that the stuck mode
    ``sqrt(sigma0 / m) / 2 pi`` is at most a quarter of the sampling rate
    (:data:`STUCK_MODE_SAMPLES`; ``m`` the records' inverse-dynamics mass): stiffer, the
    records cannot tell the bristles from the rigid limit, and the search runs to it, a
    model no time step can follow.  Searched as ``bristle > 0``, ``sigma0 = lo^(1 - w)
    hi^w`` with ``w = bristle / (1 + bristle)``.  ``vs = v_min + vs_above``, ``vs_above >
    0``, keeps ``vs`` a speed the records resolve (``v_min``: their position quantum, the
    smallest step between samples, times the sampling rate, at least :data:`VS_SHARE` of
    their largest speed).  ``sigma1`` as :class:`~motionhyst.hysteresis.LuGre`'s.

    Parameters
    ----------
    records : list of IORecord
        The records the link is identified from (their stroke, speeds, resolution and
        inertia).

    Returns
    -------
    type
        A class with the registry's ``parameters`` (``bristle``, ``sigma1``, ``sigma2``,
        ``fc``, ``stribeck``, ``vs_above``) whose call returns the
        :class:`~motionhyst.hysteresis.LuGre` link.

    Examples
    --------
    >>> t = np.arange(1001) / 1000.0
    >>> u = 100 * np.sin(2 * np.pi * t)
    >>> rec = IORecord(t, u, np.round(-u / (2 * np.pi) ** 2 / 10, 6))   # 10 kg, stroke 0.5 m
    >>> cls = lugre_stribeck([rec])
    >>> link = cls(bristle=1.0, sigma1=300.0, sigma2=0.0, fc=20.0, stribeck=5.0, vs_above=0.01)
    >>> link.fs, f"{link.sigma0:.3g}", round(link.vs, 6)   # sigma0 sqrt(3.95e4 x 2.47e7)
    (25.0, '9.87e+05', 0.015)
    >>> [f"{cls(b, 0.0, 0.0, 20.0, 0.0, 0.01).sigma0:.3g}" for b in (1e-9, 1e9)]   # lo, hi
    ['3.95e+04', '2.47e+07']
    """
    from motionhyst.identify.io_start import inverse_dynamics

    stroke = max(float(np.ptp(rec.y)) for rec in records)
    steps = np.concatenate([np.abs(np.diff(rec.y)) for rec in records])
    moving = steps[steps > 0]
    quantum = float(np.min(moving)) if moving.size else 0.0
    fs = records[0].fs
    v_min = max(quantum * fs, VS_SHARE * float(np.max(steps)) * fs)
    least = 1.0 / (PRESLIDING_BOUND * stroke) if stroke > 0 else 0.0  # sigma0 / fc
    mass = inverse_dynamics(records, floating=True)["m"]
    stiffest = (mass * (2 * math.pi * fs / STUCK_MODE_SAMPLES) ** 2
                if math.isfinite(mass) and mass > 0 else math.inf)
    by_name = {p.name: p for p in LuGre.parameters}

    class LuGreStribeck:
        """The LuGre link of :func:`lugre_stribeck` (its search's spelling)."""

        name = LuGre.name
        parameters = (Parameter("bristle", "", "the bristles' stiffness between the records' "
                                "bounds, w / (1 - w)", 1.0),
                      by_name["sigma1"], by_name["sigma2"], by_name["fc"],
                      Parameter("stribeck", "N", "static force above the Coulomb one, fs - fc",
                                None, "nonnegative"),
                      Parameter("vs_above", "m/s", "Stribeck velocity above the records' "
                                "resolution"))

        def __new__(cls, bristle: float, sigma1: float, sigma2: float, fc: float,
                    stribeck: float, vs_above: float) -> LuGre:  # type: ignore[misc]
            lo = max(fc * least, 1e-300)
            hi = max(stiffest, lo)
            w = bristle / (1.0 + bristle) if math.isfinite(bristle) else 1.0
            sigma0 = lo * (hi / lo) ** w if math.isfinite(hi) else lo * (1.0 + bristle)
            return LuGre(sigma0=sigma0, sigma1=sigma1, sigma2=sigma2, fc=fc, fs=fc + stribeck,
                         vs=v_min + vs_above)

    return LuGreStribeck


PRESLIDING_SHARE = 0.01
"""A LuGre link whose bristles deflect more than this share of the records' motion (RMS about
each record's mean) before it slides, ``fc / sigma0``, is no friction's presliding (micrometres
on a machine's guides): a warning names ``sigma0``."""


def presliding_note(link: LuGre, records: list[IORecord]) -> str | None:
    """One warning line when a LuGre link's presliding, ``fc / sigma0``, is a large part of
    the records' motion (:data:`PRESLIDING_SHARE`), else None.

    The bristles of the LuGre model are the contacts' micro-deflection before sliding;
    deflecting over a sizeable part of the stroke they are a spring (``sigma0``) and a damper
    (``sigma1``) in the link, and the fit's friction and mass are another model's.

    Parameters
    ----------
    link : LuGre
        The identified link.
    records : list of IORecord
        The records it was identified from.

    Returns
    -------
    str or None

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 1000.0
    >>> rec = IORecord(t, np.sin(2 * np.pi * t), 0.07 * np.sin(2 * np.pi * t))
    >>> soft = LuGre(sigma0=703.0, sigma1=367.0, sigma2=0.0, fc=14.0, fs=20.0, vs=0.01)
    >>> presliding_note(soft, [rec])[:62]
    'link.sigma0 = 703 N/m: the bristles deflect fc / sigma0 = 2 cm'
    >>> presliding_note(LuGre(1e7, 0.0, 0.0, 14.0, 20.0, 0.01), [rec]) is None
    True
    """
    y = np.concatenate([rec.y - np.mean(rec.y) for rec in records])
    motion = float(np.sqrt(np.mean(y ** 2)))
    deflection = link.fc / link.sigma0
    if not (motion > 0 and deflection > PRESLIDING_SHARE * motion):
        return None
    size = f"{100 * deflection:.2g} cm" if deflection >= 1e-2 else f"{1e3 * deflection:.2g} mm"
    return (f"link.sigma0 = {link.sigma0:.3g} N/m: the bristles deflect fc / sigma0 = {size} "
            f"before the link slides, {100 * deflection / motion:.2g} % of the records' "
            f"motion (RMS), not a friction's presliding: the link acts as a spring and damper "
            f"and the other estimates are that model's")


STUCK_MODE_SAMPLES = 4
"""A stuck mode faster than the sampling rate over this many samples (four samples a period;
the Nyquist frequency is two) is not resolved by a record."""
