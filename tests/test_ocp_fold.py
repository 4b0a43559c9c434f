"""A fold that takes time: the optimiser folds the wing through the 6-DOF glider's actuator and
blends the aerodynamics as the 6-DOF model does.

Checked against the real JSBSim aircraft (its fold time and its blended coefficients at fold
states 0, 0.5 and 1), against the model functions themselves (fold time 0 is the instantaneous
switch: the same collocation residuals as the recovery form on equal intervals), and by the
independent re-integration of a solved cycle with the same fold law.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from fdm_awe.pointmass.aero import POLAR_FIELDS, fold_blend
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.ocp.layout import STATE_SCALE, fold_intervals
from fdm_awe.ocp.collocation import CycleNLP
from fdm_awe.ocp.energy import WinchElectrics
from fdm_awe.ocp.model import CycleModel
from fdm_awe.pointmass.fold import fold_fraction
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.build import get_nlp, structure_key
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.ocp.verify import verify
from fdm_awe.sixdof import JSBSimGlider

COARSE = Mesh(20, 10, 3)
#: the paper scenario's mesh whose re-integration meets the reference acceptance (tests/test_ocp.py)
PAPER_MESH = Mesh(30, 16, 4)
FT2 = 0.3048**2
WIND = (3.0, 0.0)


def _model(problem: CycleProblem) -> CycleModel:
    return CycleModel.build(problem, load_glider(), WinchElectrics.from_ground_station(line=problem.line))


def _nlp(problem: CycleProblem) -> CycleNLP:
    problem = problem.validate()
    return CycleNLP(problem, _model(problem))


def _sample_w(nlp: CycleNLP, seed: int = 1) -> np.ndarray:
    """A decision vector inside the bounds (scaled), with durations long enough for the folds."""
    rng = np.random.default_rng(seed)
    lo, hi = nlp.lbw, np.minimum(nlp.ubw, nlp.lbw + 2.0)
    w = rng.uniform(lo, hi)
    for ph in nlp.phases:
        w[ph.idx_T] = 1.2  # 12 s
    return w


def _fold_state(g: JSBSimGlider, target: float) -> float:
    """Drive the 6-DOF actuator to ``target`` (it stops there: rate limited, no overshoot)."""
    fdm = g.fdm
    fdm["fcs/wing-fold-cmd-norm"] = target
    for _ in range(int(round((g.fold_time_s + 0.5) * 120))):
        fdm.run()
    return fdm["fcs/wing-fold-norm"]


def test_fold_time_is_the_aircraft_definitions():
    """Default: the actuator's full travel of the flown aircraft; 0 for the nominal glider."""
    g = JSBSimGlider("glider_foldable")
    m = _model(CycleProblem(scenario="paper", config="foldable").validate())
    assert m.fold_time == g.fold_time_s > 0.0 and m.folds
    assert _model(CycleProblem(scenario="paper", config="foldable", fold_time=0.0)).fold_time == 0.0
    assert not _model(CycleProblem(scenario="paper", config="nominal").validate()).folds
    # the cache tells fold times apart
    assert structure_key(CycleProblem(fold_time=0.0)) != structure_key(CycleProblem(fold_time=1.0))


@pytest.mark.parametrize("fold", [0.0, 0.5, 1.0])
def test_blended_coefficients_equal_the_6dof_models(fold):
    """The JSBSim aircraft at fold state 0, 0.5, 1: its point-mass polar (unfolded reference
    area) equals fold_blend of the two static forms, and so does its reference area."""
    glider = load_glider()
    g = JSBSimGlider("glider_foldable")
    g.reset((0.0, 0.0, -100.0), 15.0)
    assert _fold_state(g, fold) == pytest.approx(fold, abs=1e-12)
    g.step()
    blend = fold_blend(glider.unfolded.aero, glider.folded.aero, fold)
    for key in POLAR_FIELDS:
        assert g.fdm[f"aero/pm/{key}"] == pytest.approx(getattr(blend, key), rel=1e-9, abs=1e-12), key
    assert g.fdm["metrics/Sw-sqft"] * FT2 == pytest.approx(blend.S, rel=1e-8)  # JSBSim keeps ft2
    # at the ends: the static forms' forces (coefficient times area)
    ref = glider.unfolded.aero if fold == 0.0 else glider.folded.aero if fold == 1.0 else None
    if ref is not None:
        for key in POLAR_FIELDS:
            assert getattr(blend, key) * blend.S == pytest.approx(getattr(ref, key) * ref.S, rel=1e-12), key


