"""Scenario files: the packaged Table I default, validation errors, tf controllers, FRD plants."""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from motionhyst.analysis.quasilinear import analyze
from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.core.lti import freqresp
from motionhyst.hysteresis import Jenkins
from motionhyst.plants.frf_fit import ModalPlant
from motionhyst.plants.measured import MeasuredPlant
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.scenario import (
    Scenario,
    ScenarioError,
    default_scenario,
    default_scenario_path,
    load_scenario,
)

REPO = Path(__file__).parents[1]
EXAMPLE = REPO / "examples" / "paper.toml"

# Table I of the paper
TABLE_I = {
    "stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7},
    "hysteresis": {"model": "jenkins", "k": 20.0, "fc": 0.05},
    "controller": {"type": "leadlag-lowpass", "K": 6.2e6, "f1": 60.0, "f2": 240.0,
                   "flp": 700.0, "beta": 0.6},
    "feedforward": {"type": "rigid-body"},
    "reference": {"amplitude": 0.01, "frequencies": [5.0, 10.0, 15.0]},
}


# ------------------------------------------------------------------ helpers
def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a valid TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, float):
        return repr(v)  # nan, inf and -inf are valid TOML floats
    return str(v)


def dump_toml(data: dict) -> str:
    """Minimal TOML writer for scenario dictionaries (scalars first, then sections)."""
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for name, section in data.items():
        if isinstance(section, dict):
            lines.append(f"[{name}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in section.items()]
    return "\n".join(lines) + "\n"


def paper_dict() -> dict:
    """A fresh copy of the packaged scenario as parsed TOML."""
    return tomllib.loads(default_scenario_path().read_text())


@pytest.fixture
def write(tmp_path: Path) -> Callable[..., Path]:
    def _write(data: dict | str, name: str = "scenario.toml") -> Path:
        path = tmp_path / name
        path.write_text(data if isinstance(data, str) else dump_toml(data))
        return path

    return _write


def assert_one_line(err: ScenarioError, path: Path | str, *fragments: str) -> str:
    msg = str(err)
    assert msg, "empty error message"
    assert "\n" not in msg and "\r" not in msg, msg
    assert str(path) in msg, msg
    for fragment in fragments:
        assert fragment in msg, (fragment, msg)
    return msg


def load_error(path: Path) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        Scenario.from_file(path)
    return info.value


def char_poly_roots(stage: TwoMassStage, num, den) -> np.ndarray:
    """Closed-loop poles of 1 + C P2, computed here independently of Loop."""
    n2, d2 = stage.P2.num[0][0], stage.P2.den[0][0]
    return np.roots(np.polyadd(np.polymul(d2, den), np.polymul(n2, num)))


def leadlag_coefficients() -> tuple[list[float], list[float]]:
    c = LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6)
    return [float(x) for x in c.num[0][0]], [float(x) for x in c.den[0][0]]


# ------------------------------------------------------------ the default
def test_default_scenario_has_table_i_values():
    sc = default_scenario()
    assert sc.to_dict() == TABLE_I
    assert sc.amplitude == 0.01
    assert sc.frequencies == [5.0, 10.0, 15.0]


def test_default_scenario_builds_table_i_objects():
    sc = default_scenario()
    stage = sc.plant()
    assert isinstance(stage, TwoMassStage)
    assert (stage.m1, stage.m2, stage.b, stage.k) == (5.0, 17.5, 90.0, 7.4e7)
    assert stage.M == 22.5
    link = sc.hysteresis()
    assert isinstance(link, Jenkins)
    assert (link.k, link.fc) == (20.0, 0.05)
    c = sc.controller()
    assert isinstance(c, LeadLagLowpass)
    assert (c.K, c.f1, c.f2, c.flp, c.beta) == (6.2e6, 60.0, 240.0, 700.0, 0.6)
    loop = sc.loop()
    assert loop is sc.loop()  # built once
    assert loop.feedforward == "rigid-body"
    assert loop.M == 22.5


def test_default_loop_is_stable():
    sc = default_scenario()
    loop = sc.loop()
    loop.check_stable()
    poles = loop.closed_loop_poles()
    assert poles.size == 7  # 4 stage poles + 3 controller poles
    assert np.all(poles.real < 0)
    num, den = leadlag_coefficients()
    independent = char_poly_roots(sc.plant(), num, den)
    assert np.max(independent.real) < 0
    np.testing.assert_allclose(np.sort_complex(independent), np.sort_complex(poles), rtol=1e-6)


