"""Turbulence forms (fdm_awe.turbulence): parsing, the JSBSim parameters each form sets, the
targets, the measurement, and JSBSim's turbulence against the target over a long record.

The long record steps JSBSim's atmosphere with the glider held at one height and ground velocity
(fdm_awe.sixdof.turbulence_path): hours of air in seconds of wall time. Its sampling spread is
derived in the test's docstring; the named levels are checked bit for bit against the
properties the original code set.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.sixdof import JSBSimGlider
from fdm_awe.turbulence import (IEC_CLASSES, LOW_ALTITUDE_M, TURBULENCE_LEVELS, W20_HEIGHT_M, Turbulence,
                                TurbulenceSetting, iec_sigma, mean_height, measure, sigma_ratio)
from fdm_awe.units import FT
from fdm_awe.wind import WindProfile

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")


def test_forms_parse_with_their_seed():
    assert Turbulence.parse("light") == Turbulence("level", "light", 1)
    assert Turbulence.parse("severe:2147483647") == Turbulence("level", "severe", 2**31 - 1)
    assert Turbulence.parse("milspec:moderate:3") == Turbulence("milspec", "moderate", 3)
    assert Turbulence.parse("iec:a") == Turbulence("iec", "A", 1)
    assert Turbulence.parse("iec:C:9").text() == "iec:C:9"
    assert Turbulence.of(("moderate", 7)) == Turbulence("level", "moderate", 7)


@pytest.mark.parametrize("text, words", [
    ("storm", ("form 'storm' unknown",)), ("iec", ("needs a class", "A, B, C")), ("iec:D:1", ("class 'D'",)),
    ("milspec:strong", ("severity 'strong'", "light, moderate, severe")), ("milspec:light:0", ("seed 0",)),
    ("iec:A:1:2", ("too many fields",)), ("light:x", ("seed 'x'", "not an integer")),
])
def test_bad_forms_name_the_option_and_the_forms(text, words):
    with pytest.raises(InputError) as e:
        Turbulence.parse(text)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"--turbulence {text!r}")
    for w in words:
        assert w in msg


def test_named_levels_keep_their_fixed_wind_at_20_ft():
    """The named levels do not follow the flight's wind: W20 is 15, 30, 45 kt at every wind."""
    for level, (sev, kt) in TURBULENCE_LEVELS.items():
        for wind in (4.0, 12.0):
            st = Turbulence("level", level).setting(wind, None, 100.0)
            assert st.severity == sev and st.w20_mps == kt * 1852.0 / 3600.0
    assert TURBULENCE_LEVELS == {"light": (3, 15.0), "moderate": (4, 30.0), "severe": (6, 45.0)}


