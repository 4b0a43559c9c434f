"""The ground station as a co-simulation block: ``GroundStation.step(dt, pos, vel, cmd)``.

Wires the line (:mod:`.tether`), drum (:mod:`.winch`), DC machine (:mod:`.machine`), converter
(:mod:`.converter`) and PI speed controller (:mod:`.controller`) through the implicit
sub-stepping of :mod:`.drivetrain`, and returns the force the line exerts on the glider. One
step is the line model's (:mod:`.linemodels`; :func:`.substeps.station_step` for the straight
line): compiled by numba when available, run by Python otherwise (the same function).

Coupling with the flight model: the glider position/velocity at the start of the flight step
are given; inside the step the glider is advanced linearly with that velocity; the returned
force is the line tension averaged over the step (to be applied during the coming flight
step), along the line at the start position, plus the glider's shares of line drag and line
weight (:mod:`.tether`).
"""

from __future__ import annotations

import math
from math import isfinite
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .. import slots
from ..errors import InputError
from ..jitcache import jit_off
from .converter import GENERATOR, MODES, MOTOR
from .definitions import GroundStationParams, load_ground_station
from .drivetrain import Drivetrain
from .ledger import EnergyLedger
from .linemodels import TetherModel, parse_tether
from .lumped_forces import set_gust
from .lumped_state import LINE
from .machine import machine_mode
from .station_output import GroundStationOutput, output_from_row, step_output
from .substeps import STATION
from .tether import check_tether_drag_scale, line_drag_coefficient
_NAN = float("nan")
#: a compiled step not asked for yet
_PENDING = object()


def _finite(name: str, v: float, lo: float | None = None, hi: float | None = None,
            lo_open: bool = False) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{name}: not a number: {v!r}") from None
    if not math.isfinite(f):
        raise InputError(f"{name}: must be finite, got {f!r}")
    if lo is not None and (f <= lo if lo_open else f < lo):
        raise InputError(f"{name}: {f:g} out of range (allowed {'>' if lo_open else '>='} {lo:g}"
                         + (f" and <= {hi:g})" if hi is not None else ")"))
    if hi is not None and f > hi:
        raise InputError(f"{name}: {f:g} out of range (allowed <= {hi:g})")
    return f


def command_values(motor: float, reel_speed_ref: float, load_resistance: float, boost_duty: float, duty: float,
                   r_drum: float, boost_duty_default: float,
                   load_resistance_default: float) -> tuple[bool, bool, float, float, float, float]:
    """A winch command given as numbers (``motor`` 1.0 motor mode, 0.0 generator; NaN for
    ``load_resistance``, ``boost_duty``, ``duty``: the field left at its default, as None in a
    :class:`WinchCommand`) turned into the terms of :func:`.substeps.station_step`:
    ``(ok, motor, drum speed reference rad/s, duty (NaN: PI), boost duty, load resistance ohm)``
    on a drum of radius ``r_drum`` [m] with the definition's defaults. ``ok`` is whether
    :class:`WinchCommand` accepts the values (a plain function: compiled loops use it too)."""
    ok = (isfinite(reel_speed_ref)
          and (load_resistance != load_resistance or (isfinite(load_resistance) and load_resistance > 0.0))
          and (boost_duty != boost_duty or 0.0 <= boost_duty <= 1.0)
          and (duty != duty or 0.0 <= duty <= 1.0))
    return (ok, motor != 0.0, reel_speed_ref / r_drum, duty,
            boost_duty_default if boost_duty != boost_duty else boost_duty,
            load_resistance_default if load_resistance != load_resistance else load_resistance)


