"""Sweeps and compare with the optimiser's plant-model options (--line, --line-diameter,
--propeller, --line-weight): the points carry them into their problems, records and ids; the
points of earlier sweeps (momentum theory, massless line, Table 1's line) keep their ids."""

from __future__ import annotations

import argparse

import pytest

from fdm_awe.commands import compare as compare_cmd
from fdm_awe.commands import sweep as sweep_cmd
from fdm_awe.errors import InputError
from fdm_awe.ocp.problem import Mesh
from fdm_awe.groundstation import load_ground_station
from fdm_awe.sweep.design import resized_line
from fdm_awe.sweep.references import tether_properties
from fdm_awe.sweep.runner import base_record, canonical_spec, point_problem, point_winch
from fdm_awe.sweep.spec import Point, SweepSpec

#: the sized line's diameter as the definition derives it [m]
SIZED_D = load_ground_station(line="sized").tether.diameter


def test_points_carry_the_plant_model_and_keep_their_ids_by_default():
    # the plant model of the points of earlier sweeps: momentum theory, massless line, Table 1's line
    legacy = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3), propeller="momentum",
                       line_weight=False, lines=("paper",))
    plant = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3))  # today's physical defaults
    explicit = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3), propeller="engine",
                         line_weight=True, lines=("sized",))
    pl, pp, pe = legacy.points(), plant.points(), explicit.points()
    # ids of legacy points are those of points built without the new fields (stored sweeps resume),
    # pinned by one id an earlier sweep stored (a SHA-1 of the point's canonical JSON)
    assert [p.id for p in pl] == [Point(p.scenario, p.config, p.wind, p.d0, p.d_tf, mesh=p.mesh).id for p in pl]
    assert pl[0].id == "a867aeb4dc47f443"
    assert [p.id for p in pe] == [p.id for p in pp]  # explicit defaults = defaults
    assert not {p.id for p in pp} & {p.id for p in pl}
    pr = point_problem(pp[0])
    assert (pr.propeller, pr.line_weight, pr.line) == ("engine", True, "sized") and pr.scenario_spec.propeller == "engine"
    assert point_winch(pp[0]) is None  # the optimiser loads the problem's line itself
    old = point_problem(pl[0])
    assert (old.propeller, old.line_weight, old.line) == ("momentum", False, "paper")
    rec = base_record(pp[0])
    assert rec["propeller"] == "engine" and rec["line_weight"] is True and rec["line"] == "sized"
    assert rec["line_diameter_m"] is None
    assert base_record(pl[0])["propeller"] == "momentum" and base_record(pl[0])["line"] == "paper"
    # the paper scenario's points are those of earlier sweeps
    paper = SweepSpec(winds=(3.0,), configs=("nominal",), scenario="paper", mesh=Mesh(10, 8, 3)).points()
    assert paper[0].id == Point("paper", "nominal", 3.0, 200.0, 250.0, mesh=(10, 8, 3)).id
    assert base_record(paper[0])["propeller"] == "paper"


def test_line_and_line_diameter_axes():
    spec = canonical_spec(SweepSpec(winds=(6.0, 8.0), configs=("nominal", "foldable"), mesh=Mesh(10, 8, 3),
                                    lines=("sized", "paper"), line_diameters=(0.3e-3, SIZED_D, 0.6e-3)))
    assert spec.line_diameters == (0.3e-3, None, 0.6e-3)  # the defined diameter shares the default's ids
    pts = spec.points()
    # sized: 3 diameters, paper: its own section only; x 2 configs x 2 winds
    assert len(pts) == (3 + 1) * 2 * 2 and len({p.id for p in pts}) == len(pts)
    assert {(p.line, p.line_diameter) for p in pts} == {("sized", 0.3e-3), ("sized", None), ("sized", 0.6e-3),
                                                        ("paper", None)}
    default_ids = {p.id for p in SweepSpec(winds=(6.0, 8.0), configs=("nominal", "foldable"),
                                           mesh=Mesh(10, 8, 3)).points()}
    assert default_ids == {p.id for p in pts if p.line == "sized" and p.line_diameter is None}
    # warm-start chains never cross lines or diameters
    assert len({p.line_key for p in pts}) == 4 * 2
    thin = next(p for p in pts if p.line_diameter == 0.3e-3 and p.config == "nominal")
    w = point_winch(thin)
    sized = load_ground_station(line="sized").tether
    assert w.tether_diameter == pytest.approx(0.3e-3, rel=1e-12)
    # the section scales with d^2: mass per length (so the line weight) and the breaking load
    k = (0.3e-3 / sized.diameter) ** 2
    assert w.line_weight_per_length == pytest.approx(
        k * sized.weight_share * sized.mass_per_length * sized.gravity, rel=1e-12)
    t = resized_line(sized, 0.3e-3)
    assert t.breaking_load == pytest.approx(k * sized.breaking_load, rel=1e-12)
    assert t.axial_stiffness == pytest.approx(k * sized.axial_stiffness, rel=1e-12)
    assert t.cd_perpendicular == sized.cd_perpendicular and t.rated_tension == sized.rated_tension
    rec = base_record(thin)
    assert rec["line"] == "sized" and rec["line_diameter_m"] == 0.3e-3 and "line=sized@0.3mm" in thin.label()
    pr = point_problem(thin)
    assert pr.line == "sized"
    # the point's own line for the reference curves: a thinner line drags less
    assert tether_properties("sized", 0.3e-3)[0] == pytest.approx(0.3e-3, rel=1e-12)
    assert tether_properties("paper") == (pytest.approx(0.72e-3), pytest.approx(1.1))


