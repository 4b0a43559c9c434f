"""The lumped line integrated by linearly implicit Euler steps (``--tether lumped-implicit:N``)
against independent references and against the leapfrog line (``lumped:N``) it stands in for.

- its static shape (:func:`settle_implicit`, from the slack chord) is Irvine's elastic catenary;
- a line swept steadily about the winch gives the glider the leapfrog line's force (drag and
  weight shares within 1 %);
- a station with the line, its hook moved sideways at 10 m/s in 14 m/s wind: the force on the
  glider follows the leapfrog line's (mean within 1 %, fluctuation within 3 %), the line's ledger
  closes (the implicit step's numerical damping is its residual: below 0.1 % of the hook's work),
  and the compiled step equals the Python step bit for bit;
- a segment that goes taut or slack within a step: the step's end force is the one of the
  segments taut at its end (backward Euler of the piecewise-linear line, solved in closed form
  for one free node), not the one the step started with;
- the glider takes the work the line books at the hook (the line's mean pull over each step);
- a calm autopilot flight of one pumping cycle: the cycle's net energy within 2 % of the
  leapfrog line's; the compiled blocks fly it as the Python autopilot does, line shape included.

The tolerances: the implicit step damps the axial waves (they cross 150 m of line in 20 ms, so
the line answers them quasi-statically at 120 Hz) and the transverse modes above the step rate
(drag-dominated on this light line); the percent-level differences are what those modes carry.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.groundstation import lumped as L
from fdm_awe.groundstation import lumped_state as LS
from fdm_awe.groundstation.lumped_implicit import scratch_size
from fdm_awe.groundstation.substeps import CONST, STATE, STATION

from test_groundstation_lumped import _hook_force, _irvine, _winch_force

DATA = Path(__file__).parent / "data"


def _line(n: int, length: float, **kw) -> tuple[np.ndarray, np.ndarray]:
    gs = GroundStation(load_ground_station(line="sized"), tether=f"lumped-implicit:{n}")
    c = np.array(gs._sc)
    s = gs._s_all.copy()
    assert c[LS.LINE.scheme] == 1.0 and c[LS.LINE.h_implicit] == pytest.approx(1.0 / 120.0)
    c[LS.LINE.zeta] = kw.get("zeta", 0.0)
    c[STATION.drag_on] = 1.0 if kw.get("drag") else 0.0
    if not kw.get("gravity", True):
        c[STATION.g] = 0.0
    s[STATE.length] = length
    return s, c


def test_static_shape_is_the_elastic_catenary() -> None:
    n, span, height, L0 = 20, 150.0, 80.0, 171.0
    s, c = _line(n, L0)
    L.place_line(s, c, n, span, 0.0, -height)  # on the chord: every segment slack
    L.compiled_function("settle_implicit")(s, c, n, span, 0.0, -height)
    EA, wt = c[CONST.EA], c[CONST.mu] * c[STATION.g]
    H, V = _irvine(span, height, L0, EA, wt)
    top, bottom = _hook_force(s, c, n), _winch_force(s, c, n)
    assert np.linalg.norm(top - np.array([-H, 0.0, V])) < 0.01 * math.hypot(H, V)
    assert np.linalg.norm(bottom - np.array([H, 0.0, -(V - wt * L0)])) < 0.01 * math.hypot(H, V - wt * L0)
    assert np.abs(LS.velocities(s, n)).max() < 1e-3  # at rest


def _two_segments(gap: float, v_hook: float, zeta: float) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """A 2-segment line along x, no weight or drag: winch node at 0, the free node at rest at
    1 m, the hook at ``1 + ls - gap`` m (its segment ``gap`` m short of taut, negative: taut),
    the winch-side segment slack. Returns ``s, c``, the rest length, stiffness and damper."""
    n, ls = 2, 5.0
    s, c = _line(n, 2.0 * ls, zeta=zeta, gravity=False)
    P = LS.NODES
    s[P:P + 9] = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 + ls - gap, 0.0, 0.0)
    s[P + 9:P + 18] = 0.0
    m = c[CONST.mu] * ls
    L.compiled_function("line_forces")(s, c, n, ls, m, v_hook, 0.0, 0.0, ls)  # the start's forces
    k = c[CONST.EA] / ls
    return s, c, ls, k, 2.0 * zeta * math.sqrt(k * m)


@pytest.mark.parametrize("zeta", [0.0, 0.5])
def test_a_segment_caught_within_the_step_pulls_by_its_end_length(zeta: float) -> None:
    """The hook's segment 2 mm short of taut, the hook leaving at 5 m/s: taut after 0.4 ms of
    the 8.3 ms step. Backward Euler of the free node (mass m): ``m dv = h (k (d + h (v_h - dv)
    - ls) + c (v_h - dv))``; the step taking the segment as slack would leave the node at rest
    and the next force at ``k (h v_h - gap)`` (54 N on this 6.76 kN line)."""
    h, gap, vh = 1.0 / 120.0, 0.002, 5.0
    s, c, ls, k, cd = _two_segments(gap, vh, zeta)
    m = c[CONST.mu] * ls
    P = LS.NODES
    hook = s[P + 6] + h * vh
    w = np.empty(scratch_size(2))
    L.compiled_function("implicit_step")(s, c, 2, h, ls, ls, hook, 0.0, 0.0, w)
    d = ls - gap
    dv = h * (k * (d - ls + h * vh) + cd * vh) / (m + h * h * k + h * cd)
    assert dv > 0.5 * vh  # the node is pulled along, nearly at the hook's speed
    assert s[P + 9 + 3] == pytest.approx(dv, rel=1e-9)
    assert s[P + 3] == pytest.approx(1.0 + h * dv, rel=1e-12)
    stretch = hook - s[P + 3] - ls  # the end force: the node's mass taken to the hook's speed
    assert stretch == pytest.approx(-gap + h * (vh - dv), rel=1e-6)
    assert 0.0 < k * stretch < 0.1 * k * (h * vh - gap)


def test_a_segment_slack_by_the_steps_end_pulls_no_more() -> None:
    """The hook's segment 1 mm taut (6.8 N), the hook coming back at 5 m/s: slack after 0.2 ms.
    Backward Euler gives the free node no force over the step (it stays at rest); the step
    taking the start's tension would pull it on at h T / m."""
    h, vh = 1.0 / 120.0, -5.0
    s, c, ls, k, cd = _two_segments(-0.001, vh, 0.0)
    assert s[LS.NODES + 9 * 3] == 0.0 and s[LS.NODES + 9 * 3 + 1] == pytest.approx(k * 0.001)
    P = LS.NODES
    w = np.empty(scratch_size(2))
    L.compiled_function("implicit_step")(s, c, 2, h, ls, ls, s[P + 6] + h * vh, 0.0, 0.0, w)
    assert abs(s[P + 9 + 3]) < 1e-12 and s[P + 3] == 1.0


