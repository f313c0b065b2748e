"""A position that does not depend on the force is refused before any fit (issue 26).

Noise records given as input-output ran 8-46 s of search before "the records determine 0
of 4 parameters", the default Bouc-Wen 16 s before a message about its parameters' accepted
set; :func:`~motionhyst.identify.io_response.check_response` decides in milliseconds from
the coherence and the linear response of the position to the force.  Every kind of record
the tool identifies passes it with a wide margin; positions independent of the force
(noise, drift, a shuffled or another record's position, a stage that did not move) are
refused in one line naming the record.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from records_of_other_kinds import damper_record, piezo_record
from scipy import signal

from motionhyst.cli import main
from motionhyst.hysteresis import BoucWen, Coulomb, Jenkins
from motionhyst.identify.input_output import identify_io
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_response import (
    COHERENCE_P,
    MIN_JUDGED,
    MIN_SPREAD,
    PIECE,
    PIECES,
    RESPONSE_P,
    check_response,
    coherence,
    dependence,
    force_spread,
)
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import MassSpringDamper, OpenLoop, TwoMass

EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"
NO_RESPONSE = "the force's variations show no response of the position"
#: Evidence a record of a stage must show beyond the thresholds: a factor of 100 on the
#: p-value of at least one test
MARGIN = 100.0


def _axis(noise: float, n: int = 4000, seed: int = 0) -> IORecord:
    """A positioning axis (mass-damper) with a Jenkins friction link, from a start; `noise`
    a share of the position's RMS about its trend."""
    t = np.arange(n) / 1000.0
    u = (30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
         + 5 * np.sin(2 * np.pi * 7 * t))
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(t, u).displacement
    rms = np.std(y - np.polyval(np.polyfit(t, y, 2), t))
    y = y + noise * rms * np.random.default_rng(seed).standard_normal(n)
    return IORecord(t, u, y, f"axis {noise:g}")


def _multisine(n: int, fs: float, seed: int, rms: float = 50.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (fs / n)), int(150 / (fs / n)) + 1)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


def _stage(kind: str, n: int, noise: float) -> IORecord:
    """A Bouc-Wen stage on a spring, or the two-mass stage (its internal mode at 65 Hz, in
    the band) measured at y1 or y2, under a multisine of 5-150 Hz; `noise` a share of the
    position's RMS."""
    fs = 750.0
    t = np.arange(n) / fs
    u = _multisine(n, fs, 1)
    link = BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0)
    plant = (MassSpringDamper(2.0, 10.0, 5e4) if kind == "mass-spring-damper"
             else TwoMass(2.0, 3.0, 20.0, 2e5, output=kind))
    y = OpenLoop(plant, link).simulate(t, u, substeps=20).displacement
    y = y + noise * np.std(y) * np.random.default_rng(2).standard_normal(n)
    return IORecord(t, u, y, f"{kind} {noise:g}")


def _emps() -> IORecord:
    from scipy.io import loadmat

    d = loadmat(EMPS)
    return IORecord(d["t"].ravel(), 35.15065 * d["vir"].ravel(), d["qm"].ravel(), "EMPS")


STAGES = ([f"axis {p}" for p in (0.0, 0.01, 0.1)]
          + [f"axis {p} short" for p in (0.0, 0.01)]
          + [f"{kind} {n} {p}" for kind in ("mass-spring-damper", "y1", "y2")
             for n in (MIN_JUDGED, 1536) for p in (0.01, 0.1)]
          + [f"{make} {history}" for history in ("sines", "earthquake")
             for make in ("piezo", "damper")])


def _stage_record(key: str) -> IORecord:
    """A record of :data:`STAGES` by its name."""
    words = key.split()
    if words[0] == "axis":
        return _axis(float(words[1]), MIN_JUDGED if len(words) > 2 else 4000)
    if words[0] in ("piezo", "damper"):
        r = (piezo_record if words[0] == "piezo" else damper_record)(words[1])
        return IORecord(r.t, r.force, r.displacement, key)
    return _stage(words[0], int(words[1]), float(words[2]))


