"""Long records from a start in bounded memory (issue 26): an open-loop run goes through the
record's upsampled force block by block (motionhyst.time.resample.fine_blocks), its state
carried on, with the numbers of one run over the whole upsampled record."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.core.budget import BudgetError, parse_size, set_max_memory
from motionhyst.hysteresis import BoucWen, Coulomb, Dahl, Jenkins, LuGre, MaxwellSlip
from motionhyst.identify.io_predict import predict_from_window
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.time import openloop, resample
from motionhyst.time.bouc_wen_rk4 import simulate_bouc_wen
from motionhyst.time.openloop import MassSpringDamper, OpenLoop, simulate_elements
from motionhyst.time.resample import block_samples, fine_blocks, fine_input, held_nodes

FS = 1000.0


def _force(n: int, seed: int = 0) -> np.ndarray:
    """A force that moves an axis back and forth, with noise [N]."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    return (60.0 * np.sin(2 * np.pi * 1.3 * t) + 25.0 * np.sin(2 * np.pi * 7.1 * t + 1.0)
            + rng.standard_normal(n))


def _joined(blocks: list[np.ndarray]) -> np.ndarray:
    return np.concatenate([blocks[0]] + [b[1:] for b in blocks[1:]])


@pytest.mark.parametrize("factor", [1, 3, 20])
@pytest.mark.parametrize("n", [2, 257, 5003])
def test_the_blocks_are_the_whole_records_fine_input_bit_for_bit(factor, n):
    u = np.cumsum(np.random.default_rng(n).standard_normal(n))
    blocks = list(fine_blocks(u, factor, nodes=300 * factor))
    assert len(blocks) == (1 if factor == 1 or n - 1 <= 300 else -(-(n - 1) // 300))
    assert all(b.size == 300 * factor + 1 for b in blocks[:-1])
    np.testing.assert_array_equal(_joined(blocks), fine_input(u, factor, periodic=False))


def test_a_record_of_whole_periods_is_interpolated_as_one():
    period = np.random.default_rng(1).standard_normal(250)
    u = np.tile(period, 40)  # 10000 samples: the spectrum of the whole record, zero-padded
    blocks = list(fine_blocks(u, 20, nodes=20 * 1000))
    assert len(blocks) == 10
    whole = fine_input(u, 20, periodic=False)
    assert np.max(np.abs(_joined(blocks) - whole)) <= 1e-13 * np.max(np.abs(whole))
    # what the memory check counts: a block and the upsampled period (with its index)
    assert held_nodes(u, 20, nodes=20 * 1000) == blocks[0].size + 2 * 250 * 20
    assert held_nodes(np.cumsum(u), 20, nodes=20 * 1000) == blocks[0].size
    u = np.tile(period[:143], 70)  # 10010 samples, 13 x 11 x 70: the windowed sinc, wrapped
    np.testing.assert_array_equal(_joined(list(fine_blocks(u, 20, nodes=20 * 1000))),
                                  fine_input(u, 20, periodic=False))


def test_a_block_holds_at_least_256_samples():
    assert block_samples(20) == resample.BLOCK_NODES // 20
    assert block_samples(10000) == block_samples(20, nodes=100) == 256


SYSTEMS = {
    "axis-jenkins-offset": OpenLoop(MassDamper(95.0, 200.0, force_offset=-3.0),
                                    Jenkins(k=1e6, fc=20.0)),
    "axis-coulomb-by-direction": OpenLoop(MassDamper(95.0, 200.0, c_skew=-20.0),
                                          Coulomb(fc=20.0)),
    "axis-bouc-wen": OpenLoop(MassDamper(95.0, 200.0), BoucWen(k=2e5, fc=20.0)),
    "spring-lugre": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                             LuGre(sigma0=2e4, sigma1=30.0, sigma2=0.0, fc=5.0, fs=8.0, vs=0.02)),
    "spring-dahl": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Dahl(k=2e4, fc=5.0)),
    "two-mass-maxwell-slip": OpenLoop(TwoMassStage(2.0, 3.0, 20.0, 2e5),
                                      MaxwellSlip(k=[1e4, 2e4], fc=[2.0, 4.0])),
    "spring-bouc-wen-rk4": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=2e4, fc=5.0)),
    "axis-alone-rk4": OpenLoop(MassDamper(95.0, 200.0, force_offset=2.0)),
}


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_a_run_in_blocks_is_the_run_over_the_whole_record(monkeypatch, name):
    system = SYSTEMS[name]
    u = _force(3000)
    t = np.arange(u.size) / FS
    whole = system.simulate(t, u).displacement  # one block: 3000 samples
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    blocks = system.simulate(t, u).displacement
    assert np.all(np.isfinite(whole)) and np.ptp(whole) > 0
    np.testing.assert_array_equal(blocks, whole)


