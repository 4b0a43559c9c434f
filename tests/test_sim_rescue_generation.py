"""The motor's rescue in generation (RESC_GEN_DEPTH): a generating glider that lags its path in a
lull, or flies above it, hangs on a line the wind still pulls, and the rescue's propeller pushes
against the generator. The stored nominal 10 m/s cycle (sized line), 3 cycles, in calm air and
in light turbulence with seeds 1-10: light air keeps 67 % of the calm net energy per cycle with
the rescue for any position error (RESC_GEN_DEPTH 0, the default), 77 % at 10 m (the rescue
in generation only for a glider more than 10 m below its reference point, on a pulling line in
the cycle's wind). The bound asserted, 73 %, is the gain less the share one seed's lull cycle
moves the mean by (a cycle lost to a lull costs about 600 J, 1.5 % of the ten flights' mean).
The default keeps the flights as they were."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.auto_step import rescue_allowed
from fdm_awe.autopilot.config import autopilot_params
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly
from fdm_awe.turbulence import Turbulence

REF = Path(__file__).parent / "data" / "ref_physical_nominal_10mps_sized.json"
SEEDS = range(1, 11)


def test_the_rescue_in_generation_waits_for_a_glider_below_its_path():
    # generation (phase 0), slow (8 m/s in the air against the reference's 12), 10 m threshold,
    # a line that pulls
    assert not rescue_allowed(0, 8.0, 12.0, False, False, 5.0, 10.0, True)  # lags, 5 m below
    assert not rescue_allowed(0, 8.0, 12.0, False, False, -20.0, 10.0, True)  # above its path
    assert rescue_allowed(0, 8.0, 12.0, False, False, 10.5, 10.0, True)  # sinks away below it
    assert rescue_allowed(0, 8.0, 12.0, False, False, -20.0, 10.0, False)  # a slack line: any error
    assert rescue_allowed(0, 8.0, 12.0, False, False, -20.0, 0.0, True)  # 0: as before, any error
    assert rescue_allowed(1, 8.0, 12.0, False, False, -20.0, 10.0, True)  # recovery: any error
    assert not rescue_allowed(0, 13.0, 12.0, False, False, 20.0, 10.0, False)  # faster than its point
    assert not rescue_allowed(1, 13.0, 12.0, False, False, 20.0, 10.0, True)
    # pulling up from the ground or protecting its airspeed: always
    assert rescue_allowed(0, 13.0, 12.0, True, False, -20.0, 10.0, True)
    assert rescue_allowed(0, 13.0, 12.0, False, True, -20.0, 10.0, True)


def _mean_net(turbulence: Turbulence | None, depth: float = 10.0) -> tuple[float, float, object]:
    """(mean net energy per complete cycle [J], mean thrust energy per complete cycle [J], report)
    with RESC_GEN_DEPTH ``depth`` [m]."""
    ref = TrackingReference.from_ocp_file(str(REF))
    ps = autopilot_params()
    ps.set("RESC_GEN_DEPTH", depth)
    rep = fly(ref, config="nominal", cycles=3, turbulence=turbulence, params=ps)
    done = [c for c in rep.cycles if c.complete]
    assert len(done) == 3, rep.message
    return float(np.mean([c.E_net_J for c in done])), float(np.mean([c.E_thrust_J for c in done])), rep


@pytest.fixture(scope="module")
def flights():
    calm = _mean_net(None)
    light = [_mean_net(Turbulence.parse(f"light:{s}")) for s in SEEDS]
    return calm, light


def test_light_turbulence_keeps_most_of_the_calm_net_energy(flights):
    (calm, calm_thrust, _), light = flights
    nets = [n for n, _, _ in light]
    thrust = [t for _, t, _ in light]
    share = float(np.mean(nets)) / calm
    print(f"calm {calm:.0f} J/cycle ({calm_thrust:.0f} J thrust), light {np.mean(nets):.0f} J/cycle "
          f"({np.mean(thrust):.0f} J thrust): {100 * share:.0f} %")
    assert calm > 300.0  # the cycle nets energy in its own wind (measured 407 J)
    assert share >= 0.73  # measured 0.77; the rescue for any error (the default): 0.67
    # the propeller no longer pushes against the generator in the lulls: the thrust energy per
    # cycle stays within a few times the calm cycle's (measured 112 J against 51 J; before: 157 J,
    # up to 824 J in one cycle)
    assert float(np.mean(thrust)) < 2.5 * calm_thrust
    for _, _, rep in light:
        assert rep.status == "ok", rep.message
        assert float(np.nanmax(rep.result.tension)) <= 1.2 * 50.0  # 1.2 x the rating in light air


def test_the_default_keeps_the_rescue_in_generation():
    assert autopilot_params()["RESC_GEN_DEPTH"] == 0.0
    # light seed 3: a lull cycle the rescue flies on the motor (thrust 824 J in its third cycle)
    _, thrust0, _ = _mean_net(Turbulence.parse("light:3"), depth=0.0)
    _, thrust10, _ = _mean_net(Turbulence.parse("light:3"), depth=10.0)
    assert thrust0 > 300.0 and thrust10 < thrust0 - 100.0  # measured 389 and 222 J per cycle
