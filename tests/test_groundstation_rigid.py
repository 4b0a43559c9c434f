"""The rigid line (fdm_awe.groundstation.rigid, ``--tether rigid``) against independent references.

- steady reel-out, generator on its passive load: the glider flies radially out at constant
  speed; the drum turns at that speed, the tension and the powers are the steady relations'
  (:func:`fdm_awe.groundstation.generator_at_speed`, written apart from the integrator), the
  line's stretch is the tension over its stiffness, and the energies balance;
- steady reel-in on an open-loop duty: current and armature voltage are the motor's steady
  relation (:func:`fdm_awe.groundstation.motor_steady`) at the measured tension;
- inextensible: after a step of the glider's radial speed the rigid line carries the new
  steady tension within a quarter second, where the elastic line is still stretching;
- the stiff limit tends to the inextensible line as the step shrinks (k ~ 1/dt^2);
- the optimiser's nominal cycle flown in 6-DOF on it: the flight tracks as on the elastic line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.groundstation import GroundStation, WinchCommand, generator_at_speed, load_ground_station, motor_steady
from fdm_awe.groundstation import rigid

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

DT = 1.0 / 120.0
EL = math.radians(30.0)
U = np.array([math.cos(EL), 0.0, -math.sin(EL)])  # winch -> glider


def _station(tether: str = "rigid") -> GroundStation:
    return GroundStation(load_ground_station(line="sized"), wind_ned=(0.0, 0.0, 0.0), tether=tether)


def _radial(gs: GroundStation, d0: float, speeds: list[float], seconds: float, cmd: WinchCommand, dt: float = DT):
    """Fly the hook along ``U`` from ``d0`` m, at ``speeds[0]`` m/s and from half-time at
    ``speeds[-1]``; the outputs of every step."""
    out = []
    d = d0
    steps = int(round(seconds / dt))
    for k in range(steps):
        v = speeds[0] if k < steps // 2 else speeds[-1]
        out.append(gs.step(dt, tuple((U * d).tolist()), tuple((U * v).tolist()), cmd))
        d += v * dt
    return out


@pytest.mark.parametrize("v", [2.0, 4.0])
def test_steady_reel_out_is_the_generator_relation(v: float) -> None:
    gs = _station()
    gsp = gs.params
    ref = generator_at_speed(v, gsp)
    gs.reset(gs.unstretched_length(200.0, ref.tension), v, "generator")
    out = _radial(gs, 200.0, [v], 2.0, WinchCommand("generator"))
    o = out[-1]
    assert abs(o.reel_speed - v) < 1e-9  # the drum turns at the glider's radial speed
    assert abs(o.tension - ref.tension) < 1e-7 * ref.tension
    assert abs(o.current - ref.current) < 1e-7 * ref.current
    assert abs(o.p_electrical - ref.p_load) < 1e-7 * ref.p_load  # generator: all of it into the load
    assert abs(o.p_mechanical - ref.tension * v) < 1e-7 * ref.p_mech
    # the length is the distance, short by the stretch T / k
    d_end = o.distance + v * DT
    assert abs((d_end - o.length) - ref.tension / rigid.STIFFNESS) < 1e-6
    # power balance: the glider's work goes into the load at the steady efficiency, and the
    # station's ledger closes
    led = gs.ledger
    assert led.relative_residual() < 1e-9
    assert abs(led.load / led.glider_work - ref.efficiency) < 2e-3


def test_steady_reel_in_is_the_motor_relation() -> None:
    """The duty of the motor's steady relation for 20 N at 2 m/s reel-in holds 20 N on the rigid line."""
    gs = _station()
    gsp = gs.params
    v_in, tension = 2.0, 20.0
    ref = motor_steady(v_in, tension, gsp)
    assert 0.0 < ref.duty < 1.0
    gs.reset(200.0 - tension / rigid.STIFFNESS, -v_in, "motor")
    out = _radial(gs, 200.0, [-v_in], 2.0, WinchCommand("motor", reel_speed_ref=-v_in, duty=ref.duty))
    o = out[-1]
    assert abs(o.reel_speed + v_in) < 1e-9 and not o.slack
    assert abs(o.tension - tension) < 1e-6 * tension
    assert abs(o.current - ref.current) < 1e-6 * ref.current
    assert abs(-o.p_electrical - ref.p_supply) < 1e-6 * ref.p_supply  # drawn from the supply
    assert gs.ledger.relative_residual() < 1e-9


