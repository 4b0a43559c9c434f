"""A reference optimised with the calibrated line model (``--line-model calibrated``, fly's
flyable bounds and margins, the rate bounds of bank and angle of attack), flown on the lumped
line it was calibrated against.

``tests/data/ref_physical_nominal_10mps_calibrated.json``: the nominal glider's physical cycle
at 10 m/s (sized line, 48 V drive, tension <= 40 N, reel-in <= 10.1 m/s, C_L <= 0.85 C_Lmax,
bank rate <= 0.3 rad/s, angle-of-attack rate <= 0.1 rad/s), made by ``python
scripts/line_calibration.py --winds 10 --configs nominal``. Without the rate bounds the
calibrated model's optimum pushed over to negative lift and back (alpha +0.17 to -0.21 rad
within one or two intervals) four times a generation phase, the tension between the
rectifier's 3.8 N and the 40 N bound; the glider did not follow (generation tracked at 6.1 m
RMS on ``lumped:30``, 6.0 m on the straight line). With them the generation phase tracks at
2.9 m RMS on ``lumped:30`` (one cycle). The recovery's zero-lift dive tracked at 9.6 m while
the winch reeled the sagging line in at the diving glider's approach (up to 9.3 m/s against
the reference's 5.3) and at the path rate of a glider the line had pulled ahead, snatching the
line taut again and again; with WINCH_SLACK_T (a line pulling more than 0.5 N sags, it is not
slack) the dive tracks at 7.3 m and the cycle at 4.6 m (the issue asks for 5 m). The flown
cycle matches the optimum's generated energy (773 against 774 J) and thrust (68 against 69 J);
its reel-in costs 396 J against the 502 J the calibrated model books (the model's recovery
tension is 4.0 N, the sagging line pulls about 2 N at the winch), so it nets +309 J against
the optimum's +203 J: the gap is the model's recovery booking, checked as such. (Pacing the
reel-in at no more than flight time, WINCH_PACE_MAX 1, netted +185 J, but through 201 J of
thrust making up for the cheaper reel-in, and it broke a class A flight of the foldable 8 m/s
cycle on the straight line: 94 N, time cap; it stays off.) Energies are compared within 10 %
of the cycle's generated energy (a net near zero allows no relative tolerance on itself).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fdm_awe import ROOT
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly

REF = ROOT / "tests" / "data" / "ref_physical_nominal_10mps_calibrated.json"


@pytest.fixture(scope="module")
def flown():
    ref = TrackingReference.from_ocp_file(REF)
    return ref, fly(ref, config="nominal", cycles=1, tether="lumped:30")


def test_the_reference_records_its_line_model_and_margins(flown):
    ref, _ = flown
    assert ref.meta["line_model"] == "calibrated"
    m = ref.meta["margins"]
    assert m["tension_bound_N"] == pytest.approx(40.0) and m["cl_max_share"] == 0.85
    assert 10.0 < m["reel_in_speed_max_m_s"] < 10.2  # the 48 V drive's 11.1 m/s over 1 + 0.1
    b = ref.meta["bounds"]
    assert b["bank_rate_max"] == pytest.approx(0.3) and b["alpha_rate_max"] == pytest.approx(0.1)


def test_the_reference_does_not_push_over_in_generation():
    cols = json.loads(REF.read_text())["columns"]
    alpha, phase = (np.asarray(cols[n], dtype=float) for n in ("alpha", "phase"))
    # no negative lift while the line is pulled (the unbounded optimum: -0.21 rad)
    assert float(np.min(alpha[phase == 0])) >= 0.0
    # controls piecewise constant on intervals of at most about 0.5 s: no step larger than the
    # rate bound allows over one (the unbounded optimum stepped 0.45 rad)
    assert float(np.max(np.abs(np.diff(alpha)))) <= 0.1 * 0.6


def test_the_generation_phase_is_tracked_on_the_lumped_line(flown):
    _, rep = flown
    gen = (np.asarray(rep.result.phase) == "generation") & np.isfinite(rep.track_error)
    rms = float(np.sqrt(np.mean(rep.track_error[gen] ** 2)))
    assert rms <= 4.0, rms  # measured 2.9 m (the reference without rate bounds: 6.1 m)


def test_one_cycle_on_the_lumped_line_reproduces_the_optimum(flown):
    ref, rep = flown
    assert rep.status == "ok" and [c.complete for c in rep.cycles] == [True], rep.message
    c = rep.cycles[0]
    opt = ref.meta["energies"]
    tol = 0.10 * opt["E_generated_J"]
    assert c.E_generated_J == pytest.approx(opt["E_generated_J"], rel=0.15)
    assert abs(c.E_thrust_J - opt["E_thrust_J"]) <= tol, (c.E_thrust_J, opt)
    # the net energy is the optimum's but for the reel-in the model books dearer than it flies
    booked = opt["E_reel_in_J"] - c.E_reel_in_J
    assert abs(c.E_net_J - opt["E_net_J"] - booked) <= tol, (c.E_net_J, booked, opt)
    # the calibrated model books the recovery at 4.0 N; the line, no longer snatched taut in the
    # dive, pulls 2.1 N (work-weighted at the winch): the flown reel-in is cheaper, never dearer
    assert 0.6 * opt["E_reel_in_J"] <= c.E_reel_in_J <= 1.15 * opt["E_reel_in_J"], (c.E_reel_in_J, opt)
    k = np.isfinite(rep.track_error)
    rms = float(np.sqrt(np.nanmean(rep.track_error[k] ** 2)))
    assert rms <= 5.0, rms  # measured 4.6 m (before the recovery's winch law: 5.7 m)
    assert float(np.nanmax(rep.result.tension[k])) <= 1.2 * 50.0  # the 40 N bound's margin holds the peak


def test_the_recovery_dive_is_tracked_without_snatching_the_sagging_line(flown):
    """The recovery's winch keeps near the reference's reel-in: it does not reel the sagging
    line in at the diving glider's approach, so the dive is flown nearer its path (before:
    9.3 m/s peak reel-in against the reference's 5.3 m/s, 15.3 N peaks, 9.6 m RMS)."""
    ref, rep = flown
    rec = (np.asarray(rep.result.phase) == "recovery") & np.isfinite(rep.track_error)
    cols = json.loads(REF.read_text())["columns"]
    ref_in = -float(np.min(np.asarray(cols["reel_speed"], dtype=float)))
    flown_in = -float(np.min(rep.result.reel_speed[rec]))
    assert flown_in <= 1.5 * ref_in, (flown_in, ref_in)  # measured 7.5 against 5.3 m/s
    assert float(np.max(rep.result.tension[rec])) <= 10.0  # measured 6.9 N (the calibrated model: 4 N)
    rms = float(np.sqrt(np.mean(rep.track_error[rec] ** 2)))
    assert rms <= 8.0, rms  # measured 7.3 m