@dataclass(frozen=True)
class WinchCommand:
    """Ground-station command for one flight step.

    ``mode``: ``"generator"`` (T1 off: passive rectifier into R_L, or boost with ``boost_duty``)
    or ``"motor"`` (T2 on, T1 PWM from the PI speed controller, or open loop with ``duty``).
    ``reel_speed_ref`` m/s (reel-out positive; reel-in negative), used by the PI in motor mode.
    ``load_resistance`` ohm (None = definition default). ``duty`` (None = PI) T1 duty in [0, 1].
    ``boost_duty`` (None = definition default) T2 duty in generator mode, in [0, 1].
    """

    mode: str = GENERATOR
    reel_speed_ref: float = 0.0
    load_resistance: float | None = None
    duty: float | None = None
    boost_duty: float | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise InputError(f"WinchCommand.mode: {self.mode!r} not one of {', '.join(MODES)}")
        _finite("WinchCommand.reel_speed_ref", self.reel_speed_ref)
        if self.load_resistance is not None:
            _finite("WinchCommand.load_resistance", self.load_resistance, lo=0.0, lo_open=True)
        if self.duty is not None:
            _finite("WinchCommand.duty", self.duty, lo=0.0, hi=1.0)
        if self.boost_duty is not None:
            _finite("WinchCommand.boost_duty", self.boost_duty, lo=0.0, hi=1.0)


