"""The optimiser's tether line (CycleProblem.line) and the plant the physical scenario models by
default: the sized line, the glider's own drive and the line's weight. Table 1's line with the
earlier plant options is one option away and builds the very problem the earlier published
physical numbers came from. No solve: the problems, their NLP keys, the winch electrics, the
models' right-hand sides and the reference metadata are compared directly."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.groundstation import load_ground_station
from fdm_awe.groundstation.line import LINES
from fdm_awe.ocp.energy import WinchElectrics
from fdm_awe.ocp.model import CycleModel
from fdm_awe.ocp.problem import LEGACY_PHYSICAL_PLANT, PLANT_DEFAULTS, CycleProblem, Mesh, Scenario
from fdm_awe.ocp.result import CycleResult
from fdm_awe.trajectory import COLUMN_UNITS, read_reference, write_reference
from fdm_awe.ocp.build import structure_key

DATA = Path(__file__).parent / "data"
COARSE = Mesh(6, 4, 3)


def test_each_scenario_has_its_plant_by_default():
    phys = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0).validate()
    assert (phys.line, phys.propeller, phys.line_weight) == ("sized", "engine", True)
    assert phys.scenario_spec.propeller == "engine"
    paper = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0).validate()
    assert (paper.line, paper.propeller, paper.line_weight) == ("paper", None, False)
    assert paper.scenario_spec == Scenario.named("paper")
    # explicit values equal to the defaults make the same problem (and the same NLP)
    assert CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, **PLANT_DEFAULTS["physical"]) == phys
    assert CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, **PLANT_DEFAULTS["paper"]) == paper


def test_the_earlier_physical_plant_is_one_option_set_away():
    """--line paper --propeller momentum --no-line-weight: Table 1's line, momentum theory, a
    massless line -- the model of the earlier published physical numbers (e.g. the nominal
    cycle at 8 m/s). Its model evaluates exactly as one built by hand from those parts."""
    legacy = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE,
                          **LEGACY_PHYSICAL_PLANT).validate()
    assert legacy.scenario_spec == Scenario.named("physical")  # momentum theory, as before the choice
    assert (legacy.line, legacy.line_weight) == ("paper", False)
    default = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE).validate()
    assert structure_key(legacy) != structure_key(default)
    # the winch electrics of the legacy problem are those of Table 1's line
    paper_gs = load_ground_station(line="paper")
    winch = WinchElectrics.from_ground_station(line=legacy.line)
    assert winch == WinchElectrics.from_ground_station(paper_gs)
    assert winch.tether_diameter == pytest.approx(0.72e-3, rel=1e-12)
    glider = load_glider()
    m_legacy = CycleModel.build(legacy, glider, winch)
    assert m_legacy.scenario.propeller == "physical" and m_legacy.drive is None and not m_legacy.line_weight
    m_default = CycleModel.build(default, glider, WinchElectrics.from_ground_station(line=default.line))
    assert m_default.scenario.propeller == "engine" and m_default.drive is not None and m_default.line_weight
    assert m_default.winch.tether_diameter < 0.5e-3


def test_the_line_sets_line_drag_and_weight_of_the_model():
    glider = load_glider()
    s, u, w = [150.0, 20.0, -120.0, 14.0, 0.1, 2.5], [0.1, 0.3, 2.0], (8.0, 0.0)
    out = {}
    for line in LINES:  # momentum theory: the controls are (alpha, phi, T) in generation
        pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, line=line, propeller="momentum",
                          mesh=COARSE).validate()
        winch = WinchElectrics.from_ground_station(line=pr.line)
        t = load_ground_station(line=line).tether
        assert winch.tether_diameter == t.diameter
        assert winch.line_weight_per_length == pytest.approx(t.weight_share * t.mass_per_length * t.gravity, rel=1e-15)
        out[line] = CycleModel.build(pr, glider, winch).generation(s, u, w)
    # same state and controls: the thinner, lighter sized line decelerates the glider less
    assert float(out["sized"]["f"][3]) > float(out["paper"]["f"][3])


def test_the_line_is_part_of_the_nlp_key():
    keys = {structure_key(CycleProblem(line=line, mesh=COARSE).validate()) for line in LINES}
    assert len(keys) == len(LINES)


@pytest.mark.parametrize("kw, words", [
    ({"line": "thin"}, ("line 'thin' unknown", "sized, paper")),
    ({"line": 3}, ("line 3 unknown",)),
    ({"line_weight": "yes"}, ("line_weight 'yes' invalid", "true or false")),
    ({"scenario": "paper", "line_weight": True}, ("line_weight", "only the physical scenario")),
])
def test_bad_plant_choices_are_one_line_errors(kw, words):
    with pytest.raises(InputError) as ei:
        CycleProblem(**kw).validate()
    msg = str(ei.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_the_paper_scenario_takes_any_line():
    """Selectable everywhere: the paper scenario's line has no drag or weight in the optimiser,
    but it is the line its reference is flown on."""
    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, line="sized").validate()
    assert pr.line == "sized" and structure_key(pr) != structure_key(replace(pr, line="paper"))


def test_winch_electrics_take_a_line_or_parameters_not_both():
    gs = load_ground_station(line="paper")
    with pytest.raises(ValueError, match="not both"):
        WinchElectrics.from_ground_station(gs, line="sized")
    with pytest.raises(InputError, match="line 'x' unknown"):
        WinchElectrics.from_ground_station(line="x")
    # the default is the definition's default line
    assert WinchElectrics.from_ground_station() == WinchElectrics.from_ground_station(line="sized")


# ------------------------------------------------------------------ reference metadata


def _result(problem: CycleProblem) -> CycleResult:
    """An ok result of ``problem`` carrying a stored reference's columns (no solve)."""
    ref = read_reference(DATA / "ref_physical_nominal_8mps.json")
    md = ref.metadata
    return CycleResult(problem.scenario, problem.config, md["wind_mps"], md["wind_from_deg"], "ok", "Solve_Succeeded",
                       0.0, 0.0, 0, T1_s=md["T1_s"], T2_s=md["T2_s"], k_wrap=md["k_wrap"],
                       E_generated_J=1.0, E_thrust_J=2.0,
                       E_reel_in_J=0.5, columns={k: ref[k].copy() for k in COLUMN_UNITS}, problem=problem)


