"""Pumping-cycle OCP: checked independently of the optimiser.

References: docs/design.md section 6 closed-form generator point, the ground station's own steady
relations, scipy's adaptive Runge-Kutta re-integration of the optimal controls, and first
principles (no energy from still air). Coarse meshes where the check allows it keep the file
fast; the default mesh is used where the re-integration accuracy is the point.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.ocp.energy import (WinchElectrics, design_reference_generator, generator_load_power, generator_tension,
                                motor_supply_power)
from fdm_awe.ocp.problem import LEGACY_PHYSICAL_PLANT, Bounds, CycleProblem, Mesh
from fdm_awe.trajectory import read_reference, write_reference
from fdm_awe.ocp.build import get_nlp
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.ocp.verify import ENERGY_TOL_REL, POSITION_TOL_REL, verify

#: coarse mesh for convergence-only checks (verification accuracy is tested on finer meshes: at
#: this mesh a physical-scenario optimum can sit in the gaps between collocation points, with
#: defects of several percent; see fdm_awe.ocp.verify.POSITION_TOL_REL)
COARSE = Mesh(20, 12, 3)
#: The plant whose foldable cycle fails at 8 m/s (Table 1's line, momentum-theory propeller,
#: massless line: the published numbers and README's explanation of the failure); the tests
#: of that failure's cause pin it. With the physical scenario's default plant (the thinner
#: sized line, the glider's own drive, the line's weight) the foldable cycle at 8 m/s exists.
#: The wing folds instantly there (``fold_time`` 0, as when those numbers were published): with
#: the definition's 2 s fold the 8 m/s cycle on this plant exists too, at about -92 W.
#: The winch ran on the 24 V supply of the time (``supply_voltage`` 24: 5.36 m/s fastest reel-in):
#: with the definition's 48 V (11.1 m/s) the folded recovery on this plant closes with the real
#: propeller too (measured: the elastic solve of the static-thrust test's start ends with a
#: largest slack of 9e-9, against 2.05 at 24 V), so the failure is the 24 V drive's.
FAILING_FOLD_PLANT = {**LEGACY_PHYSICAL_PLANT, "fold_time": 0.0, "supply_voltage": 24.0}
#: the paper scenario has no stiff generator coupling: 30 intervals of degree 4 reproduce its
#: path within ~0.03 % (the physical scenario's check runs on the default mesh)
PAPER_MESH = Mesh(30, 16, 4)


@pytest.fixture(scope="module")
def winch() -> WinchElectrics:
    return WinchElectrics.from_ground_station()


# ---------------------------------------------------------------- energy relations
def test_generator_point_matches_design_reference(winch):
    """docs/design.md section 6: G = 30 N, R_L 1.5 ohm -> omega 117.010 rad/s, 3.5103 m/s,
    6.148 A, 56.70 W, 105.31 W, efficiency 0.538 (printed to 4-5 digits: rel 1e-3)."""
    ref = design_reference_generator(winch, 30.0)
    assert ref["omega"] == pytest.approx(117.010, rel=1e-3)
    assert ref["v_reel"] == pytest.approx(3.5103, rel=1e-3)
    assert ref["i"] == pytest.approx(6.148, rel=1e-3)
    assert ref["P_load"] == pytest.approx(56.70, rel=1e-3)
    assert ref["P_mech"] == pytest.approx(105.31, rel=1e-3)
    assert ref["efficiency"] == pytest.approx(0.538, rel=2e-3)
    # the OCP's (smoothed) inverse relation reproduces it: the smoothing of the 1 V diode
    # threshold by 0.02 V changes the current by < 1e-4 A far above the threshold
    assert float(generator_tension(ref["v_reel"], winch)) == pytest.approx(30.0, rel=1e-6)
    assert float(generator_load_power(ref["v_reel"], winch)) == pytest.approx(56.70, rel=1e-3)


def test_generator_matches_ground_station_steady(winch):
    """The OCP's tension(speed) is the inverse of the ground station's speed(tension).
    Tolerance 1e-4: the OCP smooths the rectifier's conduction threshold (0.02 V on a 2 V
    margin at 10 N, relative current error ~ (0.02/2)^2/4)."""
    from fdm_awe.groundstation.steady import generator_steady

    for G in (10.0, 25.0, 45.0):
        st = generator_steady(G, winch.gs_params)
        assert float(generator_tension(st.reel_speed, winch)) == pytest.approx(G, rel=1e-4)
        assert float(generator_load_power(st.reel_speed, winch)) == pytest.approx(st.p_load, rel=1e-4)


def test_reel_in_limit_is_full_duty(winch):
    """At the reel-in speed limit the motor needs exactly the supply voltage (duty 1)."""
    from fdm_awe.groundstation.steady import motor_steady

    v = winch.reel_in_speed_max()
    assert motor_steady(v, 0.0, winch.gs_params).duty == pytest.approx(1.0, rel=1e-12)
    # friction alone costs M_c omega: the supply power exceeds it (copper, diodes, viscous)
    assert float(motor_supply_power(-v, winch)) > winch.M_c * v / winch.r_w


# ---------------------------------------------------------------- input validation
@pytest.mark.parametrize("kwargs, words", [
    ({"d_tf": 150.0}, "d_tf"),
    ({"bounds": Bounds(V_min=30.0)}, "V_min"),
    ({"wind_speed": -3.0}, "wind speed"),
    ({"scenario": "fantasy"}, "scenario"),
    ({"config": "biplane"}, "configuration"),
    ({"bounds": Bounds(h_min=150.0)}, "clearance"),
    ({"mesh": Mesh(2, 12, 3)}, "mesh"),
])
def test_infeasible_inputs_one_line(kwargs, words):
    with pytest.raises(InputError) as ei:
        CycleProblem(**kwargs).validate()
    msg = str(ei.value)
    assert words in msg and "\n" not in msg


def test_cli_input_error_exit_code(capsys):
    from fdm_awe.cli import main

    assert main(["optimize", "--wind", "-2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "wind speed" in err[0]


def test_ipopt_failure_is_a_failed_status():
    """An iteration limit far too small: the result says failed and why, carries no energies."""
    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, mesh=COARSE)
    res = solve_cycle(pr, ipopt_options={"ipopt.max_iter": 3}, coarse=None)
    assert res.status == "failed"
    assert "Maximum_Iterations_Exceeded" in res.reason
    s = res.summary()
    assert s["E_net_J"] is None and s["P_avg_W"] is None
    with pytest.raises(InputError):
        write_reference(res, "never.json")


# ---------------------------------------------------------------- paper scenario
@pytest.fixture(scope="module")
def paper3():
    pr = CycleProblem(scenario="paper", config="foldable", wind_speed=3.0, mesh=PAPER_MESH)
    res = solve_cycle(pr, coarse=None)
    return pr, res


def test_paper_3ms_converges_and_reintegrates(paper3):
    """The interval defects of the re-integrated optimal controls sum to < 0.5 %
    of the path, energies re-counted by the adaptive integrator agree within 1 %, every scaled
    constraint holds within 1e-6."""
    pr, res = paper3
    assert res.ok, res.reason
    v = verify(res, get_nlp(pr)[0])
    assert v.position_error_rel < POSITION_TOL_REL
    for k, e in v.energy_error_rel.items():
        assert e < ENERGY_TOL_REL, k
    assert v.accurate()
    assert v.nlp_max_violation < 1e-6


def test_paper_3ms_same_order_as_table3(paper3):
    """Table 3: generation 2048 J, thrust 1121 J, rewinding 63.81 J, T1 14.24 s, T2 10.70 s.
    'Same order': each within a factor 2 (the differences are explained in the report)."""
    _, res = paper3
    for ours, paper in ((res.E_generated_J, 2048.0), (res.E_thrust_J, 1121.0), (res.E_reel_in_J, 63.81),
                        (res.T1_s, 14.24), (res.T2_s, 10.70)):
        assert 0.5 < ours / paper < 2.0
    # mechanical accounting: E_generated = int G ddot <= G_max (d_tf - d0) = 2500 J (within the
    # quadrature error of the mesh, 1e-4)
    assert res.E_generated_J <= 50.0 * 50.0 * (1 + 1e-4)  # Radau quadrature of ddot vs the exact 50 m
    # reel-in at the constant 6 W of the paper
    assert res.E_reel_in_J == pytest.approx(6.0 * res.T2_s, rel=1e-9)


def test_reference_file_round_trip(paper3, tmp_path):
    _, res = paper3
    p = write_reference(res, tmp_path / "ref.json")
    ref = read_reference(p)
    assert ref.metadata["scenario"] == "paper" and ref.metadata["config"] == "foldable"
    assert ref.period == pytest.approx(res.T1_s + res.T2_s)
    t = ref["t"]
    assert np.all(np.diff(t) >= -1e-12) and t[0] == 0.0 and t[-1] == pytest.approx(ref.period)
    # periodic: the cycle ends where it starts. The start and periodicity constraints are scaled
    # by the state scales and hold within the result's largest scaled violation each, so the
    # two ends differ by at most twice that (times the scale); the line length at the start is
    # the distance of a start point within that violation of the 200 m sphere (x, y, z each)
    from fdm_awe.ocp.layout import STATE_SCALE

    viol = res.max_violation
    assert viol < 1e-6
    for c in ("x", "y", "z", "V", "gamma"):
        assert ref[c][-1] == pytest.approx(ref[c][0], abs=2 * viol * STATE_SCALE[c] + 1e-9)
    assert ref["tether_length"][0] == pytest.approx(200.0, abs=3 ** 0.5 * viol * STATE_SCALE["x"] + 1e-9)
    s = ref.sample(res.T1_s + 0.5 * res.T2_s)
    assert s["phase"] == 1.0 and s["fold"] == 1.0 and s["tension"] == 0.0
    assert ref.sample(0.25 * res.T1_s)["fold"] == 0.0
    doc = json.loads(p.read_text())
    assert doc["format"] == "fdm-awe-reference-trajectory" and doc["units"]["tension"] == "N"


# ---------------------------------------------------------------- physical scenario
@pytest.mark.parametrize("wind", [6.0, 10.0])
def test_physical_nominal_converges(wind):
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=wind, mesh=COARSE)
    res = solve_cycle(pr, coarse=None)
    assert res.ok, res.reason
    assert res.max_violation < 1e-6
    assert res.E_generated_J > 0 and res.E_thrust_J > 0 and res.E_reel_in_J > 0


def _folded_recovery_start(pr):
    """The loop start used by the foldable feasibility checks: a 10 s recovery loop of 40 m."""
    from dataclasses import replace

    from fdm_awe.ocp.guess import default_starts

    return replace(default_starts(pr)[0], T2=10.0, r2=40.0)


def test_physical_foldable_cycle_exists_only_with_static_thrust():
    """Why the physical foldable cycle fails, first half: the propeller's thrust at speed (the
    second half, the line drag, is the next test). From the same
    start, the elastic (feasibility) solve finds a cycle when the thrust bound is the static
    T_max at every airspeed, and the strict problem then converges; with T <= T_avail(V) the
    elastic solve keeps a fictitious acceleration in the folded recovery (no feasible point
    nearby) and the solver reports that. The start is the first of the loop starts from which
    the static-thrust problem is feasible (a local solver finds a feasible point only from
    some starts; measured: the first one, a 10 s recovery loop of 40 m)."""
    from fdm_awe.ocp.guess import default_starts, loop_guess
    from fdm_awe.ocp.assemble import accept as _accept
    from fdm_awe.ocp.local import ELASTIC_PENALTY
    from fdm_awe.pointmass.model import wind_vector

    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, mesh=COARSE, **FAILING_FOLD_PLANT)
    nlp, _ = get_nlp(pr)
    wind = wind_vector(8.0, 180.0)[:2]
    for st in [_folded_recovery_start(pr)] + default_starts(pr):
        phases, k = loop_guess(pr, nlp.model, st, wind)
        w0 = nlp.pack(phases)
        static = nlp.solve(w0, nlp.params(wind, 1.0, k, 1.0, ELASTIC_PENALTY, thrust_bound=0.0), elastic=True)
        if static.status == "ok" and nlp.max_slack(static.w) < 1e-6:
            break
    else:
        pytest.fail("no loop start gives a feasible cycle with the static thrust bound")
    strict_static = nlp.solve(static.w, nlp.params(wind, 1.0, k, 1.0, 0.0, thrust_bound=0.0))
    assert _accept(nlp, strict_static), strict_static.reason
    en = nlp.energies(strict_static.w, strict_static.params)
    # the cycle lives on thrust: the propeller's energy alone exceeds all the winch books
    # (measured 15.6 kJ against 0.5 kJ; 4.6-7 kJ on the other optima found from perturbed starts)
    assert en["E_thrust_J"] > en["E_generated_J"] + en["E_reel_in_J"]
    real = nlp.solve(w0, nlp.params(wind, 1.0, k, 1.0, ELASTIC_PENALTY), elastic=True)
    assert real.status == "ok" and nlp.max_slack(real.w) > 1e-2


def test_line_drag_is_what_closes_the_folded_recovery():
    """The other half of the cause: with the real propeller (T <= T_avail(V)) the foldable cycle
    exists once the line drag is halved (``tether_drag_scale`` 0.5, e.g. half the diameter),
    it verifies, and it still loses to the nominal glider on the same line. The folded wing
    must fly its recovery at >= ~21 m/s, where the line's drag (proportional to V^2) costs far
    more than the open wing's slow recovery does.

    Both cycles are solved on the default mesh (refined from the coarse one), the mesh whose
    re-integration acceptance (``POSITION_TOL_REL``, ``ENERGY_TOL_REL``) the reference files
    are held to: on the coarse mesh the foldable optimum reaches the generation phase at 18 m/s
    and the 2.5 s intervals do not resolve the generator's stiff radial mode, so the optimum
    found there (which of several depends on the start and on rounding) re-integrates with
    1-3.4 % defects and up to 15 % error in the generated energy. Measured on the default mesh
    from the default and from perturbed starts: foldable -36.8 W (defects 0.03 %), nominal
    +6.9..+8.8 W (defects <= 0.07 %)."""
    fold_pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, tether_drag_scale=0.5,
                           **FAILING_FOLD_PLANT)
    # the claim holds for whichever local optimum a start reaches (checked from perturbed
    # starts), so one start's path suffices: the global strategy's exploration of every start
    # would only multiply the time
    fold = solve_cycle(fold_pr, strategy="first")
    assert fold.ok, fold.reason
    assert fold.max_violation < 1e-6
    v = verify(fold, get_nlp(fold_pr)[0])
    assert v.accurate(), (v.position_error_rel, v.energy_error_rel)
    assert v.nlp_max_violation < 1e-6
    nom_pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, tether_drag_scale=0.5,
                          **FAILING_FOLD_PLANT)
    nom = solve_cycle(nom_pr, strategy="first")
    assert nom.ok, nom.reason
    vn = verify(nom, get_nlp(nom_pr)[0])
    assert vn.accurate(), (vn.position_error_rel, vn.energy_error_rel)
    # the margin (10 W) is far above what the accepted re-integration leaves open (each energy
    # within ENERGY_TOL_REL: < 0.5 W of average power for either cycle) and above the spread
    # of the local optima found from perturbed starts (~2 W); measured gap ~44 W
    def power_uncertainty(r):
        return ENERGY_TOL_REL * (r.E_generated_J + r.E_thrust_J + r.E_reel_in_J) / (r.T1_s + r.T2_s)

    assert power_uncertainty(nom) + power_uncertainty(fold) < 10.0
    assert nom.P_avg_W > fold.P_avg_W + 10.0
    # the reference file says the line was scaled
    assert fold.metadata()["tether_drag_scale"] == 0.5


def test_tether_drag_scale_is_validated():
    with pytest.raises(InputError, match="tether_drag_scale"):
        CycleProblem(tether_drag_scale=-1.0).validate()


def test_physical_foldable_failure_is_deterministic():
    """The iteration budget, not the clock, ends a failing solve: two runs give the same
    iterations and the same one-line reason. The budget is checked before each attempt, so a
    call never runs more than the budget plus one attempt less one iteration; when the reason
    says the budget was used up, at least the budget was spent."""
    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, mesh=COARSE, **FAILING_FOLD_PLANT)
    st = [_folded_recovery_start(pr)]
    max_iter, budget = 60, 150
    a = solve_cycle(pr, coarse=None, starts=st, max_iter=max_iter, max_iter_total=budget)
    b = solve_cycle(pr, coarse=None, starts=st, max_iter=max_iter, max_iter_total=budget)
    assert not a.ok and not b.ok
    assert a.iterations == b.iterations and a.reason == b.reason
    assert "\n" not in a.reason and 0 < a.iterations <= budget + max_iter - 1
    if f"iteration budget of {budget} used up" in a.reason:
        assert a.iterations >= budget


def test_iteration_budget_ends_the_solve():
    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, mesh=COARSE)
    res = solve_cycle(pr, coarse=None, max_iter=5, max_iter_total=8)
    assert not res.ok and "iteration budget of 8 used up" in res.reason
    assert 8 <= res.iterations <= 8 + 5 - 1  # the last attempt starts below the budget


def test_physical_foldable_failure_is_reported():
    """Whatever the outcome, a failed solve carries a reason and no numbers."""
    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=6.0, mesh=COARSE)
    res = solve_cycle(pr, coarse=None, max_iter=150, max_iter_total=450)
    if res.ok:
        assert res.max_violation < 1e-6
    else:
        assert res.reason and res.summary()["E_net_J"] is None


def test_physical_zero_wind_gains_nothing():
    """Still air: every energy term is counted electrically with real losses, so no cycle can
    end with more energy than it started with. The line's drag is left out (factor 0): it only
    adds losses, so the claim is sharpest without it, and the still-air cycle with the full
    line converges only from some starts (measured: three of four attempts ran into the
    500-iteration limit before a figure of eight converged, ~50 s), which start depends on
    the machine's rounding."""
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=0.0, mesh=COARSE, tether_drag_scale=0.0)
    res = solve_cycle(pr, coarse=None)
    assert res.ok, res.reason
    assert res.E_net_J <= 0.0


