"""A measured plant's response that cannot give the plant asked for (issue 26, no answer from
nothing): each refused with one line that names the cause, before the fit where the lines
decide it, and a loop unstable with a fitted plant blamed on the plant.

The data are Table I's stage (eq. 2, mode at 694 Hz) at 60 log-spaced lines from 1 to
3000 Hz with 0.5 % complex noise, as ``examples/measured_plant.py`` writes them, then
spoiled one way per case.  Each case runs ``motionhyst analyze`` in a child process under an
address-space limit and asserts the exit code, one plain line on stderr, nothing on stdout,
and every file of the folder byte-identical; the refusals decided before the fit also
leave python-control unimported (its import is most of a refusal's second).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst import TwoMassStage, load_scenario
from motionhyst.plants.frf_fit import ModalPlant, fit_frf
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
LINES = np.geomspace(1.0, 3000.0, 60)
STAGE = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))


def _measured(delay: float = 0.0, seed: int = 0):
    """Table I's ``P1``, ``P2`` at :data:`LINES`, delayed by `delay` [s], 0.5 % noise."""
    p1, p2 = STAGE.response(2 * np.pi * LINES)
    rng = np.random.default_rng(seed)
    lag = np.exp(-2j * np.pi * LINES * delay)
    noise = rng.standard_normal((2, 2, LINES.size))
    return tuple(p * lag * (1 + 0.005 * (n[0] + 1j * n[1]) / np.sqrt(2))
                 for p, n in zip((p1, p2), noise, strict=True))


def _csv(f=LINES, p1=None, p2=None, reim: bool = False, both_scale: float | None = None) -> str:
    """The response as an analyser exports it: magnitude and phase (or re, im; or both sets,
    the magnitudes of the abs, phase set times `both_scale`)."""
    if p1 is None:
        p1, p2 = _measured()
    cols, head = [f], ["frequency_hz"]
    if reim or both_scale is not None:
        cols += [p1.real, p1.imag, p2.real, p2.imag]
        head += ["p1_re", "p1_im", "p2_re", "p2_im"]
    if not reim:
        k = 1.0 if both_scale is None else both_scale
        cols += [k * np.abs(p1), np.angle(p1, deg=True), k * np.abs(p2), np.angle(p2, deg=True)]
        head += ["p1_abs", "p1_phase_deg", "p2_abs", "p2_phase_deg"]
    rows = np.column_stack(cols)
    return ",".join(head) + "\n" + "\n".join(",".join(f"{v:.10e}" for v in r)
                                             for r in rows) + "\n"


def _scenario(extra: str = "") -> str:
    """Table I's scenario with ``[plant] file = "frf.csv"`` (and `extra`) for its [stage];
    `extra` from ``[controller]`` on goes into that section."""
    plant, _, controller = extra.partition("[controller]\n")
    text = PAPER.replace("[controller]          # eq. (23)\n", f"[controller]\n{controller}")
    return (text[:text.index("[stage]")] + f'[plant]\nfile = "frf.csv"\n{plant}\n'
            + text[text.index("[hysteresis]"):])


P1, P2 = _measured()
CASES = [
    # (id, scenario's extra, frf.csv, words of the one line, decided before the fit)
    ("modes-0", "modes = 0", _csv(), ["^s.toml: [plant]: modes = 0 leaves a rigid body alone",
                                      "modes >= 1"], True),
    ("two-lines", "", _csv(LINES[[20, 40]], P1[[20, 40]], P2[[20, 40]]),
     ["^s.toml: [plant] file: frf.csv: 2 measured lines cannot determine a mode"], True),
    ("discretisation-above-nyquist", '[controller]\nsample_rate_hz = 1e4\ndiscretization = '
     '"tustin-prewarp"\nprewarp_hz = 6000.0\n', _csv(),
     ["^s.toml: [controller]: prewarp_hz = 6000 Hz must lie below the Nyquist frequency"], True),
    ("delay-in-seconds-for-microseconds", "delay = 1.0", _csv(),
     ["^s.toml: [plant] delay: 1 s turns the phase of the lowest lines (1-", "is it in seconds?"],
     True),
    ("p2-in-um-per-newton", "", _csv(p1=P1, p2=P2 * 1e6),
     ["^s.toml: [plant] file: frf.csv: P1 and P2 differ by a factor 1e+06 at the lowest lines",
      "M = 22.5 kg from P1, 2.25e-05 kg from P2", "other units"], True),
    ("both-column-sets-disagree", "", _csv(both_scale=10.0),
     ["^s.toml: [plant] file: frf.csv: has both p1_re, p1_im and p1_abs, p1_phase_deg, and "
      "they disagree", "at 1 Hz (line 1)"], True),
    ("conjugated-phases", "", _csv(p1=np.conj(P1), p2=np.conj(P2)),
     ["^s.toml: [plant] file: frf.csv: the phases have the opposite sign convention",
      "negate p1_phase_deg and p2_phase_deg"], True),
    ("conjugated-phases-of-a-delayed-response", "",
     _csv(p1=np.conj(_measured(50e-6)[0]), p2=np.conj(_measured(50e-6)[1])),
     ["the phases have the opposite sign convention"], True),
    ("p1-and-p2-swapped", "", _csv(p1=P2, p2=P1),
     ["^s.toml: [plant] file: frf.csv: P1 and P2 look swapped", "put the collocated response "
      "in p1_* and the non-collocated one in p2_*"], True),
    ("response-in-mm-per-newton", "", _csv(p1=P1 * 1e3, p2=P2 * 1e3),
     ["^s.toml: [plant] file: the loop with the plant fitted to frf.csv (M = 0.0225 kg, modes "
      "at 694", "the fitted plant is what the [controller] does not stabilise",
      "with a response in mm/N read as m/N (M = 22.5 kg): check the units"], False),
    ("frequencies-in-rad-per-s", "", _csv(f=LINES * 2 * np.pi),
     ["^s.toml: [plant] file: the loop with the plant fitted to frf.csv (M = 0.57 kg",
      "frequencies in rad/s read as Hz (M = 22.5 kg)"], False),
]


