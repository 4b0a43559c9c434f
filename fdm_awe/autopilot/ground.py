"""Ground-proximity guard of AUTO: pull up before the ground, whatever the path or the underspeed
protection ask.

In a lull the line goes slack, the underspeed protection (:mod:`.underspeed`) dives for speed and
the path (or a rejoin segment begun from the diving glider's own state) may keep the dive going:
flown near the ground that ended in ground contact (foldable glider, sized line: 12 m/s in IEC
class A, seed 5; 10 m/s in moderate turbulence, seed 9). The guard is a terrain warning's
pull-up: it acts where the glider, sinking at ``sink`` [m/s], would pass below the floor
``GP_ALT`` [m] before a pull-out at the acceleration ``GP_ACC`` [m/s^2] across its path (or at
what its wing can give at its airspeed, if less) levelled it, and only once it flies fast
enough to pull (``US_V_EXIT`` times the stall speed of its fold state; slower the underspeed protection
gains speed first). It holds while the prediction stays below the floor and the airspeed above
the stall speed (``US_V_ENTER`` times it, at least 1). What the guidance then flies is
:func:`fdm_awe.autopilot.guidance.guidance_step`'s pull-up (``us`` ``US_PULL_UP``). A plain
function: the compiled AUTO step runs it too.
"""

from __future__ import annotations

import math

#: the reference 1 g load factor the available pull-out acceleration is counted from
_ONE_G = 1.0
#: the share of the pull-out acceleration the guard's prediction keeps whatever the line takes
LINE_KEEPS = 0.1


def line_against_pull_out(fx: float, fy: float, fz: float, vx: float, vy: float, vz: float, m: float) -> float:
    """Acceleration [m/s^2] the line's pull ``f*`` [N, NED] on a glider of mass ``m`` [kg] takes
    from a pull-out of its path (velocity ``v*`` [m/s], NED): the pull's component against the
    pull-out's direction, the normal of the path in its vertical plane, upward; 0 where the line
    helps or the direction is undefined (no speed, a vertical path). In a dive away from the
    winch the line pulls almost straight against it: with the generator holding 40 N a 1.5 kg
    glider loses 25 m/s^2, all its pull-out."""
    speed2 = vx * vx + vy * vy + vz * vz
    if speed2 < 1e-6:
        return 0.0
    c = -vz / speed2  # (up . v) / |v|^2, up = (0, 0, -1)
    nx, ny, nz = -c * vx, -c * vy, -1.0 - c * vz  # up minus its part along the path: the normal, up
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    if norm < 1e-3:
        return 0.0
    along = (fx * nx + fy * ny + fz * nz) / norm
    return max(-along, 0.0) / m


def pull_out_height(sink: float, speed: float, v: float, v_stall: float, g: float, acc: float,
                    a_line: float) -> float:
    """Height [m] a glider sinking at ``sink`` [m/s] (down positive) at ``speed`` [m/s] loses in a
    pull-out of constant radius ``speed^2 / a`` to level flight: ``sink^2 / (a (1 + cos gamma))``
    (``sin gamma = sink / speed``: ``sink^2 / (2 a)`` in a shallow dive, ``sink^2 / a`` in a
    vertical one), ``a`` [m/s^2] the smaller of ``acc`` and what the wing gives above 1 g at
    airspeed ``v`` [m/s] (``g ((v / v_stall)^2 - 1)``, ``v_stall`` [m/s] the 1 g stall speed, ``g``
    [m/s^2]), less ``a_line`` [m/s^2], what the line takes from it (:func:`line_against_pull_out`),
    down to :data:`LINE_KEEPS` of it (the guard's pull-up lets the line go, GP_EASE: a line that
    took all of it would have the guard pull up at any height at any sink); 0 while not sinking,
    infinite where the wing gives nothing."""
    if sink <= 0.0:
        return 0.0
    r = v / max(v_stall, 1e-6)
    a = min(acc, g * (r * r - _ONE_G))
    a = max(a - a_line, LINE_KEEPS * a)
    if a <= 0.0:
        return math.inf
    s = min(sink / max(speed, sink), 1.0)
    return sink * sink / (a * (1.0 + math.sqrt(1.0 - s * s)))


def ground_guard(active: bool, h: float, sink: float, speed: float, v: float, v_stall: float, g: float, floor: float,
                 acc: float, enter: float, stay: float, line: bool, a_line: float) -> bool:
    """Whether the guard pulls up after a step at height ``h`` [m] above the ground, sinking at
    ``sink`` [m/s] (down positive) at ``speed`` [m/s] over the ground, airspeed ``v`` [m/s], stall
    speed ``v_stall`` [m/s] of the fold state, gravity ``g`` [m/s^2]; ``active``: it pulled up at
    the step before. It pulls up where ``h - pull_out_height(...)`` (:func:`pull_out_height` with
    ``acc`` [m/s^2], less ``a_line`` [m/s^2] the line takes, ``line`` true: GP_LINE) is below ``floor`` [m] (``floor`` <= 0:
    off), entering at an airspeed of at least ``enter`` stall speeds and holding at ``stay`` stall
    speeds (at least 1). With ``line``, once it pulls up it holds until the sink is stopped: the
    generator lets the line go during the pull-up (GP_EASE) and would take it again as soon as
    the guard let go, so a guard that cleared on the eased line's prediction chattered (nominal
    9 m/s, lumped line: on at 86 m, off 0.2 s later, the line snatched back to 45-53 N, on again
    8 m lower, three times in a dive)."""
    if floor <= 0.0:
        return False
    if line and active:
        return sink > 0.0 and v >= max(stay, 1.0) * v_stall
    if h - pull_out_height(sink, speed, v, v_stall, g, acc, a_line) >= floor:
        return False
    lo = enter if not active else max(stay, 1.0)
    return v >= lo * v_stall
