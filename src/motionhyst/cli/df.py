"""``motionhyst df``: the describing function (and higher harmonics) of one link element.

Paper eq. (7); for the Jenkins element eq. (10).
"""

from __future__ import annotations

import argparse

from motionhyst.cli._common import (
    UsageError,
    distinct,
    finite,
    harmonic_count,
    nonnegative,
    positive,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def _df_parameters(model: str) -> dict[str, tuple[bool, bool]]:
    """``{option: (takes a list, required)}`` of a model, from its declared parameters."""
    from motionhyst.hysteresis import model_class

    return {p.name: (p.many, p.required) for p in model_class(model).parameters}


def _option(name: str) -> str:
    """The ``df`` option of a model parameter: ``--name`` with dashes for underscores."""
    return "--" + name.replace("_", "-")


def _element_from_args(args: argparse.Namespace):
    """The hysteresis element named by ``--model`` and its parameter options."""
    from motionhyst.hysteresis import MODELS
    from motionhyst.scenario import ScenarioError, hysteresis_from_dict

    model = args.model
    spec = _df_parameters(model)
    options = dict.fromkeys(n for m in MODELS for n in _df_parameters(m))
    for name in options:
        if getattr(args, name) is not None and name not in spec:
            raise UsageError(f"motionhyst df: {_option(name)} does not apply to --model "
                             f"{model} (its parameters: {', '.join(map(_option, spec))})")
    params: dict = {"model": model}
    for name, (many, required) in spec.items():
        values = getattr(args, name)
        if values is None:
            if required:
                raise UsageError(f"motionhyst df: {_option(name)} is required for --model "
                                 f"{model}")
            continue
        if many:
            params[name] = list(values)
        elif len(values) != 1:
            hint = " (use --model maxwell-slip for several)" if name in ("k", "fc") else ""
            raise UsageError(f"motionhyst df: {_option(name)} takes one value for --model "
                             f"{model}{hint}")
        else:
            params[name] = values[0]
    try:
        return hysteresis_from_dict(params, source="motionhyst df")
    except ScenarioError as exc:
        msg = str(exc).replace("[hysteresis]: ", "").replace("[hysteresis] ", "--")
        raise UsageError(msg) from None


def _df_frequencies(args: argparse.Namespace, el) -> list[float | None]:
    """The frequencies [Hz] of ``df``: required for rate-dependent elements, else none."""
    if el.rate_independent:
        if args.frequency is not None:
            raise UsageError(f"motionhyst df: --frequency does not apply to --model "
                             f"{args.model}: the element is rate-independent, its describing "
                             f"function depends on the amplitude only")
        return [None]
    if args.frequency is None:
        raise UsageError(f"motionhyst df: --frequency is required for --model {args.model} "
                         f"(rate-dependent: D depends on amplitude and frequency)")
    return list(args.frequency)


TEXT_VALUE_BYTES = 600
"""Memory of one value of ``df``'s answer printed as text [B]: the point's objects and its
line (measured 550: Jenkins, 1000 amplitudes x 1001 values, 695 MB at the peak beside the
process's 150 MB; LuGre, 1000 points x 501 values, 275 MB beside it)."""

JSON_VALUE_BYTES = 2000
"""The same printed as JSON (measured 1800: 400 amplitudes x 401 values, 285 MB)."""

REMEDY = "give fewer --amplitude or --frequency values, or fewer --harmonics"


def _check_size(args: argparse.Namespace, n_points: int) -> None:
    """Refuse an answer whose values would not fit the memory budget, before computing it."""
    from motionhyst.core.budget import check_memory

    values = n_points * (1 + (args.harmonics or 0))
    check_memory(values * (JSON_VALUE_BYTES if args.json else TEXT_VALUE_BYTES),
                 f"the describing function at {n_points} points of {values // n_points} "
                 f"values each", REMEDY)


def run(args: argparse.Namespace) -> int:
    """Describing function (and higher harmonics) of a hysteresis element.

    Sized before it starts (:data:`TEXT_VALUE_BYTES` or :data:`JSON_VALUE_BYTES` a value,
    against ``--max-memory``) and stopped after ``--max-seconds`` of CPU time: an
    element's periodic response costs from microseconds (Jenkins) to milliseconds (LuGre,
    integrated) a point, which no formula tells in advance.
    """
    from motionhyst.analysis.describing import describing_function
    from motionhyst.core.budget import cpu_time_limit, max_seconds
    from motionhyst.core.jsonio import dumps

    args.frequency = distinct(args.frequency, "--frequency", "df")
    el = _element_from_args(args)
    freqs = _df_frequencies(args, el)
    _check_size(args, len(args.amplitude) * len(freqs))
    with cpu_time_limit(max_seconds(), "df", REMEDY + ", or a larger --max-seconds"):
        result = describing_function(el, args.amplitude, None if freqs == [None] else freqs,
                                     harmonics=args.harmonics or 0)
        text = dumps(result.to_dict()) if args.json else str(result)
    print(text)
    return 0


def add_parser(sub) -> None:
    """Add the ``df`` command to the subparsers `sub`."""
    from motionhyst.hysteresis import MODELS

    q = sub.add_parser("df", help="describing function of a hysteresis element")
    q.add_argument("--model", choices=list(MODELS), default="jenkins",
                   help="hysteresis model (default: jenkins)")
    types = {"positive": positive, "nonnegative": nonnegative, "finite": finite}
    declared: dict[str, list] = {}
    for name, cls in MODELS.items():
        for p in cls.parameters:
            declared.setdefault(p.name, []).append((name, p))
    for option, uses in declared.items():
        p = uses[0][1]
        unit = f" [{p.unit}]" if p.unit else ""
        if p.required:
            default = ""
        elif p.many:  # a list parameter's default is a tuple
            default = f" ({', '.join(f'{v:g}' for v in p.default) or 'none'})"
        else:
            default = f" ({p.default:g})"
        many = [m for m, pm in uses if pm.many]
        several = f" (one per element for {', '.join(many)})" if many else ""
        models = "all models" if len(uses) == len(MODELS) else ", ".join(m for m, _ in uses)
        q.add_argument(_option(option), type=types[p.kind], nargs="+" if many else 1,
                       help=f"{p.help}{unit}{default}{several}; {models}")
    q.add_argument("--frequency", type=positive, nargs="+",
                   help="frequency(ies) [Hz]; required for the rate-dependent "
                        + ", ".join(m for m, c in MODELS.items() if not c.rate_independent))
    q.add_argument("--amplitude", type=nonnegative, nargs="+", required=True,
                   help="input amplitude(s) A [m]")
    q.add_argument("--harmonics", type=harmonic_count, metavar="N",
                   help="also the higher-order describing functions H_1 .. H_N")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)
