"""The bookkeeping rows of a compiled block of autopilot steps (``alog``): one vocabulary for
the kernel that writes them (:func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`) and the
flight's log that books them (:meth:`fdm_awe.sim.flight_log.FlightLog.book_block`).

Row ``k`` belongs to the step into row ``k`` of the co-simulation's log: the commands of the
step, the reference point flown (position m NED, cycle), the tracking error after the step
[m], the station's cumulative energies into the load and from the supply [J], and the glider's
mass [slug] (the ledger's kinetic energy).
"""

from __future__ import annotations

#: ``alog`` columns per row
ALOG_COLUMNS = ("aileron", "elevator", "rudder", "throttle", "fold_cmd", "ref_x", "ref_y", "ref_z", "cycle",
                "track_error", "e_load", "e_supply", "mass_slug")
(AL_AIL, AL_ELE, AL_RUD, AL_THR, AL_FOLD, AL_RX, AL_RY, AL_RZ, AL_CYCLE, AL_ERR, AL_LOAD, AL_SUPPLY,
 AL_MASS) = range(13)
#: columns per row
N_ALOG = 13
#: the step's commands: the row's first columns (aileron .. fold command)
N_COMMANDS = AL_FOLD + 1
if len(ALOG_COLUMNS) != N_ALOG:  # pragma: no cover - a definition error in this module
    raise RuntimeError("fdm_awe.sim.block_log: bookkeeping column names and offsets disagree")
