"""The JSBSim aircraft and engine definitions: loading, mass properties, aerodynamics, thrust.

References are independent of the definition files: Table 2 of the paper (mass, inertia),
the derivation formulas of docs/design.md section 5 (Helmbold lift slope, parabolic polar) and the
contract's static thrust. JSBSim itself evaluates the files. Damaged definitions:
tests/test_aircraft_damage.py.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("JSBSIM_DEBUG", "0")
import jsbsim  # noqa: E402

from fdm_awe import ROOT  # noqa: E402
from fdm_awe.definitions.aircraft import check_aircraft_file, load_airframe, load_airframe_file  # noqa: E402
from fdm_awe.definitions.xmlutil import XmlDoc  # noqa: E402
from fdm_awe.units import FT, IN, LBF, SLUG, SLUG_FT2  # noqa: E402

# jsbsim returns numpy.matrix objects from get_J()/get_xyz_cg()
pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

NAMES = ["glider_unfolded", "glider_folded", "glider_foldable"]

# Table 2 (the paper): inertia MATRIX about the CG in body axes, kg m^2.
TABLE2 = {
    "unfolded": np.array([[0.0194, 0.0, -0.001454], [0.0, 0.01762, 0.0], [-0.001454, 0.0, 0.03499]]),
    "folded": np.array([[0.009606, 0.0, -0.0007104], [0.0, 0.02077, 0.0], [-0.0007104, 0.0, 0.02204]]),
}
MASS_KG = 0.738
# JSBSim converts KG*M2 and KG with its own constants (about 1e-4 apart from fdm_awe.units'):
INERTIA_RTOL = 1e-3
INERTIA_ATOL = 2e-6  # kg m^2, for the zero products of inertia

PM_NAMES = ["CL0", "CLalpha", "CLmax", "CD0", "CDalpha1", "CDalpha2"]
COEF_NAMES = ["Cm0", "Cm_alpha", "Cm_q", "Cm_adot", "Cm_de", "CL_q", "CL_adot", "CL_de", "CY_beta",
              "CY_dr", "Cl_beta", "Cl_p", "Cl_r", "Cl_da", "Cl_dr", "Cn_beta", "Cn_p", "Cn_r", "Cn_da", "Cn_dr"]


def _fdm(name: str, dt: float = 1.0 / 120.0) -> jsbsim.FGFDMExec:
    fdm = jsbsim.FGFDMExec(str(ROOT))
    fdm.set_debug_level(0)
    assert fdm.load_model(name), name
    fdm.set_dt(dt)
    return fdm


def _inertia_kgm2(fdm: jsbsim.FGFDMExec) -> np.ndarray:
    return np.array(fdm.get_mass_balance().get_J()) * SLUG_FT2


def _doc(name: str) -> XmlDoc:
    return XmlDoc.load(ROOT / "aircraft" / name / f"{name}.xml")


def _jsbsim_cli() -> Path:
    exe = Path(sys.executable).with_name("jsbsim")
    if not exe.exists():
        pytest.skip("jsbsim command-line program not installed next to the interpreter")
    return exe


@pytest.mark.parametrize("name", NAMES)
def test_loads_with_fdmexec_and_flies_finite(name):
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 100.0 / FT
    fdm["ic/vt-fps"] = 12.0 / FT
    fdm["ic/alpha-rad"] = 0.1
    assert fdm.run_ic()
    for _ in range(60):
        assert fdm.run()
    for prop in ("velocities/vt-fps", "attitude/theta-rad", "aero/alpha-rad", "position/h-agl-ft"):
        assert math.isfinite(fdm[prop]), prop


@pytest.mark.parametrize("name", NAMES)
def test_bare_jsbsim_flies_the_numbers_the_loader_reads(name):
    """JSBSim alone (the repository root as its root, section files included by JSBSim itself)
    against fdm_awe's loader: mass, CG, wing area, span, chord, the point-mass polar and the
    contacts. The morphing aircraft keeps the unfolded form's metrics, mass and CG."""
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 300.0
    fdm["ic/vt-fps"] = 40.0
    assert fdm.run_ic()
    path = ROOT / "aircraft" / name / f"{name}.xml"
    af = load_airframe("unfolded") if name == "glider_foldable" else load_airframe_file(path)
    assert fdm["inertia/mass-slugs"] * SLUG == pytest.approx(af.mass.mass, rel=1e-4)
    np.testing.assert_allclose(np.array(fdm.get_mass_balance().get_xyz_cg()).ravel() * IN, af.mass.cg_structural, atol=1e-9)
    assert fdm["metrics/Sw-sqft"] * FT**2 == pytest.approx(af.aero.S, rel=1e-6)
    assert fdm["metrics/bw-ft"] * FT == pytest.approx(af.aero.b, rel=1e-6)
    assert fdm["metrics/cbarw-ft"] * FT == pytest.approx(af.aero.c, rel=1e-6)
    for key in PM_NAMES:
        assert fdm[f"aero/pm/{key}"] == pytest.approx(getattr(af.aero, key), rel=1e-12), key
    assert fdm["propulsion/pm/T-max-N"] == af.propulsion.T_max
    if name != "glider_foldable":
        np.testing.assert_allclose(_inertia_kgm2(fdm), af.mass.inertia_matrix, rtol=INERTIA_RTOL, atol=INERTIA_ATOL)
    doc = check_aircraft_file(path)
    assert fdm["gear/num-units"] == len(doc.root.findall("ground_reactions/contact")) == 6
    assert fdm["contact/wow"] == 0.0  # airborne