@pytest.mark.parametrize("nperseg", [16, 250, 511])
def test_coherence_is_welchs(nperseg):
    rng = np.random.default_rng(nperseg)
    u = rng.standard_normal(3001)
    y = signal.lfilter([1.0, 0.5], [1.0, -0.8], u) + rng.standard_normal(3001)
    c, p_uu, segments = coherence(u, y, nperseg, block=700)  # blocks of segments as one
    _, c_scipy = signal.coherence(u, y, nperseg=nperseg, detrend="linear")
    _, p_scipy = signal.welch(u, nperseg=nperseg, detrend="linear")
    assert c == pytest.approx(c_scipy, abs=1e-9)
    inner = slice(1, -1)  # scipy's one-sided density doubles all but 0 and fs/2
    assert p_uu[inner] / p_uu[5] == pytest.approx(p_scipy[inner] / p_scipy[5], rel=1e-9)
    count = (3001 - nperseg) // (nperseg - nperseg // 2) + 1
    assert 0.5 * count < segments <= count  # steady signals: each segment counts (its power
    # varies by chance: 0.7 of them over 16 samples)
    step, response = (np.arange(3001) >= 1500).astype(float), np.zeros(3001)
    response[1500:] = 1.0 - np.exp(-np.arange(1501) / 40.0)  # a transient's response
    assert coherence(step, response, nperseg)[2] < 3.0  # two transients: a segment or two


def test_independent_positions_give_uniform_p_values():
    """Under independence a p-value is below 0.1 in a tenth of the records, not more (the
    coherence test's, with its conservative count of segments, less often)."""
    rng = np.random.default_rng(3)
    found = []
    for i in range(200):
        n = 600 + 37 * i
        u = rng.standard_normal(n) if i % 2 else np.cumsum(rng.standard_normal(n))
        found.append(dependence(u, rng.standard_normal(n)))
    below = [sum(getattr(p, name) < 0.1 for p in found) for name in ("coherence", "response")]
    # binomial(200, 0.1): mean 20, standard deviation 4.2
    assert below[0] <= 33 and 8 <= below[1] <= 33


@pytest.mark.parametrize("key", STAGES)
def test_records_of_stages_pass_by_a_wide_margin(key):
    record = _stage_record(key)
    p = dependence(record.u, record.y)
    assert p.coherence < COHERENCE_P / MARGIN or p.response < RESPONSE_P / MARGIN, p
    check_response([record])


@pytest.mark.skipif(not EMPS.is_file(), reason="needs the EMPS benchmark's files beside")
def test_the_emps_record_and_each_period_pass():
    rec = _emps()
    for piece in [slice(None)] + [slice(i * 6210, (i + 1) * 6210) for i in range(4)]:
        p = dependence(rec.u[piece], rec.y[piece])
        assert p.coherence < 1e-30 and p.response < 1e-30


def _independent() -> list[tuple[str, IORecord]]:
    rng = np.random.default_rng(5)
    axis = _axis(0.0)
    t, u, n = axis.t, axis.u, axis.t.size
    return [("white position", IORecord(t, u, 1e-3 * rng.standard_normal(n), "a.csv")),
            ("white force", IORecord(t, 10 * rng.standard_normal(n), axis.y, "a.csv")),
            ("shuffled position", IORecord(t, u, rng.permutation(axis.y), "a.csv")),
            ("noise and drift", IORecord(t, u, 1e-3 * rng.standard_normal(n) + 0.05 * t,
                                         "a.csv")),
            ("random walk", IORecord(t, u, 1e-4 * np.cumsum(rng.standard_normal(n)), "a.csv")),
            ("stuck stage", IORecord(t, 3 * np.sin(3 * t), 0.02 + 1e-7 * rng.standard_normal(n),
                                     "a.csv")),
            ("quantised noise", IORecord(t, u, np.round(1e-7 * rng.standard_normal(n), 7),
                                         "a.csv"))]


@pytest.mark.parametrize("name, record", _independent(), ids=[n for n, _ in _independent()])
def test_positions_independent_of_the_force_are_refused(name, record):
    with pytest.raises(ValueError, match=r"^a\.csv: " + NO_RESPONSE):
        check_response([_axis(0.0), record])
    with pytest.raises(ValueError, match=NO_RESPONSE):
        identify_io([record], Jenkins, plant="mass-damper")  # before the search


