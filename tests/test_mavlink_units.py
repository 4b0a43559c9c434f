"""Parameter store, geodetic mapping, vehicle records and real-time pacer (no sockets)."""

from __future__ import annotations

import json
import math

import pytest

from fdm_awe.errors import DefinitionError, InputError
from fdm_awe.mavlink.geo import GeoFrame, Home
from fdm_awe.autopilot.params import ParamStore
from fdm_awe.mode_table import MODE_NAMES, MODE_NUMBERS
from fdm_awe.autopilot.vehicle import Waypoint
from fdm_awe.autopilot.modes import mode_number
from fdm_awe.sim.pacing import RealtimePacer


# ---------------------------------------------------------------- ParamStore
def test_param_ids_kinds_and_ranges_are_validated():
    ps = ParamStore()
    ps.add("AP_ROLL_KP", 0.8, 0.0, 5.0)
    for bad in ("", "A" * 17, "lower_case", "BAD-CHAR", 12):
        with pytest.raises(InputError):
            ps.add(bad, 1.0, 0.0, 2.0)
    with pytest.raises(InputError, match="declared twice"):
        ps.add("AP_ROLL_KP", 0.8, 0.0, 5.0)
    with pytest.raises(InputError, match="kind"):
        ps.add("X_KIND", 1.0, 0.0, 2.0, kind="double")
    with pytest.raises(InputError, match="range"):
        ps.add("X_RANGE", 1.0, 2.0, 0.0)
    with pytest.raises(InputError, match="default"):
        ps.add("X_DEFAULT", 3.0, 0.0, 2.0)
    ps.add("A" * 16, 1.0, 0.0, 2.0)          # 16 characters is the MAVLink limit: allowed
    ps.add("N_INT", 3, 0, 10, kind="int")
    ps.add("B_FLAG", 1, 0, 1, kind="bool")
    assert ps.try_set("AP_ROLL_KP", 5.5)[0] is False
    assert ps.try_set("AP_ROLL_KP", math.nan)[0] is False
    assert ps.try_set("AP_ROLL_KP", math.inf)[0] is False
    assert ps.try_set("N_INT", 2.5)[0] is False
    assert ps.try_set("B_FLAG", 0.5)[0] is False
    assert ps.try_set("NOPE", 1.0)[0] is False
    assert ps["AP_ROLL_KP"] == 0.8 and ps["N_INT"] == 3 and ps["B_FLAG"] == 1
    assert ps.names() == ["AP_ROLL_KP", "A" * 16, "N_INT", "B_FLAG"]
    assert ps.index("N_INT") == 2 and ps.name_at(2) == "N_INT" and ps.name_at(4) is None


def test_param_callbacks_and_persistence(tmp_path):
    path = tmp_path / "params.json"
    seen = []
    ps = ParamStore(path)
    ps.add("WINCH_PI_KP", 0.004, 0.0, 0.1, on_change=lambda n, v: seen.append((n, v)))
    ps.add("FOLD_TIME_S", 0.6, 0.05, 5.0)
    ps.set("WINCH_PI_KP", 0.006)
    assert seen == [("WINCH_PI_KP", 0.006)]
    ps.set("WINCH_PI_KP", 0.006)             # unchanged value: no callback
    assert len(seen) == 1
    with pytest.raises(InputError, match=r"outside \[0, 0.1\]"):
        ps.set("WINCH_PI_KP", 0.2)
    assert json.loads(path.read_text())["params"]["WINCH_PI_KP"] == 0.006

    # a restart: new store on the same file, same declarations -> saved value wins
    ps2 = ParamStore(path)
    ps2.add("WINCH_PI_KP", 0.004, 0.0, 0.1)
    ps2.add("FOLD_TIME_S", 0.6, 0.05, 5.0)
    assert ps2["WINCH_PI_KP"] == 0.006 and ps2["FOLD_TIME_S"] == 0.6

    # a saved value outside a (new) range is reported with file and parameter
    ps3 = ParamStore(path)
    with pytest.raises(DefinitionError, match="parameter WINCH_PI_KP"):
        ps3.add("WINCH_PI_KP", 0.004, 0.0, 0.005)


def test_param_callback_failure_keeps_value(tmp_path):
    ps = ParamStore()

    def boom(n, v):
        raise RuntimeError("controller rejected")

    ps.add("AP_PITCH_KP", 1.0, 0.0, 5.0, on_change=boom)
    ok, why = ps.try_set("AP_PITCH_KP", 2.0)
    assert ok and "callback failed" in why and ps["AP_PITCH_KP"] == 2.0


def test_param_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "p.json"
    bad.write_text("{not json")
    with pytest.raises(DefinitionError, match="p.json"):
        ParamStore(bad)
    bad.write_text(json.dumps({"format": "fdm-awe-params-1", "params": {"X": "fast"}}))
    with pytest.raises(DefinitionError, match="parameter X"):
        ParamStore(bad)


# ---------------------------------------------------------------- geo
def _deg_lat_m(phi):
    # Length of one degree of latitude on WGS-84 (standard series, accurate to ~1 mm)
    return 111132.954 - 559.822 * math.cos(2 * phi) + 1.175 * math.cos(4 * phi)


