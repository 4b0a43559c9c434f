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


def pull_out_height(sink: float, speed: float, v: float, v_stall: float, g: float, acc: float) -> float:
    """Height [m] a glider sinking at ``sink`` [m/s] (down positive) at ``speed`` [m/s] loses in a
    pull-out of constant radius ``speed^2 / a`` to level flight: ``sink^2 / (a (1 + cos gamma))``
    (``sin gamma = sink / speed``: ``sink^2 / (2 a)`` in a shallow dive, ``sink^2 / a`` in a
    vertical one), ``a`` [m/s^2] the smaller of ``acc`` and what the wing gives above 1 g at
    airspeed ``v`` [m/s] (``g ((v / v_stall)^2 - 1)``, ``v_stall`` [m/s] the 1 g stall speed, ``g``
    [m/s^2]); 0 while not sinking, infinite where the wing gives nothing."""
    if sink <= 0.0:
        return 0.0
    r = v / max(v_stall, 1e-6)
    a = min(acc, g * (r * r - _ONE_G))
    if a <= 0.0:
        return math.inf
    s = min(sink / max(speed, sink), 1.0)
    return sink * sink / (a * (1.0 + math.sqrt(1.0 - s * s)))


def ground_guard(active: bool, h: float, sink: float, speed: float, v: float, v_stall: float, g: float, floor: float,
                 acc: float, enter: float, stay: float) -> bool:
    """Whether the guard pulls up after a step at height ``h`` [m] above the ground, sinking at
    ``sink`` [m/s] (down positive) at ``speed`` [m/s] over the ground, airspeed ``v`` [m/s], stall
    speed ``v_stall`` [m/s] of the fold state, gravity ``g`` [m/s^2]; ``active``: it pulled up at
    the step before. It pulls up where ``h - pull_out_height(...)`` (:func:`pull_out_height` with
    ``acc`` [m/s^2]) is below ``floor`` [m] (``floor`` <= 0: off), entering at an airspeed of at
    least ``enter`` stall speeds and holding at ``stay`` stall speeds (at least 1)."""
    if floor <= 0.0:
        return False
    if h - pull_out_height(sink, speed, v, v_stall, g, acc) >= floor:
        return False
    lo = enter if not active else max(stay, 1.0)
    return v >= lo * v_stall