def test_short_records_are_not_judged():
    rng = np.random.default_rng(6)
    t = np.arange(MIN_JUDGED - 1) / 1000.0
    check_response([IORecord(t, np.sin(7 * t), rng.standard_normal(t.size), "short.csv")])
    t = np.arange(MIN_JUDGED) / 1000.0
    with pytest.raises(ValueError, match=r"short\.csv"):
        check_response([IORecord(t, np.sin(7 * t), rng.standard_normal(t.size), "short.csv")])


def test_a_long_record_is_judged_where_its_force_moves_the_stage():
    """Beyond PIECES pieces of PIECE samples, the pieces where the force varies most: a
    record at rest but for one burst of motion is a stage's; noise there is refused."""
    n = (PIECES + 4) * PIECE + 123
    rng = np.random.default_rng(7)
    t = np.arange(n) / 1000.0
    u = 0.01 * rng.standard_normal(n)
    burst = slice(3 * PIECE + 500, 3 * PIECE + 24000)
    u[burst] += 40 * np.sin(2 * np.pi * 3.0 * t[burst])
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(t, u).displacement
    y = y + 1e-7 * rng.standard_normal(n)
    check_response([IORecord(t, u, y, "burst.csv")])
    with pytest.raises(ValueError, match=r"burst\.csv"):
        check_response([IORecord(t, u, 1e-3 * rng.standard_normal(n), "burst.csv")])


