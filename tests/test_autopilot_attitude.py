"""The autopilot's attitude loops as one source: the path rate, the bank error's wrap and their
composition with the law compiled by numba give exactly the numbers Python gives, and
:class:`AttitudeLoops` delegates to :func:`attitude_commands`."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from fdm_awe.autopilot.attitude import CALLED, AttitudeLoops, attitude_commands, path_rate
from fdm_awe.sixdof import row as R
from fdm_awe.sixdof.attitude_law import StabilizerGains, wrap_angle

from attitude_helpers import Glider, random_coef, state


def _numba():
    return pytest.importorskip("numba", reason="numba is not installed: nothing compiled to compare")


def test_path_rate_and_wrap_compiled_equal_python():
    """Bit for bit on random flight states, airspeeds below the limit of 1 m/s among them, and
    bank errors beyond +-pi."""
    numba = _numba()
    jit_rate, jit_wrap = numba.njit(path_rate), numba.njit(wrap_angle)
    rnd = random.Random(4)
    for k in range(500):
        x = (rnd.choice((9.81, 9.80665)), rnd.uniform(-math.pi, math.pi), rnd.uniform(-1.5, 1.5),
             rnd.uniform(-30, 30), rnd.uniform(-30, 30), rnd.uniform(-60, 10),
             rnd.uniform(0.0, 1.0) if k % 6 == 0 else rnd.uniform(5.0, 50.0),
             rnd.uniform(-0.3, 0.5), rnd.uniform(-0.3, 0.3))
        py = path_rate(*x)
        assert jit_rate(*x) == py
        if k % 6 == 0:
            assert py == path_rate(*x[:6], 1.0, *x[7:])  # airspeed limited to 1 m/s
        e = rnd.uniform(-10.0, 10.0)
        assert jit_wrap(e) == wrap_angle(e) and -math.pi <= wrap_angle(e) <= math.pi


def test_attitude_commands_compiled_equals_python():
    """The composition (path rate, wrap, the law inverting the free moments) on random inputs:
    commands and the alpha integrator; the bank integrator untouched."""
    numba = _numba()
    from numba.extending import register_jitable

    for f in CALLED:
        register_jitable(f)
    jit = numba.njit(attitude_commands)
    rnd = random.Random(6)
    seen = set()
    for k in range(500):
        c, gains = random_coef(rnd, True), StabilizerGains(w_phi=rnd.uniform(3, 7)).law_gains()
        x = [9.80665, rnd.uniform(0.0, 500.0), rnd.uniform(0.0, 45.0) if k % 5 else 0.3,
             rnd.uniform(-1.5, 1.5), rnd.uniform(-1, 1), rnd.uniform(-0.2, 0.4), rnd.uniform(-0.2, 0.2),
             rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-30, 30),
             rnd.uniform(-30, 30), rnd.uniform(-60, 10), rnd.uniform(0.0, 0.3), rnd.uniform(-4.0, 4.0),
             rnd.choice((0.0, 1 / 120, 0.5))]
        if k % 3 == 0:  # small errors, on the path: inside the limits
            x[7:10] = [rnd.uniform(-0.02, 0.02) for _ in range(3)]
            x[10:13] = [0.0, 0.0, -9.80665]
            x[3], x[4], x[13], x[14] = 0.0, 0.0, x[5], 0.0
        if k % 41 == 0:
            x[5] = math.nan
        integ = [rnd.uniform(-0.3, 0.3), rnd.uniform(-0.3, 0.3)]
        py_integ, jit_integ = list(integ), np.array(integ)
        py = attitude_commands(c, gains, *x, py_integ)
        assert jit(np.array(c), np.array(gains), *x, jit_integ) == py
        assert jit_integ.tolist() == py_integ and py_integ[1] == integ[1]
        seen.update("+1" if v == 1.0 else "-1" if v == -1.0 else "0" if v == 0.0 else "in" for v in py)
    assert seen == {"+1", "-1", "0", "in"}


def test_the_loops_delegate_to_attitude_commands():
    """``AttitudeLoops.update`` gives :func:`attitude_commands` of the law's coefficient vector,
    gains and the state's SI values (specific force from ``accel_body``)."""
    rnd = random.Random(2)
    loops = AttitudeLoops(Glider(), StabilizerGains())
    integ = [0.0, 0.0]
    for k in range(20):
        s = state(0.0, rnd)
        s._r[R.ROW.fbz] = -rnd.uniform(0.5, 3.0)
        fx, fy, fz = s.accel_body.tolist()
        out = loops.update(s, 0.12, 0.5, 1 / 120)
        assert out == attitude_commands(loops.law.coef.tolist(), loops.gains.law_gains(), 9.80665, s.qbar,
                                        s.airspeed, s.phi, s.theta, s.alpha, s.beta, s.p, s.q, s.r, fx, fy, fz, 0.12,
                                        0.5, 1 / 120, integ)
        assert loops.law.integ.tolist() == integ
    loops.reset()
    assert loops.law.integ.tolist() == [0.0, 0.0]