@pytest.mark.parametrize("line", LINES)
def test_reference_metadata_carries_the_line(tmp_path, line):
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, line=line).validate()
    p = write_reference(_result(pr), tmp_path / "ref.json")
    raw = json.loads(p.read_text())["metadata"]
    assert raw["line"] == line and raw["propeller"] == "engine" and raw["line_weight"] is True
    assert read_reference(p).metadata["line"] == line


def test_reference_without_a_line_is_table1s_and_a_bad_line_is_refused(tmp_path):
    doc = json.loads((DATA / "ref_physical_nominal_8mps.json").read_text())
    assert "line" not in doc["metadata"]  # written before lines were named
    assert "line" not in read_reference(DATA / "ref_physical_nominal_8mps.json").metadata  # flown on Table 1's line
    for bad, shown in (("thin", "'thin'"), (7, "7")):
        doc["metadata"]["line"] = bad
        p = tmp_path / "bad.json"
        p.write_text(json.dumps(doc))
        with pytest.raises(InputError) as ei:
            read_reference(p)
        msg = str(ei.value)
        assert "\n" not in msg and str(p) in msg and "metadata.line" in msg and shown in msg and "sized, paper" in msg


def test_a_flight_takes_the_line_of_its_reference():
    """What `fly` flies: the reference metadata's line, checked before JSBSim loads."""
    from fdm_awe.sim.flight import fly
    from fdm_awe.autopilot.tracking import TrackingReference

    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps.json")
    ref.meta["line"] = "thin"
    with pytest.raises(InputError, match="metadata.line 'thin' unknown"):
        fly(ref, cycles=1, t_end=0.1)
    assert np.isfinite(ref.period)
