"""Wind profile (shear): closed forms, backends, the uniform wind unchanged, the optimiser and
its re-integration in a log profile, the 6-DOF flight's wind following the altitude."""

from __future__ import annotations

import json
import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.wind import LINE_HEIGHT_FRACTION, WindProfile

DATA = Path(__file__).parent / "data"
LOG = WindProfile("log", z0=0.1, ref_height=10.0)
POWER = WindProfile("power", exponent=1 / 7, ref_height=10.0)


# ---------------------------------------------------------------- profile values
def test_profiles_match_their_closed_forms():
    for h in (2.0, 10.0, 50.0, 120.0, 300.0):
        assert LOG.factor(h) == pytest.approx(math.log(h / 0.1) / math.log(10.0 / 0.1), rel=1e-14)
        assert POWER.factor(h) == pytest.approx((h / 10.0) ** (1 / 7), rel=1e-14)
        assert WindProfile().factor(h) == 1.0
    # the reference height's wind is the given one; the speed grows with height
    assert LOG.factor(10.0) == pytest.approx(1.0, abs=1e-15) and POWER.factor(10.0) == pytest.approx(1.0, abs=1e-15)
    hs = np.linspace(1.0, 400.0, 50)
    for p in (LOG, POWER):
        assert np.all(np.diff(p.factor(hs)) > 0)
    # log profile, open country: ~1.54 x the 10 m wind at 120 m
    assert 1.5 < LOG.factor(120.0) < 1.6
    # below the floor the factor holds (no sign change at z0, no infinite slope at the ground)
    assert LOG.factor(0.01) == LOG.factor(-5.0) == LOG.factor(LOG.floor()) > 0.0


def test_casadi_and_numpy_evaluations_agree():
    h = ca.SX.sym("h")
    hs = np.array([0.5, 3.0, 10.0, 77.0, 150.0, 400.0])
    for p in (LOG, POWER, WindProfile("log", z0=1.5, ref_height=50.0)):
        f = ca.Function("f", [h], [p.factor(h)])
        assert np.allclose([float(f(v)) for v in hs], p.factor(hs), rtol=1e-13, atol=0.0)


def test_profile_input_errors_are_one_line():
    bad = [lambda: WindProfile("log", z0=0.0).validate(), lambda: WindProfile("power", exponent=1.5).validate(),
           lambda: WindProfile("log", z0=0.1, ref_height=0.5).validate(), lambda: WindProfile("weird").validate(),
           lambda: WindProfile.parse("log"), lambda: WindProfile.parse("power:x"), lambda: WindProfile.parse("cubic:1"),
           lambda: WindProfile.from_dict({"kind": "log", "z0_m": 0.1}),
           lambda: CycleProblem(scenario="paper", wind_profile=LOG).validate()]
    for f in bad:
        with pytest.raises(InputError) as exc:
            f()
        assert "\n" not in str(exc.value)
    assert WindProfile.parse("log:0.1") == LOG
    assert WindProfile.parse("power:0.2@80") == WindProfile("power", exponent=0.2, ref_height=80.0)
    assert WindProfile.parse("uniform", 50.0) == WindProfile()
    for p in (WindProfile(), LOG, POWER):
        assert WindProfile.from_dict(p.as_dict()) == p
        assert WindProfile.parse(p.label()) == p


# ---------------------------------------------------------------- the model
def _model(profile: WindProfile):
    from fdm_awe.ocp.build import get_nlp

    pr = CycleProblem(config="nominal", wind_speed=8.0, mesh=Mesh(20, 12, 3), wind_profile=profile)
    return pr, get_nlp(pr)[0].model


S = [150.0, 20.0, -90.0, 18.0, 0.1, 0.3]
U_GEN, U_REC, WIND = [0.1, 0.2, 1.0], [0.1, 0.2, 1.0, -3.0], (6.0, -1.0)
#: the phase blocks of the nominal physical model (sized line, engine drive, line weight) at
#: S, U_GEN / U_REC and WIND, evaluated by the model before wind profiles existed (the parent
#: of commit 6af3129) with standard gravity G0 (fdm_awe.constants) in both of its places: the
#: model's ``g`` and the line weight's (the ground-station file's ``tether/gravity``), first
#: recorded with its 9.81. Only entries 3 and 4 of each block moved (at most 1.5e-4 relative); with
#: 9.81 in both places the present model still gives the first record bit for bit.
GEN_BEFORE = [23.110148146597144, 4.292789057933406, -1.797001499642907, -209.07100285698823, -4.419372754673169,
              2.1430035183085665]
