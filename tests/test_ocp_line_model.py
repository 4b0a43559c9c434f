"""The optimiser's line models (CycleProblem.line_model): ``straight`` (the straight line's 1/4 drag
and 1/2 weight shares) and ``calibrated`` (the shares fitted to flights on the lumped line, with
the still line's drag in the wind and the reel-in tension: ``tether/calibrated``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fdm_awe import ROOT
from fdm_awe.cli import main
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import DefinitionError, InputError
from fdm_awe.groundstation import load_ground_station
from fdm_awe.ocp.energy import WinchElectrics, motor_supply_power
from fdm_awe.ocp.model import CycleModel
from fdm_awe.ocp.problem import CycleProblem
from fdm_awe.ocp.build import structure_key

WIND = (10.0, 0.0)  # north, east [m/s]: from the south
STATE = [170.0, 30.0, -100.0, 20.0, 0.1, 1.5]  # downwind of the winch, a little east


def _models():
    glider, winch = load_glider(), WinchElectrics.from_ground_station(line="sized")
    straight = CycleModel.build(CycleProblem(config="nominal", wind_speed=10.0).validate(), glider, winch)
    cal = CycleModel.build(CycleProblem(config="nominal", wind_speed=10.0, line_model="calibrated").validate(), glider, winch)
    return straight, cal, winch


def test_the_definition_holds_the_calibrated_shares():
    t = load_ground_station().tether
    for config in ("nominal", "foldable"):
        a, b, c, g = t.calibrated_line(config)
        assert 0.15 <= a <= 0.25 and b == 0.5 and 0.3 <= c <= 0.6  # the fit's ranges (tether/ground_station.xml)
        assert 0.0 < g < 10.0
    # the folded recovery drags less of its line along: lower shares than the nominal glider's
    assert t.calibrated_line("foldable")[0] < t.calibrated_line("nominal")[0]
    assert t.calibrated_line("foldable")[2] < t.calibrated_line("nominal")[2]
    assert (t.drag_share, t.weight_share) == (0.25, 0.5)  # the straight line keeps its shares
    assert WinchElectrics.from_ground_station(line="paper").calibrated_line("nominal") == t.calibrated_line("nominal")


def _without(text: str, start_tag: str, end_tag: str) -> str:
    start = text.index(start_tag)
    return text[:start] + text[text.index(end_tag, start) + len(end_tag):]


def test_a_bad_calibrated_block_is_refused(tmp_path):
    text = (ROOT / "tether" / "ground_station.xml").read_text()
    p = tmp_path / "gs.xml"
    p.write_text(_without(text, "<wind_share", "</wind_share>"))
    with pytest.raises(DefinitionError, match=r"tether/calibrated\[nominal\]/wind_share.*missing element"):
        load_ground_station(p)
    p.write_text(text.replace('<calibrated config="foldable">', '<calibrated config="nominal">'))
    with pytest.raises(DefinitionError, match="defined twice"):
        load_ground_station(p)
    p.write_text(text.replace('<calibrated config="foldable">', '<calibrated config="folded">'))
    with pytest.raises(DefinitionError, match="config attribute 'folded' not allowed"):
        load_ground_station(p)
    # no block for a configuration: the straight line's shares
    p.write_text(_without(text, '<calibrated config="foldable">', "</calibrated>"))
    assert load_ground_station(p).tether.calibrated_line("foldable") == (0.25, 0.5, 0.0, 0.0)


def test_the_straight_model_has_no_wind_term_and_the_calibrated_one_pushes_downwind_normal_to_the_line():
    straight, cal, winch = _models()
    d = float(np.linalg.norm(STATE[:3]))
    assert straight._line_wind_force(STATE, d, 230.0, WIND, 1.0) is None
    f = np.array([float(v) for v in cal._line_wind_force(STATE, d, 230.0, WIND, 1.0)])
    u = np.array(STATE[:3]) / d
    w = np.array([*WIND, 0.0])
    w_n = w - (w @ u) * u
    t = load_ground_station().tether
    c = t.calibrated_line("nominal")[2]
    expect = c * 0.5 * t.air_density * t.cd_perpendicular * t.diameter * 230.0 * math.hypot(float(np.linalg.norm(w_n)), 0.1) * w_n
    assert f == pytest.approx(expect, rel=1e-12)
    assert abs(f @ u) < 1e-12 * np.linalg.norm(f)  # normal to the line
    assert f[0] > 0 and f[2] > 0  # downwind (north) and down, for a glider downwind and above the winch
    # no wind, no force beyond the smoothing's
    f0 = np.array([float(v) for v in cal._line_wind_force(STATE, d, 230.0, (0.0, 0.0), 1.0)])
    assert np.linalg.norm(f0) == 0.0


def test_the_calibrated_shares_enter_the_phase_blocks():
    straight, cal, winch = _models()
    a, b, c, g_rec = winch.calibrated_line("nominal")
    u = [0.1, 0.2, 0.5, 0.5]
    d = float(np.linalg.norm(STATE[:3]))
    cdt_s, _ = straight._tether_drag(straight.gen_airframe.aero, STATE, d, d, 1.0)
    cdt_c, _ = cal._tether_drag(cal.gen_airframe.aero, STATE, d, d, 1.0)
    assert float(cdt_c) == pytest.approx(float(cdt_s) * a / 0.25, rel=1e-12)
    assert cal._line_weight(200.0) == pytest.approx(b * winch.line_weight_total_per_length * 200.0, rel=1e-12)
    assert straight._line_weight(200.0) == pytest.approx(winch.line_weight_per_length * 200.0, rel=1e-15)
    # the wind on the line pushes the glider downwind: it speeds up along a downwind path
    g_s, g_c = straight.generation(STATE, u, WIND), cal.generation(STATE, u, WIND)
    assert np.all(np.isfinite(np.array(g_c["f"], float))) and g_c["f"] != g_s["f"]
    # reeling in pays the calibrated line's tension at the winch; the straight line is slack
    rec = STATE + [230.0]
    r_s, r_c = straight.recovery(rec, [0.1, 0.2, 0.5, -4.0, 1.0], WIND), cal.recovery(rec, [0.1, 0.2, 0.5, -4.0, 1.0], WIND)
    assert float(r_s["P_rw"]) == pytest.approx(float(motor_supply_power(-4.0, winch)), rel=1e-15)
    assert float(r_c["P_rw"]) == pytest.approx(float(motor_supply_power(-4.0, winch, g_rec)))
    assert float(r_c["P_rw"]) > float(r_s["P_rw"]) + g_rec * 4.0  # the work and its losses


def test_the_line_model_is_part_of_the_problem():
    pr = CycleProblem(line_model="calibrated").validate()
    assert structure_key(pr) != structure_key(CycleProblem().validate())
    with pytest.raises(InputError, match=r"line_model 'lumped' unknown \(allowed: straight, calibrated\)"):
        CycleProblem(line_model="lumped").validate()
    with pytest.raises(InputError, match="line_model 'calibrated': only the physical scenario"):
        CycleProblem(scenario="paper", wind_speed=3.0, line_model="calibrated").validate()


def test_line_model_option_on_the_paper_scenario_is_one_line(capsys):
    rc = main(["optimize", "--scenario", "paper", "--line-model", "calibrated"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "--line-model calibrated: only the physical scenario" in err, err


def test_fly_refuses_a_line_model_with_a_reference(capsys):
    rc = main(["fly", "--reference", "tests/data/ref_physical_nominal_8mps_sized.json", "--line-model", "calibrated"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "--line-model" in err and "fixes this" in err, err


def test_the_fixed_weight_fit_recovers_the_shares_it_was_given():
    """scripts/compare_tether.py's calibration fit: line forces made from known drag and wind
    shares (weight share 1/2) give those shares back, even where the weight and the wind's
    normal parts point the same way (the glider straight downwind)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("compare_tether", ROOT / "scripts" / "compare_tether.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # type: ignore[union-attr]
    rng = np.random.default_rng(1)
    n = 400
    D, W, Dw = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    Dw[: n // 2] = W[: n // 2] * 3.0  # collinear half: only the held weight share separates them
    F = 0.21 * D + 0.5 * W + 0.47 * Dw
    a, c = mod.fixed_weight_fit(D, W, Dw, F, 0.5)
    assert (a, c) == (pytest.approx(0.21, abs=1e-12), pytest.approx(0.47, abs=1e-12))