@pytest.mark.parametrize("name", NAMES)
def test_aircraft_follow_jsbsim_idioms_and_share_the_common_sections(name):
    doc = _doc(name)
    assert doc.root.attrib["release"] in ("BETA", "PRODUCTION")
    assert {el.attrib["type"] for el in doc.root.iterfind("ground_reactions/contact")} == {"STRUCTURE"}
    assert not doc.root.findall("propulsion/tank") and not doc.root.findall("propulsion/engine/feed")
    # every section file of aircraft/common/ is included, none is copied into the aircraft file
    common = sorted((ROOT / "aircraft" / "common").glob("*.xml"))
    assert sorted(doc.section_files) == common
    def key(el: ET.Element) -> tuple[str, str]:  # tag and name (or text: a property's name)
        return el.tag, el.attrib.get("name") or (el.text or "").strip()

    own = {key(el) for el in ET.parse(ROOT / "aircraft" / name / f"{name}.xml").getroot().iter()}
    for f in common:
        for el in ET.parse(f).getroot():
            assert key(el) not in own, (f.name, key(el))


@pytest.mark.parametrize("name", NAMES)
def test_ground_contact_flag_follows_the_skids_and_wingtips(name):
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 0.035 / FT  # resting on the skids
    fdm["ic/vt-fps"] = 0.0
    fdm.run_ic()
    for _ in range(12):
        fdm.run()
    assert fdm["contact/wow"] == 1.0 and fdm["gear/wow"] == 0.0  # STRUCTURE contacts only
    assert [fdm[f"contact/unit[{i}]/WOW"] for i in range(6)] == [0.0, 0.0, 1.0, 1.0, 1.0, 1.0]  # tips, skids
    fdm["ic/h-agl-ft"] = 0.08 / FT  # banked 60 deg to the right, low: the right wingtip alone touches
    fdm["ic/phi-deg"] = 60.0
    fdm.run_ic()
    assert [fdm[f"contact/unit[{i}]/WOW"] for i in range(6)] == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    assert fdm["contact/wow"] == 1.0
    fdm["ic/h-agl-ft"] = 10.0 / FT
    fdm.run_ic()
    assert fdm["contact/wow"] == 0.0


