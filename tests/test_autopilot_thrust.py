"""The thrust loop as one source: :func:`throttle_step` compiled by numba gives exactly the
numbers Python gives (armed and disarmed, the integral's limits, the anti-windup, a ceiling
below 1), and :class:`ThrustLoop` delegates to it, reading its gains at each call."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from fdm_awe.autopilot.thrust import THR, ThrustLoop, throttle_step


def _inputs(rnd: random.Random, k: int) -> tuple:
    """(thrust_cmd, thrust, airspeed, dt, armed, u_max, kp, ki, v_zero, thrust_max_static)."""
    return (rnd.uniform(-5.0, 60.0) if k % 9 else 0.0, rnd.uniform(0.0, 60.0), rnd.uniform(0.0, 45.0),
            rnd.choice((0.0, 1 / 120, rnd.uniform(0.0, 2.0))), k % 7 != 0,
            1.0 if k % 3 else rnd.uniform(0.1, 1.0), rnd.uniform(0.0, 0.05), rnd.uniform(0.0, 0.5),
            rnd.uniform(25.0, 40.0), rnd.uniform(20.0, 50.0))


def test_throttle_step_compiled_equals_python_on_every_branch():
    """Bit for bit on random inputs: throttle and integral; disarmed, both saturations (with
    the anti-windup's undo), the integral's limits and a ceiling below 1 reached."""
    numba = pytest.importorskip("numba", reason="numba is not installed: nothing compiled to compare")
    jit = numba.njit(throttle_step)
    rnd = random.Random(8)
    seen = set()
    for k in range(800):
        x = _inputs(rnd, k)
        i0 = rnd.uniform(-1.2, 1.2)
        py_integ, jit_integ = [i0], np.array([i0])
        u = throttle_step(*x, py_integ)
        assert jit(*x, jit_integ) == u
        assert jit_integ.tolist() == py_integ
        armed, u_max, ki, dt = x[4], x[5], x[7], x[3]
        if not armed:
            assert u == 0.0 and py_integ == [0.0]
            seen.add("disarmed")
            continue
        assert 0.0 <= u <= u_max
        seen.add("u=0" if u == 0.0 else "u=max<1" if u == u_max < 1.0 else "u=1" if u == u_max else "in")
        clipped = min(max(i0 + ki * (x[0] - x[1]) * dt, -1.0), 1.0)
        if u in (0.0, u_max) and ki * dt != 0.0:
            seen.add("undo")
            assert py_integ[THR.integral] != clipped
        else:
            assert py_integ[THR.integral] == clipped
        if abs(clipped) == 1.0:
            seen.add("limit")
    assert seen == {"disarmed", "u=0", "u=max<1", "u=1", "in", "undo", "limit"}, seen


def test_the_loop_delegates_and_reads_its_gains_at_each_call():
    """``ThrustLoop.throttle`` gives :func:`throttle_step` of the current THR_KP, THR_KI (changed
    between calls), THR_VZERO at construction and the static thrust; disarmed resets it."""
    params = {"THR_KP": 0.01, "THR_KI": 0.2, "THR_VZERO": 32.0}
    loop = ThrustLoop(params, 30.0)
    integ = [0.0, 0.0, 0.0]  # the integral (the thrust loop's only state throttle_step touches), THR.last, THR.thrust
    rnd = random.Random(1)
    for k in range(60):
        params["THR_KP"], params["THR_KI"] = rnd.uniform(0.0, 0.05), rnd.uniform(0.0, 0.5)
        params["THR_VZERO"] = 99.0  # read once, at construction
        cmd, thrust, v, u_max = rnd.uniform(0, 40), rnd.uniform(0, 40), rnd.uniform(10, 35), rnd.choice((1.0, 0.4))
        u = loop.throttle(cmd, thrust, v, 1 / 120, k % 10 != 9, u_max)
        assert u == throttle_step(cmd, thrust, v, 1 / 120, k % 10 != 9, u_max, params["THR_KP"], params["THR_KI"],
                                  32.0, 30.0, integ)
        assert loop.state.tolist() == integ
    assert loop.throttle(10.0, 0.0, 20.0, 1 / 120, False) == 0.0 and loop.state.tolist() == [0.0, 0.0, 0.0]
    # the feed-forward alone: zero thrust at the zero-thrust airspeed, full throttle when static
    params["THR_KP"] = params["THR_KI"] = 0.0
    assert loop.throttle(0.0, 0.0, 32.0, 0.0, True) == 1.0
    assert loop.throttle(30.0, 30.0, 0.0, 0.0, True) == 1.0
    assert loop.throttle(7.5, 7.5, 0.0, 0.0, True) == math.sqrt(0.25)
