"""The ground station's step compiled by numba gives exactly the numbers of the same functions
run by Python (one source, two executions). Numba is a dependency: these tests fail, not skip,
when it does not compile; only ``FDM_AWE_JIT=0`` (Python asked for) skips them."""

import dataclasses
import math
import os
import random
import subprocess
import sys

import numpy as np
import pytest

from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.groundstation.substeps import compiled, compiled_station, pi_step
from fdm_awe.groundstation.winch import drum_speed
from fdm_awe.jitcache import jit_off, register_helpers

P = load_ground_station()
U = np.array([math.cos(math.radians(30.0)), 0.0, -math.sin(math.radians(30.0))])
E = np.array([0.0, 1.0, 0.0])
GEN = WinchCommand("generator")


def _require_compiled() -> None:
    """Skip under ``FDM_AWE_JIT=0``; otherwise fail when the step did not compile."""
    if jit_off() == "FDM_AWE_JIT=0":
        pytest.skip("FDM_AWE_JIT=0: only Python runs")
    assert compiled() is not None and compiled_station() is not None, "numba did not compile the ground-station step"


def _pair(tether_drag_scale: float = 1.0):
    """Two stations from the same start: the Python execution and the compiled one."""
    _require_compiled()
    py, jit = (GroundStation(P, wind_ned=(3.0, 0.0, 0.0), tether_drag_scale=tether_drag_scale) for _ in range(2))
    py.drivetrain._kernel = None
    assert jit.drivetrain._kernel is not None and jit._step_kernel is not None  # the whole step compiled
    return py, jit


def _same(a, b):
    """Every field of two outputs and both ledgers identical (NaN equal to NaN)."""
    for name in ("tension", "length", "reel_speed", "omega", "current", "duty", "mode", "u_link", "p_electrical",
                 "event", "machine_mode", "p_mechanical", "distance", "slack", "broken"):
        va, vb = getattr(a, name), getattr(b, name)
        assert va == vb or (va != va and vb != vb), (name, va, vb)
    assert np.array_equal(a.force_on_glider_ned, b.force_on_glider_ned)


def _run(stations, steps):
    """Step both stations through ``steps`` = [(dt, pos, vel, cmd) or (dt, tension, cmd)]."""
    py, jit = stations
    n = 0
    for st in steps:
        if len(st) == 4:
            oa, ob = py.step(*st), jit.step(*st)
        else:
            oa, ob = py.step_with_tension(*st), jit.step_with_tension(*st)
        _same(oa, ob)
        n += 1
    la, lb = py.ledger.as_dict(), jit.ledger.as_dict()
    assert la == lb
    d1, d2 = py.drivetrain, jit.drivetrain
    for name in ("length", "omega", "current", "u_link", "integ", "duty", "broken", "at_stop", "stretch", "mode"):
        assert getattr(d1, name) == getattr(d2, name), name
    assert np.array_equal(d1._s, d2._s)  # states and every ledger term, bit for bit
    return n


def test_generation_then_pi_reel_in_at_several_flight_steps():
    for dt in (1 / 1000, 1 / 120, 1 / 60):
        st = _pair()
        for g in st:
            g.reset(200.0, 0.0, "generator")
        steps = []
        for k in range(int(round(8.0 / dt))):
            t = k * dt
            if t < 4.0:
                pos = U * (200.0 + 3.0 * t) + E * 20.0 * math.sin(0.8 * t)
                vel = U * 3.0 + E * 16.0 * math.cos(0.8 * t)
                cmd = GEN
            else:
                pos = U * (212.0 - 2.5 * (t - 4.0)) + E * 20.0 * math.sin(0.8 * t)
                vel = U * -2.5 + E * 16.0 * math.cos(0.8 * t)
                cmd = WinchCommand("motor", reel_speed_ref=-3.0)
            steps.append((dt, tuple(pos.tolist()), tuple(vel.tolist()), cmd))
        assert _run(st, steps) == len(steps)


def test_scaled_line_drag_compiled_equals_python():
    """With a line-drag scale (0.5, 0: no drag at all, 3) both paths still agree bit for bit."""
    dt = 1 / 120
    for scale in (0.5, 0.0, 3.0):
        st = _pair(scale)
        for g in st:
            g.reset(200.0, 0.0, "generator")
        steps = []
        for k in range(240):
            t = k * dt
            pos = U * (200.0 + 3.0 * t) + E * 20.0 * math.sin(0.8 * t)
            vel = U * 3.0 + E * 16.0 * math.cos(0.8 * t)
            steps.append((dt, tuple(pos.tolist()), tuple(vel.tolist()), GEN))
        assert _run(st, steps) == len(steps)
        assert (st[1].ledger.line_drag_work_on_glider < 0.0) == (scale > 0.0)


