"""The ground station's output of one step (:class:`GroundStationOutput`), as the Python step
builds it and as a compiled step's row fills it (on first read: a controller that ignores it pays
nothing)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .substeps import EVENTS, MACHINE_MODES as _MACHINE_MODES
_new = object.__new__


class GroundStationOutput:
    """Ground-station output of one step (SI). Tension/powers are means over the step;
    speeds, current and voltages are end-of-step values.

    Fields (constructor order): ``force_on_glider_ned`` N, line force acting ON the glider
    (tension + drag/weight shares; given as an array or three floats, read as an array);
    ``tension`` N, mean line tension over the step; ``length`` m, unstretched paid-out length;
    ``reel_speed`` m/s, > 0 reel-out; ``omega`` rad/s, drum speed (> 0 reel-out); ``current`` A,
    armature current (>= 0); ``duty`` T1 duty in motor mode (below 0: the current limit's braking,
    the share of the period with T2 open too, :mod:`.converter`), T2 (boost) duty in generator mode;
    ``mode`` converter mode in effect ("generator" / "motor"); ``u_link`` V, DC-link (load)
    capacitor voltage; ``p_electrical`` W, mean (load power - supply power): > 0 delivered out
    of the station; ``event`` None, "tether_break", "tether_fully_reeled_in",
    "tether_fully_paid_out"; ``machine_mode`` eq. 17 sign rule: "generator", "motor" or "idle";
    ``p_mechanical`` W, mean tension x end reel speed at the drum; ``distance`` m, winch-glider
    distance at the start of the step; ``slack`` line slack (d <= l) at the end of the step;
    ``broken`` line broken (no force from now on).

    ``force_xyz`` gives the force as a tuple of three floats (the co-simulation's hot path: the
    array is only built when ``force_on_glider_ned`` is read).
    """

    __slots__ = ("_force", "tension", "length", "reel_speed", "omega", "current", "duty", "mode", "u_link",
                 "p_electrical", "event", "machine_mode", "p_mechanical", "distance", "slack", "broken")

    def __init__(self, force_on_glider_ned: Any, tension: float, length: float, reel_speed: float, omega: float,
                 current: float, duty: float, mode: str, u_link: float, p_electrical: float, event: str | None,
                 machine_mode: str = "idle", p_mechanical: float = 0.0, distance: float = 0.0,
                 slack: bool = False, broken: bool = False) -> None:
        self._force = force_on_glider_ned
        self.tension = tension
        self.length = length
        self.reel_speed = reel_speed
        self.omega = omega
        self.current = current
        self.duty = duty
        self.mode = mode
        self.u_link = u_link
        self.p_electrical = p_electrical
        self.event = event
        self.machine_mode = machine_mode
        self.p_mechanical = p_mechanical
        self.distance = distance
        self.slack = slack
        self.broken = broken

    @property
    def force_on_glider_ned(self) -> np.ndarray:
        """N, line force acting ON the glider, NED (3,) array."""
        f = self._force
        if type(f) is not np.ndarray:
            f = self._force = np.array(f, dtype=float)
        return f

    @force_on_glider_ned.setter
    def force_on_glider_ned(self, value: Any) -> None:
        self._force = value

    @property
    def force_xyz(self) -> tuple[float, float, float]:
        """The line force on the glider as three floats (N, NED)."""
        f = self._force
        if type(f) is tuple:  # the compiled step's output
            return f
        if type(f) is np.ndarray:
            f = f.tolist()
        return (f[0], f[1], f[2])

    _FIELDS = ("force_on_glider_ned",) + __slots__[1:]

    def __repr__(self) -> str:
        return "GroundStationOutput(" + ", ".join(f"{n}={getattr(self, n)!r}" for n in self._FIELDS) + ")"

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(np.array_equal(getattr(self, n), getattr(other, n)) if n == "force_on_glider_ned"
                   else getattr(self, n) == getattr(other, n) for n in self._FIELDS)

    __hash__ = None  # type: ignore[assignment]  # mutable, like the dataclass it replaces


def _set_slots(o: GroundStationOutput, fx: float, fy: float, fz: float, tension: float, length: float,
               reel_speed: float, omega: float, current: float, duty: float, mode: str, u_link: float, p_el: float,
               ev: int, mm: int, p_mech: float, distance: float, slack: bool, broken: bool) -> GroundStationOutput:
    """Set every slot of ``o`` (no __init__ call: the hot path); ``ev`` and ``mm`` the event and
    machine-mode codes."""
    o._force = (fx, fy, fz)
    o.tension = tension
    o.length = length
    o.reel_speed = reel_speed
    o.omega = omega
    o.current = current
    o.duty = duty
    o.mode = mode
    o.u_link = u_link
    o.p_electrical = p_el
    o.event = EVENTS[ev]
    o.machine_mode = _MACHINE_MODES[mm]
    o.p_mechanical = p_mech
    o.distance = distance
    o.slack = slack
    o.broken = broken
    return o


def step_output(*fields: Any) -> GroundStationOutput:
    """GroundStationOutput(...) of a step (the fields of :func:`_set_slots`)."""
    return _set_slots(_new(GroundStationOutput), *fields)


class _RowOutput(GroundStationOutput):
    """A :class:`GroundStationOutput` of a compiled step whose fields are filled from the
    step's row (``_force`` holds it until then) on first read; it then becomes a plain
    GroundStationOutput (same slots)."""

    __slots__ = ()

    def _fill(self) -> None:
        (tmean, length, rr, w, i, duty, p_el, fx, fy, fz, u_link, ev, mm, p_mech, d, slack, broken) = self._force
        _set_slots(self, fx, fy, fz, tmean, length, rr, w, i, duty, self.mode, u_link, p_el, int(ev), int(mm), p_mech, d,
                   slack != 0.0, broken != 0.0)
        self.__class__ = GroundStationOutput

    def __getattr__(self, name: str) -> Any:  # an unfilled slot
        if name in GroundStationOutput.__slots__:
            self._fill()
            return getattr(self, name)
        raise AttributeError(name)

    @property
    def force_on_glider_ned(self) -> np.ndarray:
        self._fill()
        return self.force_on_glider_ned

    @force_on_glider_ned.setter
    def force_on_glider_ned(self, value: Any) -> None:
        self._fill()
        self._force = value

    @property
    def force_xyz(self) -> tuple[float, float, float]:
        self._fill()
        return self._force

    def __repr__(self) -> str:
        self._fill()
        return repr(self)

    def __eq__(self, other: object) -> bool:
        self._fill()
        return self == other

    __hash__ = None  # type: ignore[assignment]


def output_from_row(row: list[float], mode: str) -> GroundStationOutput:
    """The step's output from a compiled loop's row (``fdm_awe.sim.kernel.GS``, a
    list of floats), filled in when first read (a controller that ignores it pays nothing)."""
    o = _new(_RowOutput)
    o._force = row  # the row waits in the force slot until the first read
    o.mode = mode
    return o
