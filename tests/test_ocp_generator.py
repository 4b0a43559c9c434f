"""The generator's load in generation: passive rectifier, T2 duty as a control (``boost``) and
the ``ideal`` converter bound.

Checked against the ground station's own steady relations (:mod:`fdm_awe.groundstation.steady`,
a separate implementation of eqs. 14-18), against each other (the three share the machine: at
the same tension and speed they deliver the same power, so ideal contains boost contains
passive), on solved cycles (orderings with margins, warm-started from the passive optimum so
the richer problem starts where the poorer one ended), and through the reference file to the
autopilot's winch command.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.groundstation import load_ground_station
from fdm_awe.groundstation.steady import generator_at_speed
from fdm_awe.ocp.energy import (WinchElectrics, generator_load_power, generator_tension, ideal_generator_current,
                                ideal_generator_power)
from fdm_awe.ocp.model import BOOST_DUTY, CycleModel
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.trajectory import check_reference, write_reference, read_reference
from fdm_awe.ocp.solve import solve_cycle

COARSE = Mesh(20, 12, 3)
STATE = [120.0, 10.0, -150.0, 14.0, 0.1, 3.0]


def _winch() -> WinchElectrics:
    return WinchElectrics.from_ground_station(line="sized")


@pytest.mark.parametrize("v", [0.5, 1.5, 3.0, 5.0])
@pytest.mark.parametrize("d2", [0.0, 0.3, 0.6, 0.8])
def test_boost_generator_matches_the_ground_station_steady_state(v, d2):
    """Tension and load power of the optimiser's generator equal the ground station's steady
    relations at every speed and duty (the diode smoothing is < 5 mA: 1e-3 relative)."""
    w, gs = _winch(), load_ground_station(line="sized")
    ref = generator_at_speed(v, gs, boost_duty=d2)
    assert float(generator_tension(v, w, d2)) == pytest.approx(ref.tension, rel=1e-3)
    assert float(generator_load_power(v, w, d2)) == pytest.approx(ref.p_load, rel=1e-3)


def test_duty_brakes_harder_and_wastes_more():
    """At a given reel speed a larger T2 duty holds a larger tension, and a smaller share of
    the line's power reaches the load (the armature's copper takes the rest); duty 0 is the
    passive rectifier exactly."""
    w = _winch()
    v = 2.0
    assert float(generator_tension(v, w, 0.0)) == float(generator_tension(v, w))
    duties = np.linspace(0.0, w.boost_duty_max, 9)
    G = np.array([float(generator_tension(v, w, d)) for d in duties])
    eff = np.array([float(generator_load_power(v, w, d)) for d in duties]) / (G * v)
    assert np.all(np.diff(G) > 0) and np.all(np.diff(eff) < 0)
    assert G[-1] > 2.0 * G[0]  # the duty's reach: more than twice the passive tension at this speed


def test_ideal_converter_delivers_what_the_half_bridge_does_at_its_own_operating_points():
    """At the tension a duty gives, the ideal converter's power (torque balance + machine
    losses) equals the load power of that duty: the ideal bound contains every boost point."""
    w = _winch()
    for v in (1.0, 2.5, 4.0):
        for d in (0.0, 0.4, 0.8):
            G = generator_tension(v, w, d)
            assert float(ideal_generator_power(G, v, w)) == pytest.approx(float(generator_load_power(v, w, d)), rel=2e-3)
            assert float(ideal_generator_current(G, v, w)) > 0.0


def test_controls_per_generator():
    glider = load_glider()

    def model(gen):
        pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, generator=gen).validate()
        return CycleModel.build(pr, glider, WinchElectrics.from_ground_station(line=pr.line))

    assert model("passive").gen_controls[:3] == ("alpha", "phi", "T") and BOOST_DUTY not in model("passive").gen_controls
    assert model("boost").gen_controls[3] == BOOST_DUTY
    assert model("ideal").gen_controls[3] == "G"
    # boost with duty 0 flies the passive model exactly
    mp, mb = model("passive"), model("boost")
    up = [0.1, 0.2, 1.0] + ([1.0] if mp.motor_off else [])
    ub = [0.1, 0.2, 1.0, 0.0] + ([1.0] if mb.motor_off else [])
    a, b = mp.generation(STATE, up, (8.0, 0.0)), mb.generation(STATE, ub, (8.0, 0.0))
    assert list(a["f"]) == pytest.approx(list(b["f"]), rel=1e-12) and float(a["P_gen"]) == pytest.approx(float(b["P_gen"]))


def test_generator_option_is_checked():
    with pytest.raises(InputError, match="generator 'turbo' unknown"):
        CycleProblem(scenario="physical", generator="turbo").validate()
    with pytest.raises(InputError, match="only the physical scenario"):
        CycleProblem(scenario="paper", generator="boost").validate()
    assert CycleProblem(scenario="physical").generator == "passive"
    assert CycleProblem(scenario="paper").generator is None


@pytest.fixture(scope="module")
def three_generators():
    """Nominal 8 m/s cycles on the coarse mesh: passive (cold), then boost and ideal warm-started
    from the passive optimum (a feasible point of both with the same power)."""
    base = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE).validate()
    passive = solve_cycle(base)
    assert passive.ok, passive.reason
    out = {"passive": passive}
    for gen in ("boost", "ideal"):
        out[gen] = solve_cycle(dataclasses.replace(base, generator=gen).validate(), warm=passive)
        assert out[gen].ok, (gen, out[gen].reason)
    return out


def test_richer_generators_generate_more(three_generators):
    """Passive <= boost <= ideal in cycle power (each problem contains the one before; 0.5 W is
    the solver's tolerance on these coarse optima), and the duty buys a real gain at 8 m/s."""
    P = {k: r.P_avg_W for k, r in three_generators.items()}
    assert P["boost"] >= P["passive"] - 0.5
    assert P["ideal"] >= P["boost"] - 0.5
    assert P["ideal"] > P["passive"] + 2.0  # the passive rectifier's tie of tension to speed costs power


def test_boost_reference_carries_the_duty_to_the_winch_command(three_generators, tmp_path):
    """The boost optimum's T2 duty stays within the definition's bound, goes into the reference
    file (column ``boost_duty``, metadata ``generator``), is 0 in recovery, and the autopilot's
    tracking reference samples it for the ground station's generator command."""
    from fdm_awe.autopilot.tracking import TrackingReference

    res = three_generators["boost"]
    w = _winch()
    d2, ph = res.columns["boost_duty"], res.columns["phase"]
    assert np.all(d2 >= -1e-6) and np.all(d2 <= w.boost_duty_max + 1e-6)
    assert np.all(d2[ph == 1] == 0.0) and np.max(d2[ph == 0]) > 0.05
    path = write_reference(res, tmp_path / "boost.json")
    ref = read_reference(path)
    assert ref.metadata["generator"] == "boost"
    tr = TrackingReference.from_ocp(ref)
    t = 0.5 * res.T1_s
    k = int(np.searchsorted(ref["t"], t, side="right")) - 1
    assert tr.sample(t).boost_duty == pytest.approx(float(ref["boost_duty"][k]), abs=1e-9)
    assert tr.sample(res.T1_s + 0.5 * res.T2_s).boost_duty == 0.0
    # a passive file may not carry a duty
    bad = dataclasses.replace(ref, metadata={**ref.metadata, "generator": "passive"})
    with pytest.raises(InputError, match="columns.boost_duty"):
        check_reference(bad)


def test_ideal_reference_is_refused_by_a_flight(three_generators, tmp_path):
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    path = write_reference(three_generators["ideal"], tmp_path / "ideal.json")
    with pytest.raises(InputError, match="generator: 'ideal'"):
        fly(TrackingReference.from_ocp_file(path), config="nominal", cycles=1)


def test_flight_json_names_the_line_and_the_generator_it_flew():
    """The flight report says which line and which generator load flew (the reference's)."""
    from flight_helpers import DATA

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    rep = fly(TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json"), config="nominal",
              cycles=1, t_end=2.0)
    doc = rep.as_json()
    assert doc["line"] == "sized" and doc["generator"] == "passive"
    old = fly(TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps.json"), config="nominal",
              cycles=1, t_end=2.0).as_json()
    assert old["line"] == "paper" and old["generator"] == "passive"  # written before lines and generators were named
