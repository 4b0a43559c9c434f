"""The thrust bound ``T <= T_avail(V)`` acts only while the motor can push: the full-throttle
thrust of the 9x5 propeller falls to zero at 27.35 m/s and is never negative, so above that
speed the bound holds the thrust at zero and caps no airspeed (a stopped propeller limits
nothing). Checked on the fit and on the NLP's own constraint rows at a point of the cycle flown
at 30 m/s with the motor off."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.ocp.model import ON_FRACTION
from fdm_awe.ocp.problem import Bounds, CycleProblem, Mesh
from fdm_awe.ocp.build import get_nlp

#: the speed [m/s] where the propeller's full-throttle thrust fit crosses zero
V_ZERO_THRUST = 27.35


def test_thrust_available_is_never_negative():
    """The fit gives thrust below 27.35 m/s, zero above it, on floats and CasADi symbols."""
    prop = load_glider().unfolded.propulsion
    assert prop.thrust_available(20.0) > 1.0
    assert prop.thrust_available(V_ZERO_THRUST - 0.05) > 0.0
    V = ca.SX.sym("V")
    f = ca.Function("T_avail", [V], [prop.thrust_available(V)])
    for v in (V_ZERO_THRUST + 0.05, 30.0, 40.0):
        assert prop.thrust_available(v) == 0.0
        assert float(f(v)) == 0.0
    assert float(f(20.0)) == pytest.approx(prop.thrust_available(20.0), rel=1e-12)


@pytest.mark.parametrize("propeller", ["engine", "momentum"])
def test_airspeed_above_the_zero_thrust_speed_is_admissible_with_the_motor_off(propeller):
    """With the airspeed bound at 40 m/s, every point of the cycle flown at 30 m/s with zero
    thrust (the on-fraction 0 where the drive has a motor-off mode) satisfies the NLP's thrust
    rows: the airspeed bound, not the propeller, decides how fast the glider may fly."""
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, propeller=propeller,
                      bounds=Bounds(V_max=40.0), mesh=Mesh(4, 4, 2)).validate()
    nlp = get_nlp(pr, cache=False)[0]
    phases = nlp.unpack(0.5 * (nlp.lbw + nlp.ubw))
    guesses = []
    for ph in phases:
        x = np.array(ph["X"][0], float)
        x[3] = 30.0
        u = np.zeros(len(ph["controls"]))
        if ph["controls"][-1] == ON_FRACTION:
            u[-1] = 0.0  # motor off
        guesses.append({"T": 10.0, "state": lambda t, x=x: x, "control": lambda t, u=u: u})
    w = nlp.pack(guesses)
    params = nlp.params((0.0, -8.0))
    g = np.array(nlp.g_fn(w, params)).ravel()
    rows = [i for i, n in enumerate(nlp.g_names) if n.startswith("thrust_avail_")]
    assert len(rows) >= nlp.problem.mesh.n_gen + nlp.problem.mesh.n_rec
    assert np.all(g[rows] >= nlp.lbg[rows]), [nlp.g_names[i] for i in rows if g[i] < nlp.lbg[i]]
    # the same point at 30 m/s with the motor pushing is not admissible: the bound still
    # holds the thrust at what the propeller gives (nothing)
    for gs, ph in zip(guesses, nlp.phases):
        u = np.zeros(len(ph.controls))
        u[2] = 0.5
        if ph.controls[-1] == ON_FRACTION:
            u[-1] = 1.0
        gs["control"] = lambda t, u=u: u
    g1 = np.array(nlp.g_fn(nlp.pack(guesses), params)).ravel()
    assert np.all(g1[rows] < nlp.lbg[rows])