def test_open_loop_duty_boost_stage_and_prescribed_tension():
    st = _pair()
    for g in st:
        g.reset(150.0, 1.0, "generator")
    dt = 1 / 120
    steps = [(dt, 60.0, WinchCommand("generator", boost_duty=0.3)) for _ in range(120)]
    steps += [(dt, 5.0, WinchCommand("motor", duty=0.7)) for _ in range(120)]
    steps += [(dt, 150.0, WinchCommand("motor", reel_speed_ref=-3.0)) for _ in range(120)]  # PI saturates
    steps += [(dt, 0.0, WinchCommand("generator", load_resistance=50.0)) for _ in range(60)]  # stick-slip
    assert _run(st, steps) == len(steps)


def test_end_stop_and_tether_break():
    st = _pair()
    for g in st:
        g.reset(3.0, 0.0, "motor")
    dt = 1 / 120
    steps = [(dt, (0.5, 0.0, -0.5), (0.0, 0.0, 0.0), WinchCommand("motor", duty=1.0)) for _ in range(120)]
    assert _run(st, steps) == len(steps)
    assert st[1].ledger.end_stop > 0.0
    params = dataclasses.replace(P, tether=dataclasses.replace(P.tether, breaking_load=40.0))
    st = (GroundStation(params), GroundStation(params))
    st[0].drivetrain._kernel = None
    for g in st:
        g.reset(200.0, 0.0, "generator")
    steps = []
    for k in range(240):  # the glider pulls away faster than the drum pays out: the line breaks
        steps.append((dt, tuple((200.0 * U + 8.0 * k * dt * U).tolist()), tuple((8.0 * U).tolist()), GEN))
    assert _run(st, steps) == len(steps)
    assert st[1].drivetrain.broken and st[1].ledger.break_release > 0.0


def test_python_step_without_numba():
    """FDM_AWE_JIT=0: nothing is compiled and the Python step gives the same numbers."""
    code = ("import math\n"
            "from fdm_awe.groundstation import GroundStation, WinchCommand\n"
            "from fdm_awe.groundstation.substeps import compiled, compiled_station\n"
            "assert compiled() is None and compiled_station() is None\n"
            "gs = GroundStation(wind_ned=(3.0, 0.0, 0.0)); gs.reset(100.0, 0.0, 'generator')\n"
            "for k in range(240):\n"
            "    o = gs.step(1 / 120, (86.6 + 0.025 * k, 0.0, -50.0), (3.0, 0.0, 0.0), WinchCommand('generator'))\n"
            "print(repr((o.tension, o.length, o.omega, gs.ledger.load, gs.ledger.residual())))\n")
    env = dict(os.environ, FDM_AWE_JIT="0")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    py_vals = eval(out.stdout.strip())
    _require_compiled()
    gs = GroundStation(wind_ned=(3.0, 0.0, 0.0))
    gs.reset(100.0, 0.0, "generator")
    for k in range(240):
        o = gs.step(1 / 120, (86.6 + 0.025 * k, 0.0, -50.0), (3.0, 0.0, 0.0), WinchCommand("generator"))
    assert py_vals == (o.tension, o.length, o.omega, gs.ledger.load, gs.ledger.residual())
    assert o.tension > 0.0


def _jit(f):
    """``f`` compiled by numba (its calls registered as in the ground station's step)."""
    import numba

    from fdm_awe.groundstation.substeps import CALLED

    register_helpers(CALLED)
    return numba.njit(f)


def test_drum_speed_compiled_equals_python():
    """The drum solver (stick, the fast piece, the walk over the kinks) on random inputs."""
    _require_compiled()
    jit = _jit(drum_speed)
    rnd = random.Random(7)
    for _ in range(20000):
        args = (rnd.uniform(0.01, 1.0), rnd.uniform(-30, 30) * (rnd.random() < 0.8), rnd.choice((1e-3, 2e-3, 1e-2)),
                rnd.uniform(0, 0.05), rnd.uniform(0, 2.0), rnd.uniform(0.02, 0.2), rnd.uniform(-200, 400),
                rnd.uniform(0, 50) * (rnd.random() < 0.8), rnd.uniform(0.05, 1.0), rnd.uniform(-50, 50),
                rnd.uniform(0, 5) * (rnd.random() < 0.8))
        assert drum_speed(*args) == jit(*args), args


def test_pi_step_compiled_equals_python_and_holds_at_the_limits():
    _require_compiled()
    jit = _jit(pi_step)
    c = P.controller
    rnd = random.Random(3)
    for _ in range(5000):
        args = (c.kp, c.ki, c.duty_min, c.duty_max, rnd.uniform(-50, 50), rnd.uniform(c.duty_min, c.duty_max), 1e-3)
        duty, integ = pi_step(*args)
        assert (duty, integ) == jit(*args)
        assert c.duty_min <= duty <= c.duty_max and c.duty_min <= integ <= c.duty_max
    # saturated high with a positive error: the integrator holds (conditional integration)
    assert pi_step(c.kp, c.ki, c.duty_min, c.duty_max, 1e4, 0.5, 1e-3) == (c.duty_max, 0.5)