def test_default_scenario_analysis_numbers():
    sc = default_scenario()
    res = analyze(sc.loop(), sc.amplitude, sc.frequencies)
    assert res.zeta == pytest.approx(0.25)
    assert abs(res.D) / res.k_link == pytest.approx(0.309, abs=5e-4)
    assert math.degrees(np.angle(res.D)) == pytest.approx(50.7, abs=0.05)
    assert res.f_star_hz == pytest.approx(0.150, abs=5e-4)
    assert res.mismatch_crossover_hz == pytest.approx(7.6, abs=0.05)
    assert res.bandwidth_hz == pytest.approx(120.6, abs=0.1)
    assert [p.frequency_hz for p in res.points] == [5.0, 10.0, 15.0]


def test_example_file_is_identical_to_packaged_default():
    assert EXAMPLE.is_file()
    assert EXAMPLE.read_bytes() == default_scenario_path().read_bytes()


def test_default_scenario_path_is_the_packaged_file():
    path = default_scenario_path()
    assert path.name == "paper.toml"
    assert path.parent.name == "data"
    assert path.is_file()


def test_load_scenario_none_is_default_and_path_loads_file():
    assert load_scenario(None).to_dict() == TABLE_I
    sc = load_scenario(EXAMPLE)
    assert sc.to_dict() == TABLE_I
    assert sc.source == str(EXAMPLE)
    assert "Table I" in default_scenario().source


def test_to_dict_round_trips_through_from_dict():
    sc = default_scenario()
    again = Scenario.from_dict(sc.to_dict())
    assert again.to_dict() == sc.to_dict()


def test_toml_writer_round_trips_the_paper_file(write):
    path = write(paper_dict())
    assert Scenario.from_file(path).to_dict() == TABLE_I


def test_integers_accepted_where_floats_expected(write):
    d = paper_dict()
    d["stage"]["m1"] = 5
    d["stage"]["b"] = 90
    d["hysteresis"]["k"] = 20
    d["controller"]["f1"] = 60
    d["reference"]["frequencies"] = [5, 10, 15]
    path = write(d)
    assert "m1 = 5\n" in path.read_text()
    sc = Scenario.from_file(path)
    assert sc.to_dict() == TABLE_I
    m1 = sc.model.stage.m1
    assert m1 == 5.0 and isinstance(m1, float)
    assert all(isinstance(f, float) for f in sc.frequencies)
    assert sc.plant().m1 == 5.0


def test_feedforward_section_is_optional_and_none_accepted(write):
    d = paper_dict()
    del d["feedforward"]
    assert Scenario.from_file(write(d, "a.toml")).loop().feedforward == "rigid-body"
    d["feedforward"] = {"type": "none"}
    assert Scenario.from_file(write(d, "b.toml")).loop().feedforward is None


# ------------------------------------------------------------ error paths
def test_toml_syntax_error(write):
    text = default_scenario_path().read_text().replace("m1 = 5.0", "m1 = = 5.0")
    path = write(text)
    msg = assert_one_line(load_error(path), path, "TOML")
    assert "line" in msg


def test_missing_file(tmp_path):
    path = tmp_path / "no" / "such.toml"
    err = load_error(path)
    assert_one_line(err, path, "cannot read")


def test_scenario_error_is_a_value_error():
    assert issubclass(ScenarioError, ValueError)


def _set(section: str, key: str, value) -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        d[section][key] = value

    return edit


def _drop(section: str, key: str | None = None) -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        if key is None:
            del d[section]
        else:
            del d[section][key]

    return edit


def _put(section: str, value) -> Callable[[dict], None]:
    def edit(d: dict) -> None:
        d[section] = value

    return edit