def test_the_sensitivities_in_blocks_are_those_of_the_whole_record(monkeypatch):
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)
    u = _force(1500)
    mech = MassSpringDamper(2.0, 10.0, 5e4).mechanics()
    dparams = np.zeros((1, 8, 2))
    dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0  # Jenkins (k, fc)
    link = Jenkins(k=2e4, fc=5.0).time_stepping()
    y, dy = simulate_elements(mech, link, u, FS, 10, periodic=False, dparams=dparams)
    y1, dy1 = simulate_elements(mech, link, u, FS, 10, periodic=False, dparams=dparams,
                                upsampled=fine_input(u, 10, periodic=False))
    np.testing.assert_array_equal(y, y1)
    np.testing.assert_array_equal(dy, dy1)
    assert dy.shape == (1500, 5) and np.ptp(dy[:, 3]) > 0
    p = np.array([2.0, 10.0, 5e4, 2e4, 800.0, -1100.0, 1.0])
    y, dy = simulate_bouc_wen(p, u, FS, 20, periodic=False, sensitivities=True)
    y1, dy1 = simulate_bouc_wen(p, u, FS, 20, periodic=False, sensitivities=True,
                                upsampled=fine_input(u, 40, periodic=False))
    np.testing.assert_array_equal(y, y1)
    np.testing.assert_array_equal(dy, dy1)


def test_a_prediction_from_a_window_in_blocks_is_the_same(monkeypatch):
    system = SYSTEMS["axis-jenkins-offset"]
    u = _force(3000)
    t = np.arange(u.size) / FS
    y = system.simulate(t, u).displacement + 0.01
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)  # the whole record as one block
    whole = predict_from_window(system, t, u, y)
    seen = []
    blocks_of = resample.fine_blocks

    def counted(*args, **kwargs):
        for b in blocks_of(*args, **kwargs):
            seen.append(b.size)
            yield b

    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    monkeypatch.setattr(openloop, "fine_blocks", counted)
    blocks = predict_from_window(system, t, u, y)
    # the runs went through the record in blocks: the prediction's, and its run from a
    # velocity a step off (the window's noise floor, io_predict.window_noise_floor)
    assert len(seen) == 2 * -(-2999 // 256)
    np.testing.assert_array_equal(blocks.displacement, whole.displacement)
    assert whole.rmse < 1e-9
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)
    set_max_memory(parse_size("10M"))
    try:
        with pytest.raises(BudgetError, match="3000 samples of 200 integration steps each"):
            predict_from_window(system, t, u, y, substeps=200)  # 29 MB at once
        monkeypatch.setattr(resample, "BLOCK_NODES", 1)
        predict_from_window(system, t, u, y, substeps=200)  # 256-sample blocks: 2.7 MB
    finally:
        set_max_memory(None)


