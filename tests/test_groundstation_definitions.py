"""Ground-station definition file: Table 1 values, units, and one-line errors on bad files.
The tether lines (sized and paper) are tested in test_groundstation_line.py."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from fdm_awe import ROOT
from fdm_awe.errors import DefinitionError
from fdm_awe.groundstation import load_ground_station

XML = ROOT / "tether" / "ground_station.xml"


def test_table1_values_in_si():
    p = load_ground_station(line="paper")  # Table 1's line
    # Table 1 entries, converted by hand (exact decimal values, so compare to 1e-12)
    assert p.winch.radius == pytest.approx(0.03, rel=1e-12)
    assert p.winch.inertia == pytest.approx(0.000192, rel=1e-12)
    assert p.winch.viscous_friction == pytest.approx(0.0002, rel=1e-12)
    assert p.winch.coulomb_friction == pytest.approx(0.11337, rel=1e-12)
    assert p.winch.mass == pytest.approx(0.066, rel=1e-12)
    assert p.tether.mass_per_length == pytest.approx(0.0004, rel=1e-12)
    # 0.013 V/rpm -> V s/rad
    assert p.machine.k == pytest.approx(0.013 * 60.0 / (2.0 * math.pi), rel=1e-12)
    # docs/design.md section 5 estimates
    assert p.machine.resistance == 0.7 and p.machine.inductance == pytest.approx(3e-4)
    assert p.converter.device_drop == 0.5 and p.converter.supply_voltage == 48.0  # sized for the design reel-in speed
    assert p.converter.link_capacitance == pytest.approx(1e-3) and p.converter.load_resistance == 1.5
    assert p.tether.diameter == pytest.approx(0.72e-3) and p.tether.cd_perpendicular == 1.1
    assert p.tether.axial_stiffness == pytest.approx(22.6e3)


def test_pi_gains_follow_pole_zero_cancellation_at_20_rad_s():
    # The file documents Kp, Ki as pole-zero cancellation with a 20 rad/s crossover on the
    # motor plant (K V_a/R)/(J s + B + K^2/R); recompute from Table 1 + docs/design.md 5.
    p = load_ground_station()
    K, R, Va, J, B = p.machine.k, p.machine.resistance, p.converter.supply_voltage, p.winch.inertia, p.winch.viscous_friction
    kp = 20.0 * J * R / (K * Va)
    ki = kp * (B + K * K / R) / J
    assert p.controller.kp == pytest.approx(kp, rel=2e-3)  # file holds 3-4 significant digits
    assert p.controller.ki == pytest.approx(ki, rel=2e-3)


def test_every_value_has_unit_and_basis_comment():
    text = XML.read_text()
    for m in re.finditer(r"<(\w+)( unit=\"[^\"]+\")?>\s*([-+0-9.eE]+)\s*</\1>", text):
        assert m.group(2), f"<{m.group(1)}> has no unit attribute"
        before = text[: m.start()].rstrip()
        assert before.endswith("-->"), f"<{m.group(1)}> not preceded by a basis comment"
        comment = before[before.rfind("<!--"):]
        assert any(basis in comment for basis in ("Table 1", "Table 3", "data (", "estimate", "Derived", "PI of")), m.group(1)


def _bad(tmp_path: Path, old: str, new: str) -> Path:
    text = XML.read_text()
    assert old in text
    f = tmp_path / "gs.xml"
    f.write_text(text.replace(old, new, 1))
    return f


@pytest.mark.parametrize(
    "old,new,element,words",
    [
        ('<radius unit="M"> 0.03 </radius>', '<radius unit="M"> 0.0 </radius>', "winch/radius", "> 0"),
        ('<armature_resistance unit="OHM"> 0.7 </armature_resistance>',
         '<armature_resistance unit="OHM"> -0.7 </armature_resistance>', "dc_machine/armature_resistance", "> 0"),
        ('<load_resistance unit="OHM"> 1.5 </load_resistance>',
         '<load_resistance unit="OHM"> nan </load_resistance>', "converter/load_resistance", "finite"),
        ('<boost_duty unit="ND"> 0.0 </boost_duty>', '<boost_duty unit="ND"> 1.5 </boost_duty>',
         "converter/boost_duty", "<= 1"),
        ('<inertia unit="KG*M2"> 0.000192 </inertia>', '<inertia> 0.000192 </inertia>', "winch/inertia", "unit"),
        ('<armature_inductance unit="H"> 0.0003 </armature_inductance>',
         '<armature_inductance unit="MH"> 0.3 </armature_inductance>', "dc_machine/armature_inductance", "unit"),
        ('<radius unit="M"> 0.03 </radius>', '<radius unit="KG"> 0.03 </radius>', "winch/radius", "unit"),
        ('<kp unit="S/RAD"> 0.000451 </kp>', '', "speed_controller/kp", "missing"),
    ],
)
def test_bad_file_gives_one_line_error(tmp_path, old, new, element, words):
    with pytest.raises(DefinitionError) as ei:
        load_ground_station(_bad(tmp_path, old, new))
    msg = str(ei.value)
    assert "\n" not in msg and "gs.xml" in msg and element in msg and words in msg, msg


def test_english_length_unit_is_converted(tmp_path):
    p = load_ground_station(_bad(tmp_path, '<radius unit="M"> 0.03 </radius>', '<radius unit="FT"> 0.1 </radius>'))
    assert p.winch.radius == pytest.approx(0.03048)


def test_missing_file_is_definition_error(tmp_path):
    with pytest.raises(DefinitionError, match="not found"):
        load_ground_station(tmp_path / "nope.xml")


@pytest.mark.parametrize(
    "old,new,element,words",
    [
        ('<device_drop unit="V"> 0.5 </device_drop>', '<device_drop unit="V"> 25.0 </device_drop>',
         "converter/device_drop", "half the supply voltage"),
        ('<max_length unit="M"> 600.0 </max_length>', '<max_length unit="M"> 1.0 </max_length>',
         "tether/max_length", "must exceed"),
        ('<diameter unit="M"> 0.00072 </diameter>', '<diameter unit="M"> 0.72 mm </diameter>', "tether/line[paper]/diameter",
         "not a number"),
        ('<ki unit="1/RAD"> 0.0522 </ki>', '<ki unit="1/RAD"> inf </ki>', "speed_controller/ki", "finite"),
        ('<ground_station name', '<groundstation name', "groundstation", "root element"),
    ],
)
def test_more_bad_values_give_one_line_errors(tmp_path, old, new, element, words):
    text = XML.read_text()
    if old.startswith("<ground_station"):
        text = text.replace("</ground_station>", "</groundstation>")
    f = tmp_path / "gs.xml"
    assert old in text
    f.write_text(text.replace(old, new, 1))
    with pytest.raises(DefinitionError) as ei:
        load_ground_station(f)
    msg = str(ei.value)
    assert "\n" not in msg and "gs.xml" in msg and element in msg and words in msg, msg


def test_folder_and_malformed_file(tmp_path):
    with pytest.raises(DefinitionError, match="not a regular file"):
        load_ground_station(tmp_path)
    f = tmp_path / "gs.xml"
    f.write_bytes(XML.read_bytes()[:2000])
    with pytest.raises(DefinitionError, match="not well-formed"):
        load_ground_station(f)
    f.write_bytes(b"\x00\x01binary")
    with pytest.raises(DefinitionError, match="not well-formed"):
        load_ground_station(f)