ERROR_CASES = [
    # unknown keys and sections
    pytest.param(_set("stage", "mass", 3.0), ("[stage]", "mass", "unknown key"),
                 id="unknown-key-stage"),
    pytest.param(_set("controller", "Ki", 1.0), ("[controller]", "Ki", "unknown key"),
                 id="unknown-key-controller"),
    pytest.param(_set("reference", "phase", 0.0), ("[reference]", "phase", "unknown key"),
                 id="unknown-key-reference"),
    pytest.param(_put("extra", {"x": 1.0}), ("[extra]", "unknown section"),
                 id="unknown-section"),
    # wrong types
    pytest.param(_set("stage", "m1", "5"), ("[stage]", "m1"), id="string-m1"),
    pytest.param(_set("controller", "K", "6.2e6"), ("[controller]", "K"), id="string-K"),
    pytest.param(_set("reference", "amplitude", "0.01"), ("[reference]", "amplitude"),
                 id="string-amplitude"),
    pytest.param(_set("reference", "frequencies", ["5"]), ("[reference]", "frequencies"),
                 id="string-in-frequencies"),
    pytest.param(_set("stage", "b", "90"), ("[stage]", "b", "'90'"), id="string-b"),
    pytest.param(_set("hysteresis", "model", 3.0), ("[hysteresis]", "model"),
                 id="number-for-string"),
    pytest.param(_set("stage", "m1", [5.0]), ("[stage]", "m1"), id="list-for-number"),
    pytest.param(_put("stage", 3.0), ("[stage]",), id="scalar-for-section"),
    pytest.param(_set("stage", "m1", True), ("[stage]", "m1", "boolean"), id="bool-m1"),
    pytest.param(_set("stage", "b", False), ("[stage]", "b", "boolean"), id="bool-b"),
    pytest.param(_set("reference", "amplitude", True), ("[reference]", "amplitude", "boolean"),
                 id="bool-amplitude"),
    pytest.param(_set("reference", "frequencies", [True, 10.0]),
                 ("[reference]", "frequencies"), id="bool-in-frequencies"),
    # non-positive values
    pytest.param(_set("stage", "m1", 0.0), ("[stage]", "m1", "0"), id="zero-m1"),
    pytest.param(_set("stage", "m2", -17.5), ("[stage]", "m2", "-17.5"), id="negative-m2"),
    pytest.param(_set("stage", "k", 0.0), ("[stage]", "k"), id="zero-stiffness"),
    pytest.param(_set("stage", "b", -1.0), ("[stage]", "b"), id="negative-damping"),
    pytest.param(_set("hysteresis", "k", -20.0), ("[hysteresis]", "k"), id="negative-link-k"),
    pytest.param(_set("hysteresis", "fc", 0.0), ("[hysteresis]", "fc"), id="zero-force"),
    pytest.param(_set("controller", "K", 0.0), ("[controller]", "K"), id="zero-gain"),
    pytest.param(_set("controller", "beta", -0.6), ("[controller]", "beta"), id="negative-beta"),
    pytest.param(_set("reference", "amplitude", 0.0), ("[reference]", "amplitude"),
                 id="zero-amplitude"),
    pytest.param(_set("reference", "frequencies", [5.0, -1.0]),
                 ("[reference]", "frequencies[1]"), id="negative-frequency"),
    pytest.param(_set("reference", "frequencies", []), ("[reference]", "frequencies"),
                 id="no-frequencies"),
    # NaN and infinity
    pytest.param(_set("stage", "m1", math.nan), ("[stage]", "m1", "finite"), id="nan-m1"),
    pytest.param(_set("stage", "k", math.inf), ("[stage]", "k", "finite"), id="inf-stiffness"),
    pytest.param(_set("stage", "b", math.nan), ("[stage]", "b"), id="nan-damping"),
    pytest.param(_set("stage", "b", math.inf), ("[stage]", "b"), id="inf-damping"),
    pytest.param(_set("hysteresis", "fc", math.inf), ("[hysteresis]", "fc"), id="inf-force"),
    pytest.param(_set("controller", "K", math.inf), ("[controller]", "K"), id="inf-gain"),
    pytest.param(_set("controller", "f1", -math.inf), ("[controller]", "f1"), id="minus-inf-f1"),
    pytest.param(_set("reference", "amplitude", math.nan), ("[reference]", "amplitude"),
                 id="nan-amplitude"),
    pytest.param(_set("reference", "frequencies", [5.0, math.inf]),
                 ("[reference]", "frequencies[1]"), id="inf-frequency"),
    # missing keys and sections
    pytest.param(_drop("stage", "m1"), ("[stage]", "m1", "missing"), id="missing-m1"),
    pytest.param(_drop("hysteresis", "fc"), ("[hysteresis]", "fc", "missing"), id="missing-fc"),
    pytest.param(_drop("controller", "flp"), ("[controller]", "flp", "missing"),
                 id="missing-flp"),
    pytest.param(_drop("reference", "amplitude"), ("[reference]", "amplitude", "missing"),
                 id="missing-amplitude"),
    pytest.param(_drop("hysteresis"), ("[hysteresis]", "missing"), id="missing-hysteresis"),
    pytest.param(_drop("reference"), ("[reference]", "missing"), id="missing-reference"),
    pytest.param(_drop("controller", "type"), ("[controller]", "type"),
                 id="missing-controller-type"),
    # unknown models and types
    pytest.param(_set("hysteresis", "model", "preisach"), ("[hysteresis]", "model", "preisach"),
                 id="unknown-hysteresis-model"),
    pytest.param(_set("controller", "type", "lqr"), ("[controller]", "type", "lqr"),
                 id="unknown-controller-type"),
    pytest.param(_set("feedforward", "type", "magic"), ("[feedforward]", "type", "magic"),
                 id="unknown-feedforward"),
    # stage and plant
    pytest.param(_drop("stage"), ("[stage]", "[plant]"), id="neither-stage-nor-plant"),
    pytest.param(_put("plant", {"type": "frd", "file": "p.csv"}), ("[stage]", "[plant]"),
                 id="both-stage-and-plant"),
    pytest.param(_put("plant", {"type": "bode", "file": "p.csv"}), ("[plant]", "type"),
                 id="unknown-plant-type"),
    # tf controllers
    pytest.param(_put("controller", {"type": "tf", "num": [1.0, 2.0, 3.0], "den": [1.0, 1.0]}),
                 ("[controller]", "proper"), id="improper-tf"),
    pytest.param(_put("controller", {"type": "tf", "num": [0.0], "den": [1.0]}),
                 ("[controller]", "num"), id="zero-numerator"),
    pytest.param(_put("controller", {"type": "tf", "num": [1.0], "den": [0.0, 0.0]}),
                 ("[controller]", "den"), id="zero-denominator"),
    pytest.param(_put("controller", {"type": "tf", "num": [1.0], "den": []}),
                 ("[controller]", "den"), id="empty-denominator"),
    pytest.param(_put("controller", {"type": "tf", "num": [1.0]}),
                 ("[controller]", "den", "missing"), id="missing-denominator"),
    pytest.param(_put("controller", {"type": "tf", "num": [math.nan], "den": [1.0]}),
                 ("[controller]", "num[0]"), id="nan-in-numerator"),
    pytest.param(_put("controller", {"type": "tf", "num": ["1"], "den": [1.0]}),
                 ("[controller]", "num[0]"), id="string-in-numerator"),
    pytest.param(_put("controller", {"type": "tf", "num": [True], "den": [1.0]}),
                 ("[controller]", "num[0]"), id="bool-in-numerator"),
    pytest.param(_put("controller", {"type": "tf", "num": [1.0], "den": [1.0], "K": 1.0}),
                 ("[controller]", "K", "unknown key"), id="leadlag-key-in-tf"),
    pytest.param(_put("controller", {"type": "tf", "num": [-1.0], "den": [1.0]}),
                 ("[controller]", "stabilise"), id="unstable-negative-gain"),
]


