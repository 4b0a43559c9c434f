"""The per-step bookkeeping of a flight (:func:`fdm_awe.sim.flight.fly`): the glider's ledger, the
reference point flown, the tracking error, the phase, the station's energies, the paper
plant's ideal thrust and the lumped line's shape, booked step by step or, after a compiled
block of autopilot steps, from the block's rows."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .block_log import ALOG
from .cycles import NO_CYCLE, OTHER_PHASE, PHASE_CODES, step_reference
from .glider_ledger import GliderLedger

def track_error(rx: float, ry: float, rz: float, x: float, y: float, z: float) -> float:
    """The tracking error [m]: the distance from the glider's position ``(x, y, z)`` to the
    reference point ``(rx, ry, rz)`` flown (NED, m). A plain function: the compiled block books
    it too."""
    dx, dy, dz = rx - x, ry - y, rz - z
    return math.sqrt(dx * dx + dy * dy + dz * dz)


#: samples per second of the lumped line's shape in a flight report
LINE_SHAPE_HZ = 10.0


class FlightLog:
    """The per-step bookkeeping of a flight of at most ``n`` steps of ``dt`` [s] (row 0 the
    initial state, row k after step k): the glider's ledger, the reference point flown in AUTO
    cycling (position m NED, tracking error m, cycle label), the autopilot's phase code, the
    station's cumulative energies into the load and from the supply [J], the paper plant's
    ideal thrust [N] and its energy [J], and (``line_shape``) the lumped line's shape sampled
    at :data:`LINE_SHAPE_HZ`."""

    def __init__(self, n: int, dt: float, rig: Any, ledger: GliderLedger, line_shape: bool) -> None:
        self.dt = dt
        self.ap, self.gs, self.thruster, self.glider_ledger = rig.ap, rig.gs, rig.thruster, ledger
        self.station_ledger = rig.gs.ledger
        self.err = np.full(n + 1, np.nan)
        self.refpos = np.full((n + 1, 3), np.nan)
        self.e_load = np.zeros(n + 1)
        self.e_supply = np.zeros(n + 1)
        self.e_ideal = np.zeros(n + 1)  # paper plant: P(T) of the ideal thrust, J
        self.t_ideal = np.zeros(n + 1)  # paper plant: ideal thrust, N
        self._e_ideal = 0.0
        self.cycle = np.full(n + 1, NO_CYCLE, dtype=np.int64)  # per step: cycle of the reference point flown
        self.phase = np.full(n + 1, OTHER_PHASE, dtype=np.int64)  # per step: the autopilot's phase
        self.booked = 0  #: the last step whose bookkeeping is complete
        self._shape = line_shape
        self._every = max(1, int(round(1.0 / (LINE_SHAPE_HZ * dt))))  # steps between shape samples
        self.shape_t: list[float] = []
        self.shape_nodes: list[np.ndarray] = []
        self.shape_tension: list[np.ndarray] = []

    def book(self, k: int, s: Any) -> None:
        """Book step ``k``, which ended in glider state ``s``."""
        dt = self.dt
        self.glider_ledger.step(dt)
        ap = self.ap
        rp = step_reference(ap)
        if rp is not None:
            self.refpos[k] = rp.pos
            self.err[k] = track_error(*rp.pos.tolist(), *s.pos_ned.tolist())
            self.cycle[k] = rp.cycle
        self.phase[k] = PHASE_CODES.get(ap.phase, OTHER_PHASE)
        led = self.station_ledger
        self.e_load[k] = led.load
        self.e_supply[k] = led.supply
        thruster = self.thruster
        if thruster is not None:
            self._e_ideal += thruster.power() * dt  # the thrust commanded for the step just flown
            self.e_ideal[k] = self._e_ideal
            self.t_ideal[k] = thruster.thrust
        self.booked = k
        if self._shape and k % self._every == 0:
            self._sample_shape(k)

    @property
    def samples_shape(self) -> bool:
        """Whether the flight samples the line's shape (a lumped line)."""
        return bool(self._shape)

    @property
    def shape_every(self) -> int:
        """Steps between two samples of the line's shape."""
        return self._every

    def _sample_shape(self, k: int) -> None:
        self.shape_t.append(k * self.dt)
        self.shape_nodes.append(self.gs.line_nodes())
        self.shape_tension.append(self.gs.line_tensions())

    def book_block(self, k0: int, k1: int, alog: np.ndarray) -> None:
        """Book steps ``k0 + 1 .. k1`` flown in one compiled block
        (:class:`fdm_awe.sim.autopilot_kernel.AutopilotBlocks`: the autopilot in AUTO cycling, its
        phase that of every step; the glider's ledger advanced by the block itself) from its
        rows ``alog`` (:data:`fdm_awe.sim.block_log.ALOG`)."""
        rows = alog[k0 + 1: k1 + 1]
        sl = slice(k0 + 1, k1 + 1)
        self.refpos[sl] = rows[:, ALOG.ref_x:ALOG.ref_z + 1]
        self.err[sl] = rows[:, ALOG.track_error]
        self.cycle[sl] = rows[:, ALOG.cycle].astype(np.int64)
        self.phase[sl] = PHASE_CODES.get(self.ap.phase, OTHER_PHASE)
        self.e_load[sl] = rows[:, ALOG.e_load]
        self.e_supply[sl] = rows[:, ALOG.e_supply]
        self.glider_ledger.set_mass(float(alog[k1, ALOG.mass_slug]))
        self.booked = k1
        if self._shape and k1 % self._every == 0:  # a block ends where the shape is sampled (or before)
            self._sample_shape(k1)

    def line_shape(self) -> dict[str, np.ndarray] | None:
        """The lumped line's sampled shape (:attr:`FlightReport.line_shape`), None without one."""
        if not self._shape:
            return None
        return {"t": np.array(self.shape_t), "nodes": np.array(self.shape_nodes), "tension": np.array(self.shape_tension)}
