"""The lumped-mass tether (fdm_awe.groundstation.lumped) against independent references.

- the static elastic catenary under its own weight (Irvine's closed form): node positions,
  sag and both end forces;
- a line in a uniform cross flow with its ends held (normal drag only): the tension is uniform
  and the shape is a catenary of parameter T / q (q the drag per length of the flow normal to
  the line), its arc the stretched line;
- energy conservation with drag and damping off (ends held, hook moved, line reeled), and the
  line's ledger closing;
- the glider-end force of a line swept steadily about the winch against the straight line's
  1/4 drag and 1/2 weight shares;
- ``--tether`` parsing: one-line errors; a station with the lumped line in a co-simulation step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from fdm_awe.errors import InputError
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.groundstation import lumped as L
from fdm_awe.groundstation import lumped_forces as LF
from fdm_awe.groundstation import lumped_state as LS
from fdm_awe.groundstation.linemodels import parse_tether
from fdm_awe.groundstation.substeps import CONST, STATE, STATION

G_IDX, DRAG_ON, WIND = STATION.g, STATION.drag_on, slice(STATION.wind, STATION.wind + 3)


def _line(n: int, length: float, *, drag: bool = False, gravity: bool = True, zeta: float = 0.0,
          wind: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray, GroundStation]:
    """State and constants of an ``n``-segment line of unstretched ``length`` m (the sized line)."""
    gs = GroundStation(load_ground_station(line="sized"), tether=f"lumped:{n}")
    c = np.array(gs._sc)
    s = gs._s_all.copy()
    c[LS.LINE.zeta] = zeta
    c[DRAG_ON] = 1.0 if drag else 0.0
    if not gravity:
        c[G_IDX] = 0.0
    c[WIND] = wind
    s[STATE.length] = length
    return s, c, gs


def _hook_force(s: np.ndarray, c: np.ndarray, n: int) -> np.ndarray:
    """Force of the line on the hook support (the last segment's tension plus the half node
    mass's weight), N NED."""
    nd = LS.nodes(s, n)
    T = LS.tensions(s, n)
    u = (nd[-1] - nd[-2]) / np.linalg.norm(nd[-1] - nd[-2])
    return -T[-1] * u + np.array([0.0, 0.0, 0.5 * c[CONST.mu] * s[STATE.length] / n * c[G_IDX]])


def _winch_force(s: np.ndarray, c: np.ndarray, n: int) -> np.ndarray:
    nd = LS.nodes(s, n)
    T = LS.tensions(s, n)
    u = (nd[1] - nd[0]) / np.linalg.norm(nd[1] - nd[0])
    return T[0] * u + np.array([0.0, 0.0, 0.5 * c[CONST.mu] * s[STATE.length] / n * c[G_IDX]])


# ---------------------------------------------------------------- input checks

@pytest.mark.parametrize("bad", ["lumped", "lumped:", "lumped:1", "lumped:201", "lumped:x", "lumped:-3", "curved", 3,
                                 None])
def test_tether_spec_errors_are_one_line(bad: object) -> None:
    with pytest.raises(InputError) as e:
        parse_tether(bad)
    msg = str(e.value)
    assert "\n" not in msg and "--tether" in msg and "lumped:N" in msg and "2 .. 200" in msg


def test_tether_spec_values() -> None:
    assert parse_tether("straight").param == 0 and parse_tether("straight").name == "straight"
    assert parse_tether("lumped:2").param == 2 and parse_tether("lumped:30").param == 30
    assert parse_tether("lumped:30").name == "lumped" and str(parse_tether("lumped:30")) == "lumped:30"
    with pytest.raises(InputError):
        GroundStation(load_ground_station(line="sized"), tether="lumped:0")


# ---------------------------------------------------------------- static catenary

def _irvine(span: float, height: float, L0: float, EA: float, w: float) -> tuple[float, float]:
    """Horizontal tension H and vertical force at the upper support V (N) of the elastic
    catenary (Irvine, Cable Structures, 1981) of unstretched length L0 m and weight w N/m per
    unstretched length between supports ``span`` m apart horizontally, the upper ``height`` m up."""
    W = w * L0

    def eqs(v: np.ndarray) -> list[float]:
        H, V = v
        return [H * L0 / EA + H / w * (math.asinh(V / H) - math.asinh((V - W) / H)) - span,
                W * L0 / EA * (V / W - 0.5) + H / w * (math.sqrt(1 + (V / H) ** 2) - math.sqrt(1 + ((V - W) / H) ** 2))
                - height]

    H, V = fsolve(eqs, [2.0 * W, W], xtol=1e-13)
    assert max(abs(e) for e in eqs(np.array([H, V]))) < 1e-9
    return float(H), float(V)


@pytest.mark.parametrize("n", [20, 40])
def test_static_catenary_matches_the_elastic_closed_form(n: int) -> None:
    span, height, L0 = 150.0, 80.0, 171.0  # chord 170 m: a sagging line
    s, c, gs = _line(n, L0)
    L.place_line(s, c, n, span, 0.0, -height)
    L.compiled_function("relax_line")(s, c, n, 40.0)
    EA, w = c[CONST.EA], c[CONST.mu] * c[G_IDX]
    H, V = _irvine(span, height, L0, EA, w)
    Vb = V - w * L0

    def shape(sv: float) -> tuple[float, float]:  # from the lower (winch) end, unstretched arc s
        x = H * sv / EA + H / w * (math.asinh((Vb + w * sv) / H) - math.asinh(Vb / H))
        zu = w * sv / EA * (Vb / w + sv / 2) + H / w * (math.sqrt(1 + ((Vb + w * sv) / H) ** 2)
                                                          - math.sqrt(1 + (Vb / H) ** 2))
        return x, zu

    nd = LS.nodes(s, n)
    sag = max(abs(shape(i * L0 / n)[1] - height * shape(i * L0 / n)[0] / span) for i in range(n + 1))
    sag_lumped = max(abs(-nd[i, 2] - height * nd[i, 0] / span) for i in range(n + 1))
    err = max(math.hypot(nd[i, 0] - shape(i * L0 / n)[0], -nd[i, 2] - shape(i * L0 / n)[1]) for i in range(n + 1))
    assert sag > 5.0  # a real sag
    assert abs(sag_lumped - sag) < 0.01 * sag
    assert err < 0.01 * sag
    top = _hook_force(s, c, n)  # on the upper support: (H, 0, V) pulling towards the winch and down
    bottom = _winch_force(s, c, n)
    assert np.linalg.norm(top - np.array([-H, 0.0, V])) < 0.01 * math.hypot(H, V)
    assert np.linalg.norm(bottom - np.array([H, 0.0, -Vb])) < 0.01 * math.hypot(H, Vb)


# ---------------------------------------------------------------- cross flow

def test_cross_flow_shape_is_the_normal_drag_catenary() -> None:
    n, chord, L0, U = 30, 100.0, 100.3, 12.0
    s, c, gs = _line(n, L0, drag=True, gravity=False, wind=(U, 0.0, 0.0))
    L.place_line(s, c, n, 0.0, chord, 0.0)
    L.compiled_function("relax_line")(s, c, n, 40.0)
    T = LS.tensions(s, n)
    assert T.min() > 0.99 * T.max()  # normal load only: a uniform tension
    EA = c[CONST.EA]
    q = -c[LS.LINE.drag_k] * U * U  # N/m of stretched line, flow normal to the line
    # the exact shape: tan(phi) = (q/T) s from the middle, a catenary of parameter T/q whose
    # arc is the line stretched by T/EA

    def arc_gap(Tv: float) -> float:
        a = q / Tv
        return 2.0 * math.sinh(a * chord / 2.0) / a - L0 * (1.0 + Tv / EA)

    T_ref = brentq(arc_gap, 1.0, 1e4)
    a = q / T_ref
    sag_ref = (math.cosh(a * chord / 2.0) - 1.0) / a
    nd = LS.nodes(s, n)
    sag = nd[:, 0].max()
    assert abs(T.mean() - T_ref) < 0.01 * T_ref
    assert abs(sag - sag_ref) < 0.01 * sag_ref
    # every node on the reference curve x = (cosh(a (y - chord/2)) - cosh(a chord/2)) / a (mirrored: downwind)
    xs = -(np.cosh(a * (nd[:, 1] - chord / 2.0)) - math.cosh(a * chord / 2.0)) / a
    assert np.max(np.abs(nd[:, 0] - xs)) < 0.01 * sag_ref
    # the glider end takes half of the drag of the line standing in the wind (the straight line's
    # share, taken from the glider's air velocity, puts a quarter there)
    # (exactly: T sin(phi_end), tan(phi_end) = a arc / 2)
    f = _run(s, c, n, 1.0 / 120.0, lambda t: (0.0, chord, 0.0), lambda t: L0)  # line, half drag, half weight
    half_arc = 0.5 * L0 * (1.0 + T_ref / EA)
    fx_ref = T_ref * a * half_arc / math.sqrt(1.0 + (a * half_arc) ** 2)
    assert abs(f[0] - fx_ref) < 0.01 * fx_ref
    assert fx_ref > 0.45 * q * 2.0 * half_arc  # about half of the line's drag, not the straight line's quarter


# ---------------------------------------------------------------- energy

def _run(s: np.ndarray, c: np.ndarray, n: int, seconds: float, hook: callable, length: callable,
         dt: float = 1.0 / 120.0) -> np.ndarray:
    """Fly the line alone: hook position ``hook(t)`` m, unstretched length ``length(t)`` m.
    Returns the mean force on the glider over the last step, N NED."""
    steps = L.compiled_function("inner_steps")
    t = 0.0
    f = np.zeros(3)
    while t < seconds - 1e-9:
        h0, h1 = hook(t), hook(t + dt)
        l0, l1 = length(t), length(t + dt)
        m = L.inner_count(c, dt, min(l0, l1) / n)
        out = steps(s, c, n, m, dt / m, l0 / n, l1 / n, *h0, *h1, 0.0)
        f = np.array(out[:3]) / m
        s[STATE.length] = l1
        t += dt
    L.store_energies(s, c, n, 1)
    return f


@pytest.mark.parametrize("moving", [False, True])
def test_energy_is_conserved_with_drag_and_damping_off(moving: bool) -> None:
    n, L0 = 20, 120.0
    s, c, gs = _line(n, L0, zeta=0.0)
    hook0 = (80.0, 0.0, -90.0)  # chord 120.4 m: a taut line released straight, it swings and rings
    L.place_line(s, c, n, *hook0)
    L.store_energies(s, c, n, 0)
    led = LS.LineLedger(s)
    if moving:  # the hook on a circle, the line reeled out and in again
        hook = lambda t: (80.0 * math.cos(0.3 * t), 80.0 * math.sin(0.3 * t), -90.0 - 0.5 * math.sin(0.5 * t))
        length = lambda t: L0 + 0.5 * math.sin(0.4 * t)
    else:
        hook = lambda t: hook0
        length = lambda t: L0
    _run(s, c, n, 10.0, hook, length)
    e0 = led.stored0_kinetic + led.stored0_elastic + led.stored0_potential
    big = max(led.largest_term(), led.stored0_elastic)
    assert led.stored0_elastic > 1.0  # joules ringing in the line
    assert abs(led.residual()) < 1e-3 * big
    assert led.drag == 0.0 and led.damping == 0.0
    if not moving:  # nothing in, nothing out: the line's energy stays
        e1 = led.stored_kinetic + led.stored_elastic + led.stored_potential
        assert abs(e1 - e0) < 1e-3 * big
        assert led.hook_work == 0.0 and led.payout_work == 0.0


# ---------------------------------------------------------------- shares at steady flight

def _swept_line(n: int, *, drag: bool, gravity: bool, radius: float = 150.0, elev: float = 30.0,
                speed: float = 25.0, seconds: float = 30.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A line whose hook circles the winch at constant elevation and ``speed`` m/s (the line
    swept steadily, still air): the force on the glider and the hook's position and velocity
    at the end."""
    e = math.radians(elev)
    r, zh = radius * math.cos(e), -radius * math.sin(e)
    w = speed / r
    hook = lambda t: (r * math.cos(w * t), r * math.sin(w * t), zh)
    s, c, gs = _line(n, radius / (1.0 + 100.0 / 6760.0), drag=drag, gravity=gravity, zeta=0.05)
    L.place_line(s, c, n, *hook(0.0))
    L.compiled_function("relax_line")(s, c, n, 3.0)
    l_fixed = float(s[STATE.length])
    f = _run(s, c, n, seconds, hook, lambda t: l_fixed)  # line, half drag and half node weight
    p = np.array(hook(seconds))
    v = np.array([-w * p[1], w * p[0], 0.0])
    return f, p, v, c


def test_glider_end_force_against_the_straight_line_shares() -> None:
    n, radius, speed = 20, 150.0, 25.0
    # drag only: the force normal to the chord against the motion, as a share of the whole line's
    # drag at the glider's speed (straight line, velocity growing linearly along it: 1/4)
    f, p, v, c = _swept_line(n, drag=True, gravity=False, radius=radius, speed=speed)
    u = p / np.linalg.norm(p)
    full_drag = -c[LS.LINE.drag_k] * radius * speed * speed
    share_drag = -(f - (f @ u) * u) @ (v / speed) / full_drag
    assert 0.225 < share_drag < 0.275  # within 10 % of the straight line's 1/4
    # weight: what adding it changes in the force normal to the chord, as a share of the
    # weight's normal part (the drag damps the line's swinging in both runs)
    f_w, p, v, c = _swept_line(n, drag=True, gravity=True, radius=radius, speed=speed)
    W = c[CONST.mu] * radius * c[G_IDX]
    down = np.array([0.0, 0.0, 1.0])
    w_perp = down - (down @ u) * u
    df = f_w - f
    share_weight = (df - (df @ u) * u) @ w_perp / (W * np.linalg.norm(w_perp) ** 2)
    assert 0.45 < share_weight < 0.55  # within 10 % of the straight line's 1/2


# ---------------------------------------------------------------- the station with the lumped line

def test_station_step_python_and_compiled_agree_and_the_ledgers_close() -> None:
    gsp = load_ground_station(line="sized")
    outs = []
    for jit in (True, False):
        gs = GroundStation(gsp, tether="lumped:4")
        if not jit:
            gs._step_kernel = None
        gs.reset(tether_length=100.0, reel_speed=1.0, mode="generator")
        cmd = WinchCommand(mode="generator")
        pos = np.array([60.0, 0.0, -81.0])
        vel = np.array([0.0, 20.0, -1.0])
        for k in range(60):
            o = gs.step(1.0 / 120.0, tuple(pos.tolist()), tuple(vel.tolist()), cmd)
            pos = pos + vel / 120.0
        outs.append((o, gs.line_nodes(), gs.line_tensions(), gs.ledger.residual(), gs.line_ledger.as_dict()))
    (a, na, ta, ra, la), (b, nb, tb, rb, lb) = outs
    assert a == b
    assert np.array_equal(na, nb) and np.array_equal(ta, tb)
    assert la == lb
    assert a.tension > 0.0 and np.linalg.norm(a.force_on_glider_ned) > 0.0
    assert abs(ra) < 1e-9 and la["relative_residual"] < 1e-3
    assert abs(la["coupling"]) < 0.05 * abs(la["payout_work"]) + 1e-6


def test_flight_with_the_lumped_line_records_its_shape(tmp_path) -> None:
    from pathlib import Path

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight_log import LINE_SHAPE_HZ
    from fdm_awe.sim.flight import fly
    from fdm_awe.recording import record_flight

    ref = TrackingReference.from_ocp_file(Path(__file__).parent / "data" / "ref_physical_nominal_8mps_sized.json")
    rep = fly(ref, config="nominal", cycles=1, t_end=5.0, tether="lumped:6")
    assert rep.tether == "lumped:6" and rep.as_json()["tether"] == "lumped:6"
    sh = rep.line_shape
    m = len(sh["t"])
    assert m >= int(5.0 * LINE_SHAPE_HZ) - 1
    assert sh["nodes"].shape == (m, 7, 3) and sh["tension"].shape == (m, 6)
    assert np.allclose(sh["nodes"][:, 0], 0.0)  # the winch node at the origin
    assert np.all(sh["tension"] >= 0.0)
    led = rep.ledger
    assert abs(led["line_residual_J"]) < 1e-3 * max(abs(led["line_hook_work_J"]), abs(led["line_drag_J"]), 1e-9)
    out = record_flight(rep, ref, tmp_path / "lumped.rrd")
    assert out.stat().st_size > 0


def test_compiled_and_python_loops_fly_the_lumped_line_alike() -> None:
    from pathlib import Path

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(Path(__file__).parent / "data" / "ref_physical_nominal_8mps_sized.json")
    loops, data = [], []
    for compiled in (None, False):
        def setup(ap, sim, compiled=compiled):
            sim.compiled = compiled
            loops.append(sim)

        rep = fly(ref, config="nominal", cycles=1, t_end=2.0, tether="lumped:5", setup=setup)
        data.append((rep.result.data, rep.line_shape["nodes"]))
    assert [s.loop for s in loops] == ["compiled", "python"]
    assert np.array_equal(data[0][0], data[1][0], equal_nan=True)
    assert np.array_equal(data[0][1], data[1][1])


def test_nodes_see_the_wind_profile_at_their_own_height_plus_the_gust() -> None:
    """With a log profile every node's wind is the reference wind scaled to the node's height
    (the optimiser's profile factor), plus the gust of the moment; uniform keeps the station's
    wind; the compiled step and the Python step fly a sheared, gusty line alike."""
    from fdm_awe.wind import WindProfile

    prof = WindProfile("log", z0=0.1, ref_height=10.0).validate()
    s, c, gs = _line(6, 120.0, drag=True)
    gs.set_line_wind(prof, (-8.0, 1.0), (0.3, -0.2, 0.1))
    c = np.array(gs._sc)
    for h in (2.0, 10.0, 55.0, 140.0):
        f = float(prof.factor(h))
        assert LF.wind_at(c, -h) == pytest.approx((-8.0 * f + 0.3, 1.0 * f - 0.2, 0.1), rel=1e-12)
    assert float(prof.factor(10.0)) == pytest.approx(1.0) and float(prof.factor(140.0)) > 1.4
    gs.set_line_wind(None, (0.0, 0.0))  # uniform: the station's own wind
    c = np.array(gs._sc)
    assert LF.wind_at(c, -50.0) == (c[STATION.wind], c[STATION.wind + 1], c[STATION.wind + 2])
    outs = []
    for jit in (True, False):
        st = GroundStation(load_ground_station(line="sized"), wind_ned=(-8.0, 0.0, 0.0), tether="lumped:4")
        st.set_line_wind(prof, (-8.0, 0.0), (0.5, 0.0, 0.0))
        if not jit:
            st._step_kernel = None
        st.reset(tether_length=100.0, reel_speed=1.0, mode="generator")
        pos, vel = np.array([60.0, 0.0, -81.0]), np.array([0.0, 20.0, -1.0])
        for k in range(30):
            o = st.step(1.0 / 120.0, tuple(pos.tolist()), tuple(vel.tolist()), WinchCommand(mode="generator"))
            pos = pos + vel / 120.0
        outs.append((o, st.line_nodes()))
    assert outs[0][0] == outs[1][0] and np.array_equal(outs[0][1], outs[1][1])
