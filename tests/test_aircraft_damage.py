"""Damaged copies of the aircraft definitions: every fault gives one line naming the file that
holds it, the element and the allowed range or form.

The aircraft/ and engine/ folders are copied into tmp_path and one file is damaged (an aircraft
file, one of the section files of aircraft/common/ they include, or an engine file); the checks
(and the 6-DOF adapter, which runs them before JSBSim reads the file) load from that root.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import pytest

os.environ.setdefault("JSBSIM_DEBUG", "0")
import jsbsim  # noqa: E402

from fdm_awe import ROOT  # noqa: E402
from fdm_awe.definitions.aircraft import check_aircraft_file, load_airframe_file  # noqa: E402
from fdm_awe.errors import DefinitionError  # noqa: E402
from fdm_awe.sixdof import JSBSimGlider  # noqa: E402
from fdm_awe.units import SLUG  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

NAMES = ["glider_unfolded", "glider_folded", "glider_foldable"]
MASS_KG = 0.738  # Table 2

FOLDABLE = Path("aircraft") / "glider_foldable" / "glider_foldable.xml"
MOTOR = Path("engine") / "glider_motor.xml"
PROPELLER = Path("engine") / "prop_9x5.xml"
COMMON = Path("aircraft") / "common"


def _tree(tmp_path: Path) -> Path:
    root = tmp_path / "defs"
    shutil.copytree(ROOT / "aircraft", root / "aircraft")
    shutil.copytree(ROOT / "engine", root / "engine")
    return root


def _damage(root: Path, rel: Path, pattern: str, repl: str) -> Path:
    p = root / rel
    new, n = re.subn(pattern, repl, p.read_text(), count=1)
    assert n == 1, f"pattern {pattern!r} not found in {rel}"
    p.write_text(new)
    return p


def _prop(name: str, value: str) -> tuple[str, str]:
    """Pattern and replacement setting ``<property value=...> name </property>`` to ``value``."""
    return rf'value="[^"]*"(>\s*{re.escape(name)}\s*<)', rf'value="{value}"\g<1>'


def _elem(tag: str, value: str) -> tuple[str, str]:
    """Pattern and replacement setting the first ``<tag ...> text </tag>`` to ``value``."""
    return rf"(<{tag}(?: [^>]*)?>)[^<]*(</{tag}>)", rf"\g<1> {value} \g<2>"


FOLDABLE_DAMAGE = {
    "coefficient_abc": (*_prop("aero/unfolded/CL0", "abc"), "aero/unfolded/CL0", "not a number"),
    "folded_coefficient_abc": (*_prop("aero/folded/Cn_r", "abc"), "aero/folded/Cn_r", "not a number"),
    "coefficient_nan": (*_prop("aero/folded/Cm_q", "nan"), "aero/folded/Cm_q", "finite"),
    "coefficient_inf": (*_prop("aero/unfolded/CDalpha2", "inf"), "aero/unfolded/CDalpha2", "finite"),
    "coefficient_empty": (*_prop("aero/unfolded/Cl_p", ""), "aero/unfolded/Cl_p", "not a number"),
    "coefficient_removed": (r"<property[^>]*>\s*aero/folded/CD0\s*</property>", "", "aero/folded/CD0", "missing"),
    "lift_slope_negative": (*_prop("aero/unfolded/CLalpha", "-4.5"), "aero/unfolded/CLalpha", "allowed > 0"),
    "lift_slope_beyond_2pi": (*_prop("aero/folded/CLalpha", "7"), "aero/folded/CLalpha", "<= 6.28"),
    "CLmax_below_CL0": (*_prop("aero/folded/CLmax", "0.05"), "aero/folded/CLmax", "CL0"),
    "drag_zero": (*_prop("aero/unfolded/CD0", "0"), "aero/unfolded/CD0", "allowed > 0"),
    "pitch_unstable": (*_prop("aero/unfolded/Cm_alpha", "0.45"), "aero/unfolded/Cm_alpha", "< 0"),
    "no_roll_damping": (*_prop("aero/folded/Cl_p", "0"), "aero/folded/Cl_p", "< 0"),
    "aileron_zero": (*_prop("aero/folded/Cl_da", "0"), "aero/folded/Cl_da", "> 0"),
    "elevator_reversed": (*_prop("aero/unfolded/Cm_de", "0.85"), "aero/unfolded/Cm_de", "< 0"),
    "S_ratio_above_one": (*_prop("aero/fold/S-ratio", "2"), "aero/fold/S-ratio", "<= 1"),
    "b_ratio_zero": (*_prop("aero/fold/b-ratio", "0"), "aero/fold/b-ratio", "> 0"),
    "fold_time_zero": (*_prop("fcs/wing-fold-time-s", "0"), "fcs/wing-fold-time-s", "allowed > 0"),
    "fold_time_negative": (*_prop("fcs/wing-fold-time-s", "-2"), "fcs/wing-fold-time-s", "allowed > 0"),
    "fold_time_abc": (*_prop("fcs/wing-fold-time-s", "abc"), "fcs/wing-fold-time-s", "not a number"),
    "fold_time_removed": (r"<property[^>]*>\s*fcs/wing-fold-time-s\s*</property>", "", "fcs/wing-fold-time-s", "missing"),
    "emptywt_removed": (r"<emptywt[^>]*>[^<]*</emptywt>", "", "mass_balance/emptywt", "missing"),
    "emptywt_negative": (*_elem("emptywt", "-0.498"), "mass_balance/emptywt", "allowed > 0"),
    "emptywt_zero": (*_elem("emptywt", "0"), "mass_balance/emptywt", "allowed > 0"),
    "emptywt_abc": (*_elem("emptywt", "heavy"), "mass_balance/emptywt", "not a number"),
    "emptywt_unit": (r'<emptywt unit="KG">', '<emptywt unit="STONE">', "mass_balance/emptywt", "unit"),
    "point_mass_negative": (*_elem("weight", "-0.06"), "pointmass", ">= 0"),
    "ixx_zero": (*_elem("ixx", "0"), "mass_balance/ixx", "allowed > 0"),
    "iyy_removed": (r"<iyy[^>]*>[^<]*</iyy>", "", "mass_balance/iyy", "missing"),
    "inertia_not_physical": (*_elem("ixz", "-0.05"), "mass_balance", "physical"),
    "cg_location_abc": (r"(<location name=\"CG\" unit=\"M\">\s*<x>)[^<]*(</x>)", r"\g<1> aft \g<2>", "location", "not a number"),
    "wingarea_abc": (*_elem("wingarea", "big"), "metrics/wingarea", "not a number"),
    "wingspan_negative": (*_elem("wingspan", "-1.1"), "metrics/wingspan", "allowed > 0"),
    "function_value_abc": (r"(<value>)\s*1\.0\s*(</value>)", r"\g<1> one \g<2>", "value", "not a number"),
    "rate_limit_word": (*_elem("rate_limit", "fast"), "rate_limit", "neither a number nor a property"),
    "rate_limit_zero": (*_elem("rate_limit", "0"), "rate_limit", "allowed > 0"),
    "spring_negative": (*_elem("spring_coeff", "-10"), "spring_coeff", "allowed > 0"),
    "friction_abc": (*_elem("static_friction", "grippy"), "static_friction", "not a number"),
    "friction_negative": (*_elem("dynamic_friction", "-0.4"), "dynamic_friction", ">= 0"),
    "not_xml": (r"</fdm_config>", "", "xml", "not well-formed"),
}


# Damage in the section files every aircraft includes (aircraft/common/): (file, pattern,
# replacement, element, words, file the message names: None = the damaged file).
SHARED_DAMAGE = {
    "chord_removed": (COMMON / "metrics.xml", r"<chord[^>]*>[^<]*</chord>", "", "metrics/chord", "missing", FOLDABLE),
    "htailarea_negative": (COMMON / "metrics.xml", *_elem("htailarea", "-0.02"), "metrics/htailarea", ">= 0", None),
    "thrust_max_zero": (COMMON / "point_mass_propulsion.xml", *_prop("propulsion/pm/T-max-N", "0"), "propulsion/pm/T-max-N",
                        "allowed > 0", None),
    "efficiency_above_one": (COMMON / "point_mass_propulsion.xml", *_prop("propulsion/pm/eta-motor", "1.5"),
                             "propulsion/pm/eta-motor", "<= 1", None),
    "clip_reversed": (COMMON / "flight_control.xml", r"(<clipto>\s*<min>)\s*-1\s*(</min>\s*<max>)\s*1\s*(</max>)",
                      r"\g<1> 1 \g<2> -1 \g<3>", "clipto", "min < max", None),
    "elevator_range_zero": (COMMON / "flight_control.xml", r"(?s)(<aerosurface_scale name=\"fcs/pitch-cmd-rad\">.*?<max>)[^<]*(</max>)",
                            r"\g<1> 0 \g<2>", "fcs/pitch-cmd-rad", "allowed > 0", None),
    "servo_rate_zero": (COMMON / "flight_control.xml", *_elem("rate_limit", "0"), "rate_limit", "allowed > 0", None),
    "skid_spring_negative": (COMMON / "skids.xml", *_elem("spring_coeff", "-10"), "contact[NOSE_SKID]/spring_coeff",
                             "allowed > 0", None),
    "skid_friction_abc": (COMMON / "skids.xml", *_elem("static_friction", "grippy"), "contact[NOSE_SKID]/static_friction",
                          "not a number", None),
    "contact_flag_misses_a_contact": (COMMON / "skids.xml", r"\s*<property> contact/unit\[5\]/WOW </property>", "",
                                      "function[contact/wow]", "contact/unit[5]/WOW", None),
    "contact_flag_not_post": (COMMON / "skids.xml", r'(name="contact/wow") type="post"', r"\g<1>", "function[contact/wow]",
                              'type="post"', None),
    "contact_flag_removed": (COMMON / "skids.xml", r'name="contact/wow"', 'name="contact/any"', "function[contact/wow]",
                             "missing", FOLDABLE),
    "tether_hook_renamed": (COMMON / "tether_hook.xml", r'<force name="tether"', '<force name="line"', "force[tether]", "missing",
                            FOLDABLE),
    "tether_hook_frame": (COMMON / "tether_hook.xml", r'frame="LOCAL"', 'frame="BODY"', "force[tether]", "allowed LOCAL", None),
    "engine_file_missing": (COMMON / "propulsion.xml", r'<engine file="glider_motor">', '<engine file="no_such_motor">',
                            "no_such_motor.xml", "not found", Path("engine") / "no_such_motor.xml"),
    "feed_without_tank": (COMMON / "propulsion.xml", r'(<engine file="glider_motor">)', r"\g<1><feed> 0 </feed>",
                          "propulsion/engine/feed", "does not exist", None),
    "aero_model_value_abc": (COMMON / "aerodynamics.xml", r"(<value>)\s*1\.5\s*(</value>)", r"\g<1> x \g<2>", "value",
                             "not a number", None),
    "section_file_of_another_section": (FOLDABLE, r'file="\.\./common/tether_hook"', 'file="../common/skids"', "ground_reactions",
                                        "root element must be <external_reactions>", COMMON / "skids.xml"),
    "section_file_missing": (FOLDABLE, r'file="\.\./common/skids"', 'file="../common/no_skids"',
                             "ground_reactions[file=../common/no_skids]", "no_skids.xml not found", None),
    "pre_function_beside_section_file": (FOLDABLE, r"(<ground_reactions file=[^>]*>)",
                                         r'\g<1><function name="contact/x"><value> 1 </value></function>',
                                         "function[contact/x]", "does not load a pre-function", None),
}


def _foldable_refused(root: Path, element: str, words: str, damaged: Path | None = None):
    with pytest.raises(DefinitionError) as ei:
        check_aircraft_file(root / FOLDABLE, root=root)
    msg = str(ei.value)
    assert "\n" not in msg, msg
    assert str(damaged or root / FOLDABLE) in msg and element in msg and words in msg, msg
    return msg


def test_the_copied_definitions_pass_and_fly_from_another_root(tmp_path):
    root = _tree(tmp_path)
    for name in NAMES:
        check_aircraft_file(root / "aircraft" / name / f"{name}.xml", root=root)
    g = JSBSimGlider("glider_foldable", root=root)
    assert g.foldable and g.fold_time_s > 0.0


@pytest.mark.parametrize("case", list(FOLDABLE_DAMAGE))
def test_damaged_foldable_glider_gives_one_line(tmp_path, case):
    pattern, repl, element, words = FOLDABLE_DAMAGE[case]
    root = _tree(tmp_path)
    _damage(root, FOLDABLE, pattern, repl)
    _foldable_refused(root, element, words)


@pytest.mark.parametrize("case", list(SHARED_DAMAGE))
def test_damaged_section_files_give_one_line_naming_the_file_that_holds_the_fault(tmp_path, case):
    rel, pattern, repl, element, words, named = SHARED_DAMAGE[case]
    root = _tree(tmp_path)
    p = _damage(root, rel, pattern, repl)
    _foldable_refused(root, element, words, damaged=p if named is None else root / named)


ENGINE_DAMAGE = {
    "maxvolts_negative": (MOTOR, *_elem("maxvolts", "-11.1"), "maxvolts", "allowed > 0"),
    "kv_abc": (MOTOR, *_elem("velocityconstant", "fast"), "velocityconstant", "not a number"),
    "resistance_zero": (MOTOR, *_elem("coilresistance", "0"), "coilresistance", "allowed > 0"),
    "no_load_current_removed": (MOTOR, r"<noloadcurrent[^>]*>[^<]*</noloadcurrent>", "", "noloadcurrent", "missing"),
    "diameter_zero": (PROPELLER, *_elem("diameter", "0"), "diameter", "allowed > 0"),
    "prop_inertia_removed": (PROPELLER, r"<ixx[^>]*>[^<]*</ixx>", "", "ixx", "missing"),
    "blades_fractional": (PROPELLER, *_elem("numblades", "2.5"), "numblades", "whole number"),
    "table_entry_abc": (PROPELLER, r"0\.05  0\.1078", "0.05  x", "tableData", "not a number"),
    "table_entry_nan": (PROPELLER, r"0\.10  0\.1048", "0.10  nan", "tableData", "finite"),
    "table_J_decreasing": (PROPELLER, r"0\.15  0\.1009", "0.01  0.1009", "C_THRUST", "increasing"),
}


@pytest.mark.parametrize("case", list(ENGINE_DAMAGE))
def test_damaged_engine_files_give_one_line(tmp_path, case):
    rel, pattern, repl, element, words = ENGINE_DAMAGE[case]
    root = _tree(tmp_path)
    p = _damage(root, rel, pattern, repl)
    _foldable_refused(root, element, words, damaged=p)


@pytest.mark.parametrize("case", ["coefficient_abc", "emptywt_removed", "emptywt_negative", "fold_time_abc"])
def test_the_6dof_adapter_refuses_a_damaged_glider_before_jsbsim_loads_it(tmp_path, case):
    pattern, repl, element, words = FOLDABLE_DAMAGE[case]
    root = _tree(tmp_path)
    _damage(root, FOLDABLE, pattern, repl)
    with pytest.raises(DefinitionError) as ei:
        JSBSimGlider("glider_foldable", root=root)
    msg = str(ei.value)
    assert "\n" not in msg and str(root / FOLDABLE) in msg and element in msg and words in msg, msg


def test_jsbsim_alone_would_fly_without_empty_weight(tmp_path):
    """Why the check is needed: JSBSim loads the glider without <emptywt> (it flies the point
    masses alone, a third of the mass) instead of refusing it."""
    root = _tree(tmp_path)
    _damage(root, FOLDABLE, *FOLDABLE_DAMAGE["emptywt_removed"][:2])
    fdm = jsbsim.FGFDMExec(str(root))
    fdm.set_debug_level(0)
    assert fdm.load_model("glider_foldable")
    fdm["ic/h-agl-ft"] = 300.0
    fdm.run_ic()
    assert fdm["inertia/mass-slugs"] * SLUG < 0.5 * MASS_KG
    with pytest.raises(DefinitionError, match="emptywt"):
        check_aircraft_file(root / FOLDABLE, root=root)


@pytest.mark.parametrize("name", ["glider_unfolded", "glider_folded"])
def test_static_forms_stability_derivatives_are_checked(tmp_path, name):
    root = _tree(tmp_path)
    rel = Path("aircraft") / name / f"{name}.xml"
    _damage(root, rel, *_prop("aero/coef/Cn_dr", "abc"))
    with pytest.raises(DefinitionError, match=r"aero/coef/Cn_dr.*not a number"):
        load_airframe_file(root / rel)
    (root / rel).write_text((ROOT / rel).read_text())
    _damage(root, rel, *_prop("aero/coef/Cn_beta", "-0.05"))
    with pytest.raises(DefinitionError, match=r"aero/coef/Cn_beta.*allowed >= 0"):
        check_aircraft_file(root / rel, root=root)


def test_the_morphing_glider_is_not_a_static_form():
    with pytest.raises(DefinitionError, match="morphing"):
        load_airframe_file(ROOT / FOLDABLE)
