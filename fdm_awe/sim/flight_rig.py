"""The plant of a flight, wired: the wind it meets (:class:`FlightWind`), its turbulence, its
ground station with the reference's line, the glider put on the reference's first point, the
autopilot and the co-simulation (:func:`build_rig`), before the flight
(:func:`fdm_awe.sim.flight.fly`) flies them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..autopilot.autopilot import Autopilot
from ..autopilot.config import autopilot_params
from ..definitions.aircraft import Glider, load_glider
from ..definitions.catalog import Aircraft
from ..errors import InputError
from ..groundstation import GroundStation, GroundStationParams
from ..groundstation.line import check_line
from ..groundstation.linemodels import TetherModel
from ..groundstation.source import StationFile, resolve_ground_station
from ..groundstation.steady import motor_max_reel_in_speed
from ..ocp.problem import Scenario
from ..sixdof import JSBSimGlider
from ..turbulence import Turbulence, TurbulenceSetting, mean_height
from ..wind import WindProfile, line_height
from .loop import CoSim, Limits
from .paper_plant import IdealThruster, IdealWinch


class FlightWind:
    """The wind a reference was optimised in (metadata ``wind_ned_mps`` at the height of its
    ``wind_profile``; absent: uniform, no wind): JSBSim's steady wind follows the glider's
    altitude step by step, the ground station's line drag the wind at the line's height
    (:data:`fdm_awe.wind.LINE_HEIGHT_FRACTION` of the glider's), turbulence on top."""

    def __init__(self, meta: dict[str, Any]) -> None:
        #: the wind at the profile's reference height, NED [m/s]
        self.ned = tuple(float(v) for v in meta.get("wind_ned_mps", (0.0, 0.0, 0.0)))
        self.profile = WindProfile.from_dict(meta.get("wind_profile"), "reference metadata.wind_profile")

    def at(self, h: float) -> tuple[float, float, float]:
        """The steady wind at height ``h`` [m], NED [m/s]."""
        f = float(self.profile.factor(h))
        return (self.ned[0] * f, self.ned[1] * f, 0.0)

    def glider_start(self, h: float) -> tuple[float, float, float]:
        """The glider's wind at the start height ``h`` [m] (the reference wind when uniform)."""
        return self.ned if self.profile.uniform else self.at(h)

    def given(self, height: np.ndarray) -> np.ndarray:
        """The steady wind JSBSim was given for each logged row, NED [m/s] (n, 3), from the
        glider's logged heights ``height`` [m]: the start wind for the first row, then the wind
        at the height of the row before (the flight's step hook sets the next step's wind)."""
        n = len(height)
        if self.profile.uniform:
            return np.tile(np.asarray(self.ned, float), (n, 1))
        out = np.empty((n, 3))
        if n:
            out[0] = self.glider_start(float(height[0]))
            for k in range(1, n):
                out[k] = self.at(float(height[k - 1]))
        return out


def turbulence_setting(reference: Any, turbulence: Turbulence | tuple[str, int] | None,
                       flight_wind: dict[str, Any] | None = None) -> TurbulenceSetting | None:
    """The turbulence of a flight of ``reference`` (a :class:`~fdm_awe.autopilot.tracking.TrackingReference`)
    realised in its wind (metadata ``wind_ned_mps`` and ``wind_profile``; :mod:`fdm_awe.turbulence`),
    the hub height the time-mean height of its cycle; None without turbulence. A form that
    cannot be realised there raises a one-line :class:`InputError` naming ``--turbulence``.
    ``flight_wind`` (reference-metadata form) is the wind the flight meets where it is not the
    reference's own (a reference set flown in another wind)."""
    form = Turbulence.of(turbulence)
    if form is None:
        return None
    wind = FlightWind(reference.meta if flight_wind is None else flight_wind)
    hub = mean_height(reference.t, -reference.pos[:, 2])
    return form.setting(math.hypot(wind.ned[0], wind.ned[1]), wind.profile, hub)


def station_params(meta: dict[str, Any], paper: bool, station: Any) -> tuple[StationFile, GroundStationParams]:
    """The ground station ``station`` (:func:`~fdm_awe.groundstation.source.resolve_ground_station`) and its
    definition with the line a reference (metadata ``meta``) was optimised with (none named: Table 1's,
    ``paper``, that of references written before lines were named). Read and checked before JSBSim loads."""
    line = meta.get("line")
    if not paper and meta.get("generator") == "ideal":
        raise InputError("reference metadata.generator: 'ideal' is the optimiser's upper bound (a loss-free converter "
                         "holding any tension), which no ground station realises; allowed passive, boost")
    st = resolve_ground_station(station, "ground_station")
    return st, st.load("paper" if line is None else check_line(line, "reference metadata.line"))


@dataclass
class Rig:
    """The blocks of a flight, wired: glider, ground station (or the paper plant's winch),
    airframes, the paper plant's thruster (None on the physical plant), autopilot, co-simulation."""

    glider: JSBSimGlider
    gs: Any
    airframes: Glider
    thruster: IdealThruster | None
    ap: Autopilot
    sim: CoSim


def build_rig(reference: Any, wind: FlightWind, gsp: GroundStationParams, config: str, dt: float,
         turbulence: TurbulenceSetting | None, params: Any, paper: bool, tether_drag_scale: float,
         tether: TetherModel, aircraft: Aircraft) -> Rig:
    """Build the plant (see :func:`fdm_awe.sim.flight.fly`) of ``aircraft``, start it on the reference's first
    point and wire the autopilot and the co-simulation."""
    h0 = -float(reference.sample(0.0).pos[2])
    w0 = wind.glider_start(h0)
    glider = JSBSimGlider.of(aircraft, dt=dt, wind_ned=w0, turbulence=turbulence)
    airframes = load_glider(aircraft)
    if paper:
        gs = IdealWinch(gsp, P_rw=Scenario.named("paper").P_rw, wind_ned=w0)
    else:
        gs = GroundStation(gsp, wind_ned=w0 if wind.profile.uniform else wind.at(line_height(h0)),
                           tether_drag_scale=tether_drag_scale, tether=tether)
        gs.set_line_wind(wind.profile, wind.ned[:2])  # a line's nodes: the profile at their own heights
    _start_on_reference(glider, gs, reference.sample(0.0), w0, paper)
    ps = params if params is not None else autopilot_params(aircraft.autopilot_file)
    thruster = IdealThruster.for_glider(glider, airframes.unfolded.propulsion) if paper else None
    ap = Autopilot(glider, airframes, ps, reference, config=config, station=gsp,
                   thruster=thruster, winch="ideal" if paper else "physical",
                   reel_in_max=math.inf if paper else motor_max_reel_in_speed(0.0, gsp))
    # the line's own breaking load ends a run as "tether_break" (ground-station event); the
    # co-simulation's tension limit sits just above it so it never pre-empts that event
    sim = CoSim(glider, gs, ap, dt=dt, limits=Limits(max_tension=1.01 * gsp.tether.breaking_load, grace_s=1.0))
    return Rig(glider, gs, airframes, thruster, ap, sim)


def _start_on_reference(glider: JSBSimGlider, gs: Any, r0: Any, wind: tuple[float, float, float],
                        paper: bool) -> None:
    """Put the glider on the reference point ``r0`` (position, air velocity in ``wind`` [m/s],
    bank, angle of attack, wing open) and the line at its tension there."""
    va = r0.vel - np.asarray(wind)
    V = float(np.linalg.norm(va))
    gamma = -math.asin(max(-1.0, min(1.0, va[2] / V)))
    psi = math.atan2(va[1], va[0])
    glider.reset(r0.pos, V, gamma=gamma, psi=psi, phi=r0.phi, alpha=r0.alpha, fold=0.0)
    s0 = glider.state()
    # start on the reference: the line carries the reference tension at the start point
    d_start = float(np.linalg.norm(s0.hook_pos_ned))
    l_start = gs.unstretched_length(d_start, r0.tension)
    if paper:
        gs.reset(tether_length=l_start, reel_speed=max(r0.reel_speed, 0.0), mode="generator", distance=d_start)
    else:
        gs.reset(tether_length=l_start, reel_speed=max(r0.reel_speed, 0.0), mode="generator")