def test_fold_law_follows_the_actuator():
    """The fold state of the law is what the rate-limited actuator gives when the autopilot
    commands the fold at the start of recovery and the unfold one fold time before its end."""
    g = JSBSimGlider("glider_foldable")
    g.reset((0.0, 0.0, -300.0), 15.0)
    tf, dt = g.fold_time_s, g.dt
    T2 = 3.0 * tf
    fdm = g.fdm
    worst = 0.0
    for k in range(int(round(T2 / dt))):
        t = k * dt
        fdm["fcs/wing-fold-cmd-norm"] = 1.0 if t < T2 - tf else 0.0
        fdm.run()
        worst = max(worst, abs(fdm["fcs/wing-fold-norm"] - fold_fraction(t + dt, T2, tf)))
    assert worst <= dt / tf + 1e-9  # one frame of the actuator's first step


def test_fold_time_zero_is_the_instantaneous_switch():
    """Fold time 0: equal recovery intervals, the recovery form at every point, the usual
    duration bound, and each recovery collocation residual equals the one computed from the
    model function of the recovery form directly (the transcription before fold transitions)."""
    pr = CycleProblem(scenario="paper", config="foldable", fold_time=0.0, mesh=COARSE)
    nlp = _nlp(pr)
    rec = nlp.phases[1]
    assert rec.n_fold == 0 and nlp.lbw[rec.idx_T] * 10.0 == pytest.approx(pr.bounds.T_phase_min)
    w = _sample_w(nlp)
    params = nlp.params(WIND, 1.0, 0, 1.0)
    g = np.array(nlp.g_fn(w, params)).ravel()
    ph = nlp.unpack(w)[1]
    assert np.all(ph["fold"] == 1.0)
    assert np.allclose(np.diff(ph["t_nodes"]), ph["T"] / rec.n, rtol=1e-12)
    m = nlp.model
    d = nlp.d
    for k in range(rec.n):
        X = [w[rec.idx_X[k, j]] * [STATE_SCALE[s] for s in rec.states] for j in range(d + 1)]
        u = ph["U"][k]
        for j in range(1, d + 1):
            f = m.recovery(list(X[j]), list(u), WIND)["f"]
            for i, s in enumerate(rec.states):
                want = (sum(nlp.C[r, j] * X[r][i] for r in range(d + 1)) - ph["T"] / rec.n * float(f[i])) / STATE_SCALE[s]
                got = g[nlp.g_names.index(f"coll_p1_{k}_{j}_{s}")]
                assert got == pytest.approx(want, rel=1e-9, abs=1e-12), (k, j, s)


