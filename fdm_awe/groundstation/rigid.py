"""The rigid line: the straight line without elasticity (``--tether rigid``).

The optimiser's line flown in 6-DOF: straight from the winch to the hook, its paid-out length
the winch-glider distance while taut, the tension whatever the drum and the glider need to keep
it so; the glider takes the straight line's shares of the line's drag and weight
(:mod:`.tether`). Selected with ``GroundStation(tether="rigid")``; its registry entry is in
:mod:`.linemodels`.

Formulation: the stiff limit of the straight line's step (:func:`.substeps.station_step`, the
drum's implicit sub-steps included), with an axial stiffness ``k`` that does not depend on the
paid-out length (an inextensible line has no EA / l) and grows as the flight step shrinks,
``k = STIFFNESS (REFERENCE_STEP / dt)^2``: the line tends to the inextensible one as the step
tends to 0. Why tied to the step: the co-simulation hands the glider the step's mean tension
computed on the glider's motion predicted at constant velocity (explicit in its acceleration),
which feeds energy into the glider-line mode at a rate that grows with ``(omega dt)^2``; the
line's only damping is the drum's. ``omega dt`` held at ``sqrt(k / m) dt`` = 0.31 rad per step
for the 0.74 kg glider keeps that mode quiet (measured on the nominal 8 m/s cycle at 1/120 s:
k = 1000 and 1500 N/m fly the cycle's net energy within 0.03 % of each other and track as the
elastic line does; 2500 N/m rings at 16 Hz, 5000 N/m at 15 Hz with 20 N swings). Physically, at
1/120 s: 5 cm of stretch at the sized line's rated 50 N (the elastic lines on 200 m: 0.4 m to
1.5 m), so the length equals the distance to within the stretch of the tension; the mode
against the drum's inertia, ``sqrt(k r_w^2 / J)`` = 68 rad/s (drum 0.000192 kg m^2, r_w 3 cm),
is integrated implicitly in the drivetrain's 2 ms sub-steps. In steady reel-out the tension, the
reel speed and the powers are the steady relations' (:mod:`.steady`) whatever ``k``: the drum
turns at the glider's radial speed at once, where the elastic line takes seconds to stretch.

The drivetrain's step takes the stiffness as ``EA / l`` at the step's start length: the rigid
step sets the EA slot of the constants to ``k l`` before each step (the constants array is the
station's own), and books the stiffness's return to ``k`` (it ended the last step at ``EA / l``
of the new length) as the ledger's strain term, so the station's ledger closes as with the
elastic line.
"""

from __future__ import annotations

from typing import Any, Callable

from .. import slots
from . import substeps, winch
from .linestep import compile_line_step
from .substeps import CONST, LEDGER, STATE, STATION, station_step
from ..jitcache import compiled_once

#: the rigid line's axial stiffness at steps of :data:`REFERENCE_STEP`, N/m, the same at every
#: length (see the module docstring)
STIFFNESS = 1000.0
#: the flight step of :data:`STIFFNESS`, s (the co-simulation's default)
REFERENCE_STEP = 1.0 / 120.0
#: its constants after the station's (:data:`.substeps.STATION`)
RIGID = slots.declare("RigidConstants", ("stiffness", "reference_step"), start=slots.size(STATION))


def constants(param: int, tp: Any, drag_scale: float) -> list[float]:
    """The constants after the station's (:data:`RIGID`)."""
    return [STIFFNESS, REFERENCE_STEP]


def stiffness(c, dt: float) -> float:
    """The rigid line's stiffness (N/m) at flight steps of ``dt`` s (constants ``c``)."""
    q = c[RIGID.reference_step] / dt
    return c[RIGID.stiffness] * q * q


def unstretched(tp: Any, param: int, distance: float, tension: float) -> float:
    """Paid-out length (m) that carries ``tension`` (N) at ``distance`` (m): ``d - T / k`` (``k``
    at the reference step)."""
    return distance - tension / STIFFNESS


def rigid_station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL):
    """:func:`.substeps.station_step` on the rigid line (same arguments and returns; ``c`` holds
    :data:`RIGID` after the station's, its EA slot is set here)."""
    k = stiffness(c, dt)
    length = s[STATE.length]
    if s[STATE.broken] == 0.0:  # not broken: the stiffness back to k at the new start length (booked)
        k_was = c[CONST.EA] / length
        sp = s[STATE.stretch] if s[STATE.stretch] > 0.0 else 0.0
        s[LEDGER.strain_payout] += 0.5 * (k - k_was) * sp * sp
        s[LEDGER.stored_elastic] = 0.5 * k * sp * sp
    c[CONST.EA] = k * length
    return station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL)


@compiled_once
def compiled_rigid() -> Callable | None:
    """:func:`rigid_station_step` compiled by numba (cached on disk), or None (numba missing,
    ``FDM_AWE_JIT=0``, or a broken install: the Python function runs instead)."""
    return compile_line_step(rigid_station_step, (station_step, stiffness), (substeps, winch),
                             "fdm_awe.groundstation.rigid")
