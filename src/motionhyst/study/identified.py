"""Monte-Carlo samples from an identification: the link's parameters drawn around their
estimates with their standard errors.

``motionhyst identify ... --json > fit.json`` writes the estimates and their standard errors
(a force-displacement record: ``elements`` with ``k``, ``fc``, ``k_std``, ``fc_std``; an
input-output record: ``estimates`` and ``std`` with the link's parameters as ``link.NAME``).
A study's ``[samples] from_identification = "fit.json"`` (or ``motionhyst study
--from-identification fit.json``) draws each of the link's parameters lognormal around its
estimate with the relative standard error as sigma (a positive parameter stays positive; for
errors of a few percent this is the normal distribution of the estimate).  The draws are
independent: the identification reports standard errors, not their correlations.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

__all__ = ["distributions_from_identification"]


def _lognormal(key: str, value, std, where: str) -> tuple[str, float, float]:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ValueError(f"{where}: {key} = {value!r}: a link parameter to draw must be a "
                         f"positive number")
    if std is None or not (isinstance(std, int | float) and math.isfinite(std) and std >= 0):
        raise ValueError(f"{where}: {key}: its standard error is not determined by the "
                         f"identification ({std!r}); give its distribution in [samples]")
    return ("lognormal", float(value), float(std) / float(value))


def distributions_from_identification(path: str | Path) -> dict[str, tuple[str, float, float]]:
    """The link's parameters of an identification (``identify --json``) as distributions of
    the scenario's ``hysteresis.*`` keys.

    Parameters
    ----------
    path : str or Path
        The JSON that ``motionhyst identify --json`` printed.

    Returns
    -------
    dict of str to (kind, a, b)
        ``{"hysteresis.k": ("lognormal", median, sigma), ...}``: the distributions of a study's
        ``[samples]``.

    Raises
    ------
    ValueError
        One line: the file cannot be read, is not an identification, has more than one
        element, or a parameter whose standard error is not determined.

    Examples
    --------
    >>> import json, tempfile
    >>> path = Path(tempfile.mkdtemp()) / "fit.json"
    >>> _ = path.write_text(json.dumps({"model": "maxwell-slip", "elements": [
    ...     {"k": 20.0, "k_std": 0.4, "fc": 0.05, "fc_std": 0.002}]}))
    >>> distributions_from_identification(path)
    {'hysteresis.k': ('lognormal', 20.0, 0.02), 'hysteresis.fc': ('lognormal', 0.05, 0.04)}
    """
    path = Path(path)
    where = f"from_identification {path}"
    try:
        data = json.loads(path.read_text())
    except OSError as exc:
        raise ValueError(f"{where}: cannot read ({exc.strerror})") from None
    except (UnicodeDecodeError, ValueError):
        raise ValueError(f"{where}: not JSON (give what `motionhyst identify --json` "
                         f"printed)") from None
    if not isinstance(data, dict):
        raise ValueError(f"{where}: not an identification (`motionhyst identify --json`)")
    if isinstance(data.get("elements"), list):  # a force-displacement record
        elements = data["elements"]
        if len(elements) != 1 or not isinstance(elements[0], dict):
            raise ValueError(f"{where}: {len(elements)} Jenkins elements; a study draws the "
                             f"parameters of one (a Jenkins link), give the others' "
                             f"distributions in [samples]")
        e = elements[0]
        return {f"hysteresis.{name}": _lognormal(name, e.get(name), e.get(f"{name}_std"), where)
                for name in ("k", "fc")}
    estimates, std = data.get("estimates"), data.get("std")
    if isinstance(estimates, dict) and isinstance(std, dict):  # an input-output record
        out = {f"hysteresis.{name[5:]}": _lognormal(name, value, std.get(name), where)
               for name, value in estimates.items() if name.startswith("link.")}
        if out:
            return out
    raise ValueError(f"{where}: holds no link parameters with standard errors (give what "
                     f"`motionhyst identify --json` printed)")
