"""Shared checks of flight tests: the autopilot issue's per-cycle acceptance."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

DATA = Path(__file__).parent / "data"


def assert_cycle_accepted(rep: Any, ref: Any, energy_rel: float = 0.15) -> Any:
    """The flight ended without an event, its first cycle is complete with tracking RMS <= 5 m
    and max <= 15 m, its net energy is within ``energy_rel`` of the optimiser's and both
    ledgers close within 1 % of their largest term. Returns that cycle."""
    assert rep.status == "ok", rep.message
    c = rep.cycles[0]
    assert c.complete
    assert c.track_rms_m <= 5.0 and c.track_max_m <= 15.0, (c.track_rms_m, c.track_max_m)
    assert c.E_net_J == pytest.approx(ref.meta["energies"]["E_net_J"], rel=energy_rel)
    assert rep.ledger_residual_rel < 0.01
    return c