REC_BEFORE = [23.110148146597144, 4.292789057933406, -1.797001499642907, -2.3054351269560076, 1.0459043965090635,
              0.2865061135123682, -3.0]


def test_uniform_profile_reproduces_the_model_bit_for_bit():
    pr, m = _model(WindProfile())
    assert m.wind_profile.uniform
    w = (ca.SX.sym("wx"), ca.SX.sym("wy"))
    got = m.wind_at(w, ca.SX.sym("z"))
    assert got[0] is w[0] and got[1] is w[1]  # the same symbols: no factor enters the NLP
    assert [float(v) for v in m.generation(S, U_GEN, WIND)["f"]] == GEN_BEFORE
    assert [float(v) for v in m.recovery(S + [230.0], U_REC, WIND)["f"]] == REC_BEFORE


def test_model_sees_the_wind_at_the_glider_height():
    _, m = _model(LOG)
    _, mu = _model(WindProfile())
    f = LOG.factor(-S[2])
    out = m.generation(S, U_GEN, WIND)
    scaled = mu.generation(S, U_GEN, (WIND[0] * f, WIND[1] * f))
    # kinematics: the ground velocity carries the wind at the glider's height exactly
    assert np.allclose(out["f"][:3], scaled["f"][:3], rtol=1e-14)
    # the line sees the weaker wind at LINE_HEIGHT_FRACTION of the height: a small difference
    # in the dynamics, none at all without line drag
    assert 0.6 < LINE_HEIGHT_FRACTION < 1.0
    assert np.max(np.abs(np.asarray(out["f"][3:]) - np.asarray(scaled["f"][3:]))) < 0.05 * np.max(np.abs(scaled["f"][3:]))
    # CasADi evaluation of the whole block agrees with NumPy
    xs, us = ca.SX.sym("x", 6), ca.SX.sym("u", 3)
    F = ca.Function("F", [xs, us], [ca.vertcat(*m.generation([xs[i] for i in range(6)], [us[i] for i in range(3)], WIND)["f"])])
    assert np.allclose(np.asarray(F(S, U_GEN)).ravel(), out["f"], rtol=1e-12, atol=1e-12)


# ---------------------------------------------------------------- the optimiser
@pytest.fixture(scope="module")
def log_cycle():
    from fdm_awe.ocp.solve import solve_cycle

    pr = CycleProblem(config="nominal", wind_speed=8.0, mesh=Mesh(20, 12, 3), wind_profile=LOG)
    return pr, solve_cycle(pr)


def test_optimiser_solves_a_log_profile_cycle_and_its_reintegration_holds(log_cycle):
    """Coarse mesh: the re-integration holds at the level the coarse uniform cycle does (defects
    of a few per cent of the path; verify.py's tolerances are the default mesh's)."""
    from fdm_awe.ocp.build import get_nlp
    from fdm_awe.ocp.verify import verify

    pr, res = log_cycle
    assert res.ok, res.reason
    v = verify(res, get_nlp(pr)[0])
    assert v.position_error_rel < 0.06
    for k, e in v.energy_error_rel.items():
        assert e < 0.06, k
    assert v.nlp_max_violation < 1e-6
    assert res.metadata()["wind_profile"] == LOG.as_dict()


def test_shear_above_the_reference_height_gains_power(log_cycle):
    """The cycle flies far above 10 m, where the log wind is ~1.5 x the 10 m wind: it gains
    clearly more than in a uniform 8 m/s wind (margin 3 W on ~9 W)."""
    from fdm_awe.ocp.solve import solve_cycle

    _, res = log_cycle
    uni = solve_cycle(CycleProblem(config="nominal", wind_speed=8.0, mesh=Mesh(20, 12, 3)))
    assert uni.ok and res.ok
    assert -res.columns["z"].max() > 3 * LOG.ref_height
    assert res.P_avg_W > uni.P_avg_W + 3.0


def test_reference_file_records_and_checks_the_profile(log_cycle, tmp_path):
    from fdm_awe.trajectory import read_reference, write_reference

    _, res = log_cycle
    p = write_reference(res, tmp_path / "ref.json")
    assert read_reference(p).metadata["wind_profile"] == LOG.as_dict()
    doc = json.loads(p.read_text())
    doc["metadata"]["wind_profile"] = {"kind": "log", "z0_m": -1.0, "ref_height_m": 10.0}
    p.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="wind_profile"):
        read_reference(p)
    del doc["metadata"]["wind_profile"]  # files written before profiles: uniform
    p.write_text(json.dumps(doc))
    assert read_reference(p).metadata["wind_profile"] == {"kind": "uniform"}


