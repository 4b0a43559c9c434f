"""The cycle's winch command as a pure function (:func:`fdm_awe.autopilot.winch.cycle_winch_values`):
compiled by numba it gives the Python call's bits on every branch (kinematic winch, generator
with and without the length trim and its clip, motor reel-in with the tension ease-off and the
speed cap, before and after the ground station's first step); :func:`cycle_winch` builds the
:class:`WinchCommand` it built before (None where the station's definition default applies)."""

from __future__ import annotations

import math
import random
from types import SimpleNamespace

import numpy as np
from jit_helpers import compiled, same_bits

from fdm_awe.autopilot.tracking import GENERATION, RECOVERY, RefPoint
from fdm_awe.autopilot.winch import cycle_winch, cycle_winch_values
from fdm_awe.groundstation import WinchCommand


def _case(rnd: random.Random):
    """(reference point, rate, ground-station output or None, params, winch, R_L, line EA)."""
    r = RefPoint(t_cycle=0.0, cycle=0, phase=rnd.choice((GENERATION, RECOVERY)), pos=np.zeros(3), vel=np.zeros(3),
                 acc=np.zeros(3), airspeed=15.0, alpha=0.1, phi=0.0, thrust=1.0, tension=rnd.uniform(0.0, 150.0),
                 length=rnd.uniform(50.0, 300.0), reel_speed=rnd.uniform(-6.0, 4.0), boost_duty=rnd.choice((0.0, rnd.uniform(0.0, 0.8))))
    gs = None if rnd.random() < 0.15 else SimpleNamespace(length=r.length + rnd.gauss(0.0, rnd.choice((0.5, 30.0))),
                                                          tension=rnd.uniform(0.0, 200.0))
    params = {"GEN_RL_KP": rnd.choice((0.0, 0.3, rnd.uniform(0.0, 20.0))), "REC_TENSION": rnd.uniform(1.0, 100.0),
              "WINCH_KL": rnd.uniform(0.0, 5.0), "WINCH_KT": rnd.uniform(0.0, 1.0)}
    return r, rnd.uniform(0.0, 3.0), gs, params, rnd.choice(("physical", "ideal")), rnd.uniform(0.5, 15.0), rnd.uniform(1e3, 1e5)


def _values_args(r, rate, gs, p, winch, rl, ea):
    on = gs is not None
    return (r.phase, winch == "ideal", rate, r.reel_speed, r.length, r.tension, r.boost_duty, on,
            gs.length if on else math.nan, gs.tension if on else math.nan, rl, ea,
            p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"])


def _branch(args, out) -> str:
    phase, ideal, on, kp, rec = args[0], args[1], args[7], args[12], args[13]
    if phase == GENERATION and ideal:
        return f"kinematic/{on}"
    if phase == GENERATION:
        trimmed = kp > 0 and on
        return f"generator/{trimmed}" + (f"/{out[2] in (0.2, 20.0)}" if trimmed else "")
    return f"motor/{on}" + (f"/{args[9] > rec}/{out[1] == 0.5}" if on else "")


def test_cycle_winch_values_compiled_equals_python_on_every_branch():
    jit = compiled(cycle_winch_values)
    rnd = random.Random(41)
    seen = set()
    for _ in range(3000):
        args = _values_args(*_case(rnd))
        py = cycle_winch_values(*args)
        assert same_bits(jit(*args), py), (args, py)
        seen.add(_branch(args, py))
    assert seen >= {"kinematic/True", "kinematic/False", "generator/False", "generator/True/False",
                    "generator/True/True", "motor/False", "motor/True/False/False", "motor/True/True/False",
                    "motor/True/False/True", "motor/True/True/True"}, seen


def _command_before(r, rate, gs, p, winch, load_resistance, line_EA) -> WinchCommand:
    """The command as :func:`cycle_winch` built it directly."""
    if r.phase == GENERATION and winch == "ideal":
        v = rate * r.reel_speed
        if gs is not None:
            l_ref = r.length / (1.0 + r.tension / line_EA)
            v += p["WINCH_KL"] * (l_ref - gs.length) + p["WINCH_KT"] * (gs.tension - r.tension)
        return WinchCommand(mode="generator", reel_speed_ref=v)
    if r.phase == GENERATION:
        rl = load_resistance
        if p["GEN_RL_KP"] > 0 and gs is not None:
            rl = min(max(load_resistance + p["GEN_RL_KP"] * (r.length - gs.length), 0.2), 20.0)
        return WinchCommand(mode="generator", load_resistance=rl, boost_duty=r.boost_duty)
    v = rate * r.reel_speed
    if gs is not None:
        v += 0.5 * (r.length - gs.length)
        if gs.tension > p["REC_TENSION"]:
            v += 0.2 * (gs.tension - p["REC_TENSION"])
    return WinchCommand(mode="motor", reel_speed_ref=min(v, 0.5))


def test_cycle_winch_builds_the_command_it_built():
    rnd = random.Random(43)
    defaults = 0
    for _ in range(2000):
        case = _case(rnd)
        got, want = cycle_winch(*case), _command_before(*case)
        assert got == want, (got, want)
        assert same_bits(got.reel_speed_ref, want.reel_speed_ref)
        defaults += got.load_resistance is None and got.boost_duty is None and got.duty is None
    assert defaults > 500  # the kinematic winch and the motor leave R_L and the T2 duty to the station
