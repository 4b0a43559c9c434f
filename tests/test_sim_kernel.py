"""The compiled co-simulation loop (fdm_awe.sim.kernel + fdm_awe.sixdof.native) against the
Python loop it replaces: the same flights, bit for bit, the same events and messages, the same
ground-station state and energy ledger; and the fall-backs where it cannot run."""

from __future__ import annotations

import dataclasses
import math
import random

import numpy as np
import pytest

from fdm_awe import slots
from fdm_awe.sim import events as ce
from fdm_awe.sim.result import STATUSES
from fdm_awe.sim.loop import CoSim, Limits
from fdm_awe.errors import InputError
from fdm_awe.jitcache import jit_off
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.sixdof import JSBSimGlider, Stabilizer, Surfaces
from fdm_awe.sixdof import row as R

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

ALPHA = 0.10436  # rad
WIND = 14.0  # m/s
LINE = 50.0  # m
HOLD = WinchCommand(mode="motor", reel_speed_ref=0.0)


class Fixed:
    """Constant commands; ``constant_commands`` lets the compiled loop run in blocks."""

    def __init__(self, surfaces: Surfaces, winch: WinchCommand, constant: bool = True) -> None:
        self.out = (surfaces, winch)
        self.constant_commands = constant

    def update(self, t, s, gs_output):
        return self.out


class Phased(Stabilizer):
    """A stabiliser that reels out after 2 s (a command change) and names its phases."""

    phase = "hold"

    def update(self, t, s, gs_output):
        surf, _ = super().update(t, s, gs_output)
        if t > 2.0:
            self.phase = "reel-out"
            return surf, WinchCommand(mode="generator", load_resistance=5.0)
        return surf, HOLD


def _setup(name="glider_foldable", line=LINE, elevation_deg=80.0, params=None, reel_speed=0.0, mode="motor",
           turbulence=None):
    g = JSBSimGlider(name, wind_ned=(WIND, 0.0, 0.0), turbulence=turbulence)
    el = math.radians(elevation_deg)
    g.reset((line * math.cos(el), 0.0, -line * math.sin(el)), WIND, gamma=0.0, psi=math.pi, alpha=ALPHA)
    gs = GroundStation(params or load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
    gs.reset(tether_length=line, reel_speed=reel_speed, mode=mode)
    return g, gs


def _both(make_ctrl, t_end, limits=None, on_step=None, **setup):
    """The same flight with the Python loop and with the compiled loop."""
    out = []
    for compiled in (False, True):
        g, gs = _setup(**setup)
        sim = CoSim(g, gs, make_ctrl(g), limits=limits or Limits(max_tension=200.0), compiled=compiled)
        res = sim.run(t_end, on_step=on_step)
        assert sim.loop == ("compiled" if compiled else "python")
        out.append((res, g, gs, sim))
    return out


def _assert_same(a, b):
    (ra, ga, gsa, sa), (rb, gb, gsb, sb) = a, b
    assert ra.status == rb.status
    assert (ra.event is None) == (rb.event is None)
    if ra.event is not None:
        assert ra.event == rb.event  # kind, time and message
    assert ra.steps == rb.steps
    assert np.array_equal(ra.data, rb.data, equal_nan=True)
    assert ra.phase == rb.phase
    # what continues after the run: the glider's state and the station's states and ledger
    assert ga.raw() == gb.raw()
    assert ga.hook_kinematics() == gb.hook_kinematics()
    assert ga.state().tether_force_ned.tolist() == gb.state().tether_force_ned.tolist()
    assert np.array_equal(gsa.drivetrain._s, gsb.drivetrain._s)
    assert sa.last_gs_output == sb.last_gs_output


def _numba_expected() -> bool:
    """numba installed and not switched off: the compiled loop must run, its tests must not skip."""
    return jit_off() is None


@pytest.fixture(scope="module", autouse=True)
def _compiled_available():
    g, gs = _setup()
    sim = CoSim(g, gs, Fixed(g.controls, HOLD))
    sim.run(g.dt)
    if sim.loop != "compiled":
        if _numba_expected():
            pytest.fail(f"numba is installed but the compiled loop does not run: {sim.loop_reason}")
        pytest.skip(f"compiled loop not available here: {sim.loop_reason}")


def test_native_handles_are_checked_against_the_bindings():
    g, _ = _setup()
    h, why = g.native_handles()
    assert why == "" and h is not None
    assert h.dtype == np.int64 and len(h) == 7 + len(g.raw())
    assert np.all(h[:7] != 0) and len(set(h[4:].tolist()) - {0}) == len(h) - 4  # distinct nodes


@pytest.mark.parametrize("name, turbulence", [("glider_foldable", None), ("glider_unfolded", None),
                                              ("glider_foldable", ("moderate", 3))])
def test_stabilised_kite_is_bit_identical(name, turbulence):
    """Per-step mode: the stabiliser runs in Python every step (10 s on the line); the static
    aircraft (no fold property) and JSBSim's seeded turbulence included."""
    a, b = _both(lambda g: Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=HOLD), 10.0, name=name,
                 turbulence=turbulence)
    assert a[0].status == "ok" and a[0].steps == 1200
    _assert_same(a, b)


