"""Honest flight status and per-cycle numbers: the cycle segmentation on synthetic logs, and real
flights cut off by Ctrl-C in generation and in recovery, by Ctrl-C at an awkward point of the
compiled loop, and by the time cap."""

from __future__ import annotations

import json
import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.cycles import NO_CYCLE, OTHER_PHASE, CycleSpan, cycle_metrics, segment_cycles
from fdm_awe.sim.report import CycleMetrics, FlightReport
from fdm_awe.sim.flight import fly

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

DT = 1.0 / 120.0
G, R, O, N = 0, 1, OTHER_PHASE, NO_CYCLE


def _labels(*steps: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Per-step (cycle, phase) labels with row 0 (the initial state) in front."""
    cyc = np.array([N] + [c for c, _ in steps])
    ph = np.array([O] + [p for _, p in steps])
    return cyc, ph


# ------------------------------------------------------------------ segmentation (synthetic logs)
def test_whole_cycles_are_split_at_the_reference_cycle():
    cyc, ph = _labels(*[(0, G)] * 3, *[(0, R)] * 2, *[(1, G)] * 3, *[(1, R)] * 2)
    spans = segment_cycles(cyc, ph, reached=2)
    assert spans == [CycleSpan(0, 0, 5, 3, 2, True), CycleSpan(1, 5, 10, 3, 2, True)]


def test_a_cycle_cut_in_generation_books_no_recovery():
    """The reported defect: a cycle cut during generation came out with T1 = -dt and the
    generation booked as T2."""
    cyc, ph = _labels(*[(0, G)] * 3, *[(0, R)] * 2, *[(1, G)] * 4)
    spans = segment_cycles(cyc, ph, reached=1)
    assert spans[0] == CycleSpan(0, 0, 5, 3, 2, True)
    assert spans[1] == CycleSpan(1, 5, 9, 4, 0, False)


def test_a_cycle_cut_in_recovery_is_incomplete():
    cyc, ph = _labels(*[(0, G)] * 3, *[(0, R)] * 1)
    assert segment_cycles(cyc, ph, reached=0) == [CycleSpan(0, 0, 4, 3, 1, False)]
    assert segment_cycles(cyc, ph, reached=None) == [CycleSpan(0, 0, 4, 3, 1, False)]
    # the last step carried the path parameter past the cycle's end: complete
    assert segment_cycles(cyc, ph, reached=1) == [CycleSpan(0, 0, 4, 3, 1, True)]


def test_steps_outside_auto_belong_to_the_running_cycle_or_to_none():
    # FBWA before cycling starts (no cycle), then a cycle cut by RECOVER mode (recovery, no label)
    cyc, ph = _labels((N, O), (N, G), (0, G), (0, G), (N, R), (N, R), (N, R))
    assert segment_cycles(cyc, ph, reached=None) == [CycleSpan(0, 2, 7, 2, 3, False)]
    # wings level on the ground inside a cycle count in neither phase
    cyc, ph = _labels((0, G), (0, O), (0, R))
    assert segment_cycles(cyc, ph, reached=1) == [CycleSpan(0, 0, 3, 1, 1, True)]


def test_no_cycle_flown_and_degenerate_logs():
    assert segment_cycles(*_labels((N, R), (N, R)), reached=None) == []
    assert segment_cycles(np.array([N]), np.array([O])) == []
    with pytest.raises(ValueError, match="one length"):
        segment_cycles(np.zeros(3, int), np.zeros(4, int))


def test_a_cycle_left_for_an_earlier_index_is_incomplete():
    """A new mission can move the path parameter to a lower cycle index: the cycle that was
    running did not end."""
    cyc, ph = _labels((2, G), (2, G), (1, G))
    spans = segment_cycles(cyc, ph, reached=1)
    assert [(s.index, s.complete) for s in spans] == [(2, False), (1, False)]


def test_random_logs_give_non_negative_times_and_energies_that_add_up():
    """Any log of monotone cycles (each generation then recovery, cut anywhere) and
    non-decreasing cumulative energies: times and energies >= 0, the cycles tile the log from
    the first cycle step, the phase times add up to the cycle's steps."""
    rng = np.random.default_rng(16)
    for _ in range(200):
        steps: list[tuple[int, int]] = [(N, O)] * int(rng.integers(0, 4))
        n_cycles = int(rng.integers(1, 5))
        for c in range(n_cycles):
            steps += [(c, G)] * int(rng.integers(1, 30)) + [(c, R)] * int(rng.integers(0, 15))
        steps = steps[: int(rng.integers(1, len(steps) + 1))]  # cut anywhere
        cyc, ph = _labels(*steps)
        K = len(cyc) - 1
        e_gen = np.r_[0.0, np.cumsum(np.where(ph[1:] == G, rng.random(K), 0.0))]
        e_thr = np.r_[0.0, np.cumsum(rng.random(K))]
        e_rw = np.r_[0.0, np.cumsum(np.where(ph[1:] == R, rng.random(K), 0.0))]
        err = np.where(cyc >= 0, rng.random(K + 1) * 5.0, np.nan)
        spans = segment_cycles(cyc, ph, reached=None)
        mets = cycle_metrics(spans, DT, e_gen, e_thr, e_rw, err)
        labelled = np.flatnonzero(cyc >= 0)
        if len(labelled) == 0:
            assert mets == []
            continue
        assert spans[0].i0 == labelled[0] - 1 and spans[-1].i1 == K
        for a, b in zip(spans, spans[1:]):
            assert a.i1 == b.i0 and a.complete
        assert not spans[-1].complete
        for s, m in zip(spans, mets):
            assert s.n_generation + s.n_recovery == s.i1 - s.i0
            assert m.T1_s >= 0 and m.T2_s >= 0 and m.T1_s + m.T2_s == pytest.approx((s.i1 - s.i0) * DT)
            assert m.E_generated_J >= 0 and m.E_thrust_J >= 0 and m.E_reel_in_J >= 0
            assert (m.E_reel_in_J > 0) == (s.n_recovery > 0)  # reel-in energy only where recovery was flown
            assert m.E_net_J == pytest.approx(m.E_generated_J - m.E_thrust_J - m.E_reel_in_J)
            assert 0.0 <= m.track_rms_m <= m.track_max_m <= 5.0
        assert sum(m.E_thrust_J for m in mets) == pytest.approx(e_thr[K] - e_thr[spans[0].i0])


def test_a_cycle_without_reference_points_has_no_tracking_numbers_in_json():
    spans = [CycleSpan(0, 0, 3, 3, 0, False)]
    (m,) = cycle_metrics(spans, DT, np.zeros(4), np.zeros(4), np.zeros(4), np.full(4, np.nan))
    assert math.isnan(m.track_rms_m) and math.isnan(m.track_max_m)
    d = m.as_dict()
    assert d["track_rms_m"] is None and d["track_max_m"] is None and d["complete"] is False
    rep = FlightReport(scenario="physical", config="nominal", wind_mps=8.0, status="interrupted", message="x",
                       sim_time_s=0.025, wall_s=0.0, cycles=[m], ledger={"glider_residual_J": math.nan},
                       ledger_residual_rel=math.nan)
    doc = rep.as_json()
    text = json.dumps(doc, allow_nan=False)  # never NaN in the JSON
    assert doc["realtime_factor"] is None and doc["ledger_residual_rel"] is None
    assert doc["ledger"]["glider_residual_J"] is None and "NaN" not in text


# ------------------------------------------------------------------ real flights
@pytest.fixture(scope="module")
def reference():
    """The stored physical nominal 8 m/s cycle (T1 about 50 s, T2 about 10 s)."""
    return TrackingReference.from_ocp_file(str(Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"))


def _check_cut_flight(rep, n_cycles: int = 1) -> CycleMetrics:
    """Common to every cut flight: the log, the per-step arrays and the cycles agree; numbers
    keep their signs; the last cycle is flagged incomplete; the JSON carries no NaN."""
    res = rep.result
    assert len(res.t) == res.steps + 1 == len(rep.track_error) == len(rep.reference_pos)
    assert rep.sim_time_s == pytest.approx(res.steps * DT, abs=1e-9)
    assert len(rep.cycles) == n_cycles
    for c in rep.cycles:
        assert c.T1_s >= 0 and c.T2_s >= 0
        assert c.E_generated_J >= 0 and c.E_thrust_J >= 0 and c.E_reel_in_J >= 0
        assert c.E_net_J == pytest.approx(c.E_generated_J - c.E_thrust_J - c.E_reel_in_J)
        assert math.isfinite(c.track_rms_m) and c.track_rms_m <= c.track_max_m
    assert sum(c.T1_s + c.T2_s for c in rep.cycles) == pytest.approx(rep.sim_time_s, abs=1.5 * DT)
    assert not rep.cycles[-1].complete
    json.dumps(rep.as_json(), allow_nan=False)
    return rep.cycles[-1]


def test_sigint_in_generation_returns_an_interrupted_report(reference):
    """A real SIGINT 5 s into the first generation phase: the flight stops at that step and
    returns everything flown; the handler of the process is restored afterwards."""
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler

    def on_step(k, s, o):
        if k == 600:
            os.kill(os.getpid(), signal.SIGINT)

    rep = fly(reference, config="nominal", cycles=1, on_step=on_step)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert rep.status == "interrupted" and "interrupted" in rep.message, rep.message
    assert 600 <= rep.result.steps <= 601  # taken at the step boundary
    c = _check_cut_flight(rep)
    assert c.T1_s == pytest.approx(rep.sim_time_s, abs=1e-9) and c.T2_s == 0.0
    # in generation the supply delivers only where the winch's lower line limit reels in (the
    # slack at the catch: 0.5 J in these 5 s)
    assert c.E_generated_J > 0 and c.E_thrust_J > 0 and 0.0 <= c.E_reel_in_J < 0.02 * c.E_thrust_J


def _interrupt_in_recovery(after_steps: int):
    """on_step raising KeyboardInterrupt ``after_steps`` steps into the first recovery."""
    holder = {"n": 0}

    def setup(ap, sim):
        holder["ap"], holder["sim"] = ap, sim

    def on_step(k, s, o):
        if holder["ap"].phase == "recovery":
            holder["n"] += 1
            if holder["n"] == after_steps:
                raise KeyboardInterrupt

    return holder, setup, on_step


def test_ctrl_c_in_recovery_in_both_loops_alike(reference):
    """KeyboardInterrupt 1 s into the first recovery: interrupted, the generation booked as
    T1, the second of recovery as T2 with its reel-in energy; the compiled and the Python loop
    give the same report."""
    docs = []
    for compiled in (True, False):
        holder, setup0, on_step = _interrupt_in_recovery(120)

        def setup(ap, sim, setup0=setup0, compiled=compiled):
            setup0(ap, sim)
            sim.compiled = compiled

        rep = fly(reference, config="nominal", cycles=1, setup=setup, on_step=on_step)
        assert rep.status == "interrupted", rep.message
        c = _check_cut_flight(rep)
        assert c.T2_s == pytest.approx(120 * DT, abs=1e-9)
        assert c.T1_s == pytest.approx(rep.sim_time_s - c.T2_s, abs=1e-9)
        assert 0.5 * reference.T1 < c.T1_s < 2.0 * reference.T1
        assert c.E_generated_J > 0 and c.E_thrust_J > 0 and c.E_reel_in_J > 0
        doc = rep.as_json()
        doc.pop("wall_s")
        doc.pop("realtime_factor")
        assert doc.pop("loop")["loop"] == holder["sim"].loop  # how it ran: the one difference allowed
        docs.append((holder["sim"].loop, doc))
    if docs[0][0] == "compiled":  # where the compiled loop runs, it must match the Python loop
        assert json.dumps(docs[0][1], sort_keys=True) == json.dumps(docs[1][1], sort_keys=True)


def test_ctrl_c_between_a_compiled_step_and_its_bookkeeping_books_nothing_twice(reference):
    """Ctrl-C landing after the compiled loop counted a step but before the flight booked it
    (once seen: a reel-in energy of -558 J): the flight ends at the last step booked whole."""
    holder = {"n": 0}

    def setup(ap, sim):
        holder["ap"], holder["sim"] = ap, sim
        make_state = sim.glider.make_state

        def interrupting(*a, **kw):  # called by the compiled loop right after a step is counted
            if ap.phase == "recovery":
                holder["n"] += 1
                if holder["n"] == 60:
                    raise KeyboardInterrupt
            return make_state(*a, **kw)

        sim.glider.make_state = interrupting

    # a per-step hook: the compiled loop with the autopilot called from Python every step
    rep = fly(reference, config="nominal", cycles=1, setup=setup, on_step=lambda k, s, o: None)
    if holder["sim"].loop != "compiled":
        pytest.skip(f"compiled loop not available here: {holder['sim'].loop_reason}")
    assert rep.status == "interrupted", rep.message
    c = _check_cut_flight(rep)
    assert c.E_reel_in_J > 0 and c.T2_s == pytest.approx(59 * DT, abs=1e-9)


def test_time_cap_with_an_unfinished_cycle_is_incomplete_not_ok(reference):
    """A flight whose reference point advances at 0.4 x real time (as for a glider that keeps
    falling behind its path) cannot finish its cycle in the time cap of twice the period plus
    10 s: the cap ends the flight with its one cycle unfinished (reported ``ok`` before). The
    underspeed protection is off: held back, the glider flies as slowly as its wing lets it,
    and the protection would fly it off the crawling point into the lost-path failsafe."""

    held = {"ap": None, "s": None}

    def setup(ap, sim):
        held["ap"] = ap
        ap.params.set("US_V_ENTER", 0.0)

    def held_back(k, s, o):  # after each step: the path parameter 0.4 step lengths on
        ap = held["ap"]
        if held["s"] is not None:
            ap.s_ref = held["s"] + 0.4 * DT
        held["s"] = ap.s_ref

    rep = fly(reference, config="nominal", cycles=1, setup=setup, on_step=held_back)
    assert rep.status == "incomplete", rep.message
    assert "time cap" in rep.message and "0 of 1" in rep.message
    assert rep.sim_time_s == pytest.approx(2.0 * reference.period + 10.0, abs=DT)
    _check_cut_flight(rep)
