"""What a flight may ask for: a step its attitude loops fly with, and no more steps than its
memory holds (docs/design.md section 1, ``fdm-awe fly``).

The step. The autopilot's attitude loops (angle of attack ``W_ALPHA``, bank ``W_PHI``,
rad/s, the autopilot's parameters) are updated once per co-simulation step. With the loop's
natural frequency ``w`` and the step ``dt`` the product ``w dt`` [-] says how well one update
per step follows the loop: up to :data:`LOOP_STEP_MAX` (0.25) a flight of the stored physical
references is the flight at the default step (measured with W_PHI 20 rad/s, ``fly --reference
tests/data/ref_physical_foldable_8mps_sized.json --cycles 2``: at 1/120 and 1/80 s tracking RMS
0.90-0.97 m, maximum 3.9-4.0 m, motor energy within 0.3 %; the nominal
``ref_physical_nominal_8mps.json`` is unchanged up to 1/40 s). Beyond it the foldable cycle
degrades: at 0.33 (1/60 s) its second cycle's tracking is 1.7 m RMS, 5.6 m maximum, at 0.5
(1/40 s) 3.5 m RMS, 15 m maximum; at 0.67 (1/30 s) 9 m RMS, 31 m maximum; at 1.0 (20 Hz) the
nominal cycle is lost (the lost-path failsafe takes the glider to RECOVER).

The memory. A flight keeps every step in memory until it ends (the co-simulation's log, the
flight's book of energies, tracking errors and labels, then the recordings built from them):
about :data:`STEP_BYTES` per step (measured with ``/usr/bin/time -f %M``: ``fly --reference
tests/data/ref_physical_nominal_8mps.json`` 2 cycles 306 MB, 8 cycles 393 MB, 43 300 steps
apart: 2.0 kB per step; with ``--out`` 1.1-1.6 kB per step, the physical foldable reference
likewise). A flight may last until its time cap (:func:`time_cap`), so the cap's steps are
bounded: at most :data:`MAX_FLIGHT_STEPS`, about 1.5 GB of logs on top of the ~0.4 GB the
modules take (about 51 cycles of the stored 60 s references at the default step)."""

from __future__ import annotations

import math
from typing import Any

from ..errors import InputError

#: the autopilot's attitude-loop frequencies [rad/s] (parameter names) that bound the step
LOOP_FREQUENCIES = ("W_ALPHA", "W_PHI")
#: the largest loop frequency x step [-] a flight is flown with
LOOP_STEP_MAX = 0.25
#: the shortest co-simulation step [s]
DT_MIN = 1.0e-4
#: the memory a flight keeps per step [bytes] (measured, module doc)
STEP_BYTES = 2048
#: the most steps a flight's time cap may hold (module doc)
MAX_FLIGHT_STEPS = 750_000


def time_cap(cycles: int, period: float) -> float:
    """The time cap [s] of a flight of ``cycles`` cycles of ``period`` [s]: twice the cycles'
    time plus 10 s (a glider much slower than its reference ends ``incomplete`` there)."""
    return cycles * period * 2.0 + 10.0


def dt_max(params: Any) -> tuple[float, str, float]:
    """The longest step [s] the attitude loops fly with under ``params`` (the autopilot's
    parameters, read like a mapping), with the fastest loop's parameter name and frequency
    [rad/s]."""
    name = max(LOOP_FREQUENCIES, key=lambda k: float(params[k]))
    w = float(params[name])
    return LOOP_STEP_MAX / w, name, w


def check_step(dt: float, params: Any, option: str = "--dt") -> float:
    """``dt`` [s] if the attitude loops fly with it (:data:`LOOP_STEP_MAX`), else InputError
    naming ``option``, the loop and the allowed range."""
    hi, name, w = dt_max(params)
    if not (math.isfinite(dt) and DT_MIN <= dt <= hi):
        raise InputError(f"{option} {dt:g} (co-simulation step) out of range for the attitude loops: {name} {w:g} rad/s "
                         f"needs {name} x step <= {LOOP_STEP_MAX:g} (allowed {DT_MIN:g}..{hi:.4g} s)")
    return float(dt)


def flight_steps(cycles: int, period: float, dt: float, t_end: float | None = None) -> int:
    """The steps of a flight's time cap (or of ``t_end`` [s] when given) at step ``dt`` [s]."""
    T = t_end if t_end is not None else time_cap(cycles, period)
    return int(round(T / dt))


def max_cycles(period: float, dt: float) -> int:
    """The most cycles of ``period`` [s] at step ``dt`` [s] whose time cap holds at most
    :data:`MAX_FLIGHT_STEPS` steps (0: not even one)."""
    return max(int(math.floor((MAX_FLIGHT_STEPS * dt - 10.0) / (2.0 * period) + 1e-9)), 0)


def check_length(cycles: int, period: float, dt: float, t_end: float | None = None, option: str = "--cycles",
                 what: str = "the reference") -> None:
    """InputError (naming ``option``) when a flight of ``cycles`` cycles of ``period`` [s]
    (``what``: whose period) at step ``dt`` [s], or of length ``t_end`` [s], could hold more
    than :data:`MAX_FLIGHT_STEPS` steps in memory."""
    n = flight_steps(cycles, period, dt, t_end)
    if n <= MAX_FLIGHT_STEPS:
        return
    mb = MAX_FLIGHT_STEPS * STEP_BYTES / 1e6
    n_max = max_cycles(period, dt)
    allowed = (f"allowed 1..{n_max} cycles at this step" if n_max >= 1 else
               f"not even one cycle fits: a step of at least {time_cap(1, period) / MAX_FLIGHT_STEPS:.2g} s (--dt)")
    if t_end is not None:
        raise InputError(f"flight of {t_end:g} s at a step of {dt:g} s is {n} steps, above the {MAX_FLIGHT_STEPS} a "
                         f"flight keeps in memory (about {mb:.0f} MB)")
    raise InputError(f"{option} {cycles}: {cycles} cycles of {what} ({period:.1f} s) at a step of {dt:g} s may take "
                     f"{n} steps (time cap 2 x cycles x period + 10 s), above the {MAX_FLIGHT_STEPS} a flight keeps in "
                     f"memory (about {mb:.0f} MB, {STEP_BYTES} bytes a step); {allowed}")