@pytest.mark.parametrize(("edit", "fragments"), ERROR_CASES)
def test_invalid_scenario_gives_one_line_error(write, edit, fragments):
    d = paper_dict()
    edit(d)
    path = write(d)
    assert_one_line(load_error(path), path, *fragments)


@pytest.mark.parametrize(("edit", "fragments"), ERROR_CASES)
def test_invalid_dict_names_its_source(edit, fragments):
    d = paper_dict()
    edit(d)
    with pytest.raises(ScenarioError) as info:
        Scenario.from_dict(d, source="from-a-dict")
    assert_one_line(info.value, "from-a-dict", *fragments)


def test_unchecked_scenario_gives_the_same_error_at_its_loop(write):
    # check=False (reproduce draws the link's figures meanwhile): the loop's error at loop()
    d = paper_dict()
    d["controller"]["K"] = 6.2e9  # 1000 x Table I: unstable
    path = write(d)
    sc = Scenario.from_file(path, check=False)
    assert sc.hysteresis().k == 20.0
    with pytest.raises(ScenarioError) as info:
        sc.loop()
    assert str(info.value) == str(load_error(path))
    assert_one_line(info.value, path, "[controller]", "stabilise")


def test_tf_with_negative_gain_is_unstable_independently():
    roots = char_poly_roots(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), [-1.0], [1.0])
    assert np.max(roots.real) > 0


