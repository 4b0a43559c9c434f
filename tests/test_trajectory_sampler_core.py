"""The sampler's pure function (:func:`fdm_awe.trajectory.sampler.cycle_evaluate`): compiled by
numba it gives the Python call's bits (cycle, cycle time, phase, segment, weight and the row);
:meth:`CycleSampler.evaluate` gives what the NumPy form gave (``np.searchsorted`` and one array
expression for the row)."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest
from jit_helpers import compiled, same_bits

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.trajectory import CycleSampler, read_reference
from fdm_awe.trajectory.sampler import LINEAR, HELD, cycle_evaluate, cycle_time, segment_of
from fdm_awe.trajectory.schema import GENERATION, RECOVERY

DATA = Path(__file__).parent / "data"
STORED = sorted(DATA.glob("ref_*.json"))


def _synthetic() -> CycleSampler:
    """Rows starting after the cycle start and ending before the period, the switch row stored
    once per phase (a repeated time), a vector and a scalar linear column, a held column."""
    t = np.array([0.25, 1.0, 2.0, 3.0, 3.0, 4.5, 6.0, 7.25])
    ph = np.array([0, 0, 0, 0, 1, 1, 1, 1])
    rnd = np.random.default_rng(4)
    cols = {"pos": rnd.normal(0.0, 50.0, (8, 3)), "v": rnd.normal(0.0, 10.0, 8), "s": rnd.uniform(0.0, 1.0, 8)}
    return CycleSampler(t, ph, cols, {"pos": LINEAR, "v": LINEAR, "s": HELD}, 3.0, 8.0)


def _samplers() -> list[CycleSampler]:
    out = [_synthetic()]
    for path in STORED[:3]:
        out.append(read_reference(path).sampler())
        out.append(TrackingReference.from_ocp_file(path).sampler())
    return out


def _times(smp: CycleSampler, rnd: random.Random) -> list[float]:
    """Random times over several cycles (negative ones too), every row time and the phase
    switch in several cycles, exactly and one ulp either side, and whole periods."""
    P = smp.period
    out = [rnd.uniform(-2.0 * P, 6.0 * P) for _ in range(300)]
    for k in (-1, 0, 1, 4):
        for x in [*map(float, smp.t), smp.T1, 0.0, P]:
            x = x + k * P
            out += [x, math.nextafter(x, -math.inf), math.nextafter(x, math.inf)]
    return out


def _numpy_evaluate(smp: CycleSampler, t: float):
    """The sampler's NumPy form: ``np.searchsorted`` and one array expression for the row."""
    k = int(t // smp.period)
    tc = t - k * smp.period
    ts = smp.t
    i = min(max(int(np.searchsorted(ts, tc, side="right")) - 1, 0), len(ts) - 2)
    w = min(max((tc - ts[i]) / (ts[i + 1] - ts[i]), 0.0), 1.0)
    tab = smp.table
    return k, tc, GENERATION if tc < smp.T1 else RECOVERY, i, w, tab[i] * (1.0 - w) + tab[i + 1] * w


def _rows_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.all(a.view(np.uint64) == b.view(np.uint64)))


def test_cycle_evaluate_compiled_equals_python():
    jit = compiled(cycle_evaluate, cycle_time, segment_of)
    rnd = random.Random(17)
    n = 0
    for smp in _samplers():
        m = smp.table.shape[1]
        for t in _times(smp, rnd):
            row_py, row_jit = np.full(m, np.nan), np.full(m, np.nan)
            py = cycle_evaluate(smp.t, smp.table, smp.T1, smp.period, t, row_py)
            got = jit(smp.t, smp.table, smp.T1, smp.period, t, row_jit)
            assert same_bits(got, py), (t, got, py)
            assert _rows_equal(row_jit, row_py), t
            n += 1
    assert n > 2000


def test_evaluate_gives_the_numpy_form_bit_for_bit():
    rnd = random.Random(5)
    phases = set()
    for smp in _samplers():
        for t in _times(smp, rnd):
            got, want = smp.evaluate(t), _numpy_evaluate(smp, t)
            assert same_bits(got[:5], want[:5]), (t, got[:5], want[:5])
            assert _rows_equal(got[5], want[5]), t
            phases.add(got[2])
    assert phases == {GENERATION, RECOVERY}


def test_segment_of_is_searchsorted_and_compiles_alike():
    jit = compiled(segment_of)
    rnd = random.Random(9)
    for smp in _samplers():
        ts = smp.t
        xs = [rnd.uniform(-1.0, smp.period + 1.0) for _ in range(200)] + [*map(float, ts), -math.inf, math.inf, math.nan]
        for x in xs:
            want = min(max(int(np.searchsorted(ts, x, side="right")) - 1, 0), len(ts) - 2)
            assert segment_of(ts, x) == want == jit(ts, x), x
        assert smp.segment_index(float(ts[1])) == 1


def test_edges_before_the_first_row_beyond_the_last_and_at_the_switch():
    smp = _synthetic()
    ts = smp.t
    k, tc, phase, i, w, row = smp.evaluate(0.1)  # before the first row: the first row itself
    assert (k, i, w, phase) == (0, 0, 0.0, GENERATION) and _rows_equal(row, smp.table[0])
    k, tc, phase, i, w, row = smp.evaluate(7.5 + 8.0)  # beyond the last row: the last row
    assert (k, i, w, phase) == (1, len(ts) - 2, 1.0, RECOVERY) and _rows_equal(row, smp.table[-1])
    k, tc, phase, i, w, row = smp.evaluate(3.0 - 16.0)  # at the switch: recovery's row
    assert (k, tc, phase, i, w) == (-2, 3.0, RECOVERY, 4, 0.0) and _rows_equal(row, smp.table[4])
    assert smp.evaluate(math.nextafter(3.0, 0.0))[2:4] == (GENERATION, 2)
    assert smp.where("pos") == slice(0, 3) and smp.where("v") == 3 and smp.segments("s").shape == (len(ts) - 1,)


@pytest.mark.parametrize("path", STORED[:1], ids=lambda p: p.stem)
def test_evaluate_returns_a_new_row_each_call(path: Path):
    smp = TrackingReference.from_ocp_file(path).sampler()
    a, b = smp.evaluate(0.3)[5], smp.evaluate(5.0)[5]
    assert a is not b and not np.shares_memory(a, b)