def test_fold_transitions_in_the_transcription():
    """Fold time > 0: the first and last recovery intervals span the fold and the unfold; every
    collocation point's fold state is the law's at its time, its residual the model's with that
    wing; a transition interval's alpha stays below the stall of every wing it passes."""
    pr = CycleProblem(scenario="physical", config="foldable", fold_time=2.0, mesh=COARSE)
    nlp = _nlp(pr)
    rec = nlp.phases[1]
    n_f = fold_intervals(rec.n, 2.0)
    assert rec.n_fold == n_f >= 1
    assert nlp.lbw[rec.idx_T] * 10.0 == pytest.approx(max(pr.bounds.T_phase_min, 4.0))
    w = _sample_w(nlp, seed=2)
    params = nlp.params(WIND, 1.0, 0, 1.0)
    g = np.array(nlp.g_fn(w, params)).ravel()
    ph = nlp.unpack(w)[1]
    T2, nodes = ph["T"], ph["t_nodes"]
    assert nodes[n_f] == pytest.approx(2.0) and T2 - nodes[-1 - n_f] == pytest.approx(2.0)
    m = nlp.model
    for t, f in zip(ph["t"], ph["fold"]):
        assert f == pytest.approx(m.fold_fraction(t, T2), abs=1e-12)
    assert ph["fold"][0] == 0.0 and ph["fold"][-1] == pytest.approx(0.0, abs=1e-12) and ph["fold"].max() == 1.0
    d = nlp.d
    glider = load_glider()
    for k in list(range(n_f)) + list(range(rec.n - n_f, rec.n)):
        X = [w[rec.idx_X[k, j]] * [STATE_SCALE[s] for s in rec.states] for j in range(d + 1)]
        u = ph["U"][k]
        h = nodes[k + 1] - nodes[k]
        for j in range(1, d + 1):
            f_j = ph["fold"][k * d + j]
            f = m.recovery(list(X[j]), list(u), WIND, 1.0, 1.0, f_j)["f"]
            for i, s in enumerate(rec.states):
                want = (sum(nlp.C[r, j] * X[r][i] for r in range(d + 1)) - h * float(f[i])) / STATE_SCALE[s]
                assert g[nlp.g_names.index(f"coll_p1_{k}_{j}_{s}")] == pytest.approx(want, rel=1e-9, abs=1e-12)
        a_hi = nlp.ubw[rec.idx_U[k, 0]] * 0.3
        for f_j in ph["fold"][k * d:(k + 1) * d + 1]:
            wing = fold_blend(glider.unfolded.aero, glider.folded.aero, f_j)
            assert wing.CL0 + wing.CLalpha * a_hi <= wing.CLmax * (1 + 1e-12)


def test_fold_time_is_validated():
    for bad in (-1.0, math.nan, 100.0):
        with pytest.raises(InputError, match="fold_time"):
            CycleProblem(fold_time=bad).validate()
    with pytest.raises(InputError, match="fold_time"):
        CycleProblem(fold_time=30.0).validate()  # two folds leave no room in t_max = 60 s


def test_foldable_cycle_with_fold_time_reintegrates():
    """The paper scenario's foldable cycle at 3 m/s with the definition's fold time: it
    converges, re-integrates with the same fold law within the reference acceptance, lasts at
    least a fold and an unfold, and its reference columns show the wing folding and opening."""
    pr = CycleProblem(scenario="paper", config="foldable", wind_speed=3.0, mesh=PAPER_MESH)
    res = solve_cycle(pr, coarse=None)
    assert res.ok, res.reason
    nlp = get_nlp(pr)[0]
    tf = nlp.model.fold_time
    assert tf > 0.0 and res.T2_s >= 2.0 * tf * (1 - 1e-9)
    v = verify(res, nlp)
    assert v.accurate(), (v.position_error_rel, v.energy_error_rel)
    assert v.nlp_max_violation < 1e-6
    c = res.columns
    rec = c["phase"] == 1
    t2 = c["t"][rec] - res.T1_s
    fold = c["fold"][rec]
    assert fold[0] == 0.0 and fold[-1] == pytest.approx(0.0, abs=1e-12)
    assert np.all(fold[(t2 >= tf) & (t2 <= res.T2_s - tf)] == 1.0)
    assert np.all(fold[t2 < tf * (1 - 1e-9)] < 1.0)
    assert np.all(c["fold"][c["phase"] == 0] == 0.0)


def test_fold_blend_is_symbolic():
    """The blend evaluates on CasADi symbols (the optimiser's transition points)."""
    glider = load_glider()
    f = ca.SX.sym("f")
    blend = fold_blend(glider.unfolded.aero, glider.folded.aero, f)
    fn = ca.Function("cl0", [f], [blend.CL0])
    assert float(fn(0.5)) == pytest.approx(fold_blend(glider.unfolded.aero, glider.folded.aero, 0.5).CL0, rel=1e-15)
