"""Energy yield of a power curve: against an independent quadrature (scipy's adaptive ``quad``
of a piecewise-linear interpolant times the Weibull density), the zero curve, a curve outside
the distribution's mass, the clip policy, the height ratio, cut-in and rated winds, and the
command line's checks of the yield options."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from fdm_awe.errors import InputError
from fdm_awe.sweep.energy_yield import (HOURS_PER_YEAR, Distribution, cut_in_wind, energy_yield, parse_distributions,
                                        rated_wind, rayleigh)

# the physical scan of docs/sweep.md (nominal, W): negative below 8 m/s, rising to 14 m/s
WINDS = [4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0]
POWER = [-30.9, -19.7, -10.5, -1.2, 5.0, 21.9, 29.9, 38.4, 46.6, 54.5, 60.2]


def _hand(winds, power, k, c, clip):
    """Mean power [W] by scipy.integrate.quad of np.interp (zero outside) x the Weibull pdf."""
    def p(v):
        if v < winds[0] or v > winds[-1]:
            return 0.0
        x = float(np.interp(v, winds, power))
        return max(x, 0.0) if clip else x

    pdf = lambda v: k / c * (v / c) ** (k - 1) * math.exp(-((v / c) ** k))  # noqa: E731
    # split at every curve point so quad sees smooth pieces
    return sum(quad(lambda v: p(v) * pdf(v), a, b, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
               for a, b in zip(winds[:-1], winds[1:]))


@pytest.mark.parametrize("clip", [True, False])
def test_rayleigh_7_aep_matches_a_hand_integration(clip):
    d = rayleigh(7.0)
    assert d.k == 2.0 and d.mean == pytest.approx(7.0, rel=1e-12)
    y = energy_yield(WINDS, POWER, d, clip=clip)
    hand = _hand(WINDS, POWER, 2.0, 2 * 7.0 / math.sqrt(math.pi), clip)
    assert y.mean_power_W == pytest.approx(hand, rel=5e-3)
    assert y.aep_kWh == pytest.approx(hand * HOURS_PER_YEAR / 1000.0, rel=5e-3)
    # the clip only removes negative contributions
    assert (y.mean_power_W > 0) and (clip or y.mean_power_W < energy_yield(WINDS, POWER, d).mean_power_W)
    # the capacity factor against the curve's largest power
    assert y.capacity_factor == pytest.approx(y.mean_power_W / 60.2, rel=1e-12)
    # the masses: below 4 m/s and above 14 m/s, by the closed-form Rayleigh cdf
    F = lambda v: 1 - math.exp(-math.pi / 4 * (v / 7.0) ** 2)  # noqa: E731
    assert y.mass_below == pytest.approx(F(4.0), rel=1e-12)
    assert y.mass_above == pytest.approx(1 - F(14.0), rel=1e-12)
    # not operated (P <= 0) from 4 m/s to the zero crossing between 7 and 8 m/s
    vz = 7.0 + 1.2 / 6.2
    assert y.mass_not_operated == pytest.approx(F(vz) - F(4.0), rel=1e-9)
    assert not y.outside_mass


def test_zero_curve_gives_zero_yield():
    for clip in (True, False):
        y = energy_yield(WINDS, [0.0] * len(WINDS), rayleigh(7.0), clip=clip)
        assert y.mean_power_W == 0.0 and y.aep_kWh == 0.0 and y.capacity_factor is None


def test_curve_outside_the_mass_says_so():
    # a site with annual mean 1 m/s: a curve from 12 to 14 m/s holds almost none of its wind
    y = energy_yield([12.0, 13.0, 14.0], [10.0, 20.0, 30.0], rayleigh(1.0))
    assert y.outside_mass and y.mass_below > 0.99 and y.mean_power_W < 1e-20
    # a curve inside the mass is not flagged
    assert not energy_yield([2.0, 3.0], [10.0, 20.0], rayleigh(2.0)).outside_mass


def test_height_ratio_scales_the_site_wind():
    # the curve seen with twice the site's speeds equals the curve at half the winds with the site unscaled
    d = Distribution(2.2, 6.0, "w")
    a = energy_yield(WINDS, POWER, d, height_ratio=2.0)
    b = energy_yield([v / 2 for v in WINDS], POWER, d)
    assert a.mean_power_W == pytest.approx(b.mean_power_W, rel=1e-9)
    assert a.mass_below == pytest.approx(b.mass_below, rel=1e-12)


def test_cut_in_and_rated_wind():
    assert cut_in_wind(WINDS, POWER) == pytest.approx(7.0 + 1.2 / 6.2, rel=1e-12)
    assert cut_in_wind([5.0, 6.0], [1.0, 2.0]) == 5.0
    assert cut_in_wind([5.0, 6.0], [1.0, -2.0]) is None
    # rated: the curve's largest power at its last wind: at or above 14 m/s
    assert rated_wind(WINDS, POWER) == (14.0, True)
    # a stated rated power of 50 W is reached between 12 and 13 m/s
    v, top = rated_wind(WINDS, POWER, 50.0)
    assert v == pytest.approx(12.0 + 3.4 / 7.9, rel=1e-12) and not top
    assert rated_wind(WINDS, POWER, 100.0) == (None, True)


@pytest.mark.parametrize("text, match", [
    ("rayleigh:", "no annual mean"), ("rayleigh:7,,8", "no annual mean"), ("rayleigh:0.1", "annual mean 0.1 out of range"),
    ("rayleigh:x", "not a number"), ("weibull:2", "weibull:K:C"), ("weibull:20:8", "shape K 20 out of range"),
    ("weibull:2:0", "scale C 0 out of range"), ("gauss:7", "unknown distribution")])
def test_bad_distributions_name_the_field(text, match):
    with pytest.raises(InputError, match=match):
        parse_distributions([text])


def test_parse_distributions():
    ds = parse_distributions(["rayleigh:4,10", "weibull:2.5:9"])
    assert [d.label for d in ds] == ["Rayleigh 4 m/s", "Rayleigh 10 m/s", "Weibull k=2.5 c=9 m/s"]
    assert ds[1].mean == pytest.approx(10.0, rel=1e-12)


@pytest.mark.parametrize("argv, match", [
    (["--yield", "rayleigh:50"], "--yield 'rayleigh:50': annual mean 50 out of range"),
    (["--yield-height", "0"], "--yield-height"), (["--rated-power", "-1"], "--rated-power"),
    (["--fly", "--fly-cycles", "0"], "--fly-cycles"), (["--fly", "--fly-seeds", "101"], "--fly-seeds"),
    (["--fly", "--fly-air", "gusty"], "--fly-air"), (["--fly", "--fly-air", "light:3"], "without a seed"),
    (["--fly", "--fly-tether", "lumped:0"], "--fly-tether"),
    (["--yield", "rayleigh:7", "--yield-profile", "log:-1"], "--yield-profile")])
def test_bad_fly_and_yield_options_exit_2_before_work(tmp_path, capsys, argv, match):
    from fdm_awe.cli import main

    rc = main(["sweep", "--wind", "8", "--config", "nominal", "--out", str(tmp_path / "o"), *argv])
    err = capsys.readouterr().err
    assert rc == 2 and match in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "points").exists()


# --------------------------------------------------------------------------- flown statistics
def _flight(status, powers, complete=None, T=30.0):
    complete = complete or [True] * len(powers)
    return {"status": status, "peak_tension_N": 40.0, "peak_current_A": 9.0, "rated_tension_N": 50.0,
            "rated_current_A": 12.1,
            "cycle_list": [{"complete": c, "P_W": p, "E_net_J": p * T, "T_s": T, "track_rms_m": 2.0}
                           for p, c in zip(powers, complete)]}


def test_flown_point_statistics_by_hand():
    from fdm_awe.sweep.flown import flown_point

    # seed 1: 10, 12, 14 W; seed 2: 4 W then parked (2 cycles incomplete); seed 3: 6, 8, 10 W
    fl = [_flight("ok", [10.0, 12.0, 14.0]), _flight("parked", [4.0, -50.0, 0.0], [True, False, False]),
          _flight("ok", [6.0, 8.0, 10.0])]
    s = flown_point(fl, 3)
    P = [10.0, 12.0, 14.0, 4.0, 6.0, 8.0, 10.0]  # the complete cycles
    assert s["cycles_complete"] == 7 and s["cycles_asked"] == 9 and s["completion"] == pytest.approx(7 / 9)
    assert s["park_fraction"] == pytest.approx(1 / 3)
    assert s["P_flown_mean_W"] == pytest.approx(sum(P) / 7, rel=1e-12)
    assert s["P_flown_std_W"] == pytest.approx(float(np.std(P, ddof=1)), rel=1e-12)
    assert (s["P_flown_min_W"], s["P_flown_max_W"]) == (4.0, 14.0)
    means = [12.0, 4.0, 8.0]  # each flight's complete cycles
    assert s["P_flight_mean_W"] == pytest.approx(8.0, rel=1e-12)
    assert s["P_flight_se_W"] == pytest.approx(float(np.std(means, ddof=1)) / math.sqrt(3), rel=1e-12)
    # one flight: no standard error, no std from a single cycle
    one = flown_point([_flight("ok", [5.0])], 1)
    assert one["P_flight_se_W"] is None and one["P_flown_std_W"] is None and one["P_flown_mean_W"] == 5.0
    # no complete cycle: no power, completion 0
    none = flown_point([_flight("ground_contact", [3.0], [False])], 1)
    assert none["P_flown_mean_W"] is None and none["completion"] == 0.0