def test_leadlag_with_too_much_gain_is_rejected(write):
    num, den = leadlag_coefficients()
    K = 6.2e9  # 1000 x Table I
    roots = char_poly_roots(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), np.multiply(num, 1000.0), den)
    assert np.max(roots.real) > 0  # checked here, independently of the package
    d = paper_dict()
    d["controller"]["K"] = K
    path = write(d)
    msg = assert_one_line(load_error(path), path, "[controller]", "stabilise")
    assert "pole" in msg


def _tf_with_leading_zeros(d: dict) -> None:
    num, den = leadlag_coefficients()
    d["controller"] = {"type": "tf", "num": [0, 0.0, *num], "den": [0.0, *den]}


@pytest.mark.parametrize("edit", [
    pytest.param(lambda d: None, id="table-i"),
    pytest.param(lambda d: d["stage"].update(c1=30.0, c2=50.0), id="grounded"),
    pytest.param(_tf_with_leading_zeros, id="tf-leading-zeros"),
    pytest.param(lambda d: d.update(hysteresis={"model": "maxwell-slip", "k": [10.0, 6.0],
                                                "fc": [0.01, 0.03]}), id="maxwell-slip"),
    pytest.param(lambda d: d.update(stage={"type": "mass-spring-damper", "m": 22.5,
                                           "c": 100.0, "k": 1e4}), id="mass-spring-damper"),
    pytest.param(lambda d: d["controller"].update(flp=1e12), id="unstable-lowpass"),
    pytest.param(lambda d: d["controller"].update(K=6.2e9), id="unstable-gain"),
    pytest.param(lambda d: d["hysteresis"].update(k=2.2e8), id="unstable-stuck"),
])
def test_the_loop_is_checked_from_its_coefficients_as_the_loop_checks_itself(edit, request):
    """Before python-control builds the loop, the scenario's coefficients give its poles
    and its stability: the same numbers and the same refusal as the loop's own."""
    from motionhyst.controllers.loop import Loop

    d = paper_dict()
    edit(d)
    sc = Scenario.from_dict(d, check=False)
    loop = Loop(sc.plant(), sc.controller(), sc.hysteresis())
    try:
        loop.check_stable()
    except ValueError as exc:
        assert request.node.callspec.id.startswith("unstable")
        with pytest.raises(ScenarioError) as info:
            sc.fastest_pole()
        assert str(info.value) == f"<dict>: [controller]: {exc}"
    else:
        assert not request.node.callspec.id.startswith("unstable")
        assert sc.fastest_pole() == float(np.max(np.abs(loop.closed_loop_poles())))


@pytest.mark.parametrize("layout", ["one-line", "with-comment", "dict"])
def test_a_list_longer_than_a_scenario_holds_is_refused_naming_it(write, monkeypatch, layout):
    """Counted in the text before it is parsed (one line, or a trailing comma) or once
    parsed (an array with a comment, a dictionary): the same one line."""
    from motionhyst.scenario import schema

    monkeypatch.setattr(schema, "MAX_VALUES", 10)
    d = paper_dict()
    d["hysteresis"] = {"model": "maxwell-slip", "k": [1.0] * 10, "fc": [0.01] * 10}
    assert Scenario.from_file(write(d)).hysteresis().k.size == 10  # at the limit: read
    d["hysteresis"]["fc"] = [0.01] * 11
    if layout == "dict":
        with pytest.raises(ScenarioError) as info:
            Scenario.from_dict(d, source="from-a-dict")
        assert_one_line(info.value, "from-a-dict", "[hysteresis] fc: 11 values, more than the "
                        "10 a list of a scenario may hold")
        return
    text = dump_toml(d)
    long = "fc = [" + ", ".join(["0.01"] * 11) + "]"
    assert long in text
    text = text.replace(long, long[:-1] + (",\n  # the last\n]" if layout == "with-comment"
                                           else ",]"))
    path = write(text)
    if layout == "one-line":  # refused before the text is parsed
        import tomllib

        monkeypatch.setattr(tomllib, "loads", lambda text: pytest.fail("parsed"))
    assert_one_line(load_error(path), path, "[hysteresis] fc: 11 values, more than the 10")


def test_a_sampled_controller_or_a_measured_plant_has_its_poles_from_the_loop(tmp_path):
    d = paper_dict()
    d["controller"]["sample_rate_hz"] = 20e3
    assert Scenario.from_dict(d).fastest_pole() is None
    write_frd_csv(tmp_path / "plant.csv", np.geomspace(10.0, 3000.0, 200))
    d = paper_dict()
    d.pop("stage")
    d["plant"] = {"file": "plant.csv"}
    assert Scenario.from_dict(d, base_dir=tmp_path).fastest_pole() is None


