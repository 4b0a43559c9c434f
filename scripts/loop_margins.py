#!/usr/bin/env python
"""Gain and phase margins of the autopilot's loops on the 6-DOF glider, by loop breaking.

The closed loop is the real one: the JSBSim glider, the ground station of
:mod:`fdm_awe.groundstation` (or no line) and the autopilot's own attitude loops
(:class:`fdm_awe.autopilot.autopilot.Autopilot`'s ``att``, gains from ``autopilot.xml``)
holding a steady operating point with constant angle-of-attack and bank commands:

- ``glide``: free glide, unfolded, 13 m/s, no line;
- ``gen_low``: taut-line generation at low tension: the glider flies into a 12 m/s wind on a
  200 m line, the passive generator (definition load) pays the line out (about 4 N, 0.3 m/s);
- ``gen_high``: the same in a 20 m/s wind at a higher angle of attack (about 26 N, 3 m/s out);
- ``reel_in``: the nominal recovery: a glide at 12.5 m/s towards the winch, which reels in
  (motor mode) and keeps the line just slack, as the optimised cycles do (tension 0);
- ``folded``: the folded wing's recovery: a steep dive at alpha 0.3 rad (about 20 m/s).

Each loop is broken at its actuator input, one at a time with the others closed: elevator
(angle of attack), aileron (bank), rudder (yaw damper and sideslip), and, at the glide, the
outer guidance loop (the autopilot in AUTO on a straight glide path, broken at its alpha and
bank commands to the attitude loops). A multisine of small amplitude (:mod:`fdm_awe.sim.margins`,
20 frequencies from 0.6 to 90 rad/s, one period of 10 s to settle, two analysed) is added to
the command; a run without it from the same state is subtracted, so the glider's slow drift (a
phugoid, a line paying out, a descent) drops out and what is left is the finite difference of
the co-simulation about its own trajectory, sampled at the injected frequencies. Why a sine
sweep rather than a linearisation of JSBSim: the loop includes the ground station, the
autopilot's Python code, the servo rate limits and the one-step delay of the lock-step loop,
none of which JSBSim's own linearisation sees; the injection measures the loop as it is flown.

L(jw) = -u_out/u_in (u_in the surface command entering the plant, u_out the autopilot's
output), the crossover frequencies, the gain margin (dB) and the phase margin (deg) are
printed as a table and written as JSON (``--json``, atomically). The aim is at least 6 dB and
45 deg on every loop.

Usage: python scripts/loop_margins.py [--points glide,gen_low,...] [--loops elevator,aileron,...]
                                      [--set W_PHI=8 --set ...] [--json margins.json]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

os.environ.setdefault("JSBSIM_DEBUG", "0")
ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from fdm_awe.sim.margins import Margins, Multisine, log_multisine, loop_gain, margins  # noqa: E402

#: the surface loops: name -> index of the surface command (aileron, elevator, rudder)
SURFACE_LOOPS = {"elevator": 1, "aileron": 0, "rudder": 2}
#: the outer loop's channels (guidance commands to the attitude loops): name -> index (alpha, bank)
GUIDANCE_LOOPS = {"guidance_alpha": 0, "guidance_bank": 1}
#: s, the injection starts after the point has settled this long
SETTLE_S = 5.0
#: the aim of the issue
AIM_GAIN_DB, AIM_PHASE_DEG = 6.0, 45.0


@dataclass(frozen=True)
class OperatingPoint:
    """A steady point held by the attitude loops: ``airspeed`` m/s at start on flight-path angle
    ``gamma`` rad (heading into the wind), angle-of-attack command ``alpha`` rad, wings level,
    ``fold`` 0 open .. 1 folded, wind ``wind`` m/s blowing towards north; ``line``: None (no
    line), ``"generator"`` (passive generator, starting at ``distance`` m, elevation
    ``elevation`` rad, tension ``tension`` N, paying out at ``reel_speed`` m/s: the start's
    air velocity is that reel-out against the wind, ``airspeed`` and ``gamma`` unused) or
    ``"reel_in"`` (motor mode, the line kept just slack); ``altitude`` m at start of a free
    flight. Start values are the point's settled ones, found by flying it."""

    name: str
    doc: str
    airspeed: float
    alpha: float
    gamma: float = 0.0
    fold: float = 0.0
    wind: float = 0.0
    line: str | None = None
    distance: float = 200.0
    elevation: float = math.radians(30.0)
    tension: float = 5.0
    reel_speed: float = 0.0
    altitude: float = 400.0


