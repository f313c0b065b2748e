"""What a link's force-displacement records can determine: checked before the search and
judged after it.

A record too short or too poor for the model is no result (issue 26: no answer from
nothing).  On 64 samples of a test stand the LuGre link's fit by the force's error exited 0
with its static force ``fs = 4.2e10 +- 4.1e10 N`` against forces of 2 N, and the Dahl link's
with its exponent ``alpha = 0.0088 +- 0.0075``: values the search ended at, not values the
record holds.

* Before the search (:func:`check_samples_per_parameter`): the records hold at least
  :data:`MIN_SAMPLES_PER_PARAMETER` samples for each parameter the fit estimates (the stage's
  spring and damper, the link's, the offsets), refused in one line at once.
* After it (:func:`weakly_determined`, :func:`judge_link_force`): a parameter that must be
  positive whose standard error (of white residuals) is :data:`TWO_STANDARD_ERRORS` of its
  value or more is not determined: its estimate is not two standard errors from 0, so its
  95 % interval holds the model without it.  Any such parameter fails the fit, named in one
  line, nothing saved (a parameter whose range holds 0, a spring or damper in parallel, is
  then a value the records allow, as :func:`~motionhyst.identify.io_uncertainty.undetermined`
  has it).
"""

from __future__ import annotations

import math
import re

from motionhyst.identify.io_uncertainty import simpler_link

__all__ = ["MIN_SAMPLES_PER_PARAMETER", "TWO_STANDARD_ERRORS", "check_samples_per_parameter",
           "judge_link_force", "weakly_determined"]

MIN_SAMPLES_PER_PARAMETER = 10
"""The fewest samples of the records for each parameter a fit estimates (the rule of ten
observations a parameter of regression): fewer leave the search's values, not the records'."""

TWO_STANDARD_ERRORS = 0.5
"""A positive parameter's standard error, as a share of its value, at which the records do
not determine it: the value is then less than two standard errors from 0."""

#: Parameters of either sign, or the records' own, never judged here
_SIGNED = ("offset", "drift", "v0", "x0", "c_skew")


def check_samples_per_parameter(sizes: list[int], parameters: int, what: str) -> None:
    """Refuse records that hold fewer than :data:`MIN_SAMPLES_PER_PARAMETER` samples for each
    parameter of the fit, before its search.

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    parameters : int
        The parameters the fit estimates (stage, link and offsets).
    what : str
        The fit, as the line names it (``"the lugre link's fit"``).

    Raises
    ------
    ValueError
        One line: the samples, the parameters, the least, the remedy.

    Examples
    --------
    >>> check_samples_per_parameter([4000], 8, "the lugre link's fit")
    >>> try:
    ...     check_samples_per_parameter([64], 8, "the lugre link's fit")
    ... except ValueError as exc:
    ...     print(exc)
    the records hold 64 samples for the 8 parameters of the lugre link's fit, fewer than 10 \
for each (80): they cannot determine them; give a longer record or a simpler link
    """
    n = sum(int(s) for s in sizes)
    least = MIN_SAMPLES_PER_PARAMETER * int(parameters)
    if n < least:
        raise ValueError(f"the records hold {n} samples for the {parameters} parameters of "
                         f"{what}, fewer than {MIN_SAMPLES_PER_PARAMETER} for each ({least}): "
                         f"they cannot determine them; give a longer record or a simpler link")


def weakly_determined(estimates: dict[str, float], std: dict[str, float | None],
                      invariant: tuple[str, ...] = (),
                      zero: set[str] | frozenset = frozenset()) -> list[str]:
    """The positive parameters whose standard error is :data:`TWO_STANDARD_ERRORS` of their
    value or more (or unknown): not determined by the records.

    Parameters
    ----------
    estimates, std : dict
        The fit's estimates and the standard errors of white residuals (``None`` where not
        determined).
    invariant : tuple of str
        Parameters along whose combination the model's output does not change (left out).
    zero : set of str
        The parameters whose range holds 0
        (:func:`~motionhyst.identify.io_uncertainty.zero_allowed`): left out.

    Returns
    -------
    list of str
        Their names, in the order of `estimates`.

    Examples
    --------
    >>> weakly_determined({"k": 110.0, "link.fc": 1.97, "link.alpha": 0.0088,
    ...                    "input_offset": 1e-3},
    ...                   {"k": 9.0, "link.fc": 0.017, "link.alpha": 0.005,
    ...                    "input_offset": 0.003}, zero={"k"})
    ['link.alpha']
    """
    out = []
    for name, value in estimates.items():
        base = name.split("[")[0]
        if name in invariant or base in zero or any(word in name for word in _SIGNED):
            continue
        s = std.get(name)
        if s is None or not math.isfinite(s) or s >= TWO_STANDARD_ERRORS * abs(value):
            out.append(name)
    return out


def judge_link_force(estimates: dict[str, float], std: dict[str, float | None],
                     invariant: tuple[str, ...], zero: set[str] | frozenset,
                     link: str, said: list[str] | tuple[str, ...] = ()) -> None:
    """Fail a link's force-displacement fit of which a positive parameter is not determined
    (:func:`weakly_determined`), unless a warning of the fit names it already.

    Parameters
    ----------
    estimates, std, invariant, zero
        As for :func:`weakly_determined`.
    link : str
        The link model's name (the remedy names a simpler one).
    said : sequence of str
        The fit's own warnings: a parameter one of them names is reported there, with its
        remedy (a LuGre link's Stribeck speed on records without a Stribeck effect: the
        Dahl link), not failed here.

    Raises
    ------
    FitFailed
        One line naming the parameters, their values and standard errors.

    Examples
    --------
    >>> from motionhyst.identify.io_checks import FitFailed
    >>> try:
    ...     judge_link_force({"link.fs": 4.2e10, "link.fc": 2.28},
    ...                      {"link.fs": 4.1e10, "link.fc": 0.17}, (), set(), "lugre")
    ... except FitFailed as exc:
    ...     print(exc)
    the fit failed: the records do not determine link.fs = 4.2e+10 +- 4.1e+10 (not two \
standard errors from 0): its value would be the search's; give a longer or richer record, or \
a simpler link (--model jenkins or coulomb)
    >>> judge_link_force({"link.fs": 4.2e10}, {"link.fs": 4.1e10}, (), set(), "lugre",
    ...                  said=["no Stribeck effect in the records: link.fs = ..."])
    """
    from motionhyst.identify.io_checks import FitFailed

    names = [n for n in weakly_determined(estimates, std, invariant, zero)
             if not any(re.search(rf"(?<![\w.]){re.escape(n)}(?![\w\[])", line)
                        for line in said)]
    if not names:
        return
    shown = ", ".join(f"{n} = {estimates[n]:.2g} +- "
                      f"{'unknown' if std.get(n) is None else format(std[n], '.2g')}"
                      for n in names)
    its = ("its value" if len(names) == 1 else "their values")
    raise FitFailed(f"the fit failed: the records do not determine {shown} (not two standard "
                    f"errors from 0): {its} would be the search's; give a longer or richer "
                    f"record{simpler_link(link)}")
