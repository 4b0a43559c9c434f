"""The flight follows the optimised plant: the reference's motor-off mode (column ``motor_on``,
metadata ``motor_off``) stops the 6-DOF motor, and its fold time (metadata ``fold_time_s``)
sets the fold schedule; references written before either existed fly as before."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

from flight_helpers import DATA
from fdm_awe.autopilot.autopilot import Autopilot
from fdm_awe.autopilot.motor import MotorGate
from fdm_awe.autopilot.fold import reference_fold_time
from fdm_awe.autopilot.motor import _flip_short
from fdm_awe.autopilot.config import autopilot_params
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.result import COLUMNS
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.sim.flight import fly
from fdm_awe.pointmass.fold import fold_fraction
from fdm_awe.ocp.result import CycleResult
from fdm_awe.trajectory import COLUMN_UNITS, check_reference_document, read_reference, write_reference
from fdm_awe.sixdof import JSBSimGlider

NOMINAL = DATA / "ref_physical_nominal_8mps.json"
FOLDABLE = DATA / "ref_physical_foldable_8mps_halfline.json"
C = {name: i for i, name in enumerate(COLUMNS)}


def _doc(path) -> dict:
    return json.loads(path.read_text())


def _reference(doc: dict, source: str = "edited reference") -> TrackingReference:
    return TrackingReference.from_ocp(check_reference_document(doc, source))


def _with_motor(doc: dict, on) -> dict:
    """``doc`` with the motor-off mode and column ``motor_on = on(t, phase)`` per row."""
    d = copy.deepcopy(doc)
    d["metadata"]["motor_off"] = True
    c = d["columns"]
    d["columns"]["motor_on"] = [float(on(t, p)) for t, p in zip(c["t"], c["phase"])]
    d["units"]["motor_on"] = "-"
    return d


# ------------------------------------------------------------------ reference file


def test_older_files_read_as_instantaneous_fold_and_running_motor():
    """A file without ``fold_time_s``/``motor_off``/``motor_on`` was optimised with an
    instantaneous fold and a motor that runs throughout."""
    ref = read_reference(FOLDABLE)
    assert ref.metadata["fold_time_s"] == 0.0 and ref.metadata["motor_off"] is False
    tr = TrackingReference.from_ocp(ref)
    assert np.all(tr.motor_on == 1.0) and np.all(tr.motor_segments() == 1.0)
    assert tr.sample(3.0).motor_on == 1.0


@pytest.mark.parametrize("case, edit, match", [
    ("fold_time_negative", lambda d: d["metadata"].update(fold_time_s=-1.0), r"metadata\.fold_time_s: -1 s out of range \(allowed 0 \.\. 60 s\)"),
    ("fold_time_text", lambda d: d["metadata"].update(fold_time_s="2"), r"metadata\.fold_time_s: '2' is not a finite number"),
    ("fold_time_nominal", lambda d: d["metadata"].update(config="nominal", recovery_airframe="unfolded", fold_time_s=2.0)
     or d["columns"].update(fold=[0.0] * len(d["columns"]["t"])), r"metadata\.fold_time_s: 2 s, but metadata\.config is 'nominal'"),
    ("motor_off_text", lambda d: d["metadata"].update(motor_off="yes"), r"metadata\.motor_off: 'yes' not allowed \(allowed true or false"),
    ("motor_on_range", lambda d: d["metadata"].update(motor_off=True) or d["columns"].update(
        motor_on=[1.5] + [1.0] * (len(d["columns"]["t"]) - 1)), r"columns\.motor_on\[0\]: 1\.5 out of range \(allowed 0 \.\. 1\)"),
    ("motor_on_without_mode", lambda d: d["columns"].update(motor_on=[0.0] * len(d["columns"]["t"])),
     r"columns\.motor_on\[0\]: 0, but metadata\.motor_off is not true"),
])
def test_malformed_plant_fields_are_refused_in_one_line(case, edit, match):
    d = _doc(FOLDABLE)
    d["units"]["motor_on"] = "-"  # the unit the package writes, for the cases that add the column
    edit(d)
    with pytest.raises(InputError, match=match) as e:
        check_reference_document(d, "ref.json")
    assert "\n" not in str(e.value) and str(e.value).startswith("ref.json: ")


def test_written_reference_carries_fold_time_motor_mode_and_column(tmp_path):
    ref = read_reference(FOLDABLE)
    md = ref.metadata
    cols = {k: ref[k].copy() for k in COLUMN_UNITS}
    cols["motor_on"] = np.where(ref["T"] > 0.0, 1.0, 0.0)
    res = CycleResult(md["scenario"], md["config"], md["wind_mps"], md["wind_from_deg"], "ok", "Solve_Succeeded", 0.0, 0.0, 0,
                      T1_s=md["T1_s"], T2_s=md["T2_s"], k_wrap=md["k_wrap"], E_generated_J=1.0, E_thrust_J=2.0,
                      E_reel_in_J=0.5, columns=cols, fold_time_s=2.0, motor_off=True)
    back = read_reference(write_reference(res, tmp_path / "ref.json"))
    assert back.metadata["fold_time_s"] == 2.0 and back.metadata["motor_off"] is True
    np.testing.assert_array_equal(back["motor_on"], cols["motor_on"])
    assert json.loads((tmp_path / "ref.json").read_text())["units"]["motor_on"] == "-"


# ------------------------------------------------------------------ the motor's plan


def test_on_fraction_is_held_per_interval_and_the_recovery_starts_with_its_own():
    """Segment values are the interval's (the sample opening it); the segment after the last
    generation sample (t = T1) carries the recovery's first interval, not the generation's last."""
    d = _with_motor(_doc(NOMINAL), lambda t, p: 0.25 if p == 0 else 0.75)
    tr = _reference(d)
    seg = tr.motor_segments()
    gen = tr.t[:-1] < tr.T1 - 1e-9
    assert np.all(seg[gen] == 0.25) and np.all(seg[~gen] == 0.75)
    assert tr.sample(tr.T1 - 1e-3).motor_on == 0.25 and tr.sample(tr.T1 + 1e-3).motor_on == 0.75


def test_plan_bridges_short_pauses_and_drops_lone_short_bursts():
    dur = np.full(40, 0.5)  # 20 s cycle of 0.5 s segments
    on = np.zeros(40, bool)
    on[4:20] = True  # 8 s on
    on[22:24] = True  # 1 s pause (20, 21) then 1 s on: the pause is bridged, the burst joins
    on[30] = True  # a lone 0.5 s burst, 3 s after the last: dropped
    got = _flip_short(_flip_short(on, dur, False, 3.0), dur, True, 1.0)
    want = np.zeros(40, bool)
    want[4:24] = True
    np.testing.assert_array_equal(got, want)
    # around the cycle's end: a pause of 1 s split over the wrap is bridged too
    wrap = np.ones(40, bool)
    wrap[[0, 39]] = False
    wrap[10:30] = False  # a 10 s pause stays
    got = _flip_short(wrap, dur, False, 3.0)
    assert got[0] and got[39] and not got[10:30].any()
    # a motor that always runs or never runs is left as it is
    for flags in (np.ones(40, bool), np.zeros(40, bool)):
        np.testing.assert_array_equal(_flip_short(flags, dur, False, 3.0), flags)
        np.testing.assert_array_equal(_flip_short(flags, dur, True, 3.0), flags)


def test_gate_parameters_are_checked():
    for kw in ({"off_below": 1.5}, {"min_off_s": -1.0}, {"soft_start_s": 100.0}, {"rescue_error_m": 0.0}):
        with pytest.raises(ValueError, match=r"MotorGate\.\w+: .* out of range"):
            MotorGate(**kw)


@pytest.fixture(scope="module")
def autopilot_parts():
    g = JSBSimGlider("glider_foldable")
    return g, load_glider(), autopilot_params()


def test_motor_switches_keep_the_dwell_time(autopilot_parts):
    """A reference whose motor flips every interval, with no bridging: the gate still never
    switches twice within min_dwell_s."""
    glider, airframes, params = autopilot_parts
    d = _with_motor(_doc(NOMINAL), lambda t, p: float(int(t / 0.3) % 2))
    ref = _reference(d)
    gate = MotorGate(min_off_s=0.0, min_on_s=0.0, min_dwell_s=0.5)
    ap = Autopilot(glider, airframes, params, ref, config="nominal", motor=gate)
    switches, dt = [], 1.0 / 120.0
    for k in range(int(20.0 / dt)):
        before = ap.motor_running
        ap.motor.update(ref, k * dt, k * dt, ap.track_error)
        if ap.motor_running != before:
            switches.append(k * dt)
    assert len(switches) >= 10
    assert np.min(np.diff(switches)) >= 0.5 - 1e-9


def test_motor_is_the_reserve_when_the_glider_loses_its_path(autopilot_parts):
    """Planned off, the motor runs while the position error exceeds MotorGate.rescue_error_m
    and stops again once it is below half of that."""
    glider, airframes, params = autopilot_parts
    ref = _reference(_with_motor(_doc(NOMINAL), lambda t, p: 0.0))
    ap = Autopilot(glider, airframes, params, ref, config="nominal", motor=MotorGate(rescue_error_m=10.0, min_dwell_s=0.5))
    runs = []
    for k, err in enumerate([float("nan"), 3.0, 9.0, 11.0, 11.0, 8.0, 6.0, 4.0, 4.0]):
        ap.track_error = err
        runs.append(ap.motor.update(ref, 1.0 + k, 1.0 + k, ap.track_error))
    assert runs == [False, False, False, True, True, True, True, False, False]
    assert ap.motor_switches == 3  # stopped at the start, started for the error, stopped again


# ------------------------------------------------------------------ flights


def _throttle(rep) -> np.ndarray:
    return rep.result.data[1:, C["throttle"]]


def test_motor_cut_where_the_reference_stopped_it():
    """motor_on 0 over the first 6 s of the cycle: throttle exactly 0 there (the stopped
    propeller gives no thrust, the glider draws only P0), then a soft start: the throttle's
    ceiling rises over MotorGate.soft_start_s and thrust comes."""
    d = _with_motor(_doc(NOMINAL), lambda t, p: 0.0 if t < 6.0 else 1.0)
    ref = _reference(d)
    holder, tcs = {}, []

    def setup(ap, sim):
        holder["ap"] = ap

    def on_step(k, s, o):
        tcs.append(holder["ap"].ref_point.t_cycle)

    rep = fly(ref, config="nominal", cycles=1, t_end=12.0, setup=setup, on_step=on_step)
    assert rep.status == "ok", rep.message
    ap = holder["ap"]
    tc = np.array(tcs)
    data = rep.result.data[1:]
    off = tc < 6.0 - 1e-6
    assert off.sum() > 500 and (~off).sum() > 300
    assert np.all(_throttle(rep)[off] == 0.0)
    assert np.all(data[off, C["thrust"]] == 0.0)
    P0 = load_glider().unfolded.propulsion.P0
    assert np.all(data[off, C["p_prop"]] == P0)  # only the idle draw
    assert ap.motor_switches == 2  # stopped at the start, started once at 6 s
    t = data[:, C["t"]]
    t_on = t[np.flatnonzero(~off)[0]]
    ramp = (t >= t_on) & (t < t_on + ap.motor_gate.soft_start_s)
    assert np.all(_throttle(rep)[ramp] <= (t[ramp] - t_on + 2.0 / 120.0) / ap.motor_gate.soft_start_s)
    assert np.max(data[~off, C["thrust"]]) > 1.0


def test_motor_flipping_every_interval_does_not_chatter():
    """Pauses shorter than MotorGate.min_off_s are flown with the motor running: a reference
    flipping its motor every 0.6 s keeps it running (no switch at all)."""
    d = _with_motor(_doc(NOMINAL), lambda t, p: float(int(t / 0.6) % 2))
    holder = {}
    rep = fly(_reference(d), config="nominal", cycles=1, t_end=10.0, setup=lambda ap, sim: holder.update(ap=ap))
    assert rep.status == "ok"
    assert holder["ap"].motor_switches == 0 and holder["ap"].motor_running


def test_reference_with_a_running_motor_flies_bit_identically():
    """An explicit motor_on column of ones (motor-off mode on) and fold time 0 fly exactly as
    the older file without them."""
    a = fly(TrackingReference.from_ocp_file(str(NOMINAL)), config="nominal", cycles=1, t_end=8.0)
    d = _with_motor(_doc(NOMINAL), lambda t, p: 1.0)
    d["metadata"]["fold_time_s"] = 0.0
    b = fly(_reference(d), config="nominal", cycles=1, t_end=8.0)
    np.testing.assert_array_equal(a.result.data, b.result.data)


# ------------------------------------------------------------------ fold schedule


def test_fold_time_faster_than_the_actuator_is_refused(autopilot_parts):
    glider, airframes, params = autopilot_parts
    d = _doc(FOLDABLE)
    d["metadata"]["fold_time_s"] = 0.5 * glider.fold_time_s
    with pytest.raises(InputError, match=r"reference metadata\.fold_time_s: 1 s, faster than the aircraft's fold actuator "
                                         r"\(fcs/wing-fold-time-s 2 s\); allowed 0 .* or >= 2 s") as e:
        Autopilot(glider, airframes, params, _reference(d), config="foldable")
    assert "\n" not in str(e.value)
    # a nominal flight of it never folds: nothing to refuse
    Autopilot(glider, airframes, params, _reference(d), config="nominal")
    assert reference_fold_time({}, 2.0) == 0.0 and reference_fold_time({"fold_time_s": 3.0}, 2.0) == 3.0


@pytest.mark.parametrize("fold_time", [2.0, 3.0])
def test_fold_command_is_the_optimisers_fold_law(autopilot_parts, fold_time):
    """With the reference's fold time the command is fold_fraction (fold from the start of
    recovery, unfold over its last fold time): at the aircraft's own fold time a ramp at the
    actuator's full rate, slower for a slower fold."""
    glider, airframes, params = autopilot_parts
    d = _doc(FOLDABLE)
    d["metadata"]["fold_time_s"] = fold_time
    ref = _reference(d)
    ap = Autopilot(glider, airframes, params, ref, config="foldable")
    T1, P = ref.T1, ref.period
    assert ap.fold_command(T1 - 0.1, T1, P) == 0.0
    assert ap.fold_command(T1 + 0.5 * fold_time, T1, P) == pytest.approx(0.5)
    assert ap.fold_command(T1 + fold_time, T1, P) == 1.0
    assert ap.fold_command(P - 0.5 * fold_time, T1, P) == pytest.approx(0.5)
    assert ap.fold_command(P - 1e-6, T1, P) == pytest.approx(0.0, abs=1e-5)
    for tc in np.linspace(T1, P, 57, endpoint=False):
        assert ap.fold_command(tc, T1, P) == fold_fraction(tc - T1, P - T1, fold_time)
    assert Autopilot(glider, airframes, params, ref, config="nominal").fold_command(T1 + 3.0, T1, P) == 0.0