def test_predict_needs_the_record_and_one_block_not_the_whole_upsampled_record(tmp_path,
                                                                                monkeypatch,
                                                                                capsys):
    """20000 samples of 500 steps: 101 MB upsampled at once (10 bytes a step), above
    --max-memory 70M; in blocks of 4194 samples 44.4 MB (21 bytes a step): predicted, the
    numbers of the whole record's run."""
    u = _force(20000)
    t = np.arange(u.size) / FS
    np.savetxt(tmp_path / "f.csv", np.column_stack([t, u]), delimiter=",", header="time,force",
               comments="")
    (tmp_path / "m.toml").write_text('[stage]\ntype = "mass-damper"\nm = 95.0\nc = 200.0\n\n'
                                     '[hysteresis]\nmodel = "jenkins"\nk = 1e6\nfc = 20.0\n')
    base = ["predict", str(tmp_path / "m.toml"), str(tmp_path / "f.csv"), "--substeps", "500"]
    assert main([*base, "--out", str(tmp_path / "p.csv"), "--max-memory", "70M"]) == 0
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)  # the whole record as one block
    assert main([*base, "--out", str(tmp_path / "q.csv"), "--max-memory", "70M"]) == 2
    assert "20000 samples of 500 integration steps each needs 101 MB" in capsys.readouterr().err
    assert main([*base, "--out", str(tmp_path / "q.csv")]) == 0
    p = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert p.shape == (20000, 2) and np.ptp(p[:, 1]) > 1e-3
    np.testing.assert_array_equal(p, np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1))


def _many_elements() -> OpenLoop:
    """A stage on a spring with a Maxwell-slip link of 38 elements: a periodic run carries
    the sensitivities of the output to 40 start states (Newton's steps on the period map)."""
    return OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                    MaxwellSlip(k=[500.0] * 38, fc=[0.1 * (i + 1) for i in range(38)]))


def _periodic_force(n: int) -> np.ndarray:
    """Three sines of whole cycles in `n` samples [N]."""
    i = np.arange(n)
    return sum(10.0 * np.sin(2 * np.pi * c * i / n + c) for c in (3, 17, 40))


@pytest.mark.parametrize("name", ["spring-dahl", "spring-lugre",
                                  "many-elements"])
def test_a_period_run_in_blocks_is_the_run_over_the_whole_period(monkeypatch, name):
    """A periodic steady state goes through its period in blocks (the kernel's record of the
    start state's sensitivities, three rows of them, held for one block): the numbers of the
    whole period's run, bit for bit."""
    system = _many_elements() if name == "many-elements" else SYSTEMS[name]
    u = _periodic_force(3000) / (20.0 if name == "many-elements" else 10.0)
    t = np.arange(u.size) / FS
    whole = system.simulate(t, u, periodic=True, substeps=10).displacement
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    blocks = system.simulate(t, u, periodic=True, substeps=10).displacement
    assert np.all(np.isfinite(whole)) and np.ptp(whole) > 0
    np.testing.assert_array_equal(blocks, whole)


def test_a_periodic_run_is_sized_with_its_start_states_sensitivities(tmp_path):
    """predict --periodic of one period of 1e5 samples, 2 substeps, a link of 38 elements:
    the estimate counts the output's sensitivities to the 40 states (16 B a state and
    sample) and the kernel's record of them (two blocks of 17 MB), not only the force: above
    --max-memory 100M it is refused before the run, one line (it ran in 99 MB of address
    space; the estimate was 80 MB, below it)."""
    import limited_process
    from scipy.io import savemat

    n = 100000
    savemat(tmp_path / "f.mat", {"time": (np.arange(n) / FS)[:, None],
                                 "force": (_periodic_force(n) / 20.0)[:, None]})
    (tmp_path / "m.toml").write_text(
        '[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
        '[hysteresis]\nmodel = "maxwell-slip"\n'
        f'k = {[500.0] * 38}\nfc = {[0.1 * (i + 1) for i in range(38)]}\n')
    line = limited_process.refusal(["predict", "m.toml", "f.mat", "--periodic", "--substeps",
                                    "2", "--out", "p.csv", "--max-memory", "100M"], tmp_path)
    assert ("f.mat: 100000 samples of 2 integration steps each (and the periodic steady "
            "state's sensitivities to its 40 states) needs 107 MB") in line, line
    assert "(--max-memory)" in line and not (tmp_path / "p.csv").exists()


