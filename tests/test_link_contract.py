"""The contract every registered link model keeps (as scikit-learn's ``check_estimator``).

The analyses, the steady state, the time engine and identification use a
link only through :class:`~motionhyst.hysteresis.base.Hysteresis`; a model in
:data:`~motionhyst.hysteresis.registry.MODELS` is accepted everywhere if it
keeps the checks below.  They run over every registered model: a model added
to the registry is checked as soon as :data:`EXAMPLES` holds an instance of it
(the first test fails until it does).

Tolerances: the describing functions are stated to about 1e-10 relative
(closed forms, or the exact periodic response); ``H_1`` from the periodic
harmonics and ``D`` come from different code paths and must agree to 1e-8
of ``|D|``.  The loop area is the trapezoid rule over the default 2000
samples a period, whose error is of order ``(2 pi / 2000)^2 = 1e-5``: it
must give ``pi A^2 Im D`` to 1e-3 of ``pi A^2 |D|``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from motionhyst.hysteresis import (
    MODELS,
    BoucWen,
    Coulomb,
    Dahl,
    Hysteresis,
    Jenkins,
    LuGre,
    MaxwellIwan,
    MaxwellSlip,
)
from motionhyst.hysteresis.stepping import Stepping
from motionhyst.scenario import hysteresis_from_dict

# one instance per registered model, away from any special case (no parameter at a bound)
EXAMPLES: dict[str, Hysteresis] = {
    "jenkins": Jenkins(k=20.0, fc=0.05),
    "maxwell-slip": MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]),
    "bouc-wen": BoucWen(k=20.0, fc=0.05, n=2.0, beta=0.7, gamma=0.3),
    "dahl": Dahl(k=20.0, fc=0.05, alpha=2.0),
    "lugre": LuGre(sigma0=20.0, sigma1=0.1, sigma2=0.05, fc=0.05, fs=0.08, vs=0.02),
    "maxwell-iwan": MaxwellIwan(k0=5.0, kv=[3.0], cv=[0.5], ki=20.0, d_min=1e-4, d_max=5e-3),
    "coulomb": Coulomb(fc_pos=0.05, fc_neg=0.06, c_pos=0.1, c_neg=0.2),
}
# H_1 from the periodic output against D: both about 1e-10 where the output's harmonics are
# exact; Coulomb's come from a finely sampled period whose force jumps at each reversal, an
# error of first order in the sampling (8192 samples a period: 4e-4 of |D| measured)
RTOL_H1 = {"coulomb": 1e-3}
# known breaches of the contract, each a strict xfail: it fails loudly once mended
KNOWN = {
    ("loop_area", "coulomb"): "sine_loop calls response(x) without the times t that a "
                              "Coulomb link with viscous terms requires",
}
AMPLITUDES = np.array([1e-3, 4e-3, 1e-2])  # [m]: about 0.1 to 1 times the slip amplitude
OMEGA = 2.0 * math.pi * 5.0  # [rad/s]: where rate-dependent models are asked

NAMES = list(MODELS)


def _omega(link: Hysteresis) -> float | None:
    return None if link.rate_independent else OMEGA


def _cases(check: str, names=None) -> list:
    """The model names for `check`, a known breach marked as a strict xfail."""
    return [pytest.param(n, marks=pytest.mark.xfail(strict=True, reason=KNOWN[(check, n)]))
            if (check, n) in KNOWN else n for n in (NAMES if names is None else names)]


def test_every_registered_model_has_an_example():
    assert set(EXAMPLES) == set(MODELS), "add an instance of the new model to EXAMPLES"


@pytest.mark.parametrize("name", NAMES)
def test_registered_under_its_name(name):
    link = EXAMPLES[name]
    assert type(link) is MODELS[name] and type(link).name == name
    assert isinstance(link, Hysteresis)


@pytest.mark.parametrize("name", NAMES)
def test_to_dict_rebuilds_the_same_model(name):
    """``to_dict`` is the scenario's ``[hysteresis]`` table: reading it back gives the model."""
    link = EXAMPLES[name]
    d = link.to_dict()
    assert d["model"] == name
    declared = {p.name for p in type(link).parameters}
    declared |= {p.name for form in getattr(type(link), "forms", ()) for p in form.parameters}
    assert set(d) - {"model"} <= declared, "to_dict keys that no Parameter declares"
    again = hysteresis_from_dict(d, source="contract")
    assert type(again) is type(link) and again.to_dict() == d
    assert repr(link).startswith(type(link).__name__ + "(")