def test_instantaneous_fold_keeps_the_lead_parameters(autopilot_parts):
    """A reference optimised with an instantaneous fold (fold time 0 or absent) is flown as
    before: folded from FOLD_LEAD before recovery to UNFOLD_LEAD before its end."""
    glider, airframes, params = autopilot_parts
    ref = TrackingReference.from_ocp_file(str(FOLDABLE))
    ap = Autopilot(glider, airframes, params, ref, config="foldable")
    T1, P = ref.T1, ref.period
    lead, unlead = params["FOLD_LEAD"], params["UNFOLD_LEAD"]
    for tc in np.linspace(0.0, P, 301, endpoint=False):
        want = 1.0 if (T1 - lead) <= tc < (P - unlead) else 0.0
        assert ap.fold_command(tc, T1, P) == want


def test_flown_fold_follows_the_references_fold_time():
    """One foldable cycle with fold time 3 s (slower than the 2 s actuator, so the schedule of
    an instantaneous fold would be 1/3 off): the flown fold state follows the optimiser's fold
    law at the autopilot's cycle time (the glider's own path rate shifts it a little), folded
    through the middle of the recovery, open before generation."""
    d = _doc(FOLDABLE)
    d["metadata"]["fold_time_s"] = 3.0
    ref = _reference(d)
    holder, tcs = {}, []

    def setup(ap, sim):
        holder["ap"] = ap

    def on_step(k, s, o):
        tcs.append(holder["ap"].ref_point.t_cycle if holder["ap"].ref_point is not None else math.nan)

    rep = fly(ref, config="foldable", cycles=1, tether_drag_scale=ref.meta["tether_drag_scale"], setup=setup, on_step=on_step)
    assert rep.status == "ok", rep.message
    tc = np.array(tcs)
    fold = rep.result.data[1:, C["fold"]]
    law = np.array([fold_fraction(x - ref.T1, ref.T2, 3.0) if x >= ref.T1 else 0.0 for x in tc])
    assert np.max(np.abs(fold - law)) < 0.1
    mid = (tc > ref.T1 + 3.5) & (tc < ref.period - 3.5)
    assert mid.sum() > 300 and np.all(fold[mid] == 1.0)
    assert np.all(fold[tc < ref.T1] == 0.0)


