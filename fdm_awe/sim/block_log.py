"""The bookkeeping rows of a compiled block of autopilot steps (``alog``): one vocabulary for
the kernel that writes them (:func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`) and the
flight's log that books them (:meth:`fdm_awe.sim.flight_log.FlightLog.book_block`).

Row ``k`` belongs to the step into row ``k`` of the co-simulation's log: the commands of the
step, the reference point flown (position m NED, cycle), the tracking error after the step
[m], the station's cumulative energies into the load and from the supply [J], and the glider's
mass [slug] (the ledger's kinetic energy).
"""

from __future__ import annotations

from .. import slots

#: ``alog`` columns per row: the step's commands (aileron .. fold command), the reference point,
#: its cycle, the tracking error [m], the station's energies [J], the glider's mass [slug]
ALOG = slots.declare("AutoLog", ("aileron", "elevator", "rudder", "throttle", "fold_cmd", "ref_x", "ref_y", "ref_z",
                                 "cycle", "track_error", "e_load", "e_supply", "mass_slug"))
#: the step's commands: the row's first columns (aileron .. fold command)
N_COMMANDS = ALOG.fold_cmd + 1