def test_tf_controller_accepts_leading_zeros_and_integers(write):
    num, den = leadlag_coefficients()
    d = paper_dict()
    d["controller"] = {"type": "tf", "num": [0.0, 0.0, *num], "den": den}
    sc = Scenario.from_file(write(d))
    assert sc.model.controller.type == "tf"
    d["controller"] = {"type": "tf", "num": [int(x) for x in num], "den": den}
    Scenario.from_file(write(d, "ints.toml")).loop().check_stable()


def test_tf_controller_equal_to_leadlag_gives_same_analysis(write):
    num, den = leadlag_coefficients()
    d = paper_dict()
    d["controller"] = {"type": "tf", "num": num, "den": den}
    sc_tf = Scenario.from_file(write(d))
    sc_ll = default_scenario()
    w = 2 * np.pi * np.array([1.0, 10.0, 100.0, 1000.0])
    np.testing.assert_allclose(freqresp(sc_tf.controller(), w), freqresp(sc_ll.controller(), w),
                               rtol=1e-12)
    a = analyze(sc_tf.loop(), sc_tf.amplitude, sc_tf.frequencies).to_dict()
    b = analyze(sc_ll.loop(), sc_ll.amplitude, sc_ll.frequencies).to_dict()
    assert a.keys() == b.keys()
    for key in ("zeta", "df_re", "df_im", "df_abs_over_k", "df_phase_deg", "f_star_hz",
                "bandwidth_hz", "mismatch_crossover_hz", "mismatch_crossover_exact_hz"):
        assert a[key] == pytest.approx(b[key], rel=1e-9), key
    assert len(a["mismatch"]) == len(b["mismatch"]) == 3
    for pa, pb in zip(a["mismatch"], b["mismatch"], strict=True):
        for key in ("frequency_hz", "abs", "phase_deg", "asymptote_abs"):
            assert pa[key] == pytest.approx(pb[key], rel=1e-9), key


# ------------------------------------------------------------ measured plants
STAGE = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)


def write_frd_csv(path: Path, f_hz: np.ndarray) -> Path:
    w = 2 * np.pi * np.asarray(f_hz, dtype=float)
    p1, p2 = freqresp(STAGE.P1, w), freqresp(STAGE.P2, w)
    lines = ["frequency_hz,p1_re,p1_im,p2_re,p2_im"]
    lines += [",".join(repr(float(x)) for x in (f, a.real, a.imag, b.real, b.imag))
              for f, a, b in zip(f_hz, p1, p2, strict=True)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return path


def frd_scenario(tmp_path: Path, f_hz: np.ndarray, mass: float | None = None,
                 use: str | None = "data") -> Path:
    """A scenario in tmp_path/case whose [plant] CSV is in a subfolder, given relatively."""
    folder = tmp_path / "case"
    write_frd_csv(folder / "data" / "stage.csv", f_hz)
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"type": "frd", "file": "data/stage.csv"}
    if use is not None:
        d["plant"]["use"] = use
    if mass is not None:
        d["plant"]["mass"] = mass
    path = folder / "frd.toml"
    path.write_text(dump_toml(d))
    return path


@pytest.fixture(scope="module")
def two_mass_analysis():
    sc = default_scenario()
    return analyze(sc.loop(), sc.amplitude, sc.frequencies)


LOG_GRID = np.geomspace(0.05, 5000.0, 400)