# ---------------------------------------------------------------- the 6-DOF flight
def test_flight_wind_follows_the_glider_altitude():
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly
    from fdm_awe.trajectory import check_reference_document
    from fdm_awe.wind import line_height

    doc = json.loads((DATA / "ref_physical_nominal_8mps_sized.json").read_text())
    doc["metadata"]["wind_profile"] = LOG.as_dict()
    ref = TrackingReference.from_ocp(check_reference_document(doc, "test reference"))
    w_ref = np.asarray(ref.meta["wind_ned_mps"], float)
    rows: list[tuple[float, np.ndarray, np.ndarray]] = []
    station: list[np.ndarray] = []

    def setup(ap, sim):
        station.append(sim.gs)

    def on_step(k, s, o):
        rows.append((-float(s.pos_ned[2]), s.wind_ned.copy(), np.asarray(station[0].wind, float)))

    rep = fly(ref, config="nominal", cycles=1, t_end=3.0, setup=setup, on_step=on_step)
    assert rep.status == "ok", rep.message
    assert len(rows) > 100
    hs = np.array([r[0] for r in rows])
    assert hs.max() - hs.min() > 1.0  # the glider changes height
    for (h_prev, _, st), (_, w, _) in zip(rows[:-1], rows[1:]):
        # JSBSim flies each step in the wind set from the altitude after the step before
        assert np.allclose(w, w_ref * LOG.factor(h_prev), rtol=1e-9, atol=1e-9)
        # the ground station's line drag: the wind at the line's height
        assert np.allclose(st, w_ref * LOG.factor(line_height(h_prev)), rtol=1e-12, atol=1e-12)
    assert np.linalg.norm(rows[-1][1]) > 1.3 * np.linalg.norm(w_ref)  # ~100 m up: far more than the 10 m wind


# ---------------------------------------------------------------- command line and sweeps
@pytest.mark.parametrize("argv, words", [
    (["optimize", "--wind-profile", "log:0"], ("--wind-profile", "z0", "1e-05..2 m")),
    (["optimize", "--wind-profile", "power:2"], ("--wind-profile", "exponent", "0..1")),
    (["optimize", "--wind-profile", "cubic:1"], ("--wind-profile", "uniform, log:Z0")),
    (["optimize", "--wind-profile", "log:0.1", "--wind-ref-height", "0"], ("--wind-ref-height", "1..1000")),
    (["optimize", "--wind-ref-height", "50"], ("--wind-ref-height", "only with a log or power")),
    (["compare", "--scenario", "paper", "--wind-profile", "log:0.1"], ("--wind-profile", "paper scenario")),
    (["fly", "--reference", str(DATA / "ref_physical_nominal_8mps.json"), "--wind-profile", "log:0.1"],
     ("--wind-profile", "fixes")),
])
def test_profile_options_are_checked_before_work(argv, words, tmp_path, capsys):
    from fdm_awe.cli import main

    if argv[0] == "sweep":
        argv = argv + ["--out", str(tmp_path / "s")]
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err, err
    for w in words:
        assert w in err, (w, err)


def test_uniform_sweep_points_keep_their_ids_and_a_profile_is_recorded():
    from fdm_awe.sweep.runner import base_record, point_problem
    from fdm_awe.sweep.spec import SweepSpec

    uni = SweepSpec(winds=(6.0, 8.0), configs=("nominal",)).points()
    log = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), wind_profile=LOG.label()).points()
    assert [p.wind_profile for p in uni] == ["uniform", "uniform"]
    # the id document of a uniform point lacks the field, as before profiles existed
    from dataclasses import replace

    assert all(replace(p, wind_profile="uniform").id == p.id for p in uni)
    assert not {p.id for p in uni} & {p.id for p in log}
    assert point_problem(log[0]).wind_profile == LOG and point_problem(uni[0]).wind_profile == WindProfile()
    assert base_record(log[0])["wind_profile"] == "log:0.1@10"
    with pytest.raises(InputError):
        SweepSpec(winds=(8.0,), wind_profile="log:0.1").validate()  # not canonical: the reference height is named
