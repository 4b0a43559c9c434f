"""Turbulent flights on a lumped line with a uniform wind: the compiled autopilot blocks hand the
line the gust the glider meets after every step, as the Python autopilot's step hook does, and
fly the flight bit for bit as the Python autopilot does (the line's shape, the cycles' energies
and the ledger included)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parent / "data"


def _same(a, b) -> bool:
    """Whether two report values are equal, NaN equal to NaN (dicts and sequences item by item)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and not isinstance(b, np.ndarray):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if a is None or isinstance(a, (str, bool)):
        return a == b
    return np.array_equal(np.asarray(a, float), np.asarray(b, float), equal_nan=True)


@pytest.mark.parametrize("tether, t_end", [("lumped-implicit:30", None), ("lumped:10", 20.0)])
def test_turbulent_lumped_flight_blocks_fly_as_python(tether: str, t_end: float | None) -> None:
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")
    kw = dict(config="nominal", cycles=1, tether=tether, turbulence=("light", 3), t_end=t_end)
    b = fly(ref, **kw)
    c = fly(ref, on_step=lambda k, s, o: None, **kw)
    if b.loop["loop"] == "compiled":
        assert b.loop["autopilot_compiled_steps"] > 0.9 * b.result.steps
    assert c.loop["autopilot_compiled_steps"] == 0
    assert b.status == c.status and b.result.steps == c.result.steps
    assert np.array_equal(b.result.data, c.result.data, equal_nan=True)
    for k in ("t", "nodes", "tension"):
        assert np.array_equal(b.line_shape[k], c.line_shape[k], equal_nan=True)
    assert [m.E_net_J for m in b.cycles] == [m.E_net_J for m in c.cycles]
    assert _same(b.ledger, c.ledger)
