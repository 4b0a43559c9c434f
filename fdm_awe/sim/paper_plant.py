"""The ``paper`` plant: an ideal winch and an ideal thruster, so a 6-DOF flight of a ``paper``
scenario reference is faithful to that scenario's simplifications (docs/design.md section 4).

The ``paper`` scenario of the optimiser takes the thrust as a free control bounded by
``T_max`` with the static power fit ``P(T) = PT0 + PT1 T + PT2 T^2`` (eq. 39), the line tension
and the reel speed as free controls, books the generated energy mechanically
(``int tension x reel speed dt``) and the reel-in at a constant power ``P_rw``. The real
propeller (JSBSim 9x5, 1.6 N at 25 m/s) and the real ground station (passive rectifier,
~8.5 N per m/s of reel-out) cannot give those forces, so this plant replaces them:

- :class:`IdealThruster`: a force along the body x axis at the propeller's location
  (``external_reactions/ideal-thrust`` of ``aircraft/glider_foldable``), set to the commanded
  thrust clipped to ``[0, T_max]``; electrical power booked with the paper fit P(T) (PT0 is
  booked also at zero thrust, as the optimiser does). The real propeller stays at zero
  throttle: its folding blades then give neither thrust nor drag and draw no power.
- :class:`IdealWinch`: the ground-station interface of
  :class:`fdm_awe.groundstation.GroundStation` with a kinematic winch (the unstretched line
  length changes at exactly the commanded reel speed, in either converter mode) and the
  elastic line of ``tether/ground_station.xml`` (tension ``EA/l (d - l)`` when taut; no line
  drag and no line weight, as in the paper scenario). Booking: in generator mode the
  mechanical power ``tension x reel speed`` is the generated energy (``load``); in motor mode
  the scenario's constant ``P_rw`` is drawn from the supply, whatever the line needs.

Neither is a physical machine: they are labelled as the paper's assumptions wherever a
flight reports them (``plant: "paper"`` in the ``fdm-awe fly`` JSON).
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..groundstation.converter import GENERATOR, MODES
from ..groundstation.definitions import GroundStationParams, load_ground_station
from ..groundstation.station import WinchCommand
from ..groundstation.station_output import GroundStationOutput
from ..units import LBF

PLANTS = ("physical", "paper")

#: JSBSim property of the ideal thruster's force magnitude (lbf, along body x)
THRUST_PROPERTY = "external_reactions/ideal-thrust/magnitude"

_INPUTS = ("glider_work", "supply", "strain_payout")
_LOSSES = ("load", "reel_in_unspent", "break_release")
_INTERFACE = ("drum_work",)


class IdealWinchLedger:
    """Energy ledger of the ideal winch (J, since the last :meth:`clear`).

    Balance, exact for the discrete tension the winch applies (discrete-gradient form)::

        glider_work + supply + strain_payout = load + reel_in_unspent + break_release + delta_elastic

    ``glider_work`` = work of the glider on the line end (``int T d(d)``, > 0 generating);
    ``supply`` = ``P_rw`` x time in motor mode (the paper's constant reel-in power);
    ``strain_payout`` = change of the strain energy caused by the change of the unstretched
    length at a given stretch (< 0 while paying out strained line);
    ``load`` = ``int T dl`` in generator mode (the paper's mechanical generated energy);
    ``reel_in_unspent`` = supply minus the work the drum does on the line in motor mode
    (``int -T dl``): the part of the constant ``P_rw`` the line did not need (< 0 if it
    needed more); ``break_release`` = strain energy lost when the line breaks;
    ``drum_work`` = ``int T dl`` in both modes (interface flow).
    Field names match :class:`fdm_awe.groundstation.EnergyLedger` where they mean the same.
    """

    def __init__(self) -> None:
        self.clear()

    def clear(self, elastic: float = 0.0) -> None:
        for k in _INPUTS + _LOSSES + _INTERFACE:
            setattr(self, k, 0.0)
        self.stored0_elastic = float(elastic)
        self.stored_elastic = float(elastic)

    def delta_stored(self) -> float:
        return self.stored_elastic - self.stored0_elastic

    def residual(self) -> float:
        """Inputs - losses - change of stored energy, J."""
        return (sum(getattr(self, k) for k in _INPUTS) - sum(getattr(self, k) for k in _LOSSES)
                - self.delta_stored())

    def largest_term(self) -> float:
        return max([abs(getattr(self, k)) for k in _INPUTS + _LOSSES] + [abs(self.delta_stored())])

    def relative_residual(self) -> float:
        big = self.largest_term()
        return abs(self.residual()) / big if big > 0.0 else 0.0

    def as_dict(self) -> dict[str, float]:
        d = {k: float(getattr(self, k)) for k in _INPUTS + _LOSSES + _INTERFACE}
        d["delta_elastic"] = self.delta_stored()
        d["residual"] = self.residual()
        d["relative_residual"] = self.relative_residual()
        return d


class IdealWinch:
    """Kinematic winch + elastic line with the :class:`~fdm_awe.groundstation.GroundStation`
    co-simulation interface (``reset``, ``unstretched_length``, ``step``, ``ledger``).

    ``params``: line stiffness ``EA``, breaking load, length end stops and drum radius from
    ``tether/ground_station.xml`` (default: Table 1's line, ``line="paper"``, the paper
    scenario's); ``P_rw`` W: constant reel-in power booked in motor mode
    (the ``paper`` scenario's, fdm_awe.ocp.problem.Scenario.P_rw).
    """

    def __init__(self, params: GroundStationParams | None = None, P_rw: float = 6.0,
                 wind_ned: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        self.params = params if params is not None else load_ground_station(line="paper")
        if not (math.isfinite(P_rw) and P_rw >= 0.0):
            raise InputError(f"P_rw: {P_rw!r} W out of range (allowed >= 0)")
        self.P_rw = float(P_rw)
        tp = self.params.tether
        self._EA = tp.axial_stiffness
        self._r = self.params.winch.radius
        self.wind = tuple(float(v) for v in wind_ned)  # not used: the paper's line has no drag
        self._ledger = IdealWinchLedger()
        self.length = 200.0
        self.reel_speed = 0.0
        self.broken = False

    def set_wind(self, wind_ned: Sequence[float]) -> None:
        """Interface compatibility; the ideal line has no drag, so the wind is not used."""
        self.wind = tuple(float(v) for v in wind_ned)

    @property
    def ledger(self) -> IdealWinchLedger:
        return self._ledger

    def reset(self, tether_length: float = 200.0, reel_speed: float = 0.0, mode: str = GENERATOR,
              load_resistance: float | None = None, distance: float | None = None) -> None:
        """Unstretched paid-out length (m), reel speed (m/s, > 0 reel-out); ``mode`` and
        ``load_resistance`` are accepted for interface compatibility. ``distance`` (m), when
        given, sets the line's initial strain energy in the ledger's start state."""
        tp = self.params.tether
        if not (math.isfinite(tether_length) and tp.min_length <= tether_length <= tp.max_length):
            raise InputError(f"tether_length: {tether_length!r} out of range (allowed {tp.min_length:g} .. {tp.max_length:g} m)")
        if not math.isfinite(reel_speed):
            raise InputError(f"reel_speed: must be finite, got {reel_speed!r}")
        if mode not in MODES:
            raise InputError(f"mode: {mode!r} not one of {', '.join(MODES)}")
        self.length = float(tether_length)
        self.reel_speed = float(reel_speed)
        self.broken = False
        e0 = self._energy(distance - self.length, self.length) if distance is not None else 0.0
        self._ledger.clear(e0)

    def unstretched_length(self, distance: float, tension: float = 0.0) -> float:
        """Unstretched length (m) that carries ``tension`` (N) at winch-glider ``distance`` (m)."""
        if not (math.isfinite(distance) and distance > 0.0):
            raise InputError(f"distance: {distance!r} out of range (allowed > 0 m)")
        if not (math.isfinite(tension) and tension >= 0.0):
            raise InputError(f"tension: {tension!r} out of range (allowed >= 0 N)")
        return distance / (1.0 + tension / self._EA)

    def _energy(self, stretch: float, length: float) -> float:
        return 0.5 * self._EA / length * stretch * stretch if stretch > 0.0 else 0.0

    def step(self, dt: float, pos_ned: Sequence[float], vel_ned: Sequence[float], cmd: WinchCommand) -> GroundStationOutput:
        """Advance ``dt`` s with the line end at ``pos_ned`` (m) moving at ``vel_ned`` (m/s,
        NED, winch at the origin): the unstretched length changes by ``cmd.reel_speed_ref dt``;
        returns the line force on the glider for the coming step.

        The tension over the step is the discrete gradient of the strain energy between the
        start and the end (glider advanced linearly with ``vel_ned``), so that the ledger's
        ``glider_work - drum_work + strain_payout`` equals the change of strain energy exactly.
        """
        if not (0.0 < dt <= 1.0):
            raise InputError(f"dt: {dt!r} out of range (allowed > 0 and <= 1 s)")
        if not isinstance(cmd, WinchCommand):
            raise InputError(f"cmd: expected WinchCommand, got {type(cmd).__name__}")
        x, y, z = (float(v) for v in pos_ned)
        vx, vy, vz = (float(v) for v in vel_ned)
        if not math.isfinite(x + y + z + vx + vy + vz):
            raise InputError(f"glider position/velocity must be finite, got pos={tuple(pos_ned)!r} vel={tuple(vel_ned)!r}")
        tp = self.params.tether
        EA = self._EA
        v = float(cmd.reel_speed_ref)
        l0 = self.length
        l1 = min(max(l0 + v * dt, tp.min_length), tp.max_length)
        v = (l1 - l0) / dt  # the end stops hold the drum
        d0 = math.sqrt(x * x + y * y + z * z)
        x1, y1, z1 = x + vx * dt, y + vy * dt, z + vz * dt
        d1 = math.sqrt(x1 * x1 + y1 * y1 + z1 * z1)
        led = self._ledger
        event = None
        if self.broken:
            T = 0.0
        else:
            s0, s1 = max(d0 - l0, 0.0), max(d1 - l1, 0.0)
            k0, k1 = EA / l0, EA / l1
            # the glider's line end is where the glider is, not where the last step's linear
            # advance put it: the strain energy of that difference is work of the glider
            led.glider_work += 0.5 * k0 * s0 * s0 - led.stored_elastic
            ds = (d1 - l1) - (d0 - l0)
            T = k0 * 0.5 * (s1 * s1 - s0 * s0) / ds if abs(ds) > 1e-12 else k0 * s0
            T = max(T, 0.0)
            led.glider_work += T * (d1 - d0)
            led.drum_work += T * (l1 - l0)
            led.strain_payout += 0.5 * (k1 - k0) * s1 * s1
            if cmd.mode == GENERATOR:
                led.load += T * (l1 - l0)
            else:
                led.reel_in_unspent += T * (l1 - l0)
            led.stored_elastic = 0.5 * k1 * s1 * s1
            if T > tp.breaking_load:
                self.broken = True
                event = "tether_break"
                led.break_release += led.stored_elastic
                led.stored_elastic = 0.0
        if cmd.mode != GENERATOR:
            led.supply += self.P_rw * dt
            led.reel_in_unspent += self.P_rw * dt
        self.length, self.reel_speed = l1, v
        if event is None and l1 <= tp.min_length and v <= 0.0 and cmd.reel_speed_ref < 0.0:
            event = "tether_fully_reeled_in"
        elif event is None and l1 >= tp.max_length and cmd.reel_speed_ref > 0.0:
            event = "tether_fully_paid_out"
        if d0 > 0.0 and T > 0.0:
            c = -T / d0
            f = np.array((c * x, c * y, c * z))
        else:
            f = np.zeros(3)
        p_mech = T * v
        p_el = p_mech if cmd.mode == GENERATOR else -self.P_rw
        return GroundStationOutput(
            f, T, l1, v, v / self._r, 0.0, 0.0, cmd.mode, 0.0, p_el, event,
            "generator" if p_mech > 0.0 else ("motor" if p_mech < 0.0 else "idle"),
            p_mech, d0, d1 <= l1, self.broken)


class IdealThruster:
    """Ideal propulsive force along the glider's body x axis (see the module docstring).

    ``glider``: a :class:`fdm_awe.sixdof.JSBSimGlider` whose aircraft declares
    ``external_reactions/ideal-thrust``; ``T_max`` N: thrust bound; ``PT0, PT1, PT2``: the
    paper's power fit P(T) [W] (eq. 39, from the aircraft's ``propulsion/pm/paper-PT*``).
    """

    def __init__(self, glider: Any, T_max: float, PT0: float, PT1: float, PT2: float) -> None:
        node = glider.fdm.get_property_manager().get_node(THRUST_PROPERTY, False)
        if node is None:
            raise InputError(f"aircraft {glider.name!r}: no {THRUST_PROPERTY} (ideal thruster of the paper plant)")
        if not (math.isfinite(T_max) and T_max >= 0.0):
            raise InputError(f"T_max: {T_max!r} N out of range (allowed >= 0)")
        self._set = node.set_double_value
        self.T_max = float(T_max)
        self.PT0, self.PT1, self.PT2 = float(PT0), float(PT1), float(PT2)
        self.thrust = 0.0
        self._set(0.0)

    @classmethod
    def for_glider(cls, glider: Any, propulsion: Any) -> "IdealThruster":
        """From the aircraft's point-mass propulsion parameters (``T_max``, ``PT0..PT2``)."""
        p = propulsion
        return cls(glider, p.T_max, p.PT0, p.PT1, p.PT2)

    def command(self, thrust: float) -> float:
        """Set the thrust [N] for the coming step (clipped to ``[0, T_max]``); returns it."""
        t = float(thrust)
        t = 0.0 if not math.isfinite(t) else min(max(t, 0.0), self.T_max)
        self.thrust = t
        self._set(t / LBF)
        return t

    def power(self, thrust: float | None = None) -> float:
        """Electrical power [W] the paper's fit books for ``thrust`` (default: the current one)."""
        t = self.thrust if thrust is None else thrust
        return self.PT0 + self.PT1 * t + self.PT2 * t * t


__all__ = ["IdealThruster", "IdealWinch", "IdealWinchLedger", "PLANTS", "THRUST_PROPERTY"]