def test_frd_plant_loads_relative_to_toml_folder(tmp_path, monkeypatch, two_mass_analysis):
    path = frd_scenario(tmp_path, LOG_GRID)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    sc = Scenario.from_file(path)
    plant = sc.plant()
    assert isinstance(plant, MeasuredPlant)
    assert plant.M == pytest.approx(22.5, rel=1e-6)  # estimated from the lowest decade
    lo, hi = plant.frequency_range_hz
    assert lo == pytest.approx(0.05) and hi == pytest.approx(5000.0)
    res = analyze(sc.loop(), sc.amplitude, sc.frequencies)
    assert res.zeta == pytest.approx(0.25)
    assert res.f_star_hz == pytest.approx(two_mass_analysis.f_star_hz, rel=1e-6)
    # raw data are evaluated at the measured lines only: the crossings are interpolated
    # (log-linearly) between two lines 3 % apart
    assert res.bandwidth_hz == pytest.approx(two_mass_analysis.bandwidth_hz, rel=1e-4)
    assert res.mismatch_crossover_exact_hz == pytest.approx(
        two_mass_analysis.mismatch_crossover_exact_hz, rel=1e-3)
    assert math.isnan(res.mismatch_crossover_hz)  # eq. (21) needs a model
    # 5, 10 and 15 Hz are not measured lines: not evaluated, and said so
    for p in res.points:
        assert math.isnan(p.value.real) and math.isnan(p.asymptote.real)
        assert any(u.startswith(f"E and E~ at {p.frequency_hz:g} Hz: not a measured")
                   for u in res.unresolved)
    assert any(u.startswith("eq. (21)") for u in res.unresolved)


def test_frd_plant_exact_at_measured_frequencies(tmp_path, two_mass_analysis):
    grid = np.union1d(LOG_GRID, [5.0, 10.0, 15.0])
    sc = Scenario.from_file(frd_scenario(tmp_path, grid, mass=22.5))
    assert sc.plant().M == 22.5
    res = analyze(sc.loop(), sc.amplitude, sc.frequencies)
    for p, q in zip(res.points, two_mass_analysis.points, strict=True):
        assert abs(p.value - q.value) <= 1e-9 * abs(q.value), p.frequency_hz
        assert abs(p.asymptote - q.asymptote) <= 1e-6 * abs(q.asymptote), p.frequency_hz


def test_frd_plant_absolute_path(tmp_path):
    csv_path = write_frd_csv(tmp_path / "abs" / "stage.csv", LOG_GRID)
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"file": str(csv_path), "mass": 22.5, "use": "data"}  # type defaults to "frd"
    path = tmp_path / "other" / "s.toml"
    path.parent.mkdir()
    path.write_text(dump_toml(d))
    assert isinstance(Scenario.from_file(path).plant(), MeasuredPlant)


def test_frd_plant_is_fitted_by_default(tmp_path, two_mass_analysis):
    """Without ``use``, the measured plant is fitted and every number comes from the model."""
    sc = Scenario.from_file(frd_scenario(tmp_path, np.geomspace(1.0, 3000.0, 60), use=None))
    plant = sc.plant()
    assert isinstance(plant, ModalPlant) and sc.plant_fit().plant is plant
    assert len(plant.modes) == 1
    assert plant.modes[0].frequency_hz == pytest.approx(STAGE.resonance_hz, rel=1e-9)
    res = analyze(sc.loop(), sc.amplitude, sc.frequencies)
    assert res.mismatch_crossover_hz == pytest.approx(
        two_mass_analysis.mismatch_crossover_hz, rel=1e-8)
    for p, q in zip(res.points, two_mass_analysis.points, strict=True):
        assert abs(p.value - q.value) <= 1e-7 * abs(q.value), p.frequency_hz


def test_frd_plant_modes_given(tmp_path):
    path = frd_scenario(tmp_path, np.geomspace(1.0, 3000.0, 60), use="fit")
    text = path.read_text().replace('use = "fit"', 'use = "fit"\nmodes = 2')
    path.write_text(text)
    sc = Scenario.from_file(path)
    assert len(sc.plant().modes) == 2 and sc.plant_fit().criterion == "modes given"


@pytest.mark.parametrize(("plant", "fragment"), [
    ({"use": "model"}, "use"),
    ({"use": "data", "modes": 1}, "modes applies to use"),
    ({"modes": -1}, "modes"),
    ({"modes": 1.5}, "modes"),
    ({"modes": True}, "modes"),
    ({"modes": 21}, "modes"),
    ({"delay": -1e-6}, "delay"),
    ({"use": "data", "delay": 5e-5}, "delay applies to use"),
])
def test_bad_plant_fit_options(tmp_path, plant, fragment):
    write_frd_csv(tmp_path / "p.csv", np.geomspace(1.0, 3000.0, 60))
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"file": "p.csv", **plant}
    path = tmp_path / "s.toml"
    path.write_text(dump_toml(d))
    assert_one_line(load_error(path), path, "[plant]", fragment)