POINTS = {p.name: p for p in (
    OperatingPoint("glide", "free glide, unfolded", 13.0, 0.05, gamma=-0.08),
    OperatingPoint("gen_low", "generation, low tension", 11.7, 0.15, wind=12.0, line="generator", tension=4.0,
                   reel_speed=0.27, elevation=math.radians(58.5)),
    OperatingPoint("gen_high", "generation, high tension", 18.3, 0.20, wind=20.0, line="generator", tension=26.5,
                   reel_speed=3.05, elevation=math.radians(60.0)),
    OperatingPoint("reel_in", "reel-in, slack line", 12.5, 0.07, gamma=-0.15, wind=8.0, line="reel_in",
                   distance=200.0, elevation=math.radians(20.0)),
    OperatingPoint("folded", "folded dive", 20.0, 0.30, gamma=-0.9, fold=1.0, altitude=1500.0),
)}


class _NoLine:
    """A ground station without a line: no force, the line slack."""

    def step(self, dt: float, pos: Any, vel: Any, cmd: Any) -> Any:
        from fdm_awe.groundstation.station_output import GroundStationOutput

        return GroundStationOutput((0.0, 0.0, 0.0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "generator", 0.0, 0.0, None,
                                   slack=True)


class HoldController:
    """The autopilot's attitude loops holding ``alpha`` and wings level, with ``inject(t)``
    added to surface ``channel`` (0 aileron, 1 elevator, 2 rudder; None: nothing). Records the
    autopilot's outputs and the commands the plant gets, every step."""

    phase = "hold"

    def __init__(self, autopilot: Any, point: OperatingPoint, channel: int | None,
                 inject: Callable[[float], float]) -> None:
        self.ap, self.p, self.channel, self.inject = autopilot, point, channel, inject
        self._t: float | None = None
        self.u_out: list[float] = []
        self.u_in: list[float] = []

    def _winch(self, s: Any, gs: Any) -> Any:
        from fdm_awe.groundstation import WinchCommand

        if self.p.line == "generator":
            return WinchCommand(mode="generator")
        if self.p.line == "reel_in":  # keep 5 m of slack: reel in at the closing speed plus the excess
            d = float(np.linalg.norm(s.hook_pos_ned))
            d_rate = float(s.hook_pos_ned @ s.hook_vel_ned) / d
            slack = (gs.length - d) if gs is not None else 5.0
            return WinchCommand(mode="motor", reel_speed_ref=min(d_rate - 0.5 * (slack - 5.0), 0.0))
        return None

    def update(self, t: float, s: Any, gs: Any) -> tuple[Any, Any]:
        from fdm_awe.sixdof.state import Surfaces

        dt = 0.0 if self._t is None else t - self._t
        self._t = t
        c = list(self.ap.att.update(s, self.p.alpha, 0.0, dt))
        u = list(c)
        if self.channel is not None:
            u[self.channel] = min(max(c[self.channel] + self.inject(t), -1.0), 1.0)
        self.u_out.append(c)
        self.u_in.append(u)
        return Surfaces(u[0], u[1], u[2], 0.0, self.p.fold), self._winch(s, gs)


class GuidedController:
    """The autopilot in AUTO on a straight reference, with ``inject(t)`` added to its guidance
    command ``channel`` (0 alpha, 1 bank) on the way to the attitude loops."""

    phase = "generation"

    def __init__(self, autopilot: Any, channel: int | None, inject: Callable[[float], float]) -> None:
        self.ap, self.channel, self.inject = autopilot, channel, inject
        self.u_out: list[float] = []
        self.u_in: list[float] = []
        att = autopilot.att
        inner = att.update

        def update(s: Any, alpha_cmd: float, roll_cmd: float, dt: float) -> tuple[float, float, float]:
            c = [alpha_cmd, roll_cmd]
            u = list(c)
            if self.channel is not None:
                u[self.channel] = c[self.channel] + self.inject(s.t)
            self.u_out.append(c)
            self.u_in.append(u)
            return inner(s, u[0], u[1], dt)

        att.update = update

    def update(self, t: float, s: Any, gs: Any) -> tuple[Any, Any]:
        return self.ap.update(t, s, gs)


def _glider_and_station(p: OperatingPoint) -> tuple[Any, Any]:
    from fdm_awe.groundstation import GroundStation, load_ground_station
    from fdm_awe.sixdof import JSBSimGlider

    g = JSBSimGlider("glider_foldable", wind_ned=(p.wind, 0.0, 0.0))
    psi = math.pi if p.wind > 0.0 else 0.0  # into the wind
    if p.line is None:
        g.reset((0.0, 0.0, -p.altitude), p.airspeed, gamma=p.gamma, psi=psi, alpha=p.alpha, fold=p.fold)
        return g, _NoLine()
    e_r = np.array([math.cos(p.elevation), 0.0, -math.sin(p.elevation)])
    if p.line == "generator":  # paying out at reel_speed against the wind
        va = p.reel_speed * e_r - np.array([p.wind, 0.0, 0.0])
        V = float(np.linalg.norm(va))
        g.reset(p.distance * e_r, V, gamma=-math.asin(va[2] / V), psi=math.atan2(va[1], va[0]), alpha=p.alpha)
    else:
        g.reset(p.distance * e_r, p.airspeed, gamma=p.gamma, psi=psi, alpha=p.alpha, fold=p.fold)
    gs = GroundStation(load_ground_station(), wind_ned=(p.wind, 0.0, 0.0))
    if p.line == "generator":
        gs.reset(gs.unstretched_length(p.distance, p.tension), p.reel_speed, "generator")
    else:
        gs.reset(p.distance + 5.0, 0.0, "motor")
    return g, gs


def _autopilot(glider: Any, params: Any, config: str, reference: Any = None) -> Any:
    from fdm_awe.autopilot.autopilot import Autopilot
    from fdm_awe.definitions.aircraft import load_glider

    return Autopilot(glider, load_glider(), params, reference, config=config)


def _straight_glide(glider: Any, p: OperatingPoint, seconds: float) -> Any:
    """A straight reference along the glider's start velocity (its own glide path)."""
    from fdm_awe.autopilot.tracking import TrackingReference

    s = glider.state()
    t = np.linspace(0.0, seconds, 200)
    v = np.asarray(s.vel_ned, float)
    pos = np.asarray(s.pos_ned, float) + np.outer(t, v)
    n = len(t)
    z = np.zeros(n)
    return TrackingReference(t=t, phase=np.zeros(n, int), pos=pos, vel=np.tile(v, (n, 1)), acc=np.zeros((n, 3)),
                             airspeed=np.full(n, p.airspeed), alpha=np.full(n, p.alpha), phi=z, thrust=z.copy(),
                             tension=z.copy(), length=np.linalg.norm(pos, axis=1), reel_speed=z.copy(),
                             T1=seconds + 1.0, T2=1.0, meta={"source": "straight glide"})


def fly_broken(p: OperatingPoint, loop: str | None, signal: Multisine | None, params: Any,
               seconds: float, guided: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fly point ``p`` for ``seconds`` with ``loop`` broken and ``signal`` injected from
    :data:`SETTLE_S` (None: no injection, the baseline). ``guided``: the autopilot in AUTO on a
    straight glide (the outer loop's channels, :data:`GUIDANCE_LOOPS`), else the attitude loops
    holding the point (:data:`SURFACE_LOOPS`). Returns time [s] and, every step, the commands
    the plant got and the autopilot's outputs (one column per channel)."""
    from fdm_awe.sim.loop import CoSim, Limits

    g, gs = _glider_and_station(p)
    config = "foldable" if p.fold > 0.0 else "nominal"

    def inject(t: float) -> float:
        return float(signal(t - SETTLE_S)) if signal is not None and t >= SETTLE_S else 0.0

    if guided:
        ap = _autopilot(g, params, config, _straight_glide(g, p, seconds + 10.0))
        ctrl: Any = GuidedController(ap, None if loop is None else GUIDANCE_LOOPS[loop], inject)
    else:
        ctrl = HoldController(_autopilot(g, params, config), p, None if loop is None else SURFACE_LOOPS[loop], inject)
    sim = CoSim(g, gs, ctrl, limits=Limits(max_tension=None, airspeed_max=60.0))
    res = sim.run(seconds)
    if res.status != "ok":
        raise RuntimeError(f"{p.name}/{loop}: the run ended {res.status} ({res.event.message if res.event else ''})")
    n = len(ctrl.u_in)
    return np.asarray(res.t[:n], float), np.asarray(ctrl.u_in, float), np.asarray(ctrl.u_out, float)


def default_signal() -> Multisine:
    """20 frequencies, 0.63 .. 90 rad/s (harmonics 1 .. 143 of a 10 s period); 0.008 of full
    deflection each (0.025 RMS, 0.5 deg of surface: small enough for the loop to stay linear,
    the servos far from their rate limit)."""
    return log_multisine(10.0, 0.6, 90.0, 24, 0.008)


def analyse_point(p: OperatingPoint, loops: list[str], params: Any, signal: Multisine | None = None,
                  periods: int = 2) -> dict[str, tuple[Margins, np.ndarray, np.ndarray]]:
    """Margins of each loop in ``loops`` at point ``p``: {loop: (margins, w [rad/s], L)}."""
    sig = signal or default_signal()
    seconds = SETTLE_S + (1 + periods) * sig.period_s + 0.1
    out: dict[str, tuple[Margins, np.ndarray, np.ndarray]] = {}
    base: dict[bool, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    for loop in loops:
        guided = loop in GUIDANCE_LOOPS
        ch = GUIDANCE_LOOPS[loop] if guided else SURFACE_LOOPS[loop]
        if guided not in base:
            base[guided] = fly_broken(p, None, None, params, seconds, guided)
        t0, ui0, uo0 = base[guided]
        t, ui, uo = fly_broken(p, loop, sig, params, seconds, guided)
        n = min(len(t), len(t0))
        w, L = loop_gain(t[:n], ui[:n, ch] - ui0[:n, ch], uo[:n, ch] - uo0[:n, ch], sig, SETTLE_S,
                         settle_periods=1, periods=periods)
        out[loop] = (margins(w, L), w, L)
    return out


def _fmt(v: float | None, spec: str) -> str:
    """``v`` formatted with ``spec``, or ``-`` right-aligned in its width (no crossover)."""
    if v is None or not math.isfinite(v):
        return "-".rjust(int(spec.split(".")[0]))
    return format(v, spec)


def table(results: dict[str, dict[str, tuple[Margins, np.ndarray, np.ndarray]]]) -> str:
    """The margins as a text table, one row per point and loop."""
    lines = [f"{'point':<9} {'loop':<15} {'GM dB':>7} {'at rad/s':>9} {'PM deg':>7} {'at rad/s':>9}  aim",
             "-" * 66]
    for pname, loops in results.items():
        for loop, (m, _, _) in loops.items():
            ok = "ok" if m.meets(AIM_GAIN_DB, AIM_PHASE_DEG) else "SHORT"
            lines.append(f"{pname:<9} {loop:<15} {_fmt(m.gain_margin_db, '7.1f')} {_fmt(m.w_phase, '9.2f')} "
                         f"{_fmt(m.phase_margin_deg, '7.1f')} {_fmt(m.w_gain, '9.2f')}  {ok}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", default=",".join(POINTS), help="operating points (default: all)")
    ap.add_argument("--loops", default="elevator,aileron,rudder", help="loops to break (guidance_alpha, "
                    "guidance_bank: the outer loop, at the glide point only)")
    ap.add_argument("--set", action="append", default=[], metavar="ID=VALUE", help="autopilot parameter override")
    ap.add_argument("--json", metavar="FILE", help="write the margins and L(jw) as JSON")
    a = ap.parse_args(argv)
    from fdm_awe.autopilot.config import autopilot_params
    from fdm_awe.fileio import write_json

    params = autopilot_params()
    for item in a.set:
        k, _, v = item.partition("=")
        params.set(k.strip(), float(v))
    results: dict[str, dict[str, tuple[Margins, np.ndarray, np.ndarray]]] = {}
    for name in a.points.split(","):
        p = POINTS[name]
        loops = [lp for lp in a.loops.split(",") if not lp.startswith("guidance") or name == "glide"]
        results[name] = analyse_point(p, loops, params)
        print(table({name: results[name]}).split("\n", 2)[-1], flush=True)
    print()
    print(table(results))
    if a.json:
        doc = {"aim": {"gain_margin_db": AIM_GAIN_DB, "phase_margin_deg": AIM_PHASE_DEG},
               "signal": {"period_s": default_signal().period_s, "harmonics": list(default_signal().harmonics),
                          "amplitude": default_signal().amplitude},
               "params": {k: v for k, v in params.as_dict().items()},
               "points": {n: {"doc": POINTS[n].doc, "loops": {
                   lp: {**m.as_dict(), "w_rad_s": [round(float(x), 4) for x in w],
                        "L_re": [float(x.real) for x in L], "L_im": [float(x.imag) for x in L]}
                   for lp, (m, w, L) in loops.items()}} for n, loops in results.items()}}
        write_json(a.json, doc)
    return 0


if __name__ == "__main__":
    sys.exit(main())