def _gusts(turbulence, by_hand: bool, n: int = 600) -> np.ndarray:
    g = JSBSimGlider("glider_unfolded", wind_ned=(8.0, 0.0, 0.0), turbulence=None if by_hand else turbulence)
    g.reset((0.0, 0.0, -120.0), 18.0, psi=math.pi / 2)
    if by_hand:  # what the adapter set for a named level before the forms existed
        level, seed = turbulence
        sev, w20_kt = {"light": (3, 15.0), "moderate": (4, 30.0), "severe": (6, 45.0)}[level]
        f = g.fdm
        f["atmosphere/randomseed"] = int(seed)
        f["simulation/randomseed"] = int(seed)
        f["atmosphere/turb-type"] = 4
        f["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20_kt * 1852.0 / 3600.0 / FT
        f["atmosphere/turbulence/milspec/severity"] = sev
    out = []
    for _ in range(n):
        g.step()
        out.append(g.state().wind_ned)
    return np.array(out)


@pytest.mark.parametrize("level", ["light", "moderate", "severe"])
def test_named_levels_fly_the_old_gusts_bit_for_bit(level):
    new = _gusts((level, 5), by_hand=False)
    assert np.array_equal(new, _gusts((level, 5), by_hand=True))
    assert np.abs(new - (8.0, 0.0, 0.0)).max() > 0.05  # turbulence is on


def test_the_glider_takes_a_wind_following_form_only_as_its_setting():
    with pytest.raises(InputError, match="iec:A:1 follows the flight's wind"):
        JSBSimGlider("glider_unfolded", turbulence=Turbulence("iec", "A"))
    with pytest.raises(InputError, match="not one of light, moderate, severe"):
        JSBSimGlider("glider_unfolded", turbulence=("storm", 1))
    g = JSBSimGlider("glider_unfolded", turbulence=Turbulence("level", "severe", 3))
    assert g.turbulence == Turbulence("level", "severe", 3).setting() and g.fdm["atmosphere/turb-type"] == 4


def test_milspec_takes_the_wind_at_20_ft_from_the_profile():
    st = Turbulence("milspec", "light").setting(8.0, None, 100.0)
    assert st.w20_mps == 8.0 and st.sigma_w == pytest.approx(0.8)
    log = WindProfile("log", z0=0.1, ref_height=10.0)
    st = Turbulence("milspec", "severe", 2).setting(8.0, log, 100.0)
    w20 = 8.0 * math.log(W20_HEIGHT_M / 0.1) / math.log(10.0 / 0.1)
    assert st.w20_mps == pytest.approx(w20) and st.severity == 6
    assert st.wind_hub_mps == pytest.approx(8.0 * math.log(1000.0) / math.log(100.0))
    # the standard's low-altitude model: sigma_u = 0.1 W20 / (0.177 + 0.000823 h_ft)^0.4
    h_ft = 100.0 / FT
    assert st.targets()["sigma_u_mps"] == pytest.approx(0.1 * w20 / (0.177 + 0.000823 * h_ft) ** 0.4)
    # the intensity follows the wind: the same at 8 and 12 m/s in a uniform wind
    i8 = Turbulence("milspec", "light").setting(8.0, None, 100.0).targets()["intensity"]
    i12 = Turbulence("milspec", "light").setting(12.0, None, 100.0).targets()["intensity"]
    assert i8 == pytest.approx(i12) and 0.12 < i8 < 0.16


@pytest.mark.parametrize("cls", ["A", "B", "C"])
@pytest.mark.parametrize("wind", [8.0, 10.0, 12.0])
def test_iec_gives_its_sigma_at_the_hub_height(cls, wind):
    hub = 95.0
    st = Turbulence("iec", cls).setting(wind, None, hub)
    sigma_1 = IEC_CLASSES[cls] * (0.75 * wind + 5.6)
    assert iec_sigma(IEC_CLASSES[cls], wind) == pytest.approx(sigma_1)
    assert st.sigma_u(hub) == pytest.approx(sigma_1, rel=1e-12)
    assert st.targets()["intensity"] == pytest.approx(sigma_1 / wind)
    assert st.w20_mps == pytest.approx(10.0 * sigma_1 * (0.177 + 0.000823 * hub / FT) ** 0.4)
    assert st.sigma_u(50.0) > sigma_1 > st.sigma_u(170.0)  # JSBSim's sigma falls with height


def test_iec_refuses_a_hub_above_the_low_altitude_model():
    with pytest.raises(InputError, match=r"--turbulence iec:A:1: .*above 305 m"):
        Turbulence("iec", "A").setting(8.0, None, LOW_ALTITUDE_M[1] + 1.0)


def test_sigma_ratio_is_jsbsims_height_function():
    assert sigma_ratio(0.0) == sigma_ratio(10.0 * FT)  # held at 10 ft
    assert sigma_ratio(1000.0 * FT) == pytest.approx(1.0, abs=1e-3)  # the low-altitude model meets 0.1 W20 at 1000 ft


def test_measure_splits_the_gust_along_the_mean_wind():
    """A known gust on a wind from the south-west: RMS about zero of each part, intensity
    over the mean steady speed."""
    t = np.linspace(0.0, 40.0 * math.pi, 100001)  # whole periods of every part
    e = np.array([1.0, 1.0]) / math.sqrt(2.0)
    steady = np.tile([6.0 * e[0], 6.0 * e[1], 0.0], (len(t), 1))
    u, v, w = 0.9 * np.sin(t), 0.5 * np.cos(3 * t), 0.3 * np.sign(np.sin(7 * t))
    wind = steady + np.stack((u * e[0] - v * e[1], u * e[1] + v * e[0], w), axis=1)
    m = measure(t, wind, steady, (3.0, 3.0))
    assert m["sigma_u_mps"] == pytest.approx(0.9 / math.sqrt(2), rel=1e-3)
    assert m["sigma_v_mps"] == pytest.approx(0.5 / math.sqrt(2), rel=1e-3)
    assert m["sigma_w_mps"] == pytest.approx(0.3, rel=1e-2)
    assert m["mean_wind_mps"] == pytest.approx(6.0) and m["intensity"] == pytest.approx(0.9 / math.sqrt(2) / 6.0, rel=1e-3)
    assert m["duration_s"] == pytest.approx(40.0 * math.pi)
    assert mean_height([0.0, 1.0, 3.0], [10.0, 20.0, 20.0]) == pytest.approx((15.0 + 40.0) / 3.0)


def test_jsbsim_turbulence_meets_the_iec_target_over_a_long_record():
    """IEC class A at 8 m/s, hub 100 m, the glider held there crosswind at 20 m/s for an hour of
    air (dt 1/30 s: the filters' time constants, 5-13 s, are 150-400 steps).

    Sampling spread: the longitudinal gust is a first-order process with correlation time
    tau = L_u / V = 263 m / 20 m/s = 13 s, so an RMS over T has a relative standard error of
    sqrt(tau / (2 T)) = 4.3 % over 3600 s; the lateral (second order, same L) about as much, the
    vertical (L_w = h = 100 m, tau 5 s) 2.6 %. The bounds, 15 % and 10 %, are 3.5 and 3.8
    standard errors: a wrong mapping (e.g. the sigma_w relation taken for sigma_u, 28 % off)
    fails, the record's own spread does not."""
    from fdm_awe.sixdof.turbulence_path import sample_turbulence

    st = Turbulence("iec", "A", 4).setting(8.0, None, 100.0)
    tg = st.targets()
    assert tg["intensity"] == pytest.approx(0.16 * (0.75 * 8.0 + 5.6) / 8.0)
    t, wind, steady = sample_turbulence(st, (8.0, 0.0, 0.0), 100.0, 20.0, 3600.0, dt=1.0 / 30.0)
    assert np.array_equal(steady, np.tile([8.0, 0.0, 0.0], (len(t), 1)))
    m = measure(t, wind, steady, (1.0, 0.0))
    assert m["sigma_u_mps"] == pytest.approx(tg["sigma_u_mps"], rel=0.15)
    assert m["intensity"] == pytest.approx(tg["intensity"], rel=0.15)
    assert m["sigma_v_mps"] == pytest.approx(tg["sigma_u_mps"], rel=0.15)  # JSBSim: sigma_v = sigma_u
    assert m["sigma_w_mps"] == pytest.approx(tg["sigma_w_mps"], rel=0.10)
    assert isinstance(st, TurbulenceSetting) and st.severity > 0


def test_table_script_prints_target_and_measured_and_refuses_bad_input(capsys):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    import turbulence_table

    assert turbulence_table.main(["--forms", "iec:B", "--winds", "10", "--duration", "30"]) == 0
    row = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| iec:B")]
    assert len(row) == 1 and "| 10 | " in row[0] and "| 1.834 |" in row[0]  # sigma_1 = 0.14 (7.5 + 5.6)
    for argv, words in ((["--forms", "iec:Z"], "--forms 'iec:Z'"), (["--winds", "x"], "--winds 'x'"),
                        (["--hub", "400"], "--hub 400"), (["--profile", "log:9"], "--profile"),
                        (["--swing", "7"], "--swing '7'"), (["--swing", "20:3"], "--swing 20.0")):
        assert turbulence_table.main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and words in err


def test_a_flight_takes_its_hub_from_the_reference_and_refuses_one_too_high():
    """The hub is the reference cycle's time-mean height, the wind its metadata's; an IEC hub
    above 305 m is refused (one line naming --turbulence) before the flight."""
    import dataclasses
    from pathlib import Path

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight_rig import turbulence_setting

    ref = TrackingReference.from_ocp_file(Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json")
    st = turbulence_setting(ref, Turbulence("iec", "A", 1))
    h = -ref.pos[:, 2]
    assert h.min() < st.hub_height_m < h.max() and st.wind_hub_mps == pytest.approx(8.0)
    assert turbulence_setting(ref, None) is None
    assert turbulence_setting(ref, ("light", 2)).w20_mps == 15.0 * 1852.0 / 3600.0
    high = dataclasses.replace(ref, pos=ref.pos + np.array([0.0, 0.0, -300.0]))
    with pytest.raises(InputError, match=r"^--turbulence iec:A:1: the reference's mean height \d+ m is above 305 m"):
        turbulence_setting(high, Turbulence("iec", "A", 1))
    assert turbulence_setting(high, Turbulence("milspec", "light", 1)).w20_mps == pytest.approx(8.0)