def test_physical_reintegrates_default_mesh():
    """Default mesh (coarse solve first, then refined): same acceptance as the paper case."""
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0)
    res = solve_cycle(pr)
    assert res.ok, res.reason
    v = verify(res, get_nlp(pr)[0])
    assert v.nlp_max_violation < 1e-6
    assert v.position_error_rel < POSITION_TOL_REL
    for k, e in v.energy_error_rel.items():
        assert e < ENERGY_TOL_REL, k


def test_warm_start_from_neighbouring_wind():
    """A sweep re-solves from the previous wind speed's solution (same NLP, new wind)."""
    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, mesh=COARSE)
    first = solve_cycle(pr, coarse=None)
    assert first.ok
    again = solve_cycle(pr.with_wind(3.5), warm=first)
    assert again.ok and again.start == "warm start"
    assert again.iterations < first.iterations


def test_alpha_bounds_keep_the_negative_stall():
    """The aircraft definitions clip C_L at -C_Lmax; the stall-limited (physical) scenario keeps
    alpha above it, a reference to be flown (cl_margin < 1) keeps the same margin from the
    negative stall as from the positive one, and the paper scenario keeps Table 3's |alpha|."""
    for scn, cfg in (("physical", "nominal"), ("physical", "foldable"), ("paper", "foldable")):
        for margin in (1.0, 0.85):
            pr = CycleProblem(scenario=scn, config=cfg, wind_speed=8.0, mesh=COARSE, bounds=Bounds(cl_margin=margin))
            m = get_nlp(pr)[0].model
            for ip in (0, 1):
                a = (m.gen_airframe if ip == 0 else m.rec_airframe).aero
                lo, hi = m.alpha_lower(ip, 0.35, margin), m.alpha_upper(ip, 0.35, margin)
                cl_lo = a.CL0 + a.CLalpha * lo
                if margin < 1.0:
                    assert cl_lo >= -margin * a.CLmax - 1e-12 and a.CL0 + a.CLalpha * hi <= margin * a.CLmax + 1e-12
                if scn == "physical":
                    assert cl_lo >= -a.CLmax - 1e-12
                elif margin == 1.0:
                    assert lo == -0.35
                assert -0.35 <= lo < 0.0 < hi