def test_inextensible_the_drum_follows_a_speed_step_at_once() -> None:
    """2 -> 4 m/s at half-time: 0.25 s later the rigid line is within 2 % of the new steady
    tension; the elastic line of the same station is still more than 10 % off."""
    gsp = load_ground_station(line="sized")
    t_new = generator_at_speed(4.0, gsp).tension
    err = {}
    for tether in ("rigid", "straight"):
        gs = _station(tether)
        gs.reset(gs.unstretched_length(200.0, generator_at_speed(2.0, gsp).tension), 2.0, "generator")
        out = _radial(gs, 200.0, [2.0, 4.0], 4.0, WinchCommand("generator"))
        k = len(out) // 2 + int(round(0.25 / DT))
        err[tether] = abs(out[k].tension - t_new) / t_new
        assert gs.ledger.relative_residual() < 1e-9
    assert err["rigid"] < 0.02 < 0.10 < err["straight"]


def test_stiff_limit_tends_to_the_inextensible_line() -> None:
    c = [0.0] * rigid.RIGID.stiffness + [rigid.STIFFNESS, rigid.REFERENCE_STEP]
    assert rigid.stiffness(c, DT) == rigid.STIFFNESS
    assert rigid.stiffness(c, DT / 4) == pytest.approx(16 * rigid.STIFFNESS, rel=1e-12)
    v = 3.0
    stretch = []
    for dt in (DT, DT / 4):
        gs = _station()
        ref = generator_at_speed(v, gs.params)
        gs.reset(200.0 - ref.tension / rigid.stiffness(gs._scl, dt), v, "generator")
        o = _radial(gs, 200.0, [v], 1.0, WinchCommand("generator"), dt=dt)[-1]
        assert abs(o.tension - ref.tension) < 1e-6 * ref.tension
        stretch.append(o.distance + v * dt - o.length)
    assert stretch[1] == pytest.approx(stretch[0] / 16, rel=1e-6) and 0.0 < stretch[0] < 0.05


def test_the_nominal_cycle_flies_on_the_rigid_line_as_on_the_elastic_one() -> None:
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json")
    rep = {t: fly(ref, config="nominal", cycles=1, t_end=20.0, tether=t) for t in ("rigid", "straight")}
    r, s = rep["rigid"], rep["straight"]
    assert r.status == s.status == "ok" and r.tether == "rigid"
    assert r.loop["loop"] == "compiled" or r.loop["reason"]  # the registry's code flies the kernel
    rms = {t: float(np.sqrt(np.nanmean(rep[t].track_error ** 2))) for t in rep}
    assert rms["rigid"] < rms["straight"] + 0.3 and rms["rigid"] < 1.5
    tr, ts = np.nanmean(r.result.tension[1:]), np.nanmean(s.result.tension[1:])
    assert abs(tr - ts) < 0.05 * ts
    assert abs(r.ledger["station_residual_J"]) < 1e-6 * max(abs(r.ledger["station_glider_work_J"]), 1.0)
    # the length is the distance (of the glider's centre: the hook sits a few cm off it) to
    # within the stretch of the largest tension
    res = r.result
    gap = np.linalg.norm(res.pos[1:], axis=1) - res.length[1:]
    assert np.nanmax(np.abs(gap)) < float(np.nanmax(res.tension)) / rigid.STIFFNESS + 0.03