@pytest.mark.parametrize("name", NAMES)
def test_command_line_program_loads_without_warnings(name):
    exe = _jsbsim_cli()
    env = dict(os.environ)
    env.pop("JSBSIM_DEBUG", None)  # full console output, so that warnings would show
    proc = subprocess.run(
        [str(exe), "--root", str(ROOT), "--aircraft", name, "--initfile", "reset00", "--end", "1"],
        capture_output=True, text=True, errors="replace", timeout=60, env=env, cwd=str(ROOT),
    )
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out[-2000:]
    assert "Reading Aircraft Configuration File" in out
    bad = re.findall(r"^.*(?:warning|error|missing|not found|unknown|does not exist|deprecated|nan\b).*$",
                     out, flags=re.IGNORECASE | re.MULTILINE)
    assert not bad, bad[:5]


@pytest.mark.parametrize("name,form", [("glider_unfolded", "unfolded"), ("glider_folded", "folded")])
def test_static_forms_mass_and_inertia_equal_table2(name, form):
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 100.0
    fdm.run_ic()
    assert fdm["inertia/mass-slugs"] * SLUG == pytest.approx(MASS_KG, rel=1e-6)
    np.testing.assert_allclose(_inertia_kgm2(fdm), TABLE2[form], rtol=INERTIA_RTOL, atol=INERTIA_ATOL)


def test_foldable_mass_properties_equal_table2_at_both_ends_with_fixed_cg():
    fdm = _fdm("glider_foldable")
    fdm["ic/h-agl-ft"] = 300.0
    fdm["ic/vt-fps"] = 40.0
    fdm.run_ic()
    fdm.run()
    cg0 = np.array(fdm.get_mass_balance().get_xyz_cg()).ravel() * IN
    assert fdm["fcs/wing-fold-norm"] == 0.0
    np.testing.assert_allclose(_inertia_kgm2(fdm), TABLE2["unfolded"], rtol=INERTIA_RTOL, atol=INERTIA_ATOL)
    fdm["fcs/wing-fold-cmd-norm"] = 1.0
    fold_time = fdm["fcs/wing-fold-time-s"]
    for _ in range(int(round((fold_time + 0.5) * 120))):
        fdm.run()
    assert fdm["fcs/wing-fold-norm"] == pytest.approx(1.0)
    np.testing.assert_allclose(_inertia_kgm2(fdm), TABLE2["folded"], rtol=INERTIA_RTOL, atol=INERTIA_ATOL)
    assert fdm["inertia/mass-slugs"] * SLUG == pytest.approx(MASS_KG, rel=1e-6)
    cg1 = np.array(fdm.get_mass_balance().get_xyz_cg()).ravel() * IN
    np.testing.assert_allclose(cg1, cg0, atol=1e-9)


def test_fold_actuator_is_rate_limited_to_the_fold_time():
    fdm = _fdm("glider_foldable")
    fdm["ic/h-agl-ft"] = 300.0
    fdm["ic/vt-fps"] = 40.0
    fdm.run_ic()
    fdm["fcs/wing-fold-cmd-norm"] = 1.0
    fold_time = fdm["fcs/wing-fold-time-s"]
    assert 0.2 <= fold_time <= 10.0
    for _ in range(60):  # half a second
        fdm.run()
    # linear travel at 1/fold_time per second; one frame of slack for the actuator's first step
    assert fdm["fcs/wing-fold-norm"] == pytest.approx(0.5 / fold_time, abs=1.0 / (120 * fold_time) + 1e-9)


def _helmbold(aspect: float) -> float:
    return 2 * math.pi * aspect / (2 + math.sqrt(aspect**2 / 0.81 + 4))


def _expected_pm(span: float, area: float, clmax: float, e: float, cd_min: float) -> dict[str, float]:
    aspect = span**2 / area
    cla = _helmbold(aspect)
    cl0 = cla * math.radians(3.0)
    k = 1.0 / (math.pi * e * aspect)
    return {"CL0": cl0, "CLalpha": cla, "CLmax": clmax, "CD0": cd_min + k * cl0**2,
            "CDalpha1": 2 * k * cl0 * cla, "CDalpha2": k * cla**2}


