"""The optimiser's line weight (CycleProblem.line_weight): the glider carries the share of the
line's weight the 6-DOF plant's ground station puts on it; in the point-mass dynamics it acts
like extra gravity without extra mass."""

from __future__ import annotations

import math

import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.groundstation import load_ground_station
from fdm_awe.ocp.energy import WinchElectrics
from fdm_awe.ocp.model import CycleModel
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.ocp.build import structure_key
from fdm_awe.pointmass.model import Environment, PointMassModel


def test_a_downward_force_enters_like_gravity():
    g = load_glider().unfolded
    m = g.mass.mass
    x, u = [100.0, 20.0, -80.0, 13.0, 0.2, 2.5], [0.1, 0.3, 1.0, 12.0]
    with_force = PointMassModel(m, g.aero, Environment(g=9.81)).dynamics(x, u, 0.01, f_down=0.49)
    heavier_g = PointMassModel(m, g.aero, Environment(g=9.81 + 0.49 / m)).dynamics(x, u, 0.01)
    assert with_force == pytest.approx(heavier_g, rel=1e-13, abs=1e-13)
    assert PointMassModel(m, g.aero, Environment()).dynamics(x, u, 0.01, f_down=0.0) == \
        PointMassModel(m, g.aero, Environment()).dynamics(x, u, 0.01)


def test_line_weight_is_the_ground_stations_share():
    glider = load_glider()
    for line in ("sized", "paper"):
        t = load_ground_station(line=line).tether
        w_line = WinchElectrics.from_ground_station(line=line)
        assert w_line.line_weight_per_length == pytest.approx(t.weight_share * t.mass_per_length * t.gravity, rel=1e-15)
    # Table 1's line weighs 3.3 times the sized one (0.4 vs 0.123 g/m)
    assert (WinchElectrics.from_ground_station(line="paper").line_weight_per_length
            > 3.0 * WinchElectrics.from_ground_station(line="sized").line_weight_per_length)
    winch = WinchElectrics.from_ground_station(line="paper")
    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, line="paper").validate()
    base = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, line="paper", line_weight=False).validate()
    assert pr.line_weight is True  # the physical scenario's default
    with_w, without = CycleModel.build(pr, glider, winch), CycleModel.build(base, glider, winch)
    s = [150.0, 0.0, -140.0, 14.0, 0.1, 3.0]
    w = (8.0, 0.0)
    d = (s[0] ** 2 + s[1] ** 2 + s[2] ** 2) ** 0.5
    m = glider.unfolded.mass.mass
    gen_w, gen_0 = with_w.generation(s, [0.1, 0.2, 1.0], w), without.generation(s, [0.1, 0.2, 1.0], w)
    # generation: the taut line's length is the distance; only the gravity terms change
    assert float(gen_w["f"][3]) < float(gen_0["f"][3]) and float(gen_w["f"][4]) < float(gen_0["f"][4])
    assert float(gen_w["f"][5]) == pytest.approx(float(gen_0["f"][5]), rel=1e-12)
    dg = winch.line_weight_per_length * d / m  # extra "gravity" [m/s^2]
    assert float(gen_0["f"][3]) - float(gen_w["f"][3]) == pytest.approx(dg * math.sin(0.1), rel=1e-9)
    assert float(gen_0["f"][4]) - float(gen_w["f"][4]) == pytest.approx(dg * math.cos(0.1) / 14.0, rel=1e-9)
    # recovery: the paid-out length state
    rec_w = with_w.recovery(s + [260.0], [0.1, 0.2, 1.0, -2.0], w)
    rec_0 = without.recovery(s + [260.0], [0.1, 0.2, 1.0, -2.0], w)
    m_rec = glider.folded.mass.mass
    assert float(rec_0["f"][4]) - float(rec_w["f"][4]) == pytest.approx(
        winch.line_weight_per_length * 260.0 / m_rec * math.cos(0.1) / 14.0, rel=1e-9)
    assert structure_key(pr) != structure_key(base)


def test_line_weight_only_in_the_physical_scenario():
    with pytest.raises(InputError, match="line_weight: only the physical scenario"):
        CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, line_weight=True).validate()
    assert CycleProblem(scenario="paper", config="nominal", wind_speed=3.0).validate().line_weight is False
    with pytest.raises(InputError, match="line_weight 'yes' invalid"):
        CycleProblem(line_weight="yes").validate()  # type: ignore[arg-type]


def test_cycle_with_line_weight_and_engine_propeller_solves():
    # the physical scenario's defaults: sized line, the glider's own drive, the line's weight
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=Mesh(20, 12, 3)).validate()
    assert (pr.propeller, pr.line_weight, pr.line) == ("engine", True, "sized")
    res = solve_cycle(pr)
    assert res.ok, res.status
    md = res.metadata()
    assert md["line_weight"] is True and md["propeller"] == "engine" and md["line"] == "sized"
