"""A flight's log cut into its pumping cycles (:func:`segment_cycles`) and each cycle's times,
energies and tracking error (:func:`cycle_metrics`); the rules are described in
:mod:`fdm_awe.sim.flight`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .report import CycleMetrics

#: phase codes of the per-step labels (:func:`segment_cycles`): autopilot phase name -> code
PHASE_CODES = {"generation": 0, "recovery": 1}
OTHER_PHASE = -1  #: any other phase (e.g. on the ground)
NO_CYCLE = -1  #: cycle label of a step flown outside AUTO cycling


def step_reference(ap: Any) -> Any:
    """The reference point a step was flown on, for its cycle label and tracking error: the
    autopilot's (``ap``) last reference point while it cycles in AUTO, else None (the step's
    cycle label is then :data:`NO_CYCLE`)."""
    rp = ap.ref_point
    return rp if rp is not None and ap.mode == "AUTO" and ap.cycling else None


@dataclass(frozen=True)
class CycleSpan:
    """Where a cycle lies in a flight's log (rows: 0 the initial state, k the state after
    step k). Its steps are ``i0 + 1 .. i1``, so a cumulative quantity ``c`` changes by
    ``c[i1] - c[i0]`` over the cycle; ``n_generation``/``n_recovery`` count its steps in each
    phase (steps in another phase count in neither)."""

    index: int
    i0: int
    i1: int
    n_generation: int
    n_recovery: int
    complete: bool


def segment_cycles(cycle: np.ndarray, phase: np.ndarray, reached: int | None = None) -> list[CycleSpan]:
    """The cycles in a flight's log of steps ``1 .. K`` (row 0, the initial state, is ignored).

    ``cycle[k]``: index of the reference cycle that step k was flown on, :data:`NO_CYCLE`
    outside AUTO cycling; ``phase[k]``: 0 generation, 1 recovery, :data:`OTHER_PHASE` else
    (:data:`PHASE_CODES`). ``reached``: the cycle index the autopilot's path parameter had
    reached after the last step (None: unknown).

    A cycle starts at a step whose label differs from the running cycle's; steps without a
    label belong to the running cycle (steps before the first label to none); the last cycle
    runs to step K. A cycle is complete when the next one has a higher index, the last one
    when ``reached`` is past it."""
    cyc = np.asarray(cycle, dtype=np.int64)
    ph = np.asarray(phase, dtype=np.int64)
    if cyc.shape != ph.shape or cyc.ndim != 1:
        raise ValueError(f"cycle and phase labels must be 1-D of one length, got {cyc.shape} and {ph.shape}")
    K = len(cyc) - 1
    if K < 1:
        return []
    lab = cyc[1:]
    steps = np.flatnonzero(lab != NO_CYCLE) + 1  # labelled steps
    if len(steps) == 0:
        return []
    lv = cyc[steps]
    first = steps[np.r_[True, lv[1:] != lv[:-1]]]  # first step of each cycle
    spans: list[CycleSpan] = []
    gen = np.r_[0, np.cumsum(ph[1:] == PHASE_CODES["generation"])]
    rec = np.r_[0, np.cumsum(ph[1:] == PHASE_CODES["recovery"])]
    for j, k0 in enumerate(first):
        c = int(cyc[k0])
        i0 = int(k0) - 1
        i1 = int(first[j + 1]) - 1 if j + 1 < len(first) else K
        if j + 1 < len(first):
            complete = int(cyc[first[j + 1]]) > c
        else:
            complete = reached is not None and reached > c
        spans.append(CycleSpan(c, i0, i1, int(gen[i1] - gen[i0]), int(rec[i1] - rec[i0]), bool(complete)))
    return spans


def cycle_metrics(spans: list[CycleSpan], dt: float, e_generated: np.ndarray, e_thrust: np.ndarray,
                  e_reel_in: np.ndarray, track_error: np.ndarray) -> list[CycleMetrics]:
    """Per-cycle numbers of ``spans`` (:func:`segment_cycles`) from cumulative energies (J since
    the start, one value per log row: into the load, drawn by the glider's motor, drawn from the
    supply; a cycle gets each one's change over its steps) and the per-row tracking error (m,
    NaN where there was no reference point). ``dt``: step length, s."""
    out: list[CycleMetrics] = []
    for sp in spans:
        e = np.asarray(track_error[sp.i0 + 1: sp.i1 + 1], dtype=float)
        e = e[np.isfinite(e)]
        E_gen = float(e_generated[sp.i1] - e_generated[sp.i0])
        E_thr = float(e_thrust[sp.i1] - e_thrust[sp.i0])
        E_rw = float(e_reel_in[sp.i1] - e_reel_in[sp.i0])
        out.append(CycleMetrics(
            sp.index, sp.n_generation * dt, sp.n_recovery * dt, E_gen, E_thr, E_rw, E_gen - E_thr - E_rw,
            float(np.sqrt(np.mean(e**2))) if len(e) else float("nan"), float(e.max()) if len(e) else float("nan"),
            complete=sp.complete,
        ))
    return out
