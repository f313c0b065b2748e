"""Sampled-data controllers and the plant behind a zero-order hold (issue 22)."""

import control
import numpy as np
import pytest

from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.pid import Notch, Pid
from motionhyst.controllers.sampled import SampledController, discretize
from motionhyst.controllers.two_dof import position_velocity_cascade, two_dof_z
from motionhyst.core.sampling import ZohEquivalent, hold_response

# Table I's stage P2 (eqs. 1-2) and controller (eq. 23), written out
M1, M2, B, K = 5.0, 17.5, 90.0, 7.4e7
P2 = control.tf([B, K], [M1 * M2, B * (M1 + M2), K * (M1 + M2), 0.0, 0.0])
W1, W2, WL = 2 * np.pi * 60.0, 2 * np.pi * 240.0, 2 * np.pi * 700.0
C = control.tf(np.polymul([1.0, W1], [6.2e6 * 4.0 * WL**2]),
               np.polymul([1.0, W2], [1.0, 1.2 * WL, WL**2]))
T = 1e-4
W = 2 * np.pi * np.array([0.01, 1.0, 5.0, 120.0, 694.0, 3000.0, 4990.0])


@pytest.mark.parametrize("d", [0, 1, 2])
def test_zoh_equivalent_is_python_controls_c2d_with_whole_delays(d):
    ref_sys = control.c2d(control.ss(P2), T, "zoh")     # the state-space route keeps digits
    z = np.exp(1j * W * T)
    ref = ref_sys(z) * z ** (-d)
    got = ZohEquivalent(P2, T, d)(W)
    # the reference loses (w T)^-2 of its accuracy at low frequency; ours keeps it
    assert np.max(np.abs(got / ref - 1)) < 1e-9


@pytest.mark.parametrize("d", [0.5, 1.5, 2.25])
def test_zoh_equivalent_is_the_alias_sum_with_fractional_delays(d):
    k = np.arange(-20000, 20001)[:, None]
    wk = W[None, :] + k * 2 * np.pi / T
    num, den = P2.num[0][0], P2.den[0][0]
    terms = np.polyval(num, 1j * wk) / np.polyval(den, 1j * wk) * hold_response(wk, T, d)
    # sum from the smallest terms up (terms fall as k^-4 for this P2)
    order = np.argsort(np.abs(k[:, 0]))[::-1]
    ref = np.sum(terms[order], axis=0)
    assert np.max(np.abs(ZohEquivalent(P2, T, d)(W) / ref - 1)) < 1e-11


def test_zoh_equivalent_rejects_what_it_cannot_sample():
    with pytest.raises(ValueError, match="strictly proper"):
        ZohEquivalent(control.tf([1.0, 0.0], [1.0, 1.0]), T)
    with pytest.raises(ValueError, match="more than two integrators"):
        ZohEquivalent(control.tf([1.0], [1.0, 0.0, 0.0, 0.0]), T)
    with pytest.raises(ValueError, match="delay_samples"):
        ZohEquivalent(P2, T, -1.0)
    with pytest.raises(TypeError, match="continuous"):
        ZohEquivalent(control.tf([1.0], [1.0, 0.5], 0.1), T)


def test_hold_response():
    assert hold_response(0.0, T, 2.5) == 1.0
    # one sample of hold: a delay of T / 2 and a sinc
    w = 2 * np.pi * 1000.0
    h = hold_response(w, T, 0.0)
    assert np.isclose(abs(h), np.sinc(w * T / (2 * np.pi)), rtol=1e-14)
    assert np.isclose(np.angle(h), -w * T / 2, rtol=1e-14)
    assert np.isclose(hold_response(w, T, 1.5) / h, np.exp(-1.5j * w * T), rtol=1e-14)


def test_tustin_is_python_controls_and_the_default():
    num, den = discretize(C, 1 / T)
    ref = control.c2d(C, T, "tustin")
    c = SampledController(num, den, sample_rate_hz=1 / T)
    assert np.allclose(c.feedback_response(W[:-1]), ref(np.exp(1j * W[:-1] * T)), rtol=1e-9)
    # the frequency warping of Tustin: C_d(e^{j w T}) = C(j (2 / T) tan(w T / 2))
    warped = 2 / T * np.tan(W[:-1] * T / 2)
    assert np.allclose(c.feedback_response(W[:-1]), C(1j * warped), rtol=1e-9)