def test_command_change_and_phases_are_bit_identical():
    """A winch command change (motor hold -> generator reel-out) and phase labels mid-run."""
    a, b = _both(lambda g: Phased(g, alpha_cmd=ALPHA, psi_cmd=math.pi), 5.0)
    assert set(a[0].phase[1:]) == {"hold", "reel-out"}
    _assert_same(a, b)


def test_constant_commands_run_in_blocks_bit_identical():
    """Block mode (constant commands, no on_step): 30 s in blocks of one second."""
    a, b = _both(lambda g: Fixed(g.controls, HOLD), 30.0)
    assert a[0].steps == 3600
    _assert_same(a, b)


def test_on_step_ends_the_compiled_run_like_the_python_one():
    seen = []

    def stop(k, s, gs_out):
        seen.append((k, s.t, gs_out.tension))
        return k == 100

    a, b = _both(lambda g: Fixed(g.controls, HOLD), 5.0, on_step=stop)
    assert a[0].steps == 100 and a[0].status == "ok"
    assert seen[:100] == seen[100:]
    _assert_same(a, b)


@pytest.mark.parametrize("limits, kind", [
    (Limits(max_tension=4.0), "load_limit"),
    (Limits(airspeed_max=14.5), "airspeed_limit"),
    (Limits(airspeed_min=13.9), "airspeed_limit"),
    (Limits(max_load_factor=1.02), "load_limit"),
])
def test_limit_events_match(limits, kind):
    a, b = _both(lambda g: Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=HOLD), 10.0, limits=limits)
    assert a[0].status == kind and a[0].steps < 1200
    _assert_same(a, b)


def test_tether_break_matches():
    p = load_ground_station()
    weak = dataclasses.replace(p, tether=dataclasses.replace(p.tether, breaking_load=6.0))
    a, b = _both(lambda g: Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=HOLD), 10.0, params=weak)
    assert a[0].status == "tether_break"
    _assert_same(a, b)


def test_ground_contact_matches():
    """Nose down on a paying-out line: the glider flies into the ground."""
    a, b = _both(lambda g: Fixed(Surfaces(elevator=0.6), WinchCommand(mode="generator", load_resistance=0.5)), 30.0,
                 elevation_deg=20.0, line=30.0, limits=Limits(max_tension=200.0, airspeed_max=None))
    assert a[0].status == "ground_contact"
    _assert_same(a, b)


def test_python_loop_where_the_compiled_one_cannot_run(monkeypatch):
    monkeypatch.setenv("FDM_AWE_JIT", "0")
    g, gs = _setup()  # a new glider: its native handles are checked under FDM_AWE_JIT=0
    sim = CoSim(g, gs, Fixed(g.controls, HOLD))
    assert sim.run(0.1).steps == 12
    assert sim.loop == "python" and "FDM_AWE_JIT=0" in sim.loop_reason
    with pytest.raises(InputError, match="compiled loop is not available"):
        CoSim(g, gs, Fixed(g.controls, HOLD), compiled=True).run(0.1)


def test_long_run_grows_its_log_and_a_long_t_end_costs_nothing_up_front():
    """The compiled loop's log grows by doubling: 150 s (18000 steps, beyond the first 16384
    rows) stays bit-identical, and a 1e6 s t_end that on_step ends after 50 steps runs
    without allocating its length (1.2e8 rows)."""
    a, b = _both(lambda g: Fixed(g.controls, HOLD), 150.0)
    assert a[0].steps == 18000
    _assert_same(a, b)
    g, gs = _setup()
    res = CoSim(g, gs, Fixed(g.controls, HOLD), compiled=True).run(1.0e6, on_step=lambda k, s, o: k == 50)
    assert res.steps == 50 and res.status == "ok"


def test_a_bad_winch_command_ends_both_loops_alike():
    class BadWinch(Fixed):
        def update(self, t, s, gs_output):
            return (self.out[0], "reel in") if t > 0.5 else self.out

    a, b = _both(lambda g: BadWinch(g.controls, HOLD, constant=False), 2.0)
    assert a[0].status == "nonfinite" and "expected WinchCommand" in a[0].event.message
    _assert_same(a, b)


# ---------------------------------------------------------------------------------------------
# the relations written once: the same source compiled by numba and run by Python