def test_point_mass_values_follow_the_design_formulas():
    chord = 1.1 / 8
    refs = {
        "glider_unfolded": (1.1, 1.1 * chord, _expected_pm(1.1, 1.1 * chord, 1.2, 0.8, 0.025)),
        "glider_folded": (0.22, 0.22 * chord, _expected_pm(0.22, 0.22 * chord, 0.9, 0.7, 0.0025 / (0.22 * chord))),
    }
    for name, (span, area, pm) in refs.items():
        doc = _doc(name)
        assert doc.number("metrics/wingspan") == pytest.approx(span, rel=1e-12)
        assert doc.number("metrics/wingarea") == pytest.approx(area, rel=1e-9)
        assert doc.number("metrics/chord") == pytest.approx(chord, rel=1e-9)
        assert doc.number("mass_balance/emptywt") == pytest.approx(MASS_KG, rel=1e-12)
        for key, value in pm.items():
            # the files carry 10 significant digits
            assert doc.property_value(f"aero/pm/{key}") == pytest.approx(value, rel=1e-8), (name, key)
        assert doc.property_value("propulsion/pm/T-max-N") == 8.0
        assert doc.property_value("propulsion/pm/disk-area-m2") == pytest.approx(math.pi * 0.1143**2, rel=1e-4)


@pytest.mark.parametrize("name", ["glider_unfolded", "glider_folded"])
def test_static_stability_signs_and_damping(name):
    doc = _doc(name)
    c = {k: doc.property_value(f"aero/coef/{k}") for k in COEF_NAMES}
    assert c["Cm_alpha"] < 0 and c["Cn_beta"] > 0 and c["Cl_beta"] < 0
    assert c["Cm_q"] < 0 and c["Cl_p"] < 0 and c["Cn_r"] < 0
    assert c["Cm_de"] < 0 and c["Cl_da"] > 0 and c["Cn_dr"] < 0 and c["CY_beta"] < 0


def test_unfolded_trims_at_best_glide_alpha_with_small_elevator():
    doc = _doc("glider_unfolded")
    pm = {k: doc.property_value(f"aero/pm/{k}") for k in PM_NAMES}

    def glide_ratio(a: float) -> float:
        return (pm["CL0"] + pm["CLalpha"] * a) / (pm["CD0"] + pm["CDalpha1"] * a + pm["CDalpha2"] * a * a)

    alphas = np.linspace(0.0, 0.3, 30001)
    a_star = alphas[np.argmax([glide_ratio(a) for a in alphas])]
    assert a_star == pytest.approx(0.10436, abs=2e-5)  # docs/design.md section 6
    cm0, cma, cmde = (doc.property_value(f"aero/coef/{k}") for k in ("Cm0", "Cm_alpha", "Cm_de"))
    de_trim = -(cm0 + cma * a_star) / cmde
    assert abs(de_trim) < math.radians(3.0)


def test_foldable_coefficient_sets_equal_the_static_forms():
    fold = _doc("glider_foldable")
    unf, fol = _doc("glider_unfolded"), _doc("glider_folded")
    for tag, static in (("unfolded", unf), ("folded", fol)):
        for k in PM_NAMES:
            assert fold.property_value(f"aero/{tag}/{k}") == static.property_value(f"aero/pm/{k}"), (tag, k)
        for k in COEF_NAMES:
            assert fold.property_value(f"aero/{tag}/{k}") == static.property_value(f"aero/coef/{k}"), (tag, k)
    s_ratio = fol.number("metrics/wingarea") / unf.number("metrics/wingarea")
    b_ratio = fol.number("metrics/wingspan") / unf.number("metrics/wingspan")
    assert fold.property_value("aero/fold/S-ratio") == pytest.approx(s_ratio, rel=1e-9)
    assert fold.property_value("aero/fold/b-ratio") == pytest.approx(b_ratio, rel=1e-9)
    assert fold.number("metrics/wingarea") == unf.number("metrics/wingarea")
    assert fold.number("metrics/wingspan") == unf.number("metrics/wingspan")


