"""Tether lines: the line sized for its load from its material (against hand computations),
Table 1's line exactly as before, the summary `fdm-awe info` shows, the line a flight uses, and
one-line errors on bad names and damaged definitions."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from fdm_awe import ROOT
from fdm_awe.errors import DefinitionError, InputError
from fdm_awe.groundstation import load_ground_station
from fdm_awe.constants import G0, RHO0
from fdm_awe.ocp.problem import working_lengths
from fdm_awe.groundstation.line import (DEFAULT_LINE, LINES, N_PER_TEX, TEX, LineMaterial, LineSizing, check_line, line_summary,
                                        size_line)

XML = ROOT / "tether" / "ground_station.xml"

#: the sized line's material and sizing as the definition file gives them, in SI
UHMWPE_BRAID = LineMaterial(fibre_density=970.0, rated_tenacity=1.83e6, fill_factor=0.8, fibre_modulus=110e6,
                            stiffness_factor=0.5, cd_perpendicular=1.1)
SIZING = LineSizing(rated_tension=50.0, safety_factor=4.5)


def test_size_line_against_hand_computation():
    s = size_line(UHMWPE_BRAID, SIZING)
    # breaking load: 4.5 x 50 N = 225 N
    assert s.breaking_load == pytest.approx(225.0, rel=1e-14)
    # mass per length: 225 N / (1.83 N/tex = 1.83e6 N m/kg) = 122.951 tex = 1.229508e-4 kg/m
    assert s.mass_per_length == pytest.approx(1.229508e-4, rel=1e-6)
    # fibre section 1.229508e-4 / 970 = 1.267534e-7 m2, envelope / 0.8 = 1.584418e-7 m2,
    # d = sqrt(4 x 1.584418e-7 / pi) = 4.491485e-4 m
    assert s.diameter == pytest.approx(4.491485e-4, rel=1e-6)
    # EA = 0.5 x 110e6 N m/kg x 1.229508e-4 kg/m = 6762.295 N
    assert s.axial_stiffness == pytest.approx(6762.295, rel=1e-6)
    assert s.cd_perpendicular == 1.1


def test_size_line_scales_as_the_physics_says():
    base = size_line(UHMWPE_BRAID, SIZING)
    # twice the load: twice the fibre (mass, stiffness), sqrt(2) the diameter
    twice = size_line(UHMWPE_BRAID, dataclasses.replace(SIZING, rated_tension=100.0))
    assert twice.mass_per_length == pytest.approx(2.0 * base.mass_per_length, rel=1e-14)
    assert twice.axial_stiffness == pytest.approx(2.0 * base.axial_stiffness, rel=1e-14)
    assert twice.diameter == pytest.approx(math.sqrt(2.0) * base.diameter, rel=1e-14)
    # a solid rod (fill factor 1) of the same fibre is thinner by sqrt(0.8)
    rod = size_line(dataclasses.replace(UHMWPE_BRAID, fill_factor=1.0), SIZING)
    assert rod.diameter == pytest.approx(math.sqrt(0.8) * base.diameter, rel=1e-14)
    # Table 1's 0.4 g/m is the mass of a SOLID 0.72 mm UHMWPE rod: sqrt(4 x 4e-4 / (970 pi)) = 0.7246 mm
    tenacity = 700.0 / 4e-4  # the breaking load that gives 0.4 g/m
    paperlike = size_line(dataclasses.replace(UHMWPE_BRAID, fill_factor=1.0, rated_tenacity=tenacity),
                          LineSizing(rated_tension=700.0, safety_factor=1.0))
    assert paperlike.mass_per_length == pytest.approx(4e-4, rel=1e-14)
    assert paperlike.diameter == pytest.approx(0.72e-3, rel=0.01)


def test_the_sized_line_is_the_default_and_is_sized_for_table_3s_tension():
    assert LINES == ("sized", "paper") and DEFAULT_LINE == "sized"
    t = load_ground_station().tether
    assert t.name == "sized" and t == load_ground_station(line="sized").tether
    assert t.material == UHMWPE_BRAID and t.sizing == SIZING  # the file's numbers, in SI
    s = size_line(t.material, t.sizing)
    assert (t.mass_per_length, t.diameter, t.axial_stiffness, t.breaking_load, t.cd_perpendicular) == \
        (s.mass_per_length, s.diameter, s.axial_stiffness, s.breaking_load, s.cd_perpendicular)
    # Table 3's tension bound (50 N), a breaking load 4-5 times it
    assert t.rated_tension == 50.0
    assert 4.0 <= t.breaking_load / t.rated_tension <= 5.0
    assert t.safety_factor == pytest.approx(4.5, rel=1e-12)
    # what the issue asks of a commercially common braid: 0.35-0.45 mm, 200-250 N
    assert 0.35e-3 <= t.diameter <= 0.45e-3 and 200.0 <= t.breaking_load <= 250.0
    # the real mass per length of a PE 4 braid (222 N rated, 12.1 g/100 m), within 5 %
    assert t.mass_per_length == pytest.approx(0.121e-3, rel=0.05)
    # the braid breaks at a few per cent strain (UHMWPE braids: about 3-5 %)
    assert 0.02 < t.breaking_load / t.axial_stiffness < 0.05


def test_the_paper_line_is_table_1s_line_exactly():
    p = load_ground_station(line="paper")
    t = p.tether
    assert t.name == "paper" and t.material is None and t.sizing is None
    assert (t.mass_per_length, t.diameter, t.cd_perpendicular, t.axial_stiffness, t.breaking_load) == \
        (0.0004, 0.00072, 1.1, 22600.0, 700.0)
    assert t.rated_tension == 50.0 and t.safety_factor == 14.0
    # common to both lines: shares, end stops, air and gravity; the rest of the station alike
    s = load_ground_station(line="sized")
    for f in ("drag_share", "weight_share", "min_length", "max_length", "air_density", "gravity"):
        assert getattr(t, f) == getattr(s.tether, f), f
    assert (t.drag_share, t.weight_share, t.min_length, t.max_length, t.air_density, t.gravity) == \
        (0.25, 0.5, 2.0, 600.0, RHO0, G0)
    assert dataclasses.replace(p, tether=s.tether) == s


def test_summary_gives_the_equivalent_line_drag():
    paper = load_ground_station(line="paper")
    # docs: C_D,t = 1.1 x 0.00072 m x 150 m / (4 x 0.15125 m2) = 0.19636 ~ 0.20
    s150 = line_summary(paper, lengths=(150.0,))
    assert s150.wing_area == 0.15125  # the unfolded glider's aircraft definition
    assert s150.cd_t[0] == pytest.approx(1.1 * 0.00072 * 150.0 / (4.0 * 0.15125), rel=1e-12)
    assert round(s150.cd_t[0], 2) == 0.20
    assert s150.drag_area_m2[0] == pytest.approx(1.1 * 0.00072 * 150.0 / 4.0, rel=1e-12)
    # default lengths: the optimiser's start and end of generation
    assert working_lengths() == (200.0, 250.0)
    sp, ss = line_summary(paper, working_lengths()), line_summary(load_ground_station(), working_lengths())
    assert sp.lengths_m == ss.lengths_m == (200.0, 250.0)
    # paper line: 1.1 x 0.72 mm x (200, 250) m / 0.605 m2 = 0.2618, 0.3273
    assert sp.cd_t == pytest.approx((0.261818, 0.327273), rel=1e-5)
    # the sized line drags in proportion to its diameter: 0.449 / 0.72 of the paper line's
    for a, b in zip(ss.cd_t, sp.cd_t):
        assert a == pytest.approx(b * ss.diameter / 0.00072, rel=1e-12) and a < 0.65 * b
    assert (ss.name, ss.rated_tension, ss.breaking_load) == ("sized", 50.0, 225.0)
    assert ss.safety_factor == pytest.approx(4.5)
    d = ss.as_dict()
    assert d["name"] == "sized" and d["cd_t"] == list(ss.cd_t) and d["diameter_m"] == ss.diameter
    text = ss.text()
    assert "\n" not in text and "0.449 mm" in text and "225 N" in text and "C_D,t 0.163" in text and "C_D,t 0.204" in text
    # a summary of the tether parameters alone, with an explicit wing area
    assert line_summary(paper.tether, lengths=(150.0,), wing_area=0.15125).cd_t == s150.cd_t
    for bad in ((0.0,), (float("nan"),)):
        with pytest.raises(InputError, match="line length"):
            line_summary(paper, lengths=bad)
    with pytest.raises(InputError, match="wing area"):
        line_summary(paper, (150.0,), wing_area=-1.0)


@pytest.mark.parametrize("bad", ["foo", "", "Paper", None, 3, ["sized"]])
def test_unknown_line_name_is_a_one_line_input_error(bad):
    if bad is None:  # None selects the default line
        assert load_ground_station(line=bad).tether.name == DEFAULT_LINE
        return
    with pytest.raises(InputError) as ei:
        load_ground_station(line=bad)
    msg = str(ei.value)
    assert "\n" not in msg and "unknown" in msg and "allowed: sized, paper" in msg, msg
    with pytest.raises(InputError, match=r"^reference metadata\.line .* unknown \(allowed: sized, paper\)$"):
        check_line(bad, "reference metadata.line")


def _damaged(tmp_path: Path, old: str, new: str) -> Path:
    text = XML.read_text()
    assert text.count(old) == 1, old
    f = tmp_path / "gs.xml"
    f.write_text(text.replace(old, new))
    return f


SIZED_OPEN = '<line name="sized">'
PAPER_LINE = XML.read_text()[XML.read_text().index('    <line name="paper">'):XML.read_text().index("</line>\n  </tether>") + 8]


@pytest.mark.parametrize(
    "old,new,element,words",
    [
        ('<fibre_density unit="KG/M3"> 970.0 </fibre_density>', '<fibre_density unit="KG/M3"> 0 </fibre_density>',
         "tether/line[sized]/material/fibre_density", "allowed > 0 and <= 20000"),
        ('<rated_tenacity unit="N/TEX"> 1.83 </rated_tenacity>', '<rated_tenacity unit="N/TEX"> 35 </rated_tenacity>',
         "tether/line[sized]/material/rated_tenacity", "allowed > 0 and <= 10"),
        ('<rated_tenacity unit="N/TEX"> 1.83 </rated_tenacity>', '<rated_tenacity unit="N"> 1.83 </rated_tenacity>',
         "tether/line[sized]/material/rated_tenacity", "expected N/TEX"),
        ('<rated_tenacity unit="N/TEX"> 1.83 </rated_tenacity>', '<rated_tenacity> 1.83 </rated_tenacity>',
         "tether/line[sized]/material/rated_tenacity", "missing unit"),
        ('<fill_factor unit="ND"> 0.8 </fill_factor>', '<fill_factor unit="ND"> 1.2 </fill_factor>',
         "tether/line[sized]/material/fill_factor", "allowed > 0 and <= 1"),
        ('<fibre_modulus unit="N/TEX"> 110.0 </fibre_modulus>', '<fibre_modulus unit="N/TEX"> nan </fibre_modulus>',
         "tether/line[sized]/material/fibre_modulus", "finite"),
        ('<stiffness_factor unit="ND"> 0.5 </stiffness_factor>', '<stiffness_factor unit="ND"> 0 </stiffness_factor>',
         "tether/line[sized]/material/stiffness_factor", "allowed > 0 and <= 1"),
        ('<stiffness_factor unit="ND"> 0.5 </stiffness_factor>', '',
         "tether/line[sized]/material/stiffness_factor", "missing element"),
        ('<cd_perpendicular unit="ND"> 1.1 </cd_perpendicular>\n      </material>',
         '<cd_perpendicular unit="ND"> 4 </cd_perpendicular>\n      </material>',
         "tether/line[sized]/material/cd_perpendicular", "allowed >= 0 and <= 3"),
        ('<rated_tension unit="N"> 50.0 </rated_tension>\n        <!-- estimate: safety',
         '<rated_tension unit="N"> -50 </rated_tension>\n        <!-- estimate: safety',
         "tether/line[sized]/sizing/rated_tension", "allowed > 0 and <= 1e+06"),
        ('<safety_factor unit="ND"> 4.5 </safety_factor>', '<safety_factor unit="ND"> 0.5 </safety_factor>',
         "tether/line[sized]/sizing/safety_factor", "allowed >= 1 and <= 20"),
        # 1e6 N x 20 / 1.83 N/tex = 10.9 kg/m of braid: a 134 mm line
        ('<rated_tension unit="N"> 50.0 </rated_tension>\n        <!-- estimate: safety',
         '<rated_tension unit="N"> 1e6 </rated_tension>\n        <!-- estimate: safety',
         "tether/line[sized]/sizing", "derived diameter"),
        (SIZED_OPEN, SIZED_OPEN + '<diameter unit="M"> 0.0004 </diameter>', "tether/line[sized]/diameter",
         "not allowed beside <sizing>"),
        ('<breaking_load unit="N"> 700.0 </breaking_load>', '<breaking_load unit="N"> 40.0 </breaking_load>',
         "tether/line[paper]/breaking_load", "allowed >= tether/line[paper]/rated_tension 50 N"),
        ('<axial_stiffness unit="N"> 22600.0 </axial_stiffness>', '<axial_stiffness unit="N"> 0 </axial_stiffness>',
         "tether/line[paper]/axial_stiffness", "allowed > 0"),
        ('<line name="paper">', '<line name="thick">', "tether/line[thick]", "not allowed (allowed sized, paper)"),
        ('<line name="paper">', '<line>', "tether/line", "missing name attribute"),
        ('<line name="paper">', '<line name="sized">', "tether/line[sized]", "defined twice"),
    ],
)
def test_damaged_line_gives_one_line_error(tmp_path, old, new, element, words):
    """Every line is checked whichever is selected: a damaged paper line stops a load of the sized one."""
    f = _damaged(tmp_path, old, new)
    for line in LINES:
        with pytest.raises(DefinitionError) as ei:
            load_ground_station(f, line=line)
        msg = str(ei.value)
        assert "\n" not in msg and "gs.xml" in msg and f"<{element}>" in msg and words in msg, msg


def test_a_file_without_the_selected_line(tmp_path):
    f = _damaged(tmp_path, PAPER_LINE, "")
    assert load_ground_station(f).tether.name == "sized"
    with pytest.raises(DefinitionError) as ei:
        load_ground_station(f, line="paper")
    msg = str(ei.value)
    assert "\n" not in msg and "<tether/line[paper]>" in msg and "missing element (lines in this file: sized)" in msg, msg


def test_the_paper_plant_uses_table_1s_line():
    from fdm_awe.sim.paper_plant import IdealWinch

    assert IdealWinch().params.tether == load_ground_station(line="paper").tether


class _Built(Exception):
    """Raised by the flight's setup hook to stop before anything is flown."""


