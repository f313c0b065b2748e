"""``predict MODEL INPUT --init-from REC``: REC must be the record of INPUT's run (issue 26).

Its position sets the model's state and is the reference of the error reported, so a record
of another run gave another run's answer with exit 0.  "Another run" is judged by the
forces' shapes: a record whose force varies independently of INPUT's (forces de-meaned, and
less their lines, correlated by less than 0.5, differing by more than twice their white
noise) is refused in one line; the same run's record with a load cell's offset, drift, gain
error, reversed sign or noise (white up to three times the force's RMS, coloured up to its
RMS) is predicted, its error the position's noise.
"""

from __future__ import annotations

import json

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.cli import main

FS = 1000.0
N = 3000
AXIS = ('[stage]\ntype = "mass-damper"\nm = 2.0\nc = 10.0\n\n'
        '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 4.0\n')
POSITION_NOISE = 1e-7  # [m]


def _table(columns: dict[str, np.ndarray]) -> str:
    return ",".join(columns) + "\n" + "".join(
        ",".join(repr(float(v)) for v in row) + "\n" for row in zip(*columns.values(),
                                                                    strict=True))


def _time() -> np.ndarray:
    return np.arange(N) / FS


def _run(force: np.ndarray) -> np.ndarray:
    """The AXIS model's position for `force` from rest (a measured run's position)."""
    from motionhyst.hysteresis import Jenkins
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    return OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(
        _time(), force).displacement


def _input_force() -> np.ndarray:
    t = _time()
    return 30 * np.sin(2 * np.pi * 1.0 * t) + 12 * np.sin(2 * np.pi * 3.7 * t + 0.4)


def _measured_force(kind: str, seed: int) -> np.ndarray:
    """The run's force as a load cell of the same run measures it."""
    from scipy.signal import butter, lfilter

    u = _input_force()
    rms = float(np.sqrt(np.mean(u ** 2)))
    noise = np.random.default_rng(seed).standard_normal(N)
    if kind == "offset":
        return u + 0.2 * rms
    if kind == "gain":
        return 1.12 * u
    if kind == "reversed":
        return 0.5 - u
    if kind == "white-15-percent":
        return u + 0.15 * rms * noise
    if kind == "white-3-rms":
        return u + 3.0 * rms * noise
    if kind.startswith("drift"):  # a thermal ramp over the record, of 1.5 or 3 times the RMS
        size = 1.5 if "1.5" in kind else -3.0
        return u + size * rms * np.sqrt(3.0) * np.linspace(-1.0, 1.0, N) + 0.05 * rms * noise
    coloured = lfilter(*butter(2, 50.0 / (FS / 2)), noise)  # up to 50 Hz
    return 0.9 * u - 3.0 + rms * coloured / np.std(coloured)


def _another_run(seed: int) -> dict[str, np.ndarray]:
    """The record of another run on the same time grid: other sines, their own position."""
    t = _time()
    rng = np.random.default_rng(seed)
    force = sum(20 * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
                for f in (0.6, 2.3, 4.9))
    force = force + 0.05 * np.sqrt(np.mean(force ** 2)) * rng.standard_normal(N)
    return {"time": t, "force": force, "displacement": _run(force)}


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("kind", ["offset", "gain", "reversed", "white-15-percent",
                                  "white-3-rms", "coloured-1-rms-with-offset-and-gain",
                                  "drift-1.5-rms", "drift-minus-3-rms"])
