"""The motor switch's pure functions (:func:`fdm_awe.autopilot.motor.motor_update`,
:func:`~fdm_awe.autopilot.motor.motor_ceiling`): compiled by numba they give the Python call's
bits and state over step sequences (dwell, rescue on and off, NaN error, soft start);
:class:`MotorSwitch` gives what its boolean form gave, its state readable as before."""

from __future__ import annotations

import dataclasses
import math
import random
from pathlib import Path

import numpy as np
import pytest
from jit_helpers import compiled, same_bits

from fdm_awe import slots
from fdm_awe.autopilot.motor import (GATE, MOTOR_MEM, MotorGate, MotorSwitch, motor_ceiling, motor_memory,
                                     motor_spin_down, motor_update)
from fdm_awe.autopilot.tracking import TrackingReference

DATA = Path(__file__).parent / "data"
GATES = (MotorGate(), MotorGate(min_dwell_s=0.0, soft_start_s=0.0), MotorGate(min_off_s=0.0, min_on_s=0.0, min_dwell_s=2.0,
         soft_start_s=3.0, rescue_error_m=4.0))


def _plan(rnd: random.Random, n: int) -> np.ndarray:
    """Runs of 1.0 and 0.0 of random lengths (a whole-cycle 1.0 sometimes)."""
    out, v = [], rnd.random() < 0.5
    while len(out) < n:
        out += [1.0 if v else 0.0] * rnd.randint(1, 30)
        v = not v
    return np.array(out[:n]) if rnd.random() < 0.9 else np.ones(n)


def _errors(rnd: random.Random, rescue: float):
    """A position error [m] walking across the rescue's two thresholds, NaN at the start and now and then."""
    e = math.nan
    while True:
        yield e
        if math.isnan(e) or rnd.random() < 0.01:
            e = rnd.choice((math.nan, rnd.uniform(0.0, 2.0 * rescue)))
        else:
            e = min(max(e + rnd.gauss(0.0, 0.08 * rescue), 0.0), 3.0 * rescue)


def test_motor_update_and_ceiling_compiled_equal_python_over_sequences():
    j_update, j_ceiling, j_spin = compiled(motor_update), compiled(motor_ceiling), compiled(motor_spin_down)
    rnd = random.Random(31)
    switches = rescues = dwell_held = 0
    for case in range(12):
        gate = GATES[case % 3].vector()
        assert gate.shape == (slots.size(GATE),)
        plan = _plan(rnd, 200)
        mem_py, mem_jit = motor_memory(), motor_memory()
        assert mem_py.shape == (slots.size(MOTOR_MEM),)
        assert mem_py[MOTOR_MEM.running] == 1.0 and mem_py[MOTOR_MEM.switch_t] == -math.inf
        t, seg, err = rnd.uniform(-5.0, 50.0), rnd.randrange(200), _errors(rnd, gate[GATE.rescue_error_m])
        for _ in range(600):
            e = next(err)
            slow = rnd.random() < 0.8
            before = mem_py.copy()
            py = motor_update(plan, seg, t, e, gate, mem_py, slow)
            assert same_bits(j_update(plan, seg, t, e, gate, mem_jit, slow), py), (case, t)
            assert np.array_equal(mem_py, mem_jit), (case, t, mem_py, mem_jit)
            tc = t + rnd.choice((0.0, 0.1 * gate[GATE.soft_start_s], rnd.uniform(0.0, 2.0)))
            assert same_bits(j_ceiling(tc, gate, mem_jit), motor_ceiling(tc, gate, mem_py)), (case, tc)
            u = rnd.uniform(0.0, 1.0)
            assert same_bits(j_spin(tc, gate, mem_jit, u), motor_spin_down(tc, gate, mem_py, u)), (case, tc)
            switches += mem_py[MOTOR_MEM.switches] != before[MOTOR_MEM.switches]
            rescues += mem_py[MOTOR_MEM.rescue] != before[MOTOR_MEM.rescue]
            want = plan[seg] != 0.0 or mem_py[MOTOR_MEM.rescue] != 0.0
            dwell_held += want != (mem_py[MOTOR_MEM.running] != 0.0)
            t += rnd.choice((1.0 / 120.0, 1.0 / 120.0, 1.0 / 120.0, rnd.uniform(0.0, 1.0)))
            seg = (seg + (rnd.random() < 0.2)) % len(plan)
    assert switches > 50 and rescues > 10 and dwell_held > 10