@pytest.mark.parametrize("name", NAMES)
def test_declared_ranges_are_enforced(name):
    """A value outside a parameter's declared kind is one line naming the parameter."""
    link = EXAMPLES[name]
    params = {k: v for k, v in link.to_dict().items() if k != "model"}
    for p in type(link).parameters:
        if p.name not in params:
            continue
        bad = {"positive": [0.0, -1.0, math.nan], "nonnegative": [-1.0, math.nan],
               "finite": [math.nan, math.inf]}[p.kind]
        for value in bad:
            changed = {**params, p.name: [value] * len(params[p.name]) if p.many else value}
            with pytest.raises(ValueError) as info:
                type(link)(**changed)
            msg = str(info.value)
            assert "\n" not in msg and p.name in msg, (p.name, value, msg)


@pytest.mark.parametrize("name", NAMES)
def test_describing_function_shape_and_bounds(name):
    link = EXAMPLES[name]
    k0 = link.initial_stiffness
    assert k0 >= 0  # 0 for Coulomb friction: no elastic range
    D = np.asarray(link.describing_function(AMPLITUDES, _omega(link)))
    assert D.shape == AMPLITUDES.shape and np.all(np.isfinite(D))
    assert np.all(D.imag >= 0), "a passive link dissipates: Im D >= 0 (eq. 7)"
    scalar = link.describing_function(float(AMPLITUDES[1]), _omega(link))
    assert np.ndim(scalar) == 0 and complex(scalar) == pytest.approx(complex(D[1]), rel=1e-12)
    if link.rate_independent:
        assert np.all(np.abs(D) <= k0 * (1 + 1e-12)), "|D| above the initial stiffness"
        other = np.asarray(link.describing_function(AMPLITUDES, 2 * math.pi * 100.0))
        np.testing.assert_array_equal(other, D)  # the frequency is ignored


@pytest.mark.parametrize("name", NAMES)
def test_bad_amplitudes_raise_value_error(name):
    link = EXAMPLES[name]
    for A in (-1e-3, math.nan, math.inf):
        with pytest.raises(ValueError):
            link.describing_function(A, _omega(link))


@pytest.mark.parametrize("name", NAMES)
def test_first_harmonic_is_the_describing_function(name):
    link = EXAMPLES[name]
    H = link.hosidf(AMPLITUDES, 3, _omega(link))
    D = np.asarray(link.describing_function(AMPLITUDES, _omega(link)))
    assert H.shape == (*AMPLITUDES.shape, 3) and np.all(np.isfinite(H))
    np.testing.assert_allclose(H[:, 0], D, rtol=RTOL_H1.get(name, 1e-8), atol=0.0)


@pytest.mark.parametrize("name", _cases("loop_area"))
def test_loop_area_is_pi_a2_imag_d(name):
    """The energy a period dissipates, from the time response, is ``pi A^2 Im D``."""
    link = EXAMPLES[name]
    for A in AMPLITUDES:
        x, w = link.sine_loop(float(A), _omega(link))
        assert x.shape == w.shape and x[0] == pytest.approx(x[-1], abs=1e-15)
        area = np.trapezoid(w, x)  # the work w dx done on the link over one period
        D = complex(link.describing_function(float(A), _omega(link)))
        assert area == pytest.approx(math.pi * A**2 * D.imag, abs=1e-3 * math.pi * A**2 * abs(D))


@pytest.mark.parametrize("name", [n for n in NAMES if MODELS[n].rate_independent])
def test_sample_calls_follow_the_response(name):
    """As a python-control nonlinearity, calling the link per sample gives :meth:`response`."""
    link = EXAMPLES[name]
    x = 0.01 * np.sin(np.linspace(0.0, 3.0 * math.pi, 200)) * np.linspace(0.2, 1.0, 200)
    w = link.response(x)
    assert w.shape == x.shape and np.all(np.isfinite(w)) and w[0] == 0.0
    link.reset()
    calls = np.array([link(xi) for xi in x])
    np.testing.assert_allclose(calls, w, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", NAMES)
def test_zeta_defined_or_refused(name):
    link = EXAMPLES[name]
    if type(link).defines_zeta:
        z = np.asarray(link.zeta(AMPLITUDES))
        assert z.shape == AMPLITUDES.shape and np.all(np.diff(z) < 0)  # fc / (k A)
    else:
        with pytest.raises(ValueError, match="zeta"):
            link.zeta(AMPLITUDES)


@pytest.mark.parametrize("name", NAMES)
def test_the_time_engine_can_step_it(name):
    assert isinstance(EXAMPLES[name].time_stepping(), Stepping)