PERIODIC_CASES = {
    # a Dahl link on a spring, 3 states, its period upsampled by its spectrum (20 steps)
    "spring-dahl": ("SYSTEMS['spring-dahl']", 100000, None),
    # the same by the windowed sinc (a period of 100003 samples)
    "spring-dahl-sinc": ("SYSTEMS['spring-dahl']", 100003, None),
    # Maxwell-slip of 38 elements: the sensitivities to 40 states, in 6 blocks
    "many-elements": ("_many_elements()", 100000, 2),
    # Bouc-Wen by RK4: steps and their midpoints
    "spring-bouc-wen-rk4": ("OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=2e4, fc=0.5))",
                            100000, 5),
}


def test_a_periodic_runs_estimate_holds_it_within_one_and_a_half_times(tmp_path):
    """The estimate of a periodic steady state (what --max-memory is checked against) holds
    the run under an address-space limit of the estimate above what the process held
    before, and is at most 1.5 times the run's resident peak: measured 1.05-1.45 times the
    address space, 1.05-1.42 times the resident peak (the estimate was 1.6-3.2 times above
    for a link of few states, 107 MB for a Dahl link's 49 MB resident; 0.8 times, below,
    for 38 elements)."""
    script = tmp_path / "periodic.py"
    script.write_text(
        "import resource, sys\n"
        "import numpy as np\n"
        "sys.path.insert(0, sys.argv[1])\n"
        "from test_long_records import FS, SYSTEMS, _many_elements, _periodic_force\n"
        "from test_long_records import BoucWen, MassSpringDamper, OpenLoop\n"
        "from motionhyst.core.budget import set_max_memory\n"
        "from motionhyst.time import openloop\n"
        "set_max_memory(1 << 40)\n"  # the address-space limit alone decides
        "asked = []\n"
        "check = openloop.check_memory\n"
        "openloop.check_memory = lambda nbytes, *a: (asked.append(nbytes), check(nbytes, *a))\n"
        "def status(key):\n"
        "    with open('/proc/self/status') as f:\n"
        "        return next(int(x.split()[1]) * 1024 for x in f if x.startswith(key))\n"
        "system, n, r = eval(sys.argv[2]), int(sys.argv[3]), eval(sys.argv[4])\n"
        "system.simulate(np.arange(2000) / FS, _periodic_force(2000) / 20.0, periodic=True,\n"
        "                substeps=r)\n"  # the kernels compiled
        "u = _periodic_force(n) / 20.0\n"
        "t = np.arange(n) / FS\n"
        "asked.clear()\n"
        "system.simulate(t[:3001], _periodic_force(3001) / 20.0, periodic=True, substeps=r)\n"
        "with open('/proc/self/clear_refs', 'w') as f:\n"
        "    f.write('5')\n"  # the resident peak from here
        "size, resident = status('VmSize'), status('VmRSS')\n"
        "asked.clear()\n"
        "set_max_memory(1)\n"
        "try:\n"
        "    system.simulate(t, u, periodic=True, substeps=r)\n"  # sized, refused
        "except ValueError:\n"
        "    pass\n"
        "set_max_memory(1 << 40)\n"
        "need = asked[0]\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + int(need), resource.RLIM_INFINITY))\n"
        "y = system.simulate(t, u, periodic=True, substeps=r).displacement\n"
        "print(y.size, need / (status('VmHWM') - resident))\n")
    import subprocess
    import sys
    from pathlib import Path

    from limited_process import environment

    for name, (system, n, r) in PERIODIC_CASES.items():
        proc = subprocess.run([sys.executable, str(script), str(Path(__file__).parent), system,
                               str(n), repr(r)], capture_output=True, text=True,
                              env=environment(), timeout=600)
        assert proc.returncode == 0, (name, proc.stderr[-2000:])
        size, ratio = proc.stdout.split()
        assert int(size) == n and 1.0 <= float(ratio) <= 1.5, (name, proc.stdout)