def _flown_line(ref) -> str:
    """Name of the line ``fly`` builds its ground station with for ``ref`` (nothing flown)."""
    from fdm_awe.sim.flight import fly

    seen = {}

    def setup(ap, sim):
        seen["line"] = sim.gs.params.tether.name
        raise _Built

    with pytest.raises(_Built):
        fly(ref, config="nominal", cycles=1, setup=setup)
    return seen["line"]


def test_a_flight_uses_the_line_of_its_reference():
    """A stored reference written before lines were named (no metadata.line) was optimised with
    Table 1's line and flies it; a reference that names a line flies that line; an unknown name
    is refused in one line before JSBSim loads."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(str(Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"))
    assert "line" not in ref.meta
    assert _flown_line(ref) == "paper"
    assert _flown_line(dataclasses.replace(ref, meta={**ref.meta, "line": "sized"})) == "sized"
    assert _flown_line(dataclasses.replace(ref, meta={**ref.meta, "line": None})) == "paper"
    bad = dataclasses.replace(ref, meta={**ref.meta, "line": "thick"})
    with pytest.raises(InputError) as ei:
        fly(bad, config="nominal", cycles=1)
    assert str(ei.value) == "reference metadata.line 'thick' unknown (allowed: sized, paper)"


def test_specific_units():
    assert TEX == 1e-6  # kg/m per tex: 1 g per km
    assert N_PER_TEX * TEX == pytest.approx(1.0, rel=1e-15)  # 1 N/tex = 1 N per 1e-6 kg/m
    t = load_ground_station().tether
    assert t.material.rated_tenacity == pytest.approx(1.83 / TEX) and t.material.fibre_modulus == pytest.approx(110.0 / TEX)
