"""Input-output records that cannot describe one stage, refused before the search (issue 26:
no answer from nothing): a link's force-displacement record beside a stage's on a spring
(alone, its mass -1.2 +- 0.99 kg, 3.2 standard errors from the stage's: main searched to the
work budget), records of a 2 kg and a 20 kg stage (each shows its mass; main searched for a
stage of 10.7 kg); and records of one stage that must still pass (EMPS's windows, slow, small
or noisy records of a generated axis).

The command-line cases run in a child process under an address-space limit
(:mod:`limited_process`), with a work budget of a second that main met in its search: they
assert exit code 2, one line on stderr naming the records and their masses, nothing on
stdout, every file byte-identical and none added.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst import Jenkins
from motionhyst.identify.io_consistency import ONE_STAGE_RATIO, check_one_stage
from motionhyst.identify.io_records import IORecord
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"
FAST = (5.0, 1.3, 3.0, 4.1)
"""Two sines' amplitudes [N] and frequencies [Hz]: a record that shows the stage's mass."""


def _axis(m: float = 2.0, c: float = 10.0, link: Jenkins | None = None, n: int = 3000,
          force=None, noise: float = 1e-7, seed: int = 0, name: str = "axis.csv") -> IORecord:
    """A positioning axis's record at 1 kHz: a mass `m` on viscous friction `c` and a Jenkins
    link (2000 N/m, 1 N), driven by `force` (of time; default the two sines of FAST), its
    position with white noise of `noise` m."""
    t = np.arange(n) / 1000.0
    if force is None:
        a1, f1, a2, f2 = FAST
        u = a1 * np.sin(2 * np.pi * f1 * t) + a2 * np.sin(2 * np.pi * f2 * t + 0.4)
    else:
        u = force(t)
    link = link or Jenkins(k=2000.0, fc=1.0)
    y = OpenLoop(MassDamper(m, c), link).simulate(t, u).displacement
    y = y + noise * np.random.default_rng(seed).standard_normal(n)
    return IORecord(t, u, y, name)


def _link(n: int = 3000) -> IORecord:
    """A link's force-displacement record at 1 kHz, read as input-output: a Jenkins element
    with a spring and a damper in parallel, driven by a 1 mm sine at 2 Hz (no mass)."""
    t = np.arange(n) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * 2 * t) * (0.8 + 0.2 * np.cos(2 * np.pi * 0.05 * t))
    w = (Jenkins(k=40.0, fc=0.01).response(x) + 10 * x + 1.6 * np.gradient(x, t)
         + 1e-4 * np.random.default_rng(1).standard_normal(n))
    return IORecord(t, w, x, "link.csv")


def _csv(rec: IORecord) -> str:
    rows = np.column_stack([rec.t, rec.u, rec.y])
    return "time,force,displacement\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                                 for row in rows)


def _heavy() -> IORecord:
    """A 20 kg axis (100 N s/m, its link 20000 N/m, 10 N) driven ten times harder."""
    a1, f1, a2, f2 = FAST
    return _axis(20.0, 100.0, Jenkins(k=2e4, fc=10.0), name="heavy.csv",
                 force=lambda t: 10 * (a1 * np.sin(2 * np.pi * f1 * t)
                                       + a2 * np.sin(2 * np.pi * f2 * t + 0.4)))


def _refusal(tmp_path: Path, records: list[IORecord], *options: str) -> str:
    populate(tmp_path, {rec.name: _csv(rec) for rec in records} | {"notes.txt": "my notes"})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["identify", *(rec.name for rec in records), "--record",
                                    "input-output", *options, "--max-seconds", "1"], tmp_path)
    assert snapshot(tmp_path) == before
    return line


def test_a_link_s_record_beside_a_stage_s_on_a_spring_is_refused(tmp_path):
    """On a spring a single frequency trades the link's mass for a spring (alone -1.2 +-
    0.99 kg); with the stage's spring its mass is -0.11 +- 0.0024 kg against the stage's
    1.95 +- 0.028 kg: refused, as on a mass-damper (main: the search ran to the budget)."""
    line = _refusal(tmp_path, [_axis(name="stage.csv"), _link()], "--plant",
                    "mass-spring-damper")
    assert line.startswith("motionhyst: error: link.csv: no inertia in the force (its "
                           "inverse-dynamics mass with the others' spring -0.11"), line
    assert "while stage.csv shows 1.9" in line and "without --record input-output" in line


def test_records_of_two_stages_of_different_masses_are_refused(tmp_path):
    """A 2 kg and a 20 kg axis, each record showing its own mass (1.99 +- 0.031, 19.9 +-
    0.31 kg; 0.027 and 0.27 with the fixed rule's lags alone, newey_west_lags): one stage of
    10.7 kg would be searched for (main: to the budget)."""
    line = _refusal(tmp_path, [_axis(name="stage.csv"), _heavy()], "--plant", "mass-damper")
    assert line == ("motionhyst: error: stage.csv: an inverse-dynamics mass of 1.99 +- 0.031 "
                    "kg, while heavy.csv shows 19.9 +- 0.31 kg: records of stages of "
                    "different masses (together 10.7 kg, neither's); identify each stage "
                    "from its own records"), line


def test_two_stages_are_told_apart_on_a_spring_too():
    with pytest.raises(ValueError, match="records of stages of different masses"):
        check_one_stage([_axis(name="stage.csv"), _heavy()], floating=False)


def test_a_two_mass_stage_s_records_are_not_judged_by_one_mass():
    check_one_stage([_axis(name="stage.csv"), _heavy()], floating=True, single_mass=False)


SLOW = {"slow 0.2 Hz": lambda t: 3 * np.sin(2 * np.pi * 0.2 * t),
        "slow 0.5 Hz": lambda t: 2 * np.sin(2 * np.pi * 0.5 * t),
        "step": lambda t: 3.0 * (t > 0.5) - 3.0 * (t > 2.5),
        "ramp": lambda t: np.clip(t - 1, 0, None) * 2 - np.clip(t - 3, 0, None) * 4,
        "noisy sine": lambda t: 3 * np.sin(2 * np.pi * 0.4 * t)
        + 0.3 * np.random.default_rng(5).standard_normal(t.size)}


@pytest.mark.parametrize(("m", "c", "link"), [(2.0, 10.0, Jenkins(k=2e4, fc=0.2)),
                                              (95.0, 200.0, Jenkins(k=2000.0, fc=1.0))],
                         ids=["2kg-stiff-link", "95kg"])
def test_records_of_one_axis_pass_together(m, c, link):
    """Slow, small (0.3 of the force), stepped and noisy records of one axis (1 um noise)
    beside its fast record: their linear masses differ from its by up to a factor 3.3
    (the acceleration's noise, the link stuck), which a bound of 1.5 refused in 8 of 120
    pairs; none is refused."""
    scale = m / 2.0
    records = [_axis(m, c, link, force=lambda t: scale * np.sin(2 * np.pi * 1.3 * t)
                     * 5 + scale * 3 * np.sin(2 * np.pi * 4.1 * t + 0.4), noise=1e-6,
                     name="fast")]
    for (name, force), amp in itertools.product(SLOW.items(), (1.0, 0.3)):
        records.append(_axis(m, c, link, n=5000, noise=1e-6, seed=len(records),
                             force=lambda t, f=force, a=amp: scale * a * f(t),
                             name=f"{name} x{amp}"))
    assert ONE_STAGE_RATIO > 3.3
    for pair in itertools.combinations(records, 2):
        check_one_stage(list(pair), floating=True)
    check_one_stage(records, floating=True)


@pytest.mark.parametrize("m2", [3.0, 4.0])
def test_stages_of_close_masses_are_told_apart_where_their_records_show_them(m2):
    """A 2 kg axis's fast record beside a 3 or 4 kg axis's (each 1 um of noise): their own
    masses differ by a factor 1.47 or 1.96, at 21 or 36 robust standard errors, which main
    passed (it refused from a factor 4), searching one stage of neither mass; refused now
    beyond a factor 1.4 and 15 standard errors (one axis's records differ by 7.7 at most,
    test_records_of_one_axis_pass_together)."""
    scale = m2 / 2.0
    other = _axis(m2, 5 * m2, Jenkins(k=1000 * m2, fc=0.5 * m2), n=5000, noise=1e-6, seed=7,
                  force=lambda t: scale * (5 * np.sin(2 * np.pi * 1.3 * t)
                                           + 3 * np.sin(2 * np.pi * 4.1 * t + 0.4)),
                  name="other.csv")
    with pytest.raises(ValueError, match="records of stages of different masses"):
        check_one_stage([_axis(noise=1e-6, name="stage.csv"), other], floating=True)


@pytest.mark.skipif(not EMPS.is_file(), reason="needs ../shared/benchmarks/emps")
@pytest.mark.parametrize("floating", [True, False], ids=["mass-damper", "spring"])
def test_emps_windows_pass_together(floating):
    """EMPS's record (force = 35.15065 vir, position qm) cut into windows of 1000 to 6000
    samples: every window shows its mass (95 kg, within 3 %), given together they pass."""
    from scipy.io import loadmat

    data = loadmat(EMPS)
    t, u, y = data["t"].ravel(), 35.15065 * data["vir"].ravel(), data["qm"].ravel()
    for length in (1000, 3000, 6000):
        windows = [IORecord(t[a:a + length] - t[a], u[a:a + length], y[a:a + length], f"w{a}")
                   for a in range(0, t.size - length + 1, length)]
        check_one_stage(windows, floating)


def test_a_slow_noisy_record_of_the_axis_is_not_refused():
    """A 0.5 Hz record of 20 s with 1 um of noise beside the axis's fast record: its mass
    1.33 +- 0.11 kg against 1.93 +- 0.02 kg (5.4 standard errors, refused by main), drawn
    towards zero by the noise in its acceleration, not another system's."""
    fast = _axis(noise=1e-6, name="fast")
    slow = _axis(n=20_000, noise=1e-6, seed=10, name="slow",
                 force=lambda t: 2 * np.sin(2 * np.pi * 0.5 * t))
    check_one_stage([fast, slow], floating=True)
    with pytest.raises(ValueError, match="no inertia in the force"):
        check_one_stage([fast, _link()], floating=True)


@pytest.mark.parametrize("n", [64, 80, 100, 120, 300, 600])
def test_short_records_of_the_axis_are_not_judged_by_their_own_mass(n):
    """Records of 64-600 samples of the same 2 kg axis (1 um noise), from rest and cut from a
    running record, beside its 3000-sample record: their linear mass errs far beyond its
    Newey-West error (80 samples: 0.45 +- 0.2 kg; review A13b H1: refused as "stages of
    different masses"), so a record shorter than 20 of its lags is not judged by it."""
    stage = _axis(noise=1e-6, name="stage")
    running = _axis(n=5000, noise=1e-6, seed=99, name="running")
    for seed in range(4):
        check_one_stage([stage, _axis(n=n, noise=1e-6, seed=seed, name="short")], floating=True)
        a = 500 + 900 * seed
        window = IORecord(running.t[a:a + n] - running.t[a], running.u[a:a + n],
                          running.y[a:a + n], "window")
        check_one_stage([stage, window], floating=True)
    with pytest.raises(ValueError, match="records of stages of different masses"):
        check_one_stage([stage, _heavy()], floating=True)


def _in_units(rec: IORecord, name: str, position: float = 1.0, force: float = 1.0) -> IORecord:
    return IORecord(rec.t, force * rec.u, position * rec.y, name)


def test_a_record_in_mm_beside_one_in_m_is_named_a_unit_slip(tmp_path):
    """The same 2 kg axis logged once in m and once in mm: main refused them as "stages of
    different masses" (1.99 kg against 0.00195 kg; review A13b M3), which leads the user to
    identify a 2 g stage from the record in mm; the refusal names that record, its column,
    the factor and the --scale that undoes it."""
    stage = _axis(n=4000, noise=1e-6, name="stage.csv")
    in_mm = _in_units(_axis(n=4000, noise=1e-6, seed=5), "stage_mm.csv", position=1e3)
    for records in ([stage, in_mm], [in_mm, stage]):
        line = _refusal(tmp_path / records[0].name, records, "--plant", "mass-damper")
        assert line.startswith("motionhyst: error: stage_mm.csv: its position reads 100"), line
        assert " times stage.csv's (a range of 76." in line and "against 0.076" in line, line
        assert "is stage_mm.csv's position in mm?" in line, line
        assert "--scale displacement=0.001" in line and "different masses" not in line, line
        ratio = float(line.split("reads ")[1].split(" times")[0])
        assert abs(ratio / 1000.0 - 1.0) < 0.02, ratio


@pytest.mark.parametrize(("position", "force", "named"), [
    (1e6, 1.0, "is odd's position in um? --scale scales every record alike: write odd in m, "
               "or identify it alone with --scale displacement=1e-6"),
    (1.0, 1e3, "is odd's force in mN, or the other records' in kN? --scale scales every "
               "record alike: write the records in N"),
    (1e-3, 1.0, "are the other records' positions in mm? --scale scales every record alike: "
                "write the records in m")], ids=["um", "mN", "others-in-mm"])
def test_the_unit_slip_is_named_among_several_records(position, force, named):
    """One record of three in other units than the two others (the axis's records of 3000
    and 4000 samples): the odd one is named with the unit that explains both its readings
    and its mass; records of two stages (2 and 20 kg, forces ten times apart) are still
    "of different masses"."""
    records = [_axis(n=3000, noise=1e-6, name="a"), _axis(n=4000, noise=1e-6, seed=3, name="b"),
               _in_units(_axis(n=4000, noise=1e-6, seed=4), "odd", position, force)]
    for order in (records, records[::-1]):
        with pytest.raises(ValueError) as exc:
            check_one_stage(order, floating=True)
        assert str(exc.value).startswith("odd: its ") and str(exc.value).endswith(named), exc
    with pytest.raises(ValueError, match="records of stages of different masses"):
        check_one_stage([records[0], records[1], _heavy()], floating=True)


def test_the_others_mass_is_their_own_fit():
    """Each record is compared with the fit of all the others, summed from each record's
    pieces, not refitted for each record: the figures of the refusal are those of the
    robust least squares of the other records' samples (3 significant digits)."""
    from motionhyst.identify.io_checks import robust_least_squares
    from motionhyst.identify.io_start import equation_rows

    records = [_axis(noise=1e-6, name="stage.csv"), _heavy(),
               _axis(n=4000, noise=1e-6, seed=7, name="again.csv")]
    with pytest.raises(ValueError) as exc:
        check_one_stage(records, floating=True)
    rest = [records[0], records[2]]  # the records before and after the one refused
    rows, rhs = equation_rows(rest, floating=True)
    x, cov = robust_least_squares([np.column_stack([r, rec.y])
                                   for r, rec in zip(rows, rest, strict=True)], rhs, 11)
    expected = f"while stage.csv and the others show {x[0]:.3g} +- {np.sqrt(cov[0, 0]):.2g} kg"
    assert str(exc.value).startswith("heavy.csv: an inverse-dynamics mass of 19.9 +- 0.31"), exc
    assert expected in str(exc.value) and "1.96 +- 0.019" in expected, (expected, exc)


def test_the_check_reads_each_record_a_bounded_number_of_times(monkeypatch):
    """Eight records of the axis: the check filtered every other record again for each
    record (review A13b M5: 40 records of 10,000 samples took 5.1 s of CPU, 25 times
    two records' share); now each record's rows are formed a fixed number of times."""
    from motionhyst.identify import io_consistency, io_start

    samples, rows = [], io_start.equation_rows

    def counting(records, *args, **kwargs):
        samples.append(sum(rec.y.size for rec in records))
        return rows(records, *args, **kwargs)

    monkeypatch.setattr(io_consistency, "equation_rows", counting)
    monkeypatch.setattr(io_start, "equation_rows", counting)
    records = [_axis(n=2000, noise=1e-6, seed=s, name=f"r{s}") for s in range(8)]
    check_one_stage(records, floating=True)
    every = sum(rec.y.size for rec in records)  # the inertia check's filter, the fit's
    assert sum(samples) <= 3 * every, (sum(samples), every)  # main: 9 times (k + 1)
