"""The EMPS benchmark's models by name: a friction link and its options, and its rigid limit.

:func:`~motionhyst.identify.emps.run_emps` identifies a friction link on a mass-damper,
named as the link (:data:`LINKS`) followed by options (:data:`OPTIONS`:
``jenkins-asymmetric-drift``; without ``-asymmetric`` or ``-symmetric``, viscous friction by
direction where the record shows it, as ``identify`` fits it).  A Jenkins link whose
stiffness the record cannot resolve is reported as its rigid limit, the Coulomb link with the
same options (:func:`unresolved_stiffness`, :data:`RIGID_LIMIT`).
"""

from __future__ import annotations

from motionhyst.identify.io_friction import STUCK_MODE_SAMPLES as STUCK_MODE_SAMPLES
from motionhyst.identify.rigid_limit import unresolved_stiffness as stiffness_rule

__all__ = ["LINKS", "OPTIONS", "RIGID_LIMIT", "STUCK_MODE_SAMPLES", "check_model",
           "model_options", "unresolved_stiffness"]


#: The options a model's name may end with (``jenkins-asymmetric-drift``): viscous friction by
#: direction (``identify --asymmetric``) or one coefficient (``--symmetric``; neither: by
#: direction where the record shows it, ``identify``'s default), a drifting force offset
OPTIONS = ("asymmetric", "symmetric", "drift")


def model_options(name: str) -> tuple[str, set[str]]:
    """A model's link and its options, from its name (the link's, then ``-asymmetric`` or
    ``-symmetric`` and ``-drift``: :func:`~motionhyst.identify.input_output.identify_io`'s
    options).

    Parameters
    ----------
    name : str
        ``"jenkins-asymmetric-drift"``, ``"maxwell-slip-asymmetric"``, ...

    Returns
    -------
    link : str
        The registered link model's name.
    options : set of str
        Of :data:`OPTIONS`.

    Examples
    --------
    >>> link, options = model_options("maxwell-slip-asymmetric-drift")
    >>> link, sorted(options)
    ('maxwell-slip', ['asymmetric', 'drift'])
    >>> model_options("jenkins-symmetric")
    ('jenkins', {'symmetric'})
    """
    link, options = name, set()
    while True:
        head, _, tail = link.rpartition("-")
        if not head or tail not in OPTIONS:
            return link, options
        link = head
        options.add(tail)


#: What a failed fit says when the model needs a finer step than ``predict`` takes: on a
#: positioning axis, a link whose stiffness ran to the rigid limit (the Coulomb link)
RIGID_LIMIT = "integration steps per sample"


def check_model(name: str) -> None:
    """Refuse a model name :func:`~motionhyst.identify.emps.run_emps` cannot identify (one
    line naming the choices).

    Parameters
    ----------
    name : str
        A link of :data:`LINKS`, optionally ending in ``-asymmetric`` or ``-symmetric`` and
        in ``-drift`` (:func:`model_options`).

    Raises
    ------
    ValueError
        A name that is none of these.

    Examples
    --------
    >>> check_model("jenkins-asymmetric-drift")
    >>> check_model("bouc-wen")
    Traceback (most recent call last):
    ...
    ValueError: benchmark model 'bouc-wen': a friction link of coulomb, dahl, jenkins, lugre, ...
    >>> check_model("coulomb-symmetric-asymmetric")
    Traceback (most recent call last):
    ...
    ValueError: benchmark model 'coulomb-symmetric-asymmetric': -asymmetric and -symmetric ...
    """
    link, options = model_options(name)
    if link not in LINKS:
        raise ValueError(f"benchmark model {name!r}: a friction link of {', '.join(LINKS)}, "
                         f"optionally ending in -asymmetric or -symmetric and/or -drift "
                         f"(jenkins-asymmetric-drift)")
    if {"asymmetric", "symmetric"} <= options:
        raise ValueError(f"benchmark model {name!r}: -asymmetric and -symmetric exclude each "
                         f"other")


def unresolved_stiffness(name: str, parameters: dict, std: dict, fs: float) -> str | None:
    """Why a Jenkins link's stiffness is beyond what a record resolves, or None: the rule of
    :func:`~motionhyst.identify.rigid_limit.unresolved_stiffness` (``k`` not determined, or
    the stuck mode ``sqrt(k/m) / 2 pi`` above ``fs /`` :data:`STUCK_MODE_SAMPLES`), for a
    benchmark model by name (a stiffness run to 8.6e8 N/m, a stuck mode of 486 Hz at 1 kHz,
    pulled a mass 3 % low on ``DATA_EMPS``).

    Parameters
    ----------
    name : str
        The model's name (:func:`model_options`).
    parameters, std : dict
        Its own estimates and standard errors (``m``, ``k``; None: not determined).
    fs : float
        The record's sampling rate [Hz].

    Returns
    -------
    str or None
        One phrase saying why; None for a link without ``k`` or one the record resolves.

    Examples
    --------
    >>> def jenkins(k, std):
    ...     return unresolved_stiffness("jenkins-asymmetric", {"m": 95.0, "k": k}, {"k": std},
    ...                                 1000.0)
    >>> jenkins(3e7, 1e6) is None   # 89 Hz
    True
    >>> jenkins(8.6e8, 2.8e8)
    'its stuck mode at 479 Hz with k 8.6e+08 N/m, above 1000 Hz / 4: the records do not ...'
    >>> jenkins(9.4e9, None)
    'k 9.4e+09 N/m, not determined by the records'
    """
    if "k" not in parameters or "m" not in parameters or model_options(name)[0] != "jenkins":
        return None
    return stiffness_rule(parameters["k"], std.get("k"), parameters["m"], fs)


#: The links :func:`~motionhyst.identify.emps.run_emps` identifies on the mass-damper
LINKS = ("coulomb", "dahl", "jenkins", "lugre", "maxwell-slip")
