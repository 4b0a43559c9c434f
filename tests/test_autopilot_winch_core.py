"""The cycle's winch command as a pure function (:func:`fdm_awe.autopilot.winch.cycle_winch_values`):
compiled by numba it gives the Python call's bits on every branch (kinematic winch, generator
with and without the length trim and its clip, with the line's lower and upper tension limits,
motor reel-in with the tension ease-off, the speed cap and the glider's approach, before and
after the ground station's first step); with the line limits off :func:`cycle_winch` builds the
:class:`WinchCommand` it built before them (None where the station's definition default
applies)."""

from __future__ import annotations

import math
import random
from types import SimpleNamespace

import numpy as np
from jit_helpers import compiled, same_bits

from fdm_awe.trajectory.schema import GENERATION, RECOVERY
from fdm_awe.autopilot.tracking import RefPoint
from fdm_awe.autopilot.winch import (LIMIT_PARAMS, WL, cycle_winch, cycle_winch_values, lower_limit_holds,
                                     take_up_speed, upper_limit_load)
from fdm_awe.groundstation import WinchCommand


#: the recovery phase's reel gains at their definition defaults (the law as it was built)
REC_DEFAULTS = {"REC_LEN_KL": 0.5, "REC_TENS_KT": 0.2, "REC_PAY_MAX": 0.5}


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


def _limits(rnd: random.Random, off: bool = False) -> np.ndarray:
    """A random ``lim`` vector (:data:`LIMIT_PARAMS`, then the drive's reel-in speed); ``off``:
    every line limit off, the recovery's reel gains at their defaults and no drive bound (the law
    before the limits)."""
    if off:
        return np.array([0.0] * (len(LIMIT_PARAMS) - 3) + [*REC_DEFAULTS.values(), math.inf])
    lim = np.array([rnd.choice((0.0, rnd.uniform(1.0, 10.0))), rnd.uniform(0.0, 8.0), rnd.uniform(0.0, 0.5),
                    rnd.uniform(0.0, 2.0), rnd.uniform(0.0, 10.0), rnd.choice((0.0, rnd.uniform(0.2, 3.0))),
                    rnd.choice((0.0, rnd.uniform(20.0, 120.0))), rnd.uniform(0.0, 1.0),
                    rnd.choice((0.0, rnd.uniform(0.0, 5.0))), rnd.choice((0.0, rnd.uniform(0.5, 3.0))),
                    rnd.uniform(0.0, 2.0),
                    rnd.uniform(0.0, 1.0), rnd.choice((0.5, rnd.uniform(0.0, 3.0))), rnd.uniform(2.0, 8.0)])
    assert lim.size == len(LIMIT_PARAMS) + 1
    return lim


def _values_args(r, rate, gs, p, winch, rl, ea, dist=math.nan, dist_rate=0.0, low=False, lim=None):
    on = gs is not None
    lim = _limits(random.Random(0), off=True) if lim is None else lim
    return (r.phase, winch == "ideal", rate, r.reel_speed, r.length, r.tension, r.boost_duty, on,
            gs.length if on else math.nan, gs.tension if on else math.nan, rl, ea,
            p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"], dist, dist_rate, low, lim)


def _branch(args, out) -> str:
    phase, ideal, on, kp, rec, lim = args[0], args[1], args[7], args[12], args[13], args[19]
    if phase == GENERATION and ideal:
        return f"kinematic/{on}"
    if phase == GENERATION:
        if out[4]:
            return f"low/{args[16] == args[16]}"
        trimmed = kp > 0 and on
        upper = on and lim[WL.thi] > 0 and args[9] > lim[WL.thi]
        return f"generator/{trimmed}" + (f"/{out[2] in (0.2, 20.0)}" if trimmed else "") + ("/upper" if upper else "")
    approach = on and lim[WL.vcatch] > 0 and args[16] == args[16]
    return f"motor/{on}" + (f"/{args[9] > rec}/{out[1] == lim[WL.pay_max]}/{approach}" if on else "")


def test_cycle_winch_values_compiled_equals_python_on_every_branch():
    jit = compiled(cycle_winch_values, take_up_speed, lower_limit_holds, upper_limit_load)
    rnd = random.Random(41)
    seen = set()
    for _ in range(4000):
        case = _case(rnd)
        r, gs = case[0], case[2]
        dist = rnd.choice((math.nan, r.length + rnd.gauss(0.0, 10.0)))
        lim = _limits(rnd, off=rnd.random() < 0.2)
        args = _values_args(*case, dist, rnd.uniform(-6.0, 4.0), rnd.random() < 0.5, lim)
        py = cycle_winch_values(*args)
        assert same_bits(jit(*args), py), (args, py)
        seen.add(_branch(args, py))
    assert seen >= {"kinematic/True", "kinematic/False", "generator/False", "generator/True/False",
                    "generator/True/True", "generator/True/False/upper", "generator/False/upper", "low/True",
                    "low/False", "motor/False", "motor/True/False/False/False", "motor/True/True/False/False",
                    "motor/True/False/True/False", "motor/True/True/True/False", "motor/True/False/False/True",
                    "motor/True/True/False/True"}, seen


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
    """With the line limits off (0) the command is the one built before them."""
    rnd = random.Random(43)
    defaults = 0
    for _ in range(2000):
        case = _case(rnd)
        case[3].update({n: 0.0 for n in LIMIT_PARAMS if n.startswith("WINCH_")}, **REC_DEFAULTS)
        got, low = cycle_winch(*case, dist=case[0].length, dist_rate=-3.0)
        assert not low  # the limits are off
        want = _command_before(*case)
        assert got == want, (got, want)
        assert same_bits(got.reel_speed_ref, want.reel_speed_ref)
        defaults += got.load_resistance is None and got.boost_duty is None and got.duty is None
    assert defaults > 500  # the kinematic winch and the motor leave R_L and the T2 duty to the station