def _swept(scheme: str, gravity: bool) -> np.ndarray:
    """The force on the glider after 20 s of a hook circling the winch at 25 m/s, 150 m, 30 deg."""
    n, radius, speed = 20, 150.0, 25.0
    e = math.radians(30.0)
    r, zh = radius * math.cos(e), -radius * math.sin(e)
    om = speed / r
    hook = lambda t: (r * math.cos(om * t), r * math.sin(om * t), zh)
    gs = GroundStation(load_ground_station(line="sized"), tether=f"{scheme}:{n}")
    c = np.array(gs._sc)
    s = gs._s_all.copy()
    c[LS.LINE.zeta] = 0.05
    if not gravity:
        c[STATION.g] = 0.0
    s[STATE.length] = radius / (1.0 + 100.0 / 6760.0)
    ls = s[STATE.length] / n
    L.settle_line(s, c, n, *hook(0.0))
    dt, f = 1.0 / 120.0, np.zeros(3)
    if scheme == "lumped":
        steps = L.compiled_function("inner_steps")
        m = L.inner_count(c, dt, ls)
        for k in range(2400):
            f = np.array(steps(s, c, n, m, dt / m, ls, ls, *hook(k * dt), *hook((k + 1) * dt), 0.0)[:3]) / m
    else:
        step = L.compiled_function("implicit_step")
        w = np.empty(scratch_size(n))
        for k in range(2400):
            f = np.array(step(s, c, n, dt, ls, ls, *hook((k + 1) * dt), w)[:3])
    return f


@pytest.mark.parametrize("gravity", [False, True])
def test_swept_line_gives_the_leapfrog_force(gravity: bool) -> None:
    a, b = _swept("lumped", gravity), _swept("lumped-implicit", gravity)
    assert np.linalg.norm(a) > 10.0
    assert np.linalg.norm(b - a) < 0.01 * np.linalg.norm(a)


