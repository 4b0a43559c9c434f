"""scripts/activity_tradeoff.py: where the activity sits (the share of the surfaces' high-pass
energy near the phase switches) on signals whose answer is known, and its bad input."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import activity_tradeoff as tradeoff  # noqa: E402


def _phases(n: int, dt: float, t_switch: float) -> list[str]:
    return ["generation" if k * dt < t_switch else "recovery" for k in range(n)]


def test_a_burst_at_the_switch_is_counted_there_and_one_away_from_it_is_not():
    dt, T = 1.0 / 120.0, 60.0
    n = int(T / dt)
    t = np.arange(n) * dt
    burst = lambda t0: np.where((t > t0) & (t < t0 + 1.0), 0.5 * np.sin(2 * np.pi * 3.0 * t), 0.0)  # 3 Hz, 1 s
    slow = 0.3 * np.sin(2 * np.pi * 0.02 * t)  # a manoeuvre far below the cut-off
    near = np.column_stack([burst(30.2) + slow, slow, np.zeros(n)])
    share, time_share = tradeoff.switch_share(near, _phases(n, dt, 30.0), dt)
    assert share > 0.97
    before, after = tradeoff.SWITCH_WINDOW
    assert time_share == pytest.approx((before + after) / T, abs=2 * dt / T)
    far = np.column_stack([burst(45.0) + slow, slow, np.zeros(n)])
    share, _ = tradeoff.switch_share(far, _phases(n, dt, 30.0), dt)
    assert share < 0.03


@pytest.mark.parametrize("argv, text", [(["--config", "bogus"], "--config bogus"),
                                        (["--variant", "optimum,x"], "--variant optimum,x"),
                                        (["--cycles", "1"], "--cycles 1"),
                                        (["--json", "/nonexistent-folder/x.json"], "--json")])
def test_bad_input_exits_2_with_one_line(argv, text, capsys):
    assert tradeoff.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and text in err
