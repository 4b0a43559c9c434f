"""From the co-simulation's state to the MAVLink endpoint's :class:`Telemetry`."""

from __future__ import annotations

from typing import Any, Callable

from .vehicle import Telemetry


def telemetry_builder(autopilot: Any, sim: Any) -> Callable[[Any, Any], Telemetry]:
    """A function ``(glider_state, gs_output) -> Telemetry`` for ``MavlinkEndpoint.update``.

    Net energy = ground-station load energy - supply energy - glider motor energy (J); the
    motor energy is integrated here from the glider's electrical power, step by step.
    """
    ledger = sim.gs.ledger
    dt = sim.dt
    acc = {"thrust": 0.0, "t": None}

    def build(s: Any, o: Any) -> Telemetry:
        return Telemetry(
            t=s.t, pos_ned=s.pos_ned, vel_ned=s.vel_ned, euler=s.euler, omega_body=s.omega_body,
            airspeed=s.airspeed, throttle=autopilot.glider.controls.throttle,
            tension_N=0.0 if o is None else o.tension, reel_speed_mps=0.0 if o is None else o.reel_speed,
            winch_power_W=0.0 if o is None else o.p_electrical,
            net_energy_J=ledger.load - ledger.supply - acc["thrust"],
            phase=autopilot.phase if autopilot.phase in ("ground", "generation", "transition", "recovery") else "transition",
            fold=s.fold, battery_current_A=s.current_A, mode=autopilot.mode, armed=autopilot.armed,
            cycling=autopilot.cycling, health_ok=s.is_finite(),
        )

    def integrate(s: Any) -> None:
        acc["thrust"] += max(s.prop_power_W, 0.0) * dt

    build.integrate = integrate  # type: ignore[attr-defined]
    return build