def _scale(key: str, s: float, b: float) -> float:
    """Factor taking a folded-form coefficient to the unfolded normalisation (S_u, c, b_u)."""
    if key in PM_NAMES or key.startswith(("CL", "CY", "Cm")):
        return s
    if key in ("Cl_p", "Cl_r", "Cn_p", "Cn_r"):
        return s * b * b
    return s * b


def test_foldable_runtime_coefficients_blend_to_the_static_sets():
    unf, fol = _doc("glider_unfolded"), _doc("glider_folded")
    s = fol.number("metrics/wingarea") / unf.number("metrics/wingarea")
    b = fol.number("metrics/wingspan") / unf.number("metrics/wingspan")
    fdm = _fdm("glider_foldable")
    fdm["ic/h-agl-ft"] = 300.0
    fdm["ic/vt-fps"] = 40.0
    fdm.run_ic()
    fdm.run()

    def current(key):
        return fdm[f"aero/pm/{key}" if key in PM_NAMES else f"aero/coef/{key}"]

    def static(doc, key):
        return doc.property_value(f"aero/pm/{key}" if key in PM_NAMES else f"aero/coef/{key}")

    for key in PM_NAMES + COEF_NAMES:
        assert current(key) == pytest.approx(static(unf, key), rel=1e-12, abs=1e-15), key
    fdm["fcs/wing-fold-cmd-norm"] = 1.0
    for _ in range(int(round((fdm["fcs/wing-fold-time-s"] + 0.5) * 120))):
        fdm.run()
    for key in PM_NAMES + COEF_NAMES:
        assert current(key) == pytest.approx(static(fol, key) * _scale(key, s, b), rel=1e-12, abs=1e-15), key


@pytest.mark.parametrize("name", ["glider_unfolded", "glider_folded"])
def test_lift_stalls_above_clmax(name):
    doc = _doc(name)
    clmax = doc.property_value("aero/pm/CLmax")
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 300.0
    fdm["ic/vt-fps"] = 40.0
    for alpha in (0.45, 0.6):
        fdm["ic/alpha-rad"] = alpha
        fdm.run_ic()
        assert fdm["aero/alpha-rad"] == pytest.approx(alpha, abs=1e-6)
        assert fdm["aero/pm/CL"] <= clmax + 1e-12
        assert fdm["aero/pm/CL"] < fdm["aero/pm/CL-lin"]


@pytest.mark.parametrize("name", NAMES)
def test_static_thrust_at_full_throttle_is_8_newton(name):
    """Sitting on its skids, held by the tether hook against the thrust of the previous frame."""
    fdm = _fdm(name)
    fdm["ic/h-agl-ft"] = 0.035 / FT
    fdm["ic/vt-fps"] = 0.0
    fdm["ic/theta-deg"] = 0.0
    fdm["ic/psi-true-deg"] = 0.0
    fdm.run_ic()
    fdm["external_reactions/tether/x"] = 0.0
    fdm["external_reactions/tether/magnitude"] = 1.0
    for _ in range(120):
        fdm.run()
    fdm["fcs/throttle-cmd-norm[0]"] = 1.0
    thrust_lbf = 0.0
    for _ in range(600):
        fdm["external_reactions/tether/x"] = -thrust_lbf  # north = nose direction
        fdm.run()
        thrust_lbf = fdm["propulsion/engine[0]/thrust-lbs"]
    assert abs(fdm["velocities/u-fps"]) * FT < 0.05  # held static
    assert thrust_lbf * LBF == pytest.approx(8.0, rel=0.10)
