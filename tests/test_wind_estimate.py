"""The onboard wind estimate on samples whose wind is known exactly, the reference set's choice,
and the estimate on the MAVLink link (WIND, id 168)."""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.schedule import ReferenceSet, ScheduledReference
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.autopilot.wind_estimate import body_axes, estimate_wind
from fdm_awe.errors import InputError
from fdm_awe.wind import WindProfile

DATA = Path(__file__).parent / "data"


def _circling(wind_ref: tuple[float, float], factor=None, n: int = 2400) -> dict[str, np.ndarray]:
    """Two turns of a glider at 16-22 m/s true airspeed, climbing and sinking, banked 0.3-0.6 rad,
    at an angle of attack of 0.04-0.16 rad and no sideslip, in the wind ``wind_ref`` [m/s NED]
    times the profile's ``factor`` at its height (uniform: None): what its pitot, AHRS and GPS read."""
    u = np.linspace(0.0, 1.0, n)
    chi = 4.0 * math.pi * u                          # course of the air velocity
    gamma = 0.15 * np.sin(6.0 * math.pi * u)         # flight-path angle in the air
    mu = 0.45 + 0.15 * np.sin(10.0 * math.pi * u)    # bank about the air velocity
    alpha = 0.10 + 0.06 * np.sin(14.0 * math.pi * u)
    tas = 19.0 + 3.0 * np.cos(8.0 * math.pi * u)
    h = 100.0 + 50.0 * np.sin(2.0 * math.pi * u)
    xw = np.stack((np.cos(gamma) * np.cos(chi), np.cos(gamma) * np.sin(chi), -np.sin(gamma)), axis=1)
    side = np.stack((-np.sin(chi), np.cos(chi), np.zeros(n)), axis=1)   # horizontal, to the right
    down = np.cross(xw, side)
    yw = np.cos(mu)[:, None] * side + np.sin(mu)[:, None] * down       # banked right: y tips down
    zw = np.cross(xw, yw)
    xb = np.cos(alpha)[:, None] * xw - np.sin(alpha)[:, None] * zw     # nose above the air velocity
    zb = np.cross(xb, yw)
    euler = np.stack((np.arctan2(yw[:, 2], zb[:, 2]), -np.arcsin(xb[:, 2]), np.arctan2(xb[:, 1], xb[:, 0])), axis=1)
    f = np.ones(n) if factor is None else np.asarray(factor(h), float)
    wind = np.stack((f * wind_ref[0], f * wind_ref[1], np.zeros(n)), axis=1)
    return {"vel": tas[:, None] * xw + wind, "tas": tas, "euler": euler, "h": h, "xb": xb, "yb": yw}


def test_the_synthetic_glider_has_no_sideslip_and_its_attitude_gives_its_axes():
    s = _circling((8.0, 0.0))
    bx, by = body_axes(s["euler"])
    assert np.allclose(bx, s["xb"], atol=1e-12) and np.allclose(by, s["yb"], atol=1e-12)
    air = s["vel"] - np.array([8.0, 0.0, 0.0])
    assert np.max(np.abs(np.sum(air * by, axis=1))) < 1e-9        # no sideslip
    assert np.allclose(np.linalg.norm(air, axis=1), s["tas"])     # the pitot reads the air speed


def test_the_estimate_finds_a_uniform_wind_whatever_the_angle_of_attack():
    """Airspeed and sideslip residuals vanish at the true wind; the body axis alone (ArduPilot's
    DCM estimate, the start) is off sample by sample by TAS sin(alpha) turned into the horizontal
    by the bank (over whole turns at one bank it averages out, on a pumping cycle's path not)."""
    w = (7.0, -3.0)
    s = _circling(w)
    est = estimate_wind(s["vel"], s["tas"], s["euler"], s["h"])
    assert est is not None and est.samples == len(s["tas"])
    assert est.north == pytest.approx(w[0], abs=1e-6) and est.east == pytest.approx(w[1], abs=1e-6)
    assert est.rms < 1e-6 and est.sigma < 1e-6
    assert est.at_glider == pytest.approx(math.hypot(*w), abs=1e-6)
    assert est.direction_from_deg == pytest.approx(math.degrees(math.atan2(3.0, -7.0)) % 360.0, abs=1e-4)
    dcm = s["vel"][:, :2] - s["tas"][:, None] * s["xb"][:, :2] - np.array(w)
    assert np.max(np.hypot(dcm[:, 0], dcm[:, 1])) > 1.0  # sample by sample: what the sideslip term removes


def test_in_a_log_profile_the_estimate_is_the_wind_at_the_reference_height():
    prof = WindProfile.parse("log:0.1", 10.0)
    s = _circling((8.0, 1.0), prof.factor)
    est = estimate_wind(s["vel"], s["tas"], s["euler"], s["h"], prof.factor)
    assert est.north == pytest.approx(8.0, abs=1e-6) and est.east == pytest.approx(1.0, abs=1e-6)
    mean_f = float(np.mean(prof.factor(s["h"])))
    assert mean_f > 1.4  # 50-150 m up: half as much wind again as at 10 m
    assert est.at_glider == pytest.approx(math.hypot(8.0, 1.0) * mean_f, rel=1e-9)
    n, e, d = est.at_glider_ned()
    assert math.hypot(n, e) == pytest.approx(est.at_glider) and d == 0.0
    # read as a uniform wind, the same flight gives the mean wind it met
    flat = estimate_wind(s["vel"], s["tas"], s["euler"], s["h"])
    assert flat.speed == pytest.approx(est.at_glider, rel=0.02)