def test_prewarp_maps_its_frequency_exactly():
    f0 = 700.0
    num, den = discretize(C, 1 / T, "tustin-prewarp", prewarp_hz=f0)
    c = SampledController(num, den, sample_rate_hz=1 / T)
    w0 = np.array([2 * np.pi * f0])
    assert np.isclose(c.feedback_response(w0)[0], C(1j * w0[0]), rtol=1e-8)
    plain = SampledController(*discretize(C, 1 / T), sample_rate_hz=1 / T)
    assert abs(plain.feedback_response(w0)[0] / C(1j * w0[0]) - 1) > 1e-3


@pytest.mark.parametrize("method", ["zoh", "matched"])
def test_other_discretizations_keep_the_dc_gain(method):
    lowpass = control.tf([WL**2], [1.0, 1.2 * WL, WL**2])
    c = SampledController(*discretize(lowpass, 1 / T, method), sample_rate_hz=1 / T)
    assert np.isclose(c.dc_gain(), 1.0, rtol=1e-12)
    ref = control.c2d(lowpass, T, method)
    assert np.allclose(c.feedback_response(W[:-1]), ref(np.exp(1j * W[:-1] * T)), rtol=1e-9)


def test_discretize_rejects_bad_input():
    with pytest.raises(ValueError, match="unknown discretization"):
        discretize(C, 1e4, "euler")
    with pytest.raises(ValueError, match="prewarp_hz goes with"):
        discretize(C, 1e4, "tustin", prewarp_hz=100.0)
    with pytest.raises(ValueError, match="prewarp_hz goes with"):
        discretize(C, 1e4, "tustin-prewarp")
    with pytest.raises(ValueError, match="below the Nyquist"):
        discretize(C, 1e4, "tustin-prewarp", prewarp_hz=6000.0)
    with pytest.raises(ValueError, match="proper"):
        discretize(control.tf([1.0, 0.0], [1.0]), 1e4)
    with pytest.raises(ValueError, match="sample_rate_hz"):
        discretize(C, 0.0)


def _simulate(A, B, Cm, D, inputs):
    x = np.zeros(A.shape[0])
    out = []
    for u in inputs:
        out.append((Cm @ x + D @ u).item())
        x = A @ x + B @ u
    return np.array(out)


def test_state_space_runs_the_difference_equation():
    rng = np.random.default_rng(1)
    r, y = rng.normal(size=50), rng.normal(size=50)
    kp, kv, g, F = 160.18, 243.45, 35.15065, 1000.0
    c = position_velocity_cascade(kp, kv, g, F)
    u = _simulate(*c.state_space(), np.stack([r, y], axis=1))
    y_prev = np.concatenate([[0.0], y[:-1]])
    expected = g * kv * (kp * (r - y) - (y - y_prev) * F)
    assert np.allclose(u, expected, rtol=1e-12, atol=1e-9 * np.max(np.abs(expected)))
    # one degree of freedom: C_d acting on r - y, against python-control's own realisation
    cd = SampledController(*discretize(C, 1 / T), sample_rate_hz=1 / T)
    e = r - y
    _, ref = control.forced_response(cd.tf(), U=e)
    u = _simulate(*cd.state_space(), np.stack([r, y], axis=1))
    assert np.allclose(u, ref, rtol=1e-9, atol=1e-9 * np.max(np.abs(ref)))


def test_state_space_is_the_transfer_function():
    c = two_dof_z([2.0, -1.0], [1.0, -0.5], [3.0, -1.0, 0.2], [1.0, 0.1], 100.0)
    A, B, Cm, D = c.state_space()
    w = np.array([1.0, 30.0, 200.0])
    z = np.exp(1j * w * c.period)
    G = np.array([(Cm @ np.linalg.solve(zi * np.eye(A.shape[0]) - A, B) + D)[0] for zi in z])
    R, Y = c.response(w)
    assert np.allclose(G[:, 0], R, rtol=1e-12)
    assert np.allclose(G[:, 1], -Y, rtol=1e-12)


