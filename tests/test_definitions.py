"""Loading the aircraft definitions into typed SI parameters, and rejecting bad ones."""

import re
import shutil

import numpy as np
import pytest

from fdm_awe import ROOT
from fdm_awe.definitions.aircraft import aircraft_path, load_airframe, load_airframe_file, load_glider
from fdm_awe.errors import DefinitionError

# Paper Table 2 (inertia matrices in body axes, kg m^2) and docs/design.md section 5.
TABLE2 = {
    "unfolded": [[0.0194, 0, -0.001454], [0, 0.01762, 0], [-0.001454, 0, 0.03499]],
    "folded": [[0.009606, 0, -0.0007104], [0, 0.02077, 0], [-0.0007104, 0, 0.02204]],
}
SPAN = {"unfolded": 1.1, "folded": 0.22}


@pytest.mark.parametrize("cfg", ["unfolded", "folded"])
def test_airframe_matches_table2_and_design(cfg):
    af = load_airframe(cfg)
    assert af.mass.mass == pytest.approx(0.738, rel=1e-9)
    np.testing.assert_allclose(af.mass.inertia_matrix, TABLE2[cfg], atol=1e-9)
    assert af.aero.b == pytest.approx(SPAN[cfg], rel=1e-9)
    assert af.aero.c == pytest.approx(0.1375, rel=1e-6)
    assert af.aero.S == pytest.approx(SPAN[cfg] * 0.1375, rel=1e-6)
    # Helmbold lift slope for the aspect ratio, alpha_0L = -3 deg
    A = af.aero.aspect_ratio
    cla = 2 * np.pi * A / (2 + np.sqrt(A**2 / 0.81 + 4))
    assert af.aero.CLalpha == pytest.approx(cla, rel=1e-4)
    assert af.aero.CL0 == pytest.approx(cla * np.radians(3), rel=1e-4)


def test_both_configurations_are_the_same_vehicle():
    g = load_glider()
    assert g.unfolded.propulsion == g.folded.propulsion
    assert g.folded.aero.aspect_ratio == pytest.approx(1.6, rel=1e-6)
    assert g.unfolded.aero.aspect_ratio == pytest.approx(8.0, rel=1e-6)


def _mutated(tmp_path, pattern, repl, count=1):
    """A damaged copy of glider_unfolded, ``aircraft/glider_bad/glider_bad.xml`` beside a copy of
    the section files it includes (``aircraft/common/``)."""
    src = aircraft_path("glider_unfolded")
    text = src.read_text()
    new, n = re.subn(pattern, repl, text, count=count)
    assert n == count, f"pattern {pattern!r} not found"
    shutil.copytree(ROOT / "aircraft" / "common", tmp_path / "aircraft" / "common")
    p = tmp_path / "aircraft" / "glider_bad" / "glider_bad.xml"
    p.parent.mkdir(parents=True)
    p.write_text(new)
    return p


@pytest.mark.parametrize(
    "pattern,repl,element",
    [
        (r"<wingarea[^>]*>[^<]*</wingarea>", "", "metrics/wingarea"),  # missing element
        (r"(<wingarea[^>]*>)[^<]*(</wingarea>)", r"\g<1>-0.1\g<2>", "metrics/wingarea"),  # non-positive area
        (r"(<emptywt[^>]*>)[^<]*(</emptywt>)", r"\g<1>0\g<2>", "mass_balance/emptywt"),  # non-positive mass
        (r"(<emptywt[^>]*>)[^<]*(</emptywt>)", r"\g<1>heavy\g<2>", "mass_balance/emptywt"),  # non-numeric
        (r'value="[^"]*"(>\s*aero/pm/CLalpha\s*<)', r'value="abc"\g<1>', "aero/pm/CLalpha"),
        (r"<property[^>]*>\s*aero/pm/CD0\s*</property>", "", "aero/pm/CD0"),
        (r"<emptywt[^>]*>[^<]*</emptywt>", "", "mass_balance/emptywt"),  # removed: JSBSim would fly the point masses alone
        (r"(<emptywt[^>]*>)[^<]*(</emptywt>)", r"\g<1>-0.738\g<2>", "mass_balance/emptywt"),  # negative mass
        (r'value="[^"]*"(>\s*aero/coef/Cm_alpha\s*<)', r'value="abc"\g<1>', "aero/coef/Cm_alpha"),  # stability derivative
        (r'value="[^"]*"(>\s*aero/coef/Cl_p\s*<)', r'value="0.5"\g<1>', "aero/coef/Cl_p"),  # no roll damping
        (r"(<spring_coeff[^>]*>)[^<]*(</spring_coeff>)", r"\g<1>nan\g<2>", "spring_coeff"),
    ],
)
def test_bad_definition_fails_with_one_line_naming_file_and_element(tmp_path, pattern, repl, element):
    p = _mutated(tmp_path, pattern, repl)
    with pytest.raises(DefinitionError) as ei:
        load_airframe_file(p)
    msg = str(ei.value)
    assert "\n" not in msg
    assert str(p) in msg and element in msg


def test_range_is_named_in_message(tmp_path):
    p = _mutated(tmp_path, r"(<wingarea[^>]*>)[^<]*(</wingarea>)", r"\g<1>-0.1\g<2>")
    with pytest.raises(DefinitionError, match=r"allowed > 0"):
        load_airframe_file(p)


def test_malformed_xml_and_missing_file(tmp_path):
    p = tmp_path / "broken.xml"
    p.write_text("<fdm_config><metrics>")
    with pytest.raises(DefinitionError, match="not well-formed"):
        load_airframe_file(p)
    with pytest.raises(DefinitionError, match="not found"):
        load_airframe_file(tmp_path / "nope.xml")


def test_definitions_live_in_the_repository():
    assert (ROOT / "aircraft" / "glider_unfolded" / "glider_unfolded.xml").is_file()
    assert (ROOT / "aircraft" / "glider_folded" / "glider_folded.xml").is_file()


def test_product_of_inertia_conventions_agree(tmp_path):
    """negated_crossproduct_inertia="false" with the product (+0.001454) gives Table 2's matrix."""
    p = _mutated(tmp_path, r'<mass_balance negated_crossproduct_inertia="true"', '<mass_balance negated_crossproduct_inertia="false"')
    text = re.sub(r"(<ixz[^>]*>)\s*-0\.001454\s*(</ixz>)", r"\g<1>0.001454\g<2>", p.read_text())
    p.write_text(text)
    np.testing.assert_allclose(load_airframe_file(p).mass.inertia_matrix, TABLE2["unfolded"], atol=1e-12)
