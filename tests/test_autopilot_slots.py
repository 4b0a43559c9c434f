"""The AUTO step's arrays and their declared layouts (:mod:`fdm_awe.slots`): the arrays the
autopilot hands to the step (compiled, where nothing checks an offset) are the sizes of their
layouts, the layouts that continue or nest others agree with them, and a constant array of the
wrong size is refused before any step runs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flight_helpers import DATA
from fdm_awe import slots
from fdm_awe.autopilot.auto_step import (GSO, MEM, OUT, PAR, REF, REF_COLUMNS, REF_WHERE, SEG, WLIM_END,
                                         glider_input, paced)
from fdm_awe.autopilot.autopilot import Autopilot
from fdm_awe.autopilot.config import autopilot_params
from fdm_awe.autopilot.guidance import GIN, GK, INTEGRAL, POLAR
from fdm_awe.autopilot.guidance_loop import GuidanceGains
from fdm_awe.autopilot.motor import GATE, MOTOR_MEM
from fdm_awe.autopilot.thrust import THR
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.autopilot.winch import LIMIT_PARAMS, WL, limit_vector
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.sixdof import JSBSimGlider
from fdm_awe.trajectory import check_reference_document


@pytest.fixture(scope="module")
def ap() -> Autopilot:
    doc = json.loads((DATA / "ref_physical_nominal_8mps.json").read_text())
    ref = TrackingReference.from_ocp(check_reference_document(doc, "reference"))
    return Autopilot(JSBSimGlider("glider_foldable"), load_glider(), autopilot_params(), ref, config="nominal")


def test_the_blocks_arrays_have_their_layouts(ap):
    cycle, consts, state, results, _ = ap.auto.kernel_arrays(ap)
    ref_t, table, segs = cycle
    assert table.shape == (ref_t.shape[0], slots.size(REF)) and segs.shape[0] == slots.size(SEG)
    for layout, a in zip((GK, POLAR, POLAR, GATE, PAR), consts):
        slots.check(layout, a, type(layout).__name__)
    for layout, a in zip((MEM, INTEGRAL, THR, MOTOR_MEM), state):
        slots.check(layout, a, type(layout).__name__)
    for layout, a in zip((GIN, REF, OUT), results):
        slots.check(layout, a, type(layout).__name__)
    par = consts[4]
    # the winch's limits sit whole inside par, in the order of their parameters, then the drive's reel-in limit
    assert WLIM_END - PAR.wlim == slots.width(PAR, "wlim") == slots.size(WL) == len(LIMIT_PARAMS) + 1
    assert par[PAR.wlim:WLIM_END].tolist() == limit_vector(ap.params, ap.reel_in_max).tolist()
    assert par[PAR.wlim + WL.tlo] == ap.params["WINCH_TLO"] and par[WLIM_END - 1] == ap.reel_in_max
    # the gains vector is GuidanceGains' fields in order
    assert slots.size(GK) == len(GuidanceGains.__dataclass_fields__)
    # the reference's columns where the sampler puts them (one slot, or a slice of the wider ones)
    assert REF_COLUMNS == REF._fields and [REF_WHERE[i] for i in (0, 3)] == [slice(0, 3), 9]
    assert slots.size(GSO) == GSO.force + 3


def test_a_constant_array_of_the_wrong_size_is_refused(ap, monkeypatch):
    """A gains vector one slot short would have the compiled step read past its end: refused,
    naming the array, before any step."""
    monkeypatch.setattr(GuidanceGains, "vector", lambda self: np.zeros(slots.size(GK) - 1))
    ap.auto.invalidate()
    with pytest.raises(ValueError, match=f"AUTO step.s gk: expected {slots.size(GK)} float64 slots of GuidanceGains"):
        ap.auto.arrays(ap)
    monkeypatch.undo()
    ap.auto.invalidate()
    assert ap.auto.arrays(ap)[3].shape == (slots.size(GK),)


def test_the_guidance_input_is_the_glider_and_the_paced_reference():
    """:func:`glider_input` and :func:`paced` fill the guidance's input (GIN) by name: the
    aircraft's constants from par, the glider's SI state, the reference's point at the pace."""
    par, gin, rrow = slots.new(PAR), slots.new(GIN, np.nan), np.arange(slots.size(REF), dtype=float) + 1.0
    par[PAR.mass], par[PAR.rho], par[PAR.g], par[PAR.s_u], par[PAR.s_f] = 2.5, 1.2, 9.8, 0.5, 0.3
    paced(rrow, 0.5, 0, gin)  # generation at half the pace: velocity x 0.5, acceleration x 0.25
    assert gin[GIN.ref_pos:GIN.ref_pos + 3].tolist() == [1.0, 2.0, 3.0]
    assert gin[GIN.ref_vel:GIN.ref_vel + 3].tolist() == [2.0, 2.5, 3.0]
    assert gin[GIN.ref_acc:GIN.ref_acc + 3].tolist() == [1.75, 2.0, 2.25]
    assert gin[GIN.tension] == rrow[REF.tension]
    paced(rrow, 0.5, 1, gin)  # recovery: the row's own
    assert gin[GIN.ref_vel:GIN.ref_vel + 3].tolist() == [4.0, 5.0, 6.0]
    g = JSBSimGlider("glider_foldable")
    s = g.reset((30.0, 5.0, -60.0), 14.0, gamma=0.1, psi=0.4)
    got = glider_input(s.raw, s.scale, s.offset, par, gin)
    assert [gin[GIN.m], gin[GIN.rho], gin[GIN.g], gin[GIN.s_u], gin[GIN.s_f]] == [2.5, 1.2, 9.8, 0.5, 0.3]
    assert list(got) == gin[GIN.pos:GIN.wind + 3].tolist()
    assert np.allclose(got[:3], s.pos_ned, rtol=0.0, atol=1e-9) and np.allclose(got[3:6], s.vel_ned, atol=1e-9)
