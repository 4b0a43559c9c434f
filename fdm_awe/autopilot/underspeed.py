"""Underspeed protection of AUTO (after ArduPilot's TECS): when the airspeed falls below a margin
above the stall speed of the current fold state, the glider flies for speed before its path.

The condition is TECS's (``AP_TECS::_detect_underspeed``), on the wing's own stall speed: it is
entered when the airspeed falls below ``US_V_ENTER`` times the 1 g stall speed of the blended
polar (:func:`fdm_awe.definitions.aircraft.stall_speed`) where the reference flies faster and
the wing is open (:data:`FOLD_OPEN`), and
held until the airspeed is back above ``US_V_EXIT`` times it (or the reference's), at the
earliest ``US_HOLD`` after it was last below the entry speed. What the guidance does meanwhile is :func:`fdm_awe.autopilot.guidance.guidance_step`'s
(its ``us`` argument): speed priority (the along-path demand becomes a speed recovery, height is
given for it and never asked for) and on a slack line a pull away from the winch. With the
protection on (``US_V_ENTER`` > 0) the commanded angle of attack stays ``US_ALPHA_MARG`` below
the stall wherever the airspeed is below ``US_AMARG_V`` times the stall speed, in underspeed or
not: the attitude loop's overshoot and the gusts no longer carry it past. Leaving it, the AUTO step rejoins the path over
a rejoin segment from the glider's own state (:mod:`.rejoin`). A plain function: the compiled
AUTO step runs it too.
"""

from __future__ import annotations


#: the fold state below which the wing carries the glider: the airspeed condition acts there
#: only (the folded recovery flies the folded wing at up to 1.1 times its 1 g stall speed by
#: design, pulled in by the reel-in and diving)
FOLD_OPEN = 0.5


def underspeed_update(active: bool, t_low: float, t: float, v: float, v_stall: float, v_ref: float, fold: float,
                      enter: float, leave: float, hold: float) -> tuple[bool, float]:
    """The protection's state after a step at time ``t`` [s] with airspeed ``v`` [m/s], stall
    speed ``v_stall`` [m/s], the reference's airspeed ``v_ref`` [m/s] and fold state ``fold``
    [-]: ``(active, t_low)``, ``t_low`` the last time [s] the airspeed was below the entry speed
    ``enter * v_stall``. Entered below the entry speed where the reference flies above it and
    the wing is open (``fold`` < :data:`FOLD_OPEN`; ``enter`` <= 0: the protection is off), left
    once the airspeed is back to ``leave * v_stall`` (or the reference's airspeed, the lower)
    and ``t - t_low >= hold`` [s]."""
    if enter <= 0.0:
        return False, t_low
    lo = enter * v_stall
    if v < lo and v_ref > lo and fold < FOLD_OPEN:
        return True, t
    if active and (v < min(leave * v_stall, v_ref) or t - t_low < hold):
        return True, t_low
    return False, t_low
