"""The winch within its ratings in flight: real JSBSim flights of the stored sized-line nominal
cycles, two cycles each (the catch at the start of the second generation is the largest pull
of a cycle).

- IEC class A turbulence at 12 m/s, seed 6: the generator's current was not limited, the
  snatch of the catch drove 29.8 A through the armature against the 24.2 A peak rating
  (90.9 N); the converter now holds it at its 22 A limit and pays out above the tension limit
  (measured 22.0 A, 82.9 N: below half the sized line's 225 N breaking load).
- Calm air at 10 m/s: the peak tension within 1.2 x the 50 N rating (measured 56.1 N; 57.6 N
  before the tension limit: this bound held before too). The 12 m/s cycle's calm catch
  (62.4 N) is not within it: its glider falls back faster than the 24 V drive reels in, and
  the slack is caught on a standing drum (docs/design.md 5, the drive's design reel-in speed).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.groundstation import load_ground_station
from fdm_awe.sim.flight import fly
from fdm_awe.turbulence import Turbulence

DATA = Path(__file__).parent / "data"
GS = load_ground_station()


def _fly(wind: int, turbulence: str | None):
    ref = TrackingReference.from_ocp_file(str(DATA / f"ref_physical_nominal_{wind}mps_sized.json"))
    return fly(ref, config="nominal", cycles=2, turbulence=None if turbulence is None else Turbulence.parse(turbulence))


@pytest.fixture(scope="module")
def gusty():
    return _fly(12, "iec:A:6")


@pytest.fixture(scope="module")
def calm():
    return _fly(10, None)


def test_the_current_stays_below_the_peak_rating_in_a_gusty_catch(gusty):
    rep = gusty
    peak_t = float(np.nanmax(rep.result.tension))
    print(f"\n12 m/s iec:A seed 6: peak current {rep.peak_current_A:.1f} A (rating {GS.machine.peak_current:g} A), "
          f"peak tension {peak_t:.1f} N")
    assert rep.status == "ok" and all(c.complete for c in rep.cycles), rep.message
    # held at the converter's limit (22 A): 2.2 A below the peak rating (29.8 A before)
    assert rep.peak_current_A <= GS.converter.current_limit * (1.0 + 1e-9) < GS.machine.peak_current
    assert peak_t <= 0.5 * GS.tether.breaking_load  # the bound in turbulence (112.5 N)
    assert rep.ledger_residual_rel < 0.01


def test_the_calm_catch_stays_within_the_rating_margin(calm):
    rep = calm
    peak_t = float(np.nanmax(rep.result.tension))
    print(f"\n10 m/s calm: peak tension {peak_t:.1f} N, peak current {rep.peak_current_A:.1f} A")
    assert rep.status == "ok" and all(c.complete for c in rep.cycles), rep.message
    assert peak_t <= 1.2 * 50.0  # measured 56.1 N: 3.9 N of margin
    assert rep.peak_current_A <= GS.converter.current_limit * (1.0 + 1e-9)