def test_ipopt_instances_share_derivatives_bit_identically():
    """The IPOPT instances of one NLP (one per option set) reuse the derivative functions the
    first one generated: a warm solve with such an instance is bit-identical to one with an
    instance that generated its own."""
    from fdm_awe.ocp.local import WARM_OPTIONS
    from fdm_awe.pointmass.model import wind_vector

    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=Mesh(6, 4, 3))
    first = solve_cycle(pr, coarse=None, cache=False)
    assert first.ok
    own, _ = get_nlp(pr, cache=False)
    shared, _ = get_nlp(pr, cache=False)
    shared.solver_for(None)  # generates the derivatives; the warm instance below reuses them
    assert sorted(shared._derivatives) == ["grad_f", "hess_lag", "jac_g"] and not own._derivatives
    params = own.params(wind_vector(8.5, pr.wind_from_deg)[:2], 1.0, first.k_wrap)
    a = own.solve(first.w, params, first.lam_x, first.lam_g, WARM_OPTIONS)
    b = shared.solve(first.w, params, first.lam_x, first.lam_g, WARM_OPTIONS)
    assert a.status == "ok" and (a.status, a.iterations, a.objective) == (b.status, b.iterations, b.objective)
    assert np.array_equal(a.w, b.w) and np.array_equal(a.lam_x, b.lam_x) and np.array_equal(a.lam_g, b.lam_g)
