"""The optimiser with the 6-DOF glider's own drive (propeller model "engine"): the phase models
book exactly fdm_awe.pointmass.propeller.power_engine, the choice is validated, and a cycle solves and
carries the model in its metadata."""

from __future__ import annotations

import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.definitions.engine import load_electric_drive
from fdm_awe.errors import InputError
from fdm_awe.ocp.energy import WinchElectrics
from fdm_awe.ocp.model import CycleModel
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.ocp.build import structure_key
from fdm_awe.pointmass.propeller import power_engine, power_physical


def test_engine_propeller_is_booked_by_both_phases():
    glider = load_glider()
    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, propeller="engine").validate()
    model = CycleModel.build(pr, glider, WinchElectrics.from_ground_station(line=pr.line))
    assert model.scenario.propeller == "engine" and model.drive == load_electric_drive()
    prop, drive = glider.unfolded.propulsion, load_electric_drive()
    s = [120.0, 0.0, -150.0, 14.0, 0.1, 3.0]
    for T in (0.0, 1.5, 4.0):
        u = [0.1, 0.2, T, 0.0]
        gen = model.generation(s, u[:3], (8.0, 0.0))
        rec = model.recovery(s + [210.0], u, (8.0, 0.0))
        want = float(power_engine(T, 14.0, prop, drive, model.rho))
        assert float(gen["P_thr"]) == pytest.approx(want, rel=1e-12)
        assert float(rec["P_thr"]) == pytest.approx(want, rel=1e-12)
    # what sets the two models apart: zero thrust costs the running drive ~12 W at 14 m/s (the
    # propeller turns at its zero-thrust advance ratio), momentum theory only P0; at 4 N the
    # 9x5 drive (propeller ~0.7, motor ~0.8 efficient) needs less than momentum theory's 0.525
    assert float(power_engine(0.0, 14.0, prop, drive, 1.225)) - prop.P0 > 10.0
    assert float(power_physical(0.0, 14.0, prop, 1.225)) == pytest.approx(prop.P0)
    assert float(power_engine(4.0, 14.0, prop, drive, 1.225)) < float(power_physical(4.0, 14.0, prop, 1.225))
    # the physical scenario's default is the engine; momentum theory one option away, and the
    # NLP cache tells the two apart
    base = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0)
    assert base.propeller == "engine" and structure_key(base) == structure_key(pr)
    momentum = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, propeller="momentum")
    assert CycleModel.build(momentum, glider, WinchElectrics.from_ground_station()).scenario.propeller == "physical"
    assert structure_key(momentum) != structure_key(pr)


@pytest.mark.parametrize("kw, match", [({"propeller": "magic"}, "propeller 'magic' unknown"),
                                       ({"propeller": "engine", "scenario": "paper"}, "only the physical scenario")])
def test_bad_propeller_choice(kw, match):
    args = {"scenario": "physical", "config": "nominal", "wind_speed": 8.0, **kw}
    with pytest.raises(InputError, match=match):
        CycleProblem(**args).validate()


def test_engine_propeller_cycle_solves():
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, propeller="engine", line_weight=False,
                      mesh=Mesh(20, 12, 3)).validate()
    res = solve_cycle(pr)
    assert res.ok, res.status
    assert res.metadata()["propeller"] == "engine"
    # the booked thrust energy is the engine model's on the solution (re-integrated result)
    assert res.E_thrust_J > 0.0