def _random_row(rnd: random.Random) -> list[float]:
    r = [rnd.uniform(-2.0, 2.0) for _ in range(slots.size(R.ROW))]
    r[R.ROW.t] = rnd.uniform(0.0, 20.0)
    r[R.ROW.h_sl] = rnd.uniform(-10.0, 500.0)
    r[R.ROW.vt] = rnd.uniform(0.0, 150.0)
    r[R.ROW.fbz] = rnd.uniform(-60.0, 10.0)
    r[R.ROW.mass] = rnd.uniform(0.02, 0.1)
    r[R.ROW.wow] = rnd.choice((0.0, 1.0))
    return r


def test_hook_kinematics_compiled_equals_python():
    """Bit for bit on random rows, with and without a hook offset; the offset-free hook is the CG."""
    import numba

    jit = numba.njit(R.hook_kinematics)
    rnd = random.Random(5)
    frame = (0.1, 6.33e6, 6.37e6, 0.3048)
    for k in range(300):
        r = _random_row(rnd)
        off = (0.0, 0.0, 0.0) if k % 5 == 0 else tuple(rnd.uniform(-0.1, 0.1) for _ in range(3))
        py = R.hook_kinematics(r, *frame, *off)
        assert jit(np.array(r), *frame, *off) == py
        if off == (0.0, 0.0, 0.0):
            assert py[1] == (r[R.ROW.v_north] * 0.3048, r[R.ROW.v_east] * 0.3048, r[R.ROW.v_down] * 0.3048)


def test_step_event_compiled_equals_python_and_reaches_every_code():
    """The event check on random rows and limits: the same code and the same airborne flag
    compiled and in Python; every code of the per-step table is reached."""
    import numba

    jit = numba.njit(ce.step_event)
    rnd = random.Random(11)
    seen = set()
    for k in range(3000):
        r = _random_row(rnd)
        if k % 50 == 0:
            r[rnd.randrange(R.FINITE_FIRST, R.FINITE_END)] = rnd.choice((math.nan, math.inf))
        lim = Limits(airspeed_min=rnd.choice((None, 5.0)), airspeed_max=rnd.choice((None, 40.0)),
                     max_tension=rnd.choice((None, 150.0)), max_load_factor=rnd.choice((None, 12.0)),
                     ground_contact=rnd.random() < 0.8, grace_s=rnd.choice((0.0, 5.0)))
        v = ce.limit_vector(lim, 0.0, rnd.random() < 0.5, 0.3048, 4.448, 14.59)
        va = np.array(v)
        tension, gs_event = rnd.uniform(0.0, 200.0), rnd.random() < 0.05
        code = ce.step_event(r, tension, gs_event, v)
        assert jit(np.array(r), tension, gs_event, va) == code
        assert np.array_equal(va, np.array(v), equal_nan=True)  # the airborne flag updated alike
        seen.add(code)
    C = ce.CODE
    assert seen == {C.none, C.nonfinite_state, C.ground_station, C.ground_contact, C.airspeed_high, C.airspeed_low,
                    C.tension, C.load_factor}


def test_kernel_row_layout_matches_the_logged_columns():
    """The compiled step's ground-station columns start with CoSim's logged ones, in order."""
    from fdm_awe.sim import kernel as ck
    from fdm_awe.sim.result import COLUMNS

    logged = COLUMNS[COLUMNS.index("tension"):COLUMNS.index("fz") + 1]
    assert tuple(c.replace("p_electrical", "p_elec") for c in slots.names(ck.GS)[:len(logged)]) == logged


def test_event_table_orders_and_names():
    """Codes are table positions; statuses are run statuses; a non-finite state wins over every
    other event of its step, a ground-station event over the limits; the airborne flag is set
    once the glider is off the ground, and a contact ends a run only after that."""
    assert [e.code for e in ce.EVENTS] == list(range(len(ce.EVENTS)))
    assert {e.status for e in ce.EVENTS} - {""} <= set(STATUSES)
    lim = Limits(airspeed_max=10.0, max_tension=1.0)
    r = [0.0] * slots.size(R.ROW)
    r[R.ROW.vt], r[R.ROW.mass], r[R.ROW.wow] = 100.0, 1.0, 1.0
    v = ce.limit_vector(lim, 0.0, False, 1.0, 1.0, 1.0)
    assert ce.step_event(r, 5.0, True, v) == ce.CODE.ground_station
    # on the ground at the start
    assert ce.step_event(r, 5.0, False, v) == ce.CODE.airspeed_high and v[ce.LIM.airborne] == 0.0
    r[R.ROW.wow] = 0.0
    assert ce.step_event(r, 5.0, False, v) == ce.CODE.airspeed_high and v[ce.LIM.airborne] == 1.0
    r[R.ROW.wow] = 1.0
    assert ce.step_event(r, 5.0, False, v) == ce.CODE.ground_contact
    r[R.ROW.alpha] = math.nan
    assert ce.step_event(r, 5.0, True, v) == ce.CODE.nonfinite_state
    assert ce.event_message(ce.CODE.tension, lim, None, type("Out", (), {"tension": 2.5, "event": None})()) == (
        "load_limit", "tether tension 2.5 N above 1 N")