def test_a_soft_stop_spares_the_folded_glider_the_roll_kick():
    """The foldable glider stops its motor folded: the stored physical 8 m/s cycle flown with
    half the line drag (FOLDABLE, which runs its motor all cycle) with the motor planned off
    from 3.5 s into the recovery (folded since about 2 s in; the stop about 54 s in). Cut at
    once, the drive brakes the propeller through its coil and the reaction rolls the folded
    glider at 2.9 rad/s, its bank swinging by 0.36 rad with the ailerons at their stop for half
    a second; the soft stop (throttle to 0 over soft_stop_s) keeps the roll rate (0.22 rad/s)
    and the bank's excursion (0.11 rad) below half of that, the ailerons off their stop. (The
    sized-line cycle re-made for the 48 V supply stops its motor 1 s into its recovery, half
    folded, and is folded for only 2 s.)"""
    ref = TrackingReference.from_ocp_file(FOLDABLE)
    ref.motor_on = np.where(ref.t >= ref.T1 + 3.5, 0.0, ref.motor_on)
    out = {}
    t_stop = None
    for soft in (0.0, 1.0):
        def setup(ap, sim, soft=soft):
            ap.motor_gate = MotorGate(soft_stop_s=soft)

        rep = fly(ref, config="foldable", cycles=1, setup=setup, t_end=58.0, tether_drag_scale=ref.meta["tether_drag_scale"])
        assert rep.status == "ok", rep.message
        d = rep.result.data
        col = {n: d[:, COLUMNS.index(n)] for n in ("t", "fold", "p", "phi", "aileron", "throttle")}
        if t_stop is None:  # the cut: the first row the motor is off in recovery
            t_stop = float(col["t"][np.flatnonzero((col["t"] > ref.T1) & (col["throttle"] == 0.0))[0]])
        k = int(np.argmin(np.abs(col["t"] - t_stop)))
        w = (col["t"] > t_stop - 0.2) & (col["t"] < t_stop + 2.0)
        assert np.all(col["fold"][w] > 0.99)  # folded throughout
        out[soft] = (np.max(np.abs(col["p"][w])), np.max(np.abs(col["phi"][w] - col["phi"][k])),
                     np.sum(np.abs(col["aileron"][w]) >= 0.999))
    (p_soft, phi_soft, sat_soft), (p_cut, phi_cut, sat_cut) = out[1.0], out[0.0]
    assert p_cut > 2.0 and phi_cut > 0.25 and sat_cut > 0  # the kick is there without the soft stop
    assert p_soft < 0.5 * p_cut and phi_soft < 0.5 * phi_cut and sat_soft < 0.5 * sat_cut