def test_sampled_controller_rejects_bad_input():
    with pytest.raises(ValueError, match="den\\[0\\]"):
        SampledController([1.0], [0.0, 1.0], sample_rate_hz=1e3)
    with pytest.raises(ValueError, match="non-zero"):
        SampledController([0.0], [1.0], sample_rate_hz=1e3)
    with pytest.raises(ValueError, match="delay_samples"):
        SampledController([1.0], [1.0], sample_rate_hz=1e3, delay_samples=-0.5)
    with pytest.raises(ValueError, match="u_max"):
        SampledController([1.0], [1.0], sample_rate_hz=1e3, u_max=0.0)
    with pytest.raises(ValueError, match="both y_num and y_den"):
        SampledController([1.0], [1.0], [1.0], sample_rate_hz=1e3)
    with pytest.raises(ValueError, match="finite"):
        SampledController([np.nan], [1.0], sample_rate_hz=1e3)


def test_pid():
    pid = Pid(kp=1e6, ki=2e7, kd=2e3, derivative_filter_hz=2000.0)
    s = 2j * np.pi * 50.0
    expected = 1e6 + 2e7 / s + 2e3 * s / (1 + s / (2 * np.pi * 2000.0))
    assert np.isclose(pid.tf()(s), expected, rtol=1e-12)
    # sampled: Tustin of the whole
    c = pid.sampled(1 / T)
    assert np.allclose(c.feedback_response(W[:-1]),
                       control.c2d(pid.tf(), T, "tustin")(np.exp(1j * W[:-1] * T)), rtol=1e-9)
    # a pure derivative: the backward difference, the rest by Tustin
    pure = Pid(kp=1e6, ki=2e7, kd=2e3)
    assert not pure.proper
    w = np.array([2 * np.pi * 50.0])
    zinv = np.exp(-1j * w * T)
    integ = 2e7 * T / 2 * (1 + zinv) / (1 - zinv)
    assert np.allclose(pure.sampled(1 / T).feedback_response(w),
                       1e6 + integ + 2e3 * (1 - zinv) / T, rtol=1e-12)
    # notches in series, sampled too
    notched = Pid(kp=1e6, kd=2e3, notches=(Notch(694.0, 0.02, 0.3),))
    w0 = np.array([2 * np.pi * 694.0])
    cont = 1e6 + 2e3 * 1j * w0
    ratio = notched.sampled(1 / T, "tustin-prewarp", prewarp_hz=694.0).feedback_response(w0)
    bd = 1e6 + 2e3 * (1 - np.exp(-1j * w0 * T)) / T
    assert np.isclose(ratio[0] / bd[0], 0.02 / 0.3, rtol=1e-9)
    assert np.isclose(notched.tf()(1j * w0[0]), cont[0] * 0.02 / 0.3, rtol=1e-9)


def test_pid_and_notch_reject_bad_input():
    with pytest.raises(ValueError, match="non-zero gain"):
        Pid(kp=0.0)
    with pytest.raises(ValueError, match="ki"):
        Pid(kp=1.0, ki=-1.0)
    with pytest.raises(ValueError, match="derivative_filter_hz"):
        Pid(kp=1.0, kd=1.0, derivative_filter_hz=0.0)
    with pytest.raises(ValueError, match="zeta_pole"):
        Notch(100.0, 0.01, 0.0)


def test_feedforward():
    ff = Feedforward(viscous=3.0, coulomb=0.5, advance_samples=2.0)
    assert ff.with_mass(22.5).mass == 22.5
    assert Feedforward(mass=1.0).with_mass(22.5).mass == 1.0
    assert np.allclose(ff.with_mass(2.0).force([0.1, -0.1, 0.0], [1.0, 1.0, 1.0]),
                       [2.8, 1.2, 2.0])
    # the fundamental of fc sign(r') for r = A sin(w t) is (4 fc / pi) cos(w t)
    A, th = 0.01, (np.arange(4096) + 0.5) * 2 * np.pi / 4096
    sq = 0.5 * np.sign(np.cos(th))
    c1 = 2 * np.mean(sq * np.exp(-1j * th))     # x = Re(c1 e^{j th})
    assert np.isclose(c1 / (-1j * A), ff.coulomb_fundamental(A), rtol=1e-5)
    with pytest.raises(ValueError, match="advance_samples"):
        Feedforward(advance_samples=-1.0)