def test_identify_refuses_a_noise_record_before_its_fit(tmp_path, capsys, monkeypatch):
    """One line, exit 2, and no fit: the search is never called (it was 8-46 s of it)."""
    import motionhyst.identify.input_output as io

    def no_fit(*args, **kwargs):
        raise AssertionError("the fit ran")

    monkeypatch.setattr(io, "identify_io", no_fit)
    rec = _independent()[0][1]
    path = tmp_path / "noise.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="")
    for extra in ([], ["--plant", "mass-damper", "--model", "jenkins"],
                  ["--plant", "quasi-static", "--model", "dahl"]):
        assert main(["identify", str(path), "--record", "input-output", *extra]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and "Traceback" not in err
        assert "noise.csv: the force's variations show no response of the position" in err
        p = [float(v.split(",")[0].split(")")[0]) for v in err.split("p = ")[1:3]]
        assert p[0] > COHERENCE_P and p[1] > RESPONSE_P and not any(map(math.isnan, p))


@pytest.mark.parametrize("alpha, bg, bd, nu, why", [
    (5e4, 100.0, 800.0, 1.0, "loops would give out energy"),
    (5e4, -100.0, -300.0, 2.0, "grows without bound"),
    (5e4, -300.0, 300.0, 1.0, "loops would give out energy"),
    (5e4, -100.0, -300.0, 1.0, "small cycles raise its force"),
    (-5.0, 100.0, -50.0, 1.0, "no spring at small motion"),
    (5e4, 0.0, 0.0, 1.0, "a linear spring"),
])
def test_a_bouc_wen_fit_outside_the_model_says_what_the_records_do_not_determine(
        alpha, bg, bd, nu, why):
    """The default Bouc-Wen on a noise record ended after 16 s in "gamma must be >= delta",
    the link class's own constraint; now the fit's message says it in the link's terms."""
    from motionhyst.identify.io_bouc_wen import _bouc_wen_link

    with pytest.raises(ValueError) as exc:
        _bouc_wen_link(alpha, bg, bd, nu)
    text = str(exc.value)
    assert text.startswith("the records do not determine a Bouc-Wen link: its best fit")
    assert why in text and "must be" not in text and "\n" not in text
    assert _bouc_wen_link(5e4, 800.0, -1100.0, 1.0).to_dict()["model"] == "bouc-wen"


def _step_axis(n: int, noise: float, seed: int, force_noise: float = 0.0) -> IORecord:
    """One step of force (0 -> 60 N at 0.2 s) on a 95 kg axis with 200 N s/m and 20 N of
    Coulomb friction, at 1 kHz, with white position noise [m] and white noise of the force's
    sensor [N] (not seen by the axis)."""
    t = np.arange(n) / 1000.0
    u = np.where(t >= 0.2, 60.0, 0.0)
    y = OpenLoop(MassDamper(95.0, 200.0), Coulomb(fc=20.0)).simulate(t, u).displacement
    rng = np.random.default_rng(seed)
    return IORecord(t, u + force_noise * rng.standard_normal(n),
                    y + noise * rng.standard_normal(n), "step.csv")


@pytest.mark.parametrize("n", [1000, 2000])
@pytest.mark.parametrize("noise", [1e-6, 1e-5, 3e-5, 1e-4])
@pytest.mark.parametrize("force_noise", [0.0, 2.0, 4.0])
def test_a_record_of_one_step_is_not_refused(n, noise, force_noise):
    """Review A9 finding 2: refused 10/10 at 1e-5 m; one event, about which neither test
    can judge: left to the fit.  With 2-4 N of noise on the force's sensor (3-7 % of the
    step) the step was refused 5/5 (review B9 finding 2): the noise made the force look
    varied throughout."""
    for seed in range(3):
        rec = _step_axis(n, noise, seed, force_noise)
        assert force_spread(rec.u) < MIN_SPREAD
        check_response([rec])
    check_response([IORecord(rec.t, rec.u, _axis(0.0, n).y, "step.csv")])  # unrelated too


def test_a_few_pulses_of_force_are_not_judged():
    t = np.arange(3000) / 1000.0
    u = sum(np.where((t > a) & (t < a + 0.05), 50.0, 0.0) for a in (0.3, 1.3, 2.3))
    y = OpenLoop(MassDamper(95.0, 200.0), Coulomb(fc=20.0)).simulate(t, u).displacement
    assert force_spread(u) < MIN_SPREAD
    check_response([IORecord(t, u, y + 1e-5 * np.random.default_rng(0).standard_normal(t.size),
                             "pulses.csv")])


@pytest.mark.skipif(not EMPS.is_file(), reason="needs the EMPS benchmark's files beside")
def test_the_emps_record_with_pulses_of_force_passes():
    """The benchmark's held-out record has pulses on its periodic motion: 20 pulses of
    40 N for 50 ms added, with the response of the axis's mass and viscous friction."""
    rec = _emps()
    pulses = np.zeros(rec.t.size)
    for start in np.linspace(500, rec.t.size - 600, 20).astype(int):
        pulses[start:start + 50] = 40.0
    extra = OpenLoop(MassDamper(95.0, 200.0)).simulate(rec.t - rec.t[0], pulses).displacement
    for piece in (slice(None), slice(0, 6210), slice(6210, 12420)):
        check_response([IORecord(rec.t[piece], (rec.u + pulses)[piece],
                                 (rec.y + extra)[piece], "EMPS with pulses")])


def test_a_force_steady_but_for_its_noise_is_refused_for_what_it_is():
    """Review A9 finding 8: a scan at constant speed (22 N and 0.5 N of noise, 0.25 m) was
    refused as "a stage that did not move?"; the message now says what is true."""
    rng = np.random.default_rng(4)
    t = np.arange(2500) / 1000.0
    rec = IORecord(t, 22.0 + 0.5 * rng.standard_normal(t.size),
                   0.1 * t + 1e-6 * rng.standard_normal(t.size), "scan.csv")
    assert force_spread(rec.u) > MIN_SPREAD
    with pytest.raises(ValueError, match=r"scan\.csv: " + NO_RESPONSE + r".* too little "
                                         r"excitation"):
        check_response([rec])


def test_a_closed_loop_record_whose_position_is_noise_is_refused(tmp_path, capsys):
    """Closed-loop identify with y1 = noise answered 2 Maxwell-slip elements 'determined'
    (R^2 0.3, exit 0); the same check refuses it before the loop is built."""
    from motionhyst.scenario import default_scenario_path

    t = np.arange(3000) / 1000.0
    u = 0.5 * np.sin(2 * np.pi * 2.0 * t) + 0.1 * np.sin(2 * np.pi * 11.0 * t)
    y1 = 1e-4 * np.random.default_rng(8).standard_normal(t.size)
    path = tmp_path / "c.csv"
    np.savetxt(path, np.column_stack([t, y1, u]), delimiter=",", header="time,y1,u",
               comments="")
    assert main(["identify", str(path), "--scenario", str(default_scenario_path())]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and f"{path}: {NO_RESPONSE}" in err