class GroundStation:
    """Tether + winch + DC machine + half-bridge converter + PI, steppable with a flight model.

    ``wind_ned`` (m/s, NED) is only used for the line drag share (air-relative glider velocity).
    ``tether_drag_scale`` (-, 0 .. 10, default 1 = the defined line) multiplies the line drag
    share on the glider: a sensitivity knob, the ground-station twin of
    :attr:`fdm_awe.ocp.problem.CycleProblem.tether_drag_scale` (e.g. 0.5 ~ half the diameter).
    ``tether``: the line model, a :class:`.linemodels.TetherModel` or its ``--tether`` form
    (:func:`.linemodels.parse_tether`): ``"straight"`` (default, :mod:`.tether`), ``"lumped:N"``
    (N = 2..200 segments, :mod:`.lumped`: the line's mass, weight and drag on its nodes; its
    shape, tensions and own ledger via :meth:`line_nodes`, :meth:`line_tensions` and
    :attr:`line_ledger`), or another entry of :data:`.linemodels.LINE_MODELS`.
    """

    def __init__(self, params: GroundStationParams | None = None,
                 wind_ned: Sequence[float] = (0.0, 0.0, 0.0), tether_drag_scale: float = 1.0,
                 tether: TetherModel | str = "straight") -> None:
        self.tether_drag_scale = check_tether_drag_scale(tether_drag_scale)
        #: the line model (its registry entry ``line.kind`` and parameter)
        self.line = line = parse_tether(tether)
        self.tether = str(line)
        self.params = params if params is not None else load_ground_station()
        self.drivetrain = Drivetrain(self.params, line.state_size())
        self.set_wind(wind_ned)
        self._dt = -1.0
        self._n = 1
        self._last_cmd: Any = object()  # nothing seen yet: the first command is checked
        self._r = self.params.winch.radius
        tp = self._tp = self.params.tether
        self._RL = self.params.converter.load_resistance
        self._d2 = self.params.converter.boost_duty
        # the line model's step (compiled when numba is available) and its constants
        # (substeps.CONST, then substeps.STATION: the wind, the line-share factors of the tether
        # module, the model's code; then the model's own)
        kind = line.kind
        # the line model's step compiled at the first step that needs it (None: Python runs
        # it): a flight whose compiled loop holds the step never compiles it alone
        self._kind = kind
        self._step_kernel: Any = _PENDING if jit_off() is None else None
        drag_on = tp.drag_share > 0.0 and self.tether_drag_scale > 0.0
        sc = slots.new(STATION)
        sc[:slots.start(STATION)] = self.drivetrain.constants
        sc[STATION.wind:STATION.wind + 3] = self.wind
        sc[STATION.drag_c], sc[STATION.drag_on] = line_drag_coefficient(tp, self.tether_drag_scale), float(drag_on)
        sc[STATION.weight_c], sc[STATION.g] = tp.weight_share * tp.mass_per_length, tp.gravity
        sc[STATION.line] = kind.code
        self._scl = sc.tolist() + kind.constants(line.param, tp, self.tether_drag_scale)
        self._s_all = self.drivetrain.state  # the step's state array: the drivetrain's, then the line's block
        kind.prepare(self._s_all, line.param)
        self._step_py = kind.step
        self._sc = np.array(self._scl, dtype=float)

    @property
    def tether_segments(self) -> int:
        """Segments of a lumped line (:mod:`.lumped`), 0 for a line without nodes."""
        return self.line.param if self.line.has_shape else 0

    def set_line_wind(self, profile: Any = None, wind_ref: Sequence[float] = (0.0, 0.0),
                      gust: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        """The wind field the lumped line's nodes see (no effect on the straight line, whose
        drag takes :meth:`set_wind`): ``profile`` a :class:`fdm_awe.wind.WindProfile` (None or
        uniform: the station's wind at every height) with the horizontal wind ``wind_ref``
        (N, E) m/s at its reference height, plus ``gust`` (N, E, D) m/s, the turbulence of the
        moment, taken as uniform along the line."""
        if not self.line.has_shape:
            return
        code, param, href, floor = (0.0, 0.0, 0.0, 0.0) if profile is None else profile.numbers()
        vals = [code, param, href, floor, *(_finite(f"wind_ref[{k}]", v) for k, v in enumerate(wind_ref))]
        g = [_finite(f"gust[{k}]", v) for k, v in enumerate(gust)]
        if len(vals) != 6 or len(g) != 3:
            raise InputError("set_line_wind: wind_ref needs 2 components (N, E), gust 3 (N, E, D)")
        i = LINE.shear_code
        self._scl[i:i + 6] = vals
        self._sc[i:i + 6] = vals
        # the gust (uniform: the station's wind plus the gust, read as it is at every node)
        set_gust(self._scl, *self.wind, *g)
        set_gust(self._sc, *self.wind, *g)

    @property
    def line_ledger(self) -> Any:
        """The line's own energy ledger (J; the lumped line's :class:`.lumped_state.LineLedger`),
        None for a line without one (the straight line)."""
        return self.line.kind.ledger(self._s_all)

    def line_nodes(self) -> np.ndarray | None:
        """The line's node positions (N+1, 3) m NED, winch first; None for a line without nodes."""
        return self.line.kind.nodes(self._s_all, self.line.param)

    def line_tensions(self) -> np.ndarray | None:
        """The line's segment tensions (N,) N, winch first; None for a line without nodes."""
        return self.line.kind.tensions(self._s_all, self.line.param)

    def set_wind(self, wind_ned: Sequence[float]) -> None:
        """Wind used for the line drag, NED m/s."""
        w = [_finite(f"wind_ned[{k}]", v) for k, v in enumerate(wind_ned)]
        if len(w) != 3:
            raise InputError("wind_ned: need 3 components (N, E, D)")
        self.wind = (w[0], w[1], w[2])
        if hasattr(self, "_sc"):
            self._scl[STATION.wind:STATION.wind + 3] = self.wind
            self._sc[STATION.wind:STATION.wind + 3] = self.wind

    @property
    def ledger(self) -> EnergyLedger:
        """Energy ledger since the last :meth:`reset` (see :mod:`.ledger`)."""
        return self.drivetrain.ledger

    def reset(self, tether_length: float = 200.0, reel_speed: float = 0.0, mode: str = GENERATOR,
              load_resistance: float | None = None) -> None:
        """Start state: paid-out length (m), reel speed (m/s, > 0 reel-out), converter mode.

        ``tether_length`` is the UNSTRETCHED paid-out length: a glider farther away than that
        stretches the line at once (EA/l ~ 113 N/m at 200 m). To start with a given tension use
        :meth:`unstretched_length`. Electrical states start quasi-steady for the reel speed
        with no line load (motor mode: the PI integrator holds that duty, for a bumpless start
        of the speed loop); the ledger is cleared.
        """
        tp = self.params.tether
        _finite("tether_length", tether_length, lo=tp.min_length, hi=tp.max_length)
        _finite("reel_speed", reel_speed)
        if mode not in MODES:
            raise InputError(f"mode: {mode!r} not one of {', '.join(MODES)}")
        if load_resistance is not None:
            _finite("load_resistance", load_resistance, lo=0.0, lo_open=True)
        self.drivetrain.reset(tether_length, reel_speed / self.params.winch.radius, mode, load_resistance)
        self.line.kind.reset(self._s_all)

    def unstretched_length(self, distance: float, tension: float = 0.0) -> float:
        """Unstretched length (m) that carries ``tension`` (N) at winch-glider ``distance`` (m)
        on this station's line model."""
        _finite("distance", distance, lo=0.0, lo_open=True)
        _finite("tension", tension, lo=0.0)
        return self.line.kind.unstretched(self.params.tether, self.line.param, distance, tension)

    def _substeps(self, dt: float) -> int:
        if dt != self._dt:
            self._dt = dt
            self._n = max(1, math.ceil(dt / self.params.integration.max_substep - 1e-9))
        return self._n

    def step_with_tension(self, dt: float, tension: float, cmd: WinchCommand) -> GroundStationOutput:
        """Advance ``dt`` s with a prescribed line tension (N) at the drum instead of the line.

        For winch-only studies and tests (constant load, quasi-static checks); the returned
        force is zero (there is no glider).
        """
        if not (0.0 < dt <= 1.0):
            raise InputError(f"dt: {dt!r} out of range (allowed > 0 and <= 1 s)")
        _finite("tension", tension, lo=0.0)
        if not isinstance(cmd, WinchCommand):
            raise InputError(f"cmd: expected WinchCommand, got {type(cmd).__name__}")
        n = self._substeps(dt)
        cp = self.params.converter
        RL = cp.load_resistance if cmd.load_resistance is None else cmd.load_resistance
        d2 = cp.boost_duty if cmd.boost_duty is None else cmd.boost_duty
        dtr = self.drivetrain
        r = self.params.winch.radius
        tmean, pload, psup, event = dtr.advance(
            dt, n, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, cmd.mode, cmd.reel_speed_ref / r, cmd.duty, d2, RL,
            fixed_tension=float(tension))
        return GroundStationOutput(
            np.zeros(3), tmean, dtr.length, r * dtr.omega, dtr.omega, dtr.current, dtr.duty,
            cmd.mode, dtr.u_link, pload - psup, event,
            machine_mode(dtr.omega, dtr.current, tmean, self.params.machine.k, r),
            tmean * r * dtr.omega, 0.0, False, dtr.broken)

    def _set_command(self, cmd: WinchCommand) -> None:
        if not isinstance(cmd, WinchCommand):
            raise InputError(f"cmd: expected WinchCommand, got {type(cmd).__name__}")
        self._last_cmd = cmd
        # the command's terms of the step (a WinchCommand is immutable): converter mode,
        # motor flag, drum speed reference, open-loop duty (NaN: PI), boost duty, load resistance
        _, motor, omega_ref, duty, d2, rl = command_values(
            1.0 if cmd.mode == MOTOR else 0.0, cmd.reel_speed_ref,
            _NAN if cmd.load_resistance is None else cmd.load_resistance,
            _NAN if cmd.boost_duty is None else cmd.boost_duty, _NAN if cmd.duty is None else cmd.duty,
            self._r, self._d2, self._RL)
        self._cmd_terms = (cmd.mode, motor, omega_ref, duty, d2, rl)

    def compiled_step_args(self, dt: float) -> tuple[np.ndarray, np.ndarray, int] | None:
        """For a compiled loop that calls the line model's step itself (the
        co-simulation kernel): the state array (updated in place: the ledger and
        :attr:`drivetrain` follow), the constants and the sub-step count for steps of ``dt`` s;
        None when this station steps in Python (numba missing, ``FDM_AWE_JIT=0``). Per step the
        loop also needs :meth:`command_terms`."""
        if not (0.0 < dt <= 1.0):
            raise InputError(f"dt: {dt!r} out of range (allowed > 0 and <= 1 s)")
        dtr = self.drivetrain
        if self._step_kernel is None or not dtr.may_compile:
            return None
        return self._s_all, self._sc, self._substeps(dt)

    def command_defaults(self) -> tuple[float, float, float]:
        """What :func:`command_values` needs of this station: drum radius [m], the definition's
        T2 duty and load resistance [ohm] (a command's defaults)."""
        return self._r, self._d2, self._RL

    def ledger_offset(self) -> int:
        """Position of the ledger's first term (:data:`.ledger.FIELDS`) in the compiled step's
        state array (:meth:`compiled_step_args`)."""
        return int((self.ledger.buffer.ctypes.data - self._s_all.ctypes.data) // self._s_all.itemsize)

    def command_terms(self, cmd: WinchCommand) -> tuple[str, bool, float, float, float, float]:
        """The terms of :func:`.substeps.station_step` for ``cmd``: converter mode, motor flag,
        drum speed reference rad/s, open-loop duty (NaN: PI), boost duty, load resistance ohm
        (checked as in :meth:`step`)."""
        if cmd is not self._last_cmd:
            self._set_command(cmd)
        return self._cmd_terms

    @staticmethod
    def output_from_row(row: list[float], mode: str) -> GroundStationOutput:
        """The step's output from a compiled loop's row (``fdm_awe.sim.kernel.GS``, a
        list of floats), filled in when first read (a controller that ignores it pays nothing)."""
        return output_from_row(row, mode)

    def step(self, dt: float, pos_ned: Sequence[float], vel_ned: Sequence[float],
             cmd: WinchCommand) -> GroundStationOutput:
        """Advance the ground station by ``dt`` s with the glider's tether attachment point at
        ``pos_ned`` (m, winch at the origin) moving with ``vel_ned`` (m/s, ground-relative)."""
        if not (0.0 < dt <= 1.0):
            raise InputError(f"dt: {dt!r} out of range (allowed > 0 and <= 1 s)")
        if type(pos_ned) is tuple and type(vel_ned) is tuple:
            x, y, z = pos_ned
            vx, vy, vz = vel_ned
            if type(x) is not float or type(vx) is not float:
                x, y, z = map(float, pos_ned)
                vx, vy, vz = map(float, vel_ned)
        else:
            x, y, z = pos_ned.tolist() if type(pos_ned) is np.ndarray else map(float, pos_ned)
            vx, vy, vz = vel_ned.tolist() if type(vel_ned) is np.ndarray else map(float, vel_ned)
        if not (isfinite(x + y + z) and isfinite(vx + vy + vz)):
            raise InputError(f"glider position/velocity must be finite, got pos={tuple(pos_ned)!r} vel={tuple(vel_ned)!r}")
        if cmd is not self._last_cmd:
            self._set_command(cmd)
        n = self._n if dt == self._dt else self._substeps(dt)
        dtr = self.drivetrain
        mode, motor, omega_ref, duty, d2, RL = self._cmd_terms
        kern = self._step_kernel
        if kern is _PENDING:
            kern = self._step_kernel = self._kind.compiled()
        if kern is not None and dtr.is_compiled:  # compiled
            (fx, fy, fz, tmean, length, w, i, duty, u_link, p_el, ev, mm, d, slack, broken) = kern(
                self._s_all, self._sc, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty, d2, RL)
        else:  # the same function in Python
            (fx, fy, fz, tmean, length, w, i, duty, u_link, p_el, ev, mm, d, slack, broken) = self._step_py(
                self._s_all, self._scl, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty, d2, RL)
        r = self._r
        return step_output(fx, fy, fz, tmean, length, r * w, w, i, duty, mode, u_link, p_el, ev, mm,
                           tmean * r * w, d, slack, broken)