def test_the_same_run_s_record_with_a_sensor_s_error_sets_the_state(tmp_path, capsys, kind,
                                                                    seed):
    """The reviewer's offset (20 % of the force's RMS), 12 % gain error and 15 % noise,
    and worse: exit 0, the state set from the position, the error the position's noise
    (the old 10 % RMS rule refused all of these as another run); a load cell's drift, a
    ramp of 1.5 or 3 times the force's RMS over the record, passes as the forces less their
    lines correlate (review A13b M1: main refused the ramp of 1.5 times the RMS against the
    force's own trend, the de-meaned forces correlated by 0.39)."""
    u = _input_force()
    y = _run(u) + POSITION_NOISE * np.random.default_rng(10 + seed).standard_normal(N)
    populate(tmp_path, {"axis.toml": AXIS, "force.csv": _table({"time": _time(), "force": u}),
                        "rec.csv": _table({"time": _time(), "force": _measured_force(kind, seed),
                                           "displacement": y})})
    code = main(["predict", str(tmp_path / "axis.toml"), str(tmp_path / "force.csv"), "--out",
                 str(tmp_path / "p.csv"), "--init-from", str(tmp_path / "rec.csv"), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    rmse = json.loads(out)["rmse"]
    assert rmse < 3 * POSITION_NOISE, rmse  # measured 1.1e-7 to 1.5e-7: the run's position


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_record_of_another_run_is_refused_in_one_line(tmp_path, seed):
    """Another run's record (other sines, 5 % load-cell noise) on INPUT's time grid: exit 2,
    one line naming the correlation, no file written (was exit 0, the state and the error
    taken from the other run's position)."""
    other = _another_run(seed)
    u = _input_force()
    assert abs(np.corrcoef(u, other["force"])[0, 1]) < 0.3  # the case is another run's
    rms = float(np.sqrt(np.mean(u ** 2)))
    if seed == 2:  # another run whose load cell drifts as well: still another run
        other["force"] = other["force"] + 2 * rms * np.linspace(-1.0, 1.0, N)
    populate(tmp_path, {"axis.toml": AXIS, "force.csv": _table({"time": _time(), "force": u}),
                        "other.csv": _table(other)})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["predict", "axis.toml", "force.csv", "--out", "p.csv",
                                    "--init-from", "other.csv"], tmp_path)
    assert "other.csv is not the run of force.csv: their forces vary independently" in line
    assert "less than 0.5 in magnitude" in line and "times their white noise" in line, line
    assert snapshot(tmp_path) == before


def test_a_record_with_a_non_finite_force_sample_is_judged_by_the_others(tmp_path, capsys):
    """One inf in the --init-from record's force (the force is not used): the same run,
    judged by its finite samples, predicted (not "another run by inf %")."""
    u = _input_force()
    rec = u.copy()
    rec[50] = np.inf
    populate(tmp_path, {"axis.toml": AXIS, "force.csv": _table({"time": _time(), "force": u}),
                        "rec.csv": _table({"time": _time(), "force": rec,
                                           "displacement": _run(u)})})
    code = main(["predict", str(tmp_path / "axis.toml"), str(tmp_path / "force.csv"), "--out",
                 str(tmp_path / "p.csv"), "--init-from", str(tmp_path / "rec.csv")])
    assert code == 0, capsys.readouterr().err


def test_mains_hum_larger_than_the_force_is_said_in_the_refusal(tmp_path, capsys):
    """The same run's record with 50 Hz mains hum of twice the force's RMS (review B12 M2):
    the forces correlate by 0.45, refused, and the line says what the help says, that hum
    above 1.7 times the force's RMS decorrelates one run's forces, and
    that its force column sets nothing (main: "a sensor's ... noise keeps one run's forces
    correlated"); the column low-passed at 20 Hz, the record passes and sets the state."""
    from scipy.signal import butter, filtfilt

    t, u = _time(), _input_force()
    rms = float(np.sqrt(np.mean(u ** 2)))
    hum = u + 2 * rms * np.sqrt(2) * np.sin(2 * np.pi * 50 * t)
    y = _run(u) + POSITION_NOISE * np.random.default_rng(3).standard_normal(N)
    populate(tmp_path, {"axis.toml": AXIS, "force.csv": _table({"time": t, "force": u}),
                        "hum.csv": _table({"time": t, "force": hum, "displacement": y}),
                        "low.csv": _table({"time": t, "displacement": y, "force": filtfilt(
                            *butter(4, 20.0 / (FS / 2)), hum)})})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["predict", "axis.toml", "force.csv", "--out", "p.csv",
                                    "--init-from", "hum.csv"], tmp_path)
    assert "correlate by 0.45, less than 0.5" in line, line
    assert line.endswith("(if it is this run's, noise other than white, low-frequency noise "
                         "above about the force's RMS or mains hum above 1.7 times it, "
                         "decorrelates them: filter its force column, which sets nothing)"), line
    assert snapshot(tmp_path) == before
    code = main(["predict", str(tmp_path / "axis.toml"), str(tmp_path / "force.csv"), "--out",
                 str(tmp_path / "p.csv"), "--init-from", str(tmp_path / "low.csv"), "--json"])
    out, err = capsys.readouterr()
    assert code == 0 and json.loads(out)["rmse"] < 3 * POSITION_NOISE, err


def test_the_help_says_which_noise_passes(capsys):
    with pytest.raises(SystemExit):
        main(["predict", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert ("a load cell's offset, drift, gain or white noise is not, nor other noise up to "
            "about the force's RMS (mains hum up to 1.7 times it); low-frequency noise larger "
            "than that may make the same run's force look another's") in text, text


def _noise(colour: str, seed: int) -> np.ndarray:
    """Unit-RMS noise on the records' grid: white, 50 Hz hum of a random phase, or white
    noise low-passed (second-order Butterworth) below ``lp<Hz>``."""
    from scipy.signal import butter, lfilter

    rng = np.random.default_rng(seed)
    if colour == "white":
        return rng.standard_normal(N)
    if colour == "hum":
        return np.sqrt(2) * np.sin(2 * np.pi * 50 * _time() + rng.uniform(0, 2 * np.pi))
    c = lfilter(*butter(2, float(colour[2:]) / (FS / 2)), rng.standard_normal(N))
    return c / np.std(c)


@pytest.mark.parametrize(("colour", "factor"), [
    ("white", 3.0), ("hum", 1.7), ("lp50", 1.0), ("lp20", 1.0), ("lp5", 1.0), ("lp1", 1.0),
    ("lp0.5", 1.0)])
def test_the_noise_the_help_lets_pass_passes_for_every_seed(colour, factor):
    """What the help claims, for 20 seeds each: the same run's force with noise of the factor
    of its RMS is taken for the same run.  The old claim, any noise below 1.7 times the RMS,
    failed for band-limited noise in half the seeds at 1.7 (in 1-6 of 20 at 1.5: the
    correlation of a few independent values scatters about 1 / sqrt(1 + 1.7^2) = 0.51)."""
    import argparse

    from motionhyst.cli._common import UsageError
    from motionhyst.cli.predict import _check_same_run

    u = _input_force()
    rms = float(np.sqrt(np.mean(u ** 2)))
    args = argparse.Namespace(init_from="rec.csv", data="force.csv")
    refused = []
    for seed in range(20):
        try:
            _check_same_run(args, u, u + factor * rms * _noise(colour, seed))
        except UsageError as exc:
            refused.append((seed, str(exc)[:120]))
    assert refused == [], refused