def _deg_lon_m(phi):
    # Length of one degree of longitude on WGS-84 (standard series, accurate to ~1 cm)
    return 111412.84 * math.cos(phi) - 93.5 * math.cos(3 * phi) + 0.118 * math.cos(5 * phi)


@pytest.mark.parametrize("lat", [0.0, 45.0, -35.363262, 60.0])
def test_geo_known_offsets_match_wgs84_degree_lengths(lat):
    g = GeoFrame(Home(lat, 10.0, 100.0))
    phi = math.radians(lat)
    la, lo, alt = g.to_geodetic(1000.0, 0.0, -50.0)
    # 1 km north: independent series gives the metres per degree; tolerance 1e-5
    # relative covers the series truncation (~1 mm per degree)
    assert (la - lat) * _deg_lat_m(phi) == pytest.approx(1000.0, rel=1e-5)
    assert lo == pytest.approx(10.0, abs=1e-12) and alt == pytest.approx(150.0)
    la, lo, alt = g.to_geodetic(0.0, 1000.0, 20.0)
    assert (lo - 10.0) * _deg_lon_m(phi) == pytest.approx(1000.0, rel=1e-5)
    assert la == pytest.approx(lat, abs=1e-12) and alt == pytest.approx(80.0)


def test_geo_round_trip_and_dateline():
    g = GeoFrame(Home(-35.0, 179.999, 500.0))
    for ned in [(0.0, 0.0, 0.0), (250.0, -120.0, -140.0), (-300.0, 400.0, 10.0)]:
        back = g.to_ned(*g.to_geodetic(*ned))
        assert back == pytest.approx(ned, abs=1e-6)   # float round off only
    la, lo, _ = g.to_geodetic(0.0, 500.0, 0.0)      # crosses the date line
    assert -180.0 <= lo < -179.99


def test_home_is_validated():
    for kw in ({"lat_deg": 95.0}, {"lon_deg": math.nan}, {"alt_m": 1e6}):
        with pytest.raises(InputError, match="home"):
            Home(**kw)


# ---------------------------------------------------------------- vehicle records
def test_mode_table_is_one_to_one_and_contains_required_modes():
    assert {"MANUAL", "AUTO", "RECOVER"} <= set(MODE_NUMBERS)
    assert len(MODE_NAMES) == len(MODE_NUMBERS)
    assert mode_number("AUTO") == 10 and MODE_NAMES[11] == "RECOVER"
    with pytest.raises(InputError, match="allowed"):
        mode_number("SPORT")


def test_waypoint_validation():
    Waypoint(100.0, 0.0, -50.0, time_s=1.0, phase="generation")
    with pytest.raises(InputError, match="north"):
        Waypoint(math.nan, 0.0, -50.0)
    with pytest.raises(InputError, match="phase"):
        Waypoint(1.0, 0.0, -50.0, phase="climb")


# ---------------------------------------------------------------- pacer (simulated clock)
class FakeClock:
    def __init__(self, oversleep=0.0):
        self.t = 1000.0
        self.oversleep = oversleep

    def __call__(self):
        return self.t

    def sleep(self, s):
        self.t += s + self.oversleep


def test_pacer_absolute_deadlines_do_not_drift():
    clk = FakeClock(oversleep=0.002)         # every sleep 2 ms too long
    p = RealtimePacer(1.0, clock=clk, sleep=clk.sleep)
    dt = 0.01
    for k in range(1001):
        clk.t += 0.001                      # 1 ms of work per step
        p.wait(k * dt)
    st = p.stats()
    # With relative sleeps the error would grow to 1000 * 2 ms = 2 s; absolute deadlines
    # keep the end within one oversleep of the schedule.
    assert st.wall_s == pytest.approx(10.0 + 0.001, abs=0.0025)
    assert st.max_ms == pytest.approx(2.0, abs=1e-6) and st.resyncs == 0


def test_pacer_catches_up_after_a_slow_step_and_resyncs_when_far_behind():
    clk = FakeClock()
    p = RealtimePacer(2.0, clock=clk, sleep=clk.sleep, max_lag_s=0.5)
    dt = 0.02
    p.wait(0.0)
    t0 = clk.t
    for k in range(1, 101):
        if k == 10:
            clk.t += 0.1                    # one slow step: 100 ms late
        p.wait(k * dt)
    # factor 2: 2 s simulated in 1 s wall despite the slow step (caught up, no drift)
    assert clk.t - t0 == pytest.approx(1.0, abs=1e-9)
    clk.t += 2.0                            # a 2 s stall (beyond max_lag): re-base
    p.wait(101 * dt)
    assert p.resyncs == 1
    p.wait(102 * dt)
    assert clk.t - t0 == pytest.approx(3.0 + dt / 2.0, abs=1e-9)


def test_pacer_rejects_bad_factor():
    for f in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(InputError, match="realtime"):
            RealtimePacer(f)


def test_stand_in_vehicle_satisfies_the_protocol():
    from mavlink_helpers import StandInVehicle

    from fdm_awe.autopilot.vehicle import VehicleInterface
    assert isinstance(StandInVehicle(), VehicleInterface)
    assert not isinstance(object(), VehicleInterface)
