"""A reference's smoothness bounds: the bank's and the angle of attack's rate between
neighbouring intervals (around the whole cycle, across both phase switches) and the slack
line's catch at the end of recovery (Bounds.bank_rate_max, alpha_rate_max, catch_speed_max).

Checked on a solved cycle against the bounds, with the catch's closing speed computed here from
the states (position, airspeed, angles, wind), independently of the model's code; and the rows
are shown to be real: a solution pushed across a bound is reported as violating that row.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.ocp.problem import Bounds, CycleProblem, Mesh
from fdm_awe.ocp.build import get_nlp
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.pointmass.model import wind_vector

COARSE = Mesh(20, 12, 3)
BANK_RATE, ALPHA_RATE, CATCH = 0.3, 0.1, 1.0  # rad/s, rad/s, m/s
#: bound tolerance: IPOPT's constraint tolerance on rows scaled by O(1)
TOL = 1e-6


@pytest.mark.parametrize("field, value", [("bank_rate_max", 0.0), ("alpha_rate_max", -0.1),
                                          ("bank_rate_max", math.inf), ("catch_speed_max", -1.0),
                                          ("catch_speed_max", math.nan)])
def test_bad_bounds_are_refused_with_their_name(field, value):
    with pytest.raises(InputError, match=field):
        Bounds(**{field: value}).validate()


def test_the_bounds_add_rows_only_when_set():
    plain = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE)
    names = get_nlp(plain)[0].g_names
    assert not [n for n in names if n.startswith("rate_") or n == "catch"]
    bounded = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE,
                           bounds=Bounds(bank_rate_max=BANK_RATE, alpha_rate_max=ALPHA_RATE, catch_speed_max=CATCH))
    names = get_nlp(bounded)[0].g_names
    n = COARSE.n_gen + COARSE.n_rec  # neighbouring pairs around the cycle
    for c in ("phi", "alpha"):
        assert len([x for x in names if x.startswith(f"rate_{c}_up_")]) == n
        assert len([x for x in names if x.startswith(f"rate_{c}_down_")]) == n
    assert names.count("catch") == 1


@pytest.fixture(scope="module")
def smooth():
    b = Bounds(cl_margin=0.85, phi_max=0.8, bank_rate_max=BANK_RATE, alpha_rate_max=ALPHA_RATE, catch_speed_max=CATCH)
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE, bounds=b)
    res = solve_cycle(pr)
    assert res.ok, res.reason
    return pr, res


def _cycle_controls(res, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The control ``name`` of every interval around the cycle and the intervals' lengths [s]."""
    u, h = [], []
    for ph in res.phases:
        u.append(ph["U"][:, list(ph["controls"]).index(name)])
        h.append(np.diff(ph["t_nodes"]))
    return np.concatenate(u), np.concatenate(h)


def test_bank_and_alpha_change_within_their_rates_around_the_cycle(smooth):
    _, res = smooth
    for name, rate in (("phi", BANK_RATE), ("alpha", ALPHA_RATE)):
        u, h = _cycle_controls(res, name)
        step = np.abs(np.roll(u, -1) - u)  # the last pair: recovery's end to the next generation's start
        reach = rate * 0.5 * (h + np.roll(h, -1))
        assert np.all(step <= reach + TOL), (name, float(np.max(step - reach)))


def test_the_line_goes_taut_within_the_catch_speed(smooth):
    """Closing speed at the end of recovery: the distance rate from the final state's ground
    velocity (airspeed along its flight-path angle and heading, plus the uniform wind) minus
    the last interval's reel speed."""
    pr, res = smooth
    rec = res.phases[1]
    x, y, z, V, gamma, psi, _ = rec["X"][-1]
    wn, we, _ = wind_vector(pr.wind_speed, pr.wind_from_deg)
    v = np.array([V * math.cos(gamma) * math.cos(psi) + wn, V * math.cos(gamma) * math.sin(psi) + we,
                  -V * math.sin(gamma)])
    p = np.array([x, y, z])
    ddot = float(p @ v / np.linalg.norm(p))
    v_reel = float(rec["U"][-1, list(rec["controls"]).index("v_reel")])
    assert ddot - v_reel <= CATCH + TOL
    # the generation that follows pays out (ddot >= 0) and the recovery reeled in (<= 0)
    assert ddot >= -TOL and v_reel <= TOL


def test_a_solution_pushed_across_a_bound_violates_its_row(smooth):
    pr, res = smooth
    nlp = get_nlp(pr)[0]
    params = nlp.params(wind_vector(pr.wind_speed, pr.wind_from_deg)[:2], 1.0, res.k_wrap, 1.0)
    viol, _ = nlp.constraint_violation(res.w, params)
    assert viol < 1e-5
    gen = nlp.phases[0]
    i_phi = gen.controls.index("phi")
    w = res.w.copy()
    w[gen.idx_U[5, i_phi]] = w[gen.idx_U[4, i_phi]] + 1.5  # scaled by 1 rad: a 1.5 rad jump (reach ~0.7 rad)
    g = np.array(nlp.g_fn(w, params)).ravel()
    up, down = nlp.g_names.index("rate_phi_up_p0_4"), nlp.g_names.index("rate_phi_down_p0_4")
    assert g[up] > nlp.ubg[up] + 0.3  # the change from interval 4 to 5 exceeds its reach
    assert g[down] >= nlp.lbg[down]
    g0 = np.array(nlp.g_fn(res.w, params)).ravel()
    assert g0[up] <= nlp.ubg[up] + TOL