class _BooleanSwitch:
    """The switch's boolean form (the state in attributes), for the wrapper's check."""

    def __init__(self, gate: MotorGate) -> None:
        self.gate, self.running, self.switches, self.rescue, self.switch_t = gate, True, 0, False, -math.inf

    def update(self, plan: np.ndarray, seg: int, t: float, track_error: float, slow: bool = True) -> bool:
        gate = self.gate
        want = bool(plan[seg])
        if not want:
            if track_error > gate.rescue_error_m and slow:
                self.rescue = True
            elif not track_error > 0.5 * gate.rescue_error_m:
                self.rescue = False
            want = self.rescue
        if want != self.running and t - self.switch_t >= gate.min_dwell_s:
            self.running, self.switch_t, self.switches = want, t, self.switches + 1
        return self.running

    def ceiling(self, t: float) -> float:
        if self.switches and t - self.switch_t < self.gate.soft_start_s:
            return (t - self.switch_t) / self.gate.soft_start_s
        return 1.0


def test_motor_switch_gives_what_the_boolean_form_gave():
    base = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps.json")
    rnd = random.Random(37)
    rescued = 0
    for case, gate in enumerate(GATES):
        on = np.array([rnd.choice((0.0, 0.1)) if i % 80 < 40 else 1.0 for i in range(len(base.t))])
        ref = dataclasses.replace(base, motor_on=on)
        plan = gate.plan(ref)
        assert np.array_equal(gate.plan_vector(ref), plan.astype(float))
        sw, old = MotorSwitch(gate), _BooleanSwitch(gate)
        t, err = 0.0, _errors(rnd, gate.rescue_error_m)
        for _ in range(3000):
            e, tc, slow = next(err), t % ref.period, rnd.random() < 0.8
            assert sw.update(ref, tc, t, e, slow) is old.update(plan, ref.segment_index(tc), t, e, slow)
            assert (sw.running, sw.switches, sw.rescue, sw.switch_t) == (old.running, old.switches, old.rescue, old.switch_t)
            assert type(sw.running) is bool and type(sw.switches) is int and type(sw.rescue) is bool
            assert sw.ceiling(t + 0.3) == old.ceiling(t + 0.3)
            rescued += sw.rescue
            t += 1.0 / 120.0 if rnd.random() < 0.98 else rnd.uniform(0.0, 5.0)
        assert sw.switches > 0, case
    assert rescued > 0


def test_the_rescue_runs_the_motor_only_for_a_slow_glider():
    """Past the rescue error on a stopped segment the motor starts for a glider no faster in the
    air than its reference point (``slow``), not for a faster one (a dive: energy to spare, and
    a fixed-pitch propeller spun up at that speed draws its power for next to no thrust); a
    rescue under way ends below half the rescue error as before."""
    gate = MotorGate(min_dwell_s=0.0).vector()
    plan = np.zeros(4)
    fast, slow = motor_memory(), motor_memory()
    for mem in (fast, slow):
        mem[MOTOR_MEM.running] = 0.0
    assert motor_update(plan, 0, 1.0, 12.0, gate, fast, False) == 0.0 and fast[MOTOR_MEM.rescue] == 0.0
    assert motor_update(plan, 0, 1.0, 12.0, gate, slow, True) == 1.0 and slow[MOTOR_MEM.rescue] == 1.0
    assert motor_update(plan, 0, 2.0, 8.0, gate, slow, False) == 1.0  # still above half: runs on
    assert motor_update(plan, 0, 3.0, 4.0, gate, slow, True) == 0.0 and slow[MOTOR_MEM.rescue] == 0.0


def test_gate_vector_layout():
    gate = MotorGate(off_below=0.3, min_off_s=2.0, min_on_s=1.5, min_dwell_s=0.25, soft_start_s=0.75, rescue_error_m=7.0,
                     soft_stop_s=0.6)
    assert gate.vector().tolist() == [0.3, 2.0, 1.5, 0.25, 0.75, 7.0, 0.6]
    assert gate.vector()[GATE.min_dwell_s] == 0.25 and gate.vector()[GATE.soft_start_s] == 0.75


def test_spin_down_falls_linearly_from_the_last_throttle():
    """After a stop the throttle falls from its last value to 0 over soft_stop_s; 0 without a
    switch yet, after the soft stop, and at once with soft_stop_s 0."""
    mem = motor_memory()
    gate = MotorGate(soft_stop_s=0.8).vector()
    assert motor_spin_down(5.0, gate, mem, 0.6) == 0.0  # no switch yet
    mem[MOTOR_MEM.running], mem[MOTOR_MEM.switch_t], mem[MOTOR_MEM.switches] = 0.0, 10.0, 1.0
    assert motor_spin_down(10.0, gate, mem, 0.6) == 0.6
    assert motor_spin_down(10.4, gate, mem, 0.6) == pytest.approx(0.3, abs=1e-12)
    assert motor_spin_down(10.8, gate, mem, 0.6) == 0.0 and motor_spin_down(12.0, gate, mem, 0.6) == 0.0
    assert motor_spin_down(10.1, MotorGate(soft_stop_s=0.0).vector(), mem, 0.6) == 0.0