def test_a_periodic_run_holds_its_sensitivities_once_a_period(tmp_path):
    """The periodic steady state of a link of 38 elements over a period of 1e5 samples (its
    output's sensitivities to 40 start states: 32 MB a period) runs within 120 MB of address
    space above what the process held before; the period's run held the kernel's record of
    three rows of them too (96 MB more)."""
    script = tmp_path / "period.py"
    script.write_text(
        "import resource, sys\n"
        "import numpy as np\n"
        "sys.path.insert(0, sys.argv[1])\n"
        "from test_long_records import FS, _many_elements, _periodic_force\n"
        "from motionhyst.core.budget import set_max_memory\n"
        "set_max_memory(1 << 30)\n"  # the address-space limit alone decides
        "system = _many_elements()\n"
        "u = _periodic_force(2000) / 20.0\n"
        "system.simulate(np.arange(2000) / FS, u, periodic=True, substeps=2)\n"
        "t = np.arange(100000) / FS\n"
        "u = _periodic_force(100000) / 20.0\n"
        "with open('/proc/self/status') as f:\n"
        "    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith('VmSize'))\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + (120 << 20),) * 2)\n"
        "y = system.simulate(t, u, periodic=True, substeps=2).displacement\n"
        "print(y.size, float(np.ptp(y)))\n")
    import subprocess
    import sys
    from pathlib import Path

    from limited_process import environment

    proc = subprocess.run([sys.executable, str(script), str(Path(__file__).parent)],
                          capture_output=True, text=True, env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("100000 "), proc.stdout



def _axis_problem(n: int, r: int, drift: bool = False):
    """The search problem of a positioning axis with a Jenkins link, its force offset (and a
    drift) and initial velocity estimated, on one record of `n` samples, `r` substeps; and a
    point of it."""
    from motionhyst.identify.io_elements import _ElementProblem, _LinkLayout
    from motionhyst.identify.io_offsets import Extras
    from motionhyst.identify.io_records import IORecord

    u = _force(n)
    t = np.arange(n) / FS
    y = SYSTEMS["axis-jenkins-offset"].simulate(t, u).displacement
    layout = _LinkLayout.of(Jenkins, 1)
    extras = Extras.choose("auto", floating=True, periodic=False, from_rest=False,
                           n_records=1, drift=drift)
    y_scale = float(np.sqrt(np.mean(y ** 2)))
    scale = np.concatenate([[95.0, 200.0], layout.scales(1e6, 200.0, y_scale, 0.1),
                            extras.scales(60.0, y_scale, 0.1, t[-1])])
    prob = _ElementProblem([IORecord(t, u, y)], False, r, layout, y_scale, scale,
                           plant=MassDamper(1.0, 1.0), extras=extras)
    v = np.concatenate([[94.0, 210.0, 9e5, 21.0], 0.03 * scale[4:] + 2.9 * (
        np.array(extras.names) == "input_offset")])
    return prob, prob.variables(v)


@pytest.mark.parametrize("drift", [False, True])
def test_a_search_runs_the_fine_force_in_blocks_with_the_numbers_of_the_whole(monkeypatch,
                                                                             drift):
    """The residuals and the Jacobian of identify's search (a force offset and its drift
    applied to each block as the run goes) are those of the whole record's fine force less
    the offsets, bit for bit."""
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)  # the whole record as one block
    prob, q = _axis_problem(1500, 10, drift)
    r_whole, J_whole = prob.residuals(q), prob.jacobian(q)
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    prob, q = _axis_problem(1500, 10, drift)
    r_blocks, J_blocks = prob.residuals(q), prob.jacobian(q)
    assert J_whole.shape == (1500, 8 if drift else 7) and np.ptp(r_whole) > 0.1
    np.testing.assert_array_equal(r_blocks, r_whole)
    np.testing.assert_array_equal(J_blocks, J_whole)
    # the run of the whole fine force less the offsets, as the search ran it before
    u0 = prob.extras.split(prob.values(q)[4:])[0]
    rate = prob.extras.drift(prob.values(q)[4:])
    rec = prob.records[0]
    fine = fine_input(rec.u, 10, False) - u0 * fine_input(np.ones(1500), 10, False)
    if drift:
        fine = fine - rate * fine_input(rec.t, 10, False)
    force = prob.forces[0]
    np.testing.assert_array_equal(force.whole(u0, rate), fine)
    np.testing.assert_array_equal(_joined(list(force.blocks(u0, rate))), fine)