def test_frd_plant_that_cannot_be_fitted_gives_one_line_error(tmp_path):
    # 2 lines (8 real values) cannot determine a mass and a mode (5 parameters)
    write_frd_csv(tmp_path / "p.csv", [1.0, 2.0])
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"file": "p.csv", "modes": 1}
    path = tmp_path / "s.toml"
    path.write_text(dump_toml(d))
    assert_one_line(load_error(path), path, "[plant] file", "cannot determine 1 modes")


_HEADER = "frequency_hz,p1_re,p1_im,p2_re,p2_im\n"

BAD_CSVS = [
    pytest.param(_HEADER + "1.0,1e-3,0,1e-3,0\n2.0,x,0,1e-3,0\n", "non-numeric", id="non-numeric"),
    pytest.param("frequency_hz,p1_re,p1_im\n1.0,1,0\n2.0,1,0\n", "columns", id="missing-columns"),
    pytest.param("f,p1_re,p1_im,p2_re,p2_im\n1.0,1,0,1,0\n2.0,1,0,1,0\n", "frequency_hz",
                 id="no-frequency-column"),
    pytest.param(_HEADER, "no data", id="header-only"),
    pytest.param("", "no data", id="empty"),
    pytest.param(_HEADER + "2.0,-1e-3,0,-1e-3,0\n1.0,-1e-3,0,-1e-3,0\n", "increasing",
                 id="decreasing-frequency"),
    pytest.param(_HEADER + "0.0,-1e-3,0,-1e-3,0\n1.0,-1e-3,0,-1e-3,0\n", "positive",
                 id="zero-frequency"),
    pytest.param(_HEADER + "1.0,-1e-3,0,-1e-3,0\n2.0,inf,0,-1e-3,0\n", "finite", id="inf-value"),
    pytest.param(_HEADER + "1.0,-1e-3,0,-1e-3,0\n", "two", id="one-row"),
    pytest.param(_HEADER + "1.0,1e-3,0,1e-3,0\n2.0,1e-3,0,1e-3,0\n", "mass",
                 id="mass-not-estimable"),
]


@pytest.mark.parametrize(("csv_text", "fragment"), BAD_CSVS)
def test_bad_csv_gives_one_line_error(tmp_path, csv_text, fragment):
    (tmp_path / "bad.csv").write_text(csv_text)
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"type": "frd", "file": "bad.csv"}
    path = tmp_path / "s.toml"
    path.write_text(dump_toml(d))
    assert_one_line(load_error(path), path, "[plant] file", "bad.csv", fragment)


def test_missing_csv_gives_one_line_error(tmp_path):
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"type": "frd", "file": "nowhere.csv"}
    path = tmp_path / "s.toml"
    path.write_text(dump_toml(d))
    assert_one_line(load_error(path), path, "[plant] file", "nowhere.csv", "cannot read")


@pytest.mark.parametrize("mass", [0.0, -22.5, math.nan, math.inf])
def test_bad_plant_mass(tmp_path, mass):
    d = paper_dict()
    del d["stage"]
    d["plant"] = {"type": "frd", "file": "whatever.csv", "mass": mass}
    path = tmp_path / "s.toml"
    path.write_text(dump_toml(d))
    assert_one_line(load_error(path), path, "[plant]", "mass")


@pytest.mark.parametrize("values", [
    [20.0] * 1000 + [1e-300] + [1e40],      # the first outside is named
    [3] * 10 + [10**31] + [1.0],            # integers
    [1.0, True, 1e-300],                     # a boolean: not a number of the scale
    [1.0, 1e-300, 10**400],                  # an integer beyond a float, after one outside
    [0.0, -1e30, float("inf"), float("nan"), -1e-30] * 3,  # 0, the bounds, non-finite: allowed
])
def test_a_list_s_magnitudes_are_checked_as_each_number_is(values):
    """A scenario's list (up to 100 000 values) is checked at once, with the answer of checking
    each number in turn (:func:`~motionhyst.core.validation.check_magnitude`)."""
    from motionhyst.core.validation import check_magnitude, check_magnitudes

    def each():
        for i, v in enumerate(values):
            if isinstance(v, int | float) and not isinstance(v, bool):
                check_magnitude(f"[hysteresis] k[{i}]", v)

    expected = got = None
    try:
        each()
    except (ValueError, OverflowError) as exc:
        expected = (type(exc), str(exc))
    try:
        check_magnitudes({"hysteresis": {"k": values}})
    except (ValueError, OverflowError) as exc:
        got = (type(exc), str(exc))
    assert got == expected
    assert expected is not None or values[0] == 0.0