def _controllers() -> list[tuple[np.ndarray, np.ndarray]]:
    """Proper controllers over many magnitudes: the paper's, integrators, resonances."""
    rng = np.random.default_rng(7)
    out = [(C.num[0][0], C.den[0][0]), (np.array([1.0]), np.array([1.0, 0.0])),
           (np.array([3.0, 2.0]), np.array([1.0, 5.0, 0.0]))]
    for i in range(40):
        poles = -np.abs(rng.normal(size=rng.integers(1, 5))) * 10 ** rng.uniform(0, 4)
        if i % 3 == 0:
            poles = np.r_[poles, -1 + 50j, -1 - 50j]
        zeros = -np.abs(rng.normal(size=rng.integers(0, poles.size + 1))) * 10 ** rng.uniform(0, 4)
        if i % 4 == 0 and zeros.size + 2 <= poles.size:
            zeros = np.r_[zeros, -3 + 700j, -3 - 700j]
        out.append((np.atleast_1d(np.real(np.poly(zeros))) * 10 ** rng.uniform(-3, 7),
                    np.real(np.poly(poles))))
    return out


@pytest.mark.parametrize("method", ["tustin", "tustin-prewarp", "zoh", "matched"])
def test_discretize_gives_python_controls_c2d_bit_for_bit(method):
    """discretize_coefficients (numpy and scipy.linalg: what a scenario's check uses before
    python-control loads) returns python-control's c2d coefficients exactly."""
    import warnings

    from scipy.linalg import LinAlgWarning
    from scipy.signal import BadCoefficients

    from motionhyst.controllers.sampled import ascending, discretize_coefficients

    prewarp = 100.0 if method == "tustin-prewarp" else None
    options = {"prewarp_frequency": 2 * np.pi * prewarp} if prewarp else {}
    compared = 0
    for num, den in _controllers():
        for rate in (1e3, 1e4):
            if method == "matched" and den[-1] == 0.0:
                continue  # an integrator has no gain at s = 0 to keep
            with warnings.catch_warnings():  # badly scaled ones among them: both warn alike
                warnings.simplefilter("ignore", BadCoefficients)
                warnings.simplefilter("ignore", LinAlgWarning)
                ref = ascending(control.c2d(control.tf(num, den), 1 / rate,
                                            "tustin" if prewarp else method, **options))
                got = discretize_coefficients(num, den, rate, method, prewarp)
            assert all(np.array_equal(a, b) for a, b in zip(got, ref, strict=True)), (num, den)
            compared += 1
    assert compared >= 80


def test_pid_coefficients_are_python_controls_sum_and_products():
    """Pid.coefficients forms C(s) with numpy as python-control's arithmetic does."""
    rng = np.random.default_rng(11)
    for _ in range(60):
        kp, ki, kd = (float(rng.choice([0.0, 10 ** rng.uniform(-2, 8)])) for _ in range(3))
        kp = kp or 1.0
        fd = None if rng.random() < 0.3 else float(10 ** rng.uniform(1, 4))
        notches = tuple(Notch(float(10 ** rng.uniform(1, 3.5)), float(rng.uniform(0, 0.1)),
                              float(rng.uniform(0.05, 1))) for _ in range(rng.integers(0, 3)))
        pi = control.tf([kp, ki], [1.0, 0.0]) if ki else control.tf([kp], [1.0])
        wd = None if fd is None else 2 * np.pi * fd
        ref = pi + (control.tf([kd, 0.0], [1.0] if wd is None else [1.0 / wd, 1.0])) \
            if kd else pi
        if notches:
            prod = control.tf([1.0], [1.0])
            for n in notches:
                w = 2 * np.pi * n.frequency_hz
                prod = prod * control.tf([1.0, 2 * n.zeta_zero * w, w * w],
                                         [1.0, 2 * n.zeta_pole * w, w * w])
            ref = ref * prod
        num, den = Pid(kp, ki, kd, fd, notches).coefficients()
        assert np.array_equal(num, np.trim_zeros(ref.num[0][0], "f"))
        assert np.array_equal(den, np.trim_zeros(ref.den[0][0], "f"))