@pytest.mark.parametrize(("n", "phases"), [(1499, True), (1500, True), (2800, False),
                                          (3 * 2 ** 10, True)])
def test_the_upsampled_constant_is_kept_as_its_phases(monkeypatch, n, phases):
    """The force offset's fine force (the upsampled 1) repeats the fine step's phases: kept
    as those (checked block by block), equal to the whole one bit for bit where the record
    is interpolated by the windowed sinc (a prime length; 1500 = 2 x 750), to rounding where
    by its spectrum (3072 samples in blocks of 256); a record of one block whose constant
    does not repeat to the last bit (2800 samples, by its spectrum) keeps it whole."""
    from motionhyst.identify.io_force import RecordForce
    from motionhyst.identify.io_records import IORecord

    if n > 3000:
        monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    rec = IORecord(np.arange(n) / FS, _force(n), np.zeros(n))
    force = RecordForce(rec, 20, periodic=False, offset=True)
    # the phases: 20 values, not 20 n
    assert force.nbytes == (1 if phases else 2) * force.fine.nbytes
    one = fine_input(np.ones(n), 20, periodic=False)
    if n > 3000:
        assert np.max(np.abs(force.whole(1.0) - (force.fine - one))) <= 2.5e-16 * 60.0
    else:
        np.testing.assert_array_equal(force.whole(1.0), force.fine - one)