def test_too_few_or_unusable_samples_give_no_estimate():
    s = _circling((5.0, 0.0), n=40)
    tas = s["tas"].copy()
    tas[5:] = 0.5  # on the ground: no airspeed
    assert estimate_wind(s["vel"], tas, s["euler"]) is None
    tas[:] = np.nan
    assert estimate_wind(s["vel"], tas, s["euler"]) is None


def _member(ref: TrackingReference, wind: float, name: str, **meta) -> ScheduledReference:
    return ScheduledReference(wind, dataclasses.replace(ref, meta={**ref.meta, "wind_mps": wind, **meta}), name)


@pytest.fixture(scope="module")
def ref8() -> TrackingReference:
    return TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")


def test_the_scheduler_picks_the_nearest_reference_and_keeps_the_flown_one_on_a_tie(ref8):
    refs = ReferenceSet([_member(ref8, 12.0, "b"), _member(ref8, 8.0, "a"), _member(ref8, 10.0, "c")])
    assert refs.winds == [8.0, 10.0, 12.0]
    assert [refs.nearest(w) for w in (0.0, 8.9, 9.1, 10.9, 11.1, 25.0)] == [0, 0, 1, 1, 2, 2]
    assert refs.nearest(9.0, current=0) == 0 and refs.nearest(9.0, current=1) == 1
    assert refs.nearest(9.0) == 0
    assert refs.nearest(math.nan, current=2) == 2 and refs.nearest(math.nan) == 0


def test_a_set_of_two_cycle_families_is_refused_naming_the_file_and_field(ref8):
    with pytest.raises(InputError, match=r"^x\.json: metadata\.config 'foldable' .*configuration"):
        ReferenceSet([_member(ref8, 8.0, "a.json"), _member(ref8, 12.0, "x.json", config="foldable")])
    with pytest.raises(InputError, match=r"^x\.json: metadata\.wind_mps 8 .*one reference per wind"):
        ReferenceSet([_member(ref8, 8.0, "a.json"), _member(ref8, 8.0, "x.json")])
    with pytest.raises(InputError, match=r"^x\.json: metadata\.wind_profile .*one profile per set"):
        ReferenceSet([_member(ref8, 8.0, "a.json"),
                      _member(ref8, 12.0, "x.json", wind_profile={"kind": "log", "z0_m": 0.1, "ref_height_m": 10.0})])
    with pytest.raises(InputError, match=r"^x\.json: metadata\.wind_from_deg 200 "):
        ReferenceSet([_member(ref8, 8.0, "a.json"), _member(ref8, 12.0, "x.json", wind_from_deg=200.0)])


def test_a_reference_folder_is_read_and_checked(tmp_path):
    with pytest.raises(InputError, match="--references .*not a folder"):
        ReferenceSet.from_folder(tmp_path / "none")
    with pytest.raises(InputError, match=r"--references .*no reference file"):
        ReferenceSet.from_folder(tmp_path)
    for name in ("ref_physical_nominal_8mps_sized.json", "ref_physical_nominal_12mps_sized.json"):
        (tmp_path / name).write_bytes((DATA / name).read_bytes())
    refs = ReferenceSet.from_folder(tmp_path)
    assert refs.winds == [8.0, 12.0] and refs.profile.uniform
    assert refs.longest_period == pytest.approx(refs.entries[0].reference.period)


def test_the_vehicle_sends_its_wind_estimate_as_ardupilots_wind_message():
    from mavlink_helpers import Link, telemetry_at

    lk = Link(rates={"WIND": 10.0})
    try:
        for wind in (None, np.array([11.0, -2.0, 0.0])):
            for _ in range(60):
                t = lk.t
                lk.ep.update(t, lambda: dataclasses.replace(telemetry_at(t, lk.vehicle), wind_ned=wind))
                lk.t += lk.dt
                lk.drain()
            time.sleep(0.05)
            lk.drain()
            got = [m for m in lk.received if m.get_type() == "WIND"]
            if wind is None:
                assert got == []  # no estimate yet: nothing sent
        assert 4 <= len(got) <= 6  # 10 Hz over 0.5 s of simulated time
        m = got[-1]
        assert m.get_msgId() == 168
        assert m.direction == pytest.approx(math.degrees(math.atan2(2.0, -11.0)), abs=1e-3)  # from 170 deg
        assert m.speed == pytest.approx(math.hypot(11.0, 2.0), abs=1e-5) and m.speed_z == 0.0
    finally:
        lk.close()


def test_the_set_script_gathers_references_of_one_family_only(tmp_path):
    import subprocess
    import sys

    script = Path(__file__).parent.parent / "scripts" / "reference_set.py"
    ok = [str(DATA / "ref_physical_nominal_8mps_sized.json"), str(DATA / "ref_physical_nominal_12mps_sized.json")]
    r = subprocess.run([sys.executable, str(script), "--files", ",".join(ok), "--out", str(tmp_path / "set")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert ReferenceSet.from_folder(tmp_path / "set").winds == [8.0, 12.0]
    mixed = [ok[0], str(DATA / "ref_physical_foldable_8mps_sized.json")]
    r = subprocess.run([sys.executable, str(script), "--files", ",".join(mixed), "--out", str(tmp_path / "mixed")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "metadata.config" in r.stderr and not (tmp_path / "mixed").exists()