@pytest.mark.parametrize("kw, words", [
    ({"lines": ("thin",)}, ("line 'thin' unknown", "sized, paper")),
    ({"lines": ()}, ("line: at least one",)),
    ({"line_diameters": (0.01,)}, ("line diameter 0.01 m out of range", "0.01..5 mm")),
    ({"line_diameters": (0.3e-3,), "lines": ("paper",)}, ("only the sized line is resized",)),
    ({"line_weight": "yes"}, ("line weight 'yes' invalid",)),
])
def test_bad_line_axes_are_one_line_errors(kw, words):
    with pytest.raises(InputError) as ei:
        SweepSpec(winds=(8.0,), **kw).validate()
    msg = str(ei.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_a_diameter_that_breaks_below_the_rated_tension_is_refused():
    # 225 N at 0.449 mm: 50 N needs d >= 0.449 mm x sqrt(50 / 225) = 0.212 mm
    with pytest.raises(InputError, match=r"breaking load .* below the rated tension 50 N \(allowed >= 0.212 mm\)"):
        canonical_spec(SweepSpec(winds=(8.0,), line_diameters=(0.2e-3,)))
    with pytest.raises(InputError, match="'paper' line states its section"):
        resized_line(load_ground_station(line="paper").tether, 0.5e-3)


def test_plant_model_only_for_the_physical_scenario():
    with pytest.raises(InputError, match="only the physical scenario"):
        SweepSpec(winds=(3.0,), scenario="paper", line_weight=True).validate()
    with pytest.raises(InputError, match="propeller 'x' unknown"):
        SweepSpec(winds=(3.0,), propeller="x").validate()


def test_command_lines_take_the_options():
    p = argparse.ArgumentParser()
    sweep_cmd.add_arguments(p)
    args = p.parse_args(["--out", "x", "--wind", "8", "--config", "nominal", "--propeller", "momentum",
                         "--no-line-weight", "--line", "paper,sized", "--line-diameter", "0.0003,0.0006"])
    spec = sweep_cmd.build_spec(args)
    assert spec.propeller == "momentum" and spec.line_weight is False
    assert spec.lines == ("paper", "sized") and spec.line_diameters == (0.3e-3, 0.6e-3)
    d = sweep_cmd.build_spec(p.parse_args(["--out", "x", "--wind", "8"]))
    assert (d.propeller, d.line_weight, d.lines, d.line_diameters) == (None, None, (None,), (None,))
    assert d.plant() == {"propeller": "engine", "line_weight": True} and d.line_names() == ("sized",)
    c = argparse.ArgumentParser()
    compare_cmd.add_arguments(c)
    a = c.parse_args(["--propeller", "engine", "--line-weight", "--line", "paper"])
    assert a.propeller == "engine" and a.line_weight is True and a.line == "paper"
    assert c.parse_args([]).line_weight is None and c.parse_args(["--no-line-weight"]).line_weight is False


def test_compare_report_names_the_plant_model():
    res = {c: {"status": "failed", "reason": "x", "T1_s": None, "T2_s": None, "E_generated_J": None, "E_thrust_J": None,
               "E_reel_in_J": None, "E_net_J": None, "P_avg_W": None} for c in ("nominal", "foldable")}
    text = compare_cmd.markdown("physical", 8.0, res, None, 1.0, "engine", True, "sized")
    assert "6-DOF glider's own drive" in text and "line's weight" in text and "line `sized`" in text
    legacy = compare_cmd.markdown("physical", 8.0, res, None, 1.0, "momentum", False, "paper")
    assert "momentum theory" in legacy and "massless line" in legacy and "Table 1's line" in legacy
    assert "plant model" not in compare_cmd.markdown("physical", 8.0, res, None)


def test_sweep_summary_names_the_plant_model():
    from fdm_awe.sweep.report import plant_note

    assert plant_note(SweepSpec(winds=(8.0,))) == \
        "Plant model: tether line sized; propeller engine; line weight on the glider on."
    note = plant_note(SweepSpec(winds=(8.0,), lines=("sized", "paper"), line_diameters=(None, 0.3e-3),
                                propeller="momentum", line_weight=False))
    assert "sized, paper" in note and "0.3 mm" in note and "propeller momentum" in note and "off" in note
    assert "paper" in plant_note(SweepSpec(winds=(3.0,), scenario="paper"))