def test_a_search_holds_the_records_fine_force_once(tmp_path):
    """An evaluation of identify's search (residuals and exact Jacobian, with the force
    offset) on 20000 samples of 500 substeps (80 MB of fine force) runs within 150 MB of
    address space above what the process held before it; the search held the fine force, the
    upsampled constant of the force offset and their difference (240 MB)."""
    script = tmp_path / "evaluate.py"
    script.write_text(
        "import resource, sys\n"
        "sys.path.insert(0, sys.argv[1])\n"
        "from test_long_records import _axis_problem\n"
        "prob, q = _axis_problem(600, 20)\n"  # the kernels compiled, the modules loaded
        "prob.residuals(q), prob.jacobian(q)\n"
        "with open('/proc/self/status') as f:\n"
        "    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith('VmSize'))\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + (150 << 20),) * 2)\n"
        "prob, q = _axis_problem(20000, 500)\n"
        "r, J = prob.residuals(q), prob.jacobian(q)\n"
        "print(J.shape, float(abs(r).max()))\n")
    import subprocess
    import sys
    from pathlib import Path

    from limited_process import environment

    proc = subprocess.run([sys.executable, str(script), str(Path(__file__).parent)],
                          capture_output=True, text=True, env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("(20000, 7) "), proc.stdout


def _axis_record(n: int, seed: int = 0):
    """An input-output record of the positioning axis with a Jenkins link and a -3 N force
    offset, `n` samples at 1 kHz, 1e-7 m of position noise."""
    from motionhyst.identify.io_records import IORecord

    t = np.arange(n) / FS
    u = _force(n, seed)
    y = SYSTEMS["axis-jenkins-offset"].simulate(t, u).displacement
    return IORecord(t, u, y + 1e-7 * np.random.default_rng(seed + 1).standard_normal(n))


def test_identify_refuses_a_search_above_the_budget_before_any_run(monkeypatch, tmp_path):
    """identify's search of 20000 samples (20 integration steps each: a Jenkins axis, 7
    parameters) is sized before the starts run (the records upsampled, the runs of two threads,
    the Jacobian's copies: 52 MB): above --max-memory it is refused with one line naming what
    takes the memory and the option, no model run first (the search ran before, and a long
    record's was killed by the operating system)."""
    import limited_process

    from motionhyst.identify import io_elements
    from motionhyst.identify.input_output import identify_io
    from motionhyst.identify.io_start import search_memory

    rec = _axis_record(20000)
    assert 30e6 < search_memory([rec], 20, 7, 4, threads=2)["total"] < 120e6
    # the forward differences run a column a thread: 64 cores run the 7 columns 7 at a time
    assert (search_memory([rec], 20, 7, 4, threads=64)
            == search_memory([rec], 20, 7, 4, threads=7))
    need = search_memory([rec], 20, 7, 4)["total"]  # this machine's threads
    runs = []
    monkeypatch.setattr(io_elements, "simulate_elements", lambda *a, **k: runs.append(1))
    monkeypatch.setattr(io_elements, "run_from_state", lambda *a, **k: runs.append(1))
    set_max_memory(int(need) - 1)
    try:
        with pytest.raises(BudgetError, match=r"^identify's search of 20000 samples \(20 "
                                              r"integration steps each, 7 parameters\) needs"):
            identify_io([rec], "jenkins", plant="mass-damper")
    finally:
        set_max_memory(None)
    assert runs == []
    np.savetxt(tmp_path / "axis.csv", np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="")
    line = limited_process.refusal(["identify", "axis.csv", "--record", "input-output",
                                    "--plant", "mass-damper", "--model", "jenkins",
                                    "--max-memory", "20M", "--save", "m.toml"], tmp_path)
    assert line.startswith("motionhyst: error: identify's search of 20000 samples"), line
    assert "above the memory budget of 21 MB (--max-memory)" in line, line
    assert "a larger --max-memory if the machine has it" in line, line
    assert not (tmp_path / "m.toml").exists()


def test_identify_within_the_budget_stays_within_its_estimate(tmp_path):
    """identify of a Jenkins axis from 20000 samples (its starts, the Coulomb fit it starts
    from with a thread of forward differences a core, the refinement with exact
    sensitivities, the standard errors) runs within its estimate of address space above what
    the process held before it (kernels compiled, threads made), and finds the axis."""
    script = tmp_path / "within.py"
    script.write_text(
        "import resource, sys, warnings\n"
        "sys.path.insert(0, sys.argv[1])\n"
        "from test_long_records import _axis_record\n"
        "from motionhyst.core.budget import set_max_memory\n"
        "from motionhyst.identify.input_output import identify_io\n"
        "from motionhyst.identify.io_start import search_memory\n"
        "set_max_memory(1 << 40)\n"  # the address-space limit alone decides
        "warnings.simplefilter('ignore')\n"
        "identify_io([_axis_record(3000, 1)], 'jenkins', plant='mass-damper')\n"
        "rec = _axis_record(20000)\n"
        "need = search_memory([rec], 20, 7, 4, segments=True)['total']\n"
        "with open('/proc/self/status') as f:\n"
        "    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith('VmSize'))\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + int(need),) * 2)\n"
        "fit = identify_io([rec], 'jenkins', plant='mass-damper')\n"
        "print(round(need / 1e6), fit.fit_rms, fit.estimates['m'])\n")
    import subprocess
    import sys
    from pathlib import Path

    from limited_process import environment

    proc = subprocess.run([sys.executable, str(script), str(Path(__file__).parent)],
                          capture_output=True, text=True, env=environment(), timeout=900)
    assert proc.returncode == 0, proc.stderr[-2000:]
    need, rms, m = (float(x) for x in proc.stdout.split())
    assert need > 30 and rms < 1.05e-7 and m == pytest.approx(95.0, rel=1e-4), proc.stdout