@pytest.mark.parametrize(("extra", "frf", "words", "before_fit"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_response_that_cannot_give_the_plant_is_refused_in_one_line(tmp_path, extra, frf,
                                                                      words, before_fit):
    populate(tmp_path, {"s.toml": _scenario(extra), "frf.csv": frf})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["analyze", "s.toml", "--frequency", "1", "5", "10"],
                                   tmp_path)
    for word in words:
        if word.startswith("^"):
            assert line.startswith(f"motionhyst: error: {word[1:]}"), (word, line)
        else:
            assert word in line, (word, line)
    assert "[controller]" in extra or "[controller]:" not in line, line  # the data's, not it
    assert snapshot(tmp_path) == before


def _analyze_imports(folder: Path) -> tuple[str, str]:
    """``motionhyst analyze s.toml`` in a child process: its exit code and which of
    python-control and scipy.optimize it imported ("2 ['control']"), and its stderr."""
    code = ("import sys\nfrom motionhyst.cli import main\n"
            "code = main(['analyze', 's.toml', '--frequency', '1'])\n"
            "print(code, sorted({'control', 'scipy.optimize'} & set(sys.modules)))\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=folder, capture_output=True,
                          text=True, timeout=120, env=limited_process.environment())
    return proc.stdout.splitlines()[-1], proc.stderr


@pytest.mark.parametrize("case", [c for c in CASES if c[4]], ids=lambda c: c[0])
def test_what_the_lines_decide_is_refused_before_python_control_loads(tmp_path, case):
    """Checks first, the fit and python-control after: a refusal the lines decide does not
    wait for them."""
    populate(tmp_path, {"s.toml": _scenario(case[1]), "frf.csv": case[2]})
    loaded, err = _analyze_imports(tmp_path)
    assert loaded == "2 []", err


def test_a_fit_refusal_comes_before_python_control_loads(tmp_path):
    """Three lines below the mode determine none (the fit's refusal): python-control, which a
    loop needs, is not imported for it."""
    populate(tmp_path, {"s.toml": _scenario(), "frf.csv": _csv(LINES[:3], P1[:3], P2[:3])})
    loaded, err = _analyze_imports(tmp_path)
    assert loaded == "2 ['scipy.optimize']", err
    assert "determine none of the 1 mode(s)" in err


def _fit(tmp_path: Path, extra: str, frf: str):
    populate(tmp_path, {"s.toml": _scenario(extra), "frf.csv": frf})
    return load_scenario(tmp_path / "s.toml").plant_fit()


def test_both_column_sets_that_agree_are_read_as_one(tmp_path):
    """The same response written twice (re, im and abs, phase, 11 digits): the fit is that of
    either set alone, to the digits written."""
    both = _fit(tmp_path / "both", "", _csv(both_scale=1.0))
    alone = fit_frf(LINES, P1, P2)
    assert both.plant.M == pytest.approx(alone.plant.M, rel=1e-8)
    assert both.plant.modes[0].frequency_hz == pytest.approx(694.26, abs=0.5)  # eq. (2)


def test_a_delay_that_is_the_data_s_is_divided_out(tmp_path):
    """50 us given for a chain that delays by 50 us: the check passes and the fit finds
    Table I's stage (M = 22.5 kg, eq. 2: the mode at 694.26 Hz)."""
    fit = _fit(tmp_path, "delay = 50e-6", _csv(p1=_measured(50e-6)[0], p2=_measured(50e-6)[1]))
    assert fit.delay_s == 50e-6 and fit.delay_given
    assert fit.plant.M == pytest.approx(22.5, rel=0.01)
    assert fit.plant.modes[0].frequency_hz == pytest.approx(694.26, rel=0.005)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("delay", [0.0, 50e-6, 300e-6, 1e-3])
def test_a_causal_response_is_never_taken_for_a_conjugate(delay, seed):
    """Table I measured through delays of 0-1 ms (up to three turns at 3 kHz) with 0.5 % or
    2 % noise: the phase check passes, and the conjugate of each is refused where its
    noise lets a mode show (0.5 %, or any delay)."""
    from motionhyst.plants.frf_checks import FrfInputError, check_phase_sense

    for noise in (0.005, 0.02):
        p1, _ = STAGE.response(2 * np.pi * LINES)
        rng = np.random.default_rng(seed)
        n = rng.standard_normal((2, LINES.size))
        p1 = p1 * np.exp(-2j * np.pi * LINES * delay) * (1 + noise * (n[0] + 1j * n[1]) / 2**.5)
        check_phase_sense(LINES, p1)
        if noise == 0.005 or delay:
            with pytest.raises(FrfInputError, match="opposite sign convention"):
                check_phase_sense(LINES, np.conj(p1))


def test_one_mode_of_negative_residue_is_not_a_conjugate():
    """A second mode with r1 < 0 beside a passive one: not every mode leads, so the data are
    not conjugated (the fit warns of that mode instead)."""
    from motionhyst.plants.frf_checks import check_phase_sense
    from motionhyst.plants.modal import Mode

    stage = ModalPlant(22.5, (Mode(694.26, 0.003, 17.5 / (22.5 * 5.0), 1 / 22.5),
                              Mode(1500.0, 0.02, -0.05, 0.01)))
    p1, _ = stage.response(2 * np.pi * LINES)
    check_phase_sense(LINES, p1 * (1 + 0.005 * np.random.default_rng(0).standard_normal(60)))