def _station_run(tether: str, jit: bool = True, seconds: float = 3.0):
    gs = GroundStation(load_ground_station(), wind_ned=(14.0, 0.0, 0.0), tether=tether)
    if not jit:
        gs._step_kernel = None
    gs.reset(tether_length=150.0, reel_speed=0.0, mode="motor")
    hold = WinchCommand(mode="motor", reel_speed_ref=0.0)
    e = math.radians(60.0)
    pos = np.array((150.0 * math.cos(e) * 1.003, 0.0, -150.0 * math.sin(e) * 1.003))
    vel = np.array((0.0, 10.0, 0.0))
    f, outs = [], []
    for _ in range(int(round(seconds * 120))):
        o = gs.step(1.0 / 120.0, tuple(pos.tolist()), tuple(vel.tolist()), hold)
        pos = pos + vel / 120.0
        f.append(o.force_xyz)
        outs.append(o)
    return np.array(f), gs, outs


def test_station_follows_the_leapfrog_line_and_its_ledger_closes() -> None:
    fa, _, _ = _station_run("lumped:30")
    fb, gs, _ = _station_run("lumped-implicit:30")
    assert np.linalg.norm(fa.mean(0)) > 30.0
    assert np.linalg.norm(fb.mean(0) - fa.mean(0)) < 0.01 * np.linalg.norm(fa.mean(0))
    sa, sb = fa[120:].std(0), fb[120:].std(0)
    assert np.linalg.norm(sb - sa) < 0.03 * np.linalg.norm(sa)
    led = gs.line_ledger.as_dict()
    assert led["hook_work"] > 100.0
    assert abs(led["residual"]) < 1e-3 * led["hook_work"]
    assert abs(led["coupling"]) < 0.01 * led["payout_work"]
    assert float(gs._s_all[LS.HEAD.inner]) * gs._substeps(1.0 / 120.0) == 1.0  # one implicit step per flight step


def test_the_glider_takes_the_work_the_line_books() -> None:
    """The force on the glider is the line's mean pull over each step (the mean of its pulls at
    the step's start and end) besides its half drag and half weight: the work it does on the
    glider over the hook's path is the hook work the line's ledger books, to rounding."""
    gs = GroundStation(load_ground_station(), wind_ned=(14.0, 0.0, 0.0), tether="lumped-implicit:30")
    gs.reset(tether_length=150.0, reel_speed=0.0, mode="motor")
    hold = WinchCommand(mode="motor", reel_speed_ref=0.0)
    e, dt = math.radians(60.0), 1.0 / 120.0
    pos = np.array((150.0 * math.cos(e) * 1.003, 0.0, -150.0 * math.sin(e) * 1.003))
    vel = np.array((0.0, 10.0, -2.0))
    work = 0.0
    H = LS.HEAD
    for _ in range(240):
        o = gs.step(dt, tuple(pos.tolist()), tuple(vel.tolist()), hold)
        s = gs._s_all
        pull = np.array(o.force_xyz) - np.array((s[H.drag_x], s[H.drag_y], s[H.drag_z] + s[H.weight_z]))
        work += float(pull @ (vel * dt))
        pos = pos + vel * dt
    hook = gs.line_ledger.as_dict()["hook_work"]
    assert abs(hook) > 50.0
    assert work == pytest.approx(-hook, rel=1e-9)


def test_compiled_and_python_station_steps_are_bit_identical() -> None:
    fa, ga, oa = _station_run("lumped-implicit:6", jit=True, seconds=0.5)
    fb, gb, ob = _station_run("lumped-implicit:6", jit=False, seconds=0.5)
    assert oa == ob and np.array_equal(fa, fb)
    assert np.array_equal(ga.line_nodes(), gb.line_nodes()) and np.array_equal(ga.line_tensions(), gb.line_tensions())
    assert ga.line_ledger.as_dict() == gb.line_ledger.as_dict()


def test_flight_energy_matches_the_leapfrog_line_and_blocks_fly_as_python() -> None:
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")
    a = fly(ref, config="nominal", cycles=1, tether="lumped:30")
    b = fly(ref, config="nominal", cycles=1, tether="lumped-implicit:30")
    assert a.status == b.status == "ok" and a.cycles[0].complete and b.cycles[0].complete
    ea, eb = a.cycles[0].E_net_J, b.cycles[0].E_net_J
    assert abs(ea) > 100.0 and abs(eb - ea) < 0.02 * abs(ea)
    # the compiled autopilot flies blocks with a line shape; the Python autopilot every step
    c = fly(ref, config="nominal", cycles=1, tether="lumped-implicit:30", on_step=lambda k, s, o: None)
    if b.loop["loop"] == "compiled":
        assert b.loop["autopilot_compiled_steps"] > 0.9 * b.result.steps
    assert c.loop["autopilot_compiled_steps"] == 0
    assert np.array_equal(b.result.data, c.result.data, equal_nan=True)
    for k in ("t", "nodes", "tension"):
        assert np.array_equal(b.line_shape[k], c.line_shape[k])
