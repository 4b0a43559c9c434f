"""scripts/line_calibration.py without its flights: the references it optimises carry the rate
bounds of bank and angle of attack (the calibrated line model's unbounded optimum pushes over in
generation, docs/design.md section 10), and bad rate bounds exit 2 with one line naming the
option."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

import line_calibration  # noqa: E402


def _captured_bounds(monkeypatch, tmp_path, **kw):
    seen = {}

    def solve(problem):
        seen["problem"] = problem
        return SimpleNamespace(ok=False, reason="not solved here")

    monkeypatch.setattr("fdm_awe.ocp.solve.solve_cycle", solve)
    res, _ = line_calibration.optimise("nominal", 10.0, "calibrated", str(tmp_path), **kw)
    assert not res.ok
    return seen["problem"]


def test_the_references_bound_bank_and_alpha_rates(monkeypatch, tmp_path):
    p = _captured_bounds(monkeypatch, tmp_path)
    assert p.line_model == "calibrated"
    assert p.bounds.bank_rate_max == pytest.approx(0.3) and p.bounds.alpha_rate_max == pytest.approx(0.1)
    assert p.bounds.reel_in_speed_max is not None  # the reel-in margin stays


def test_zero_turns_a_rate_bound_off(monkeypatch, tmp_path):
    p = _captured_bounds(monkeypatch, tmp_path, bank_rate_max=0.0, alpha_rate_max=0.0)
    assert p.bounds.bank_rate_max is None and p.bounds.alpha_rate_max is None


@pytest.mark.parametrize("opt, value", [("--alpha-rate-max", "20"), ("--bank-rate-max", "-1"),
                                        ("--alpha-rate-max", "0.001")])
def test_bad_rate_bounds_exit_2_naming_the_option(opt, value, capsys):
    with pytest.raises(SystemExit) as e:
        line_calibration.main([opt, value])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert opt in err and "0.01..10" in err
