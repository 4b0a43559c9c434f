"""The airframe checks every JSBSim aircraft file gets besides its geometry, mass, propulsion
values and aerodynamics (:mod:`.aircraft` checks those): flight controls (the surface scalings
the 6-DOF adapter reads, ranges, clips and rate limits), ground contacts and their ground-contact
flag (:data:`GROUND_CONTACT`), the tether hook and the engine feeds. Each raises
:class:`~fdm_awe.errors.DefinitionError` (file, element, allowed range).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from ..errors import DefinitionError
from .xmlutil import XmlDoc, element_number, location

#: Surface command scalings the 6-DOF adapter reads (deflection at full command, rad).
SURFACES = ("fcs/pitch-cmd-rad", "fcs/roll-cmd-rad", "fcs/yaw-cmd-rad")
#: Largest surface deflection at full command [rad].
SURFACE_MAX_RAD = math.pi / 2
#: The airframe's ground-contact flag, 1 when any contact touches the ground: a post function of
#: ``<ground_reactions>`` over the WOW of every contact (JSBSim's ``gear/wow`` counts BOGEY
#: contacts only; skids and wingtips are STRUCTURE contacts). The 6-DOF row reads it.
GROUND_CONTACT = "contact/wow"


def _controls(doc: XmlDoc) -> None:
    """Flight controls: the three surface scalings the adapter reads (deflection at full command
    in (0, pi/2] rad, at the opposite full command in [-pi/2, 0) rad), every numeric ``<range>`` and
    ``<clipto>`` with min < max, every numeric ``<rate_limit>`` > 0."""
    fcs = doc.find("flight_control")
    assert fcs is not None
    for name in SURFACES:
        el = fcs.find(f".//aerosurface_scale[@name='{name}']")
        if el is None:
            raise DefinitionError(doc.path, f"flight_control/aerosurface_scale[{name}]", "missing element (the 6-DOF adapter reads it)")
        what = f"aerosurface_scale[{name}]/range"
        lo_el, hi_el = el.find("range/min"), el.find("range/max")
        if lo_el is None or hi_el is None:
            raise DefinitionError(doc.origin(el), what, "needs <min> and <max> (deflection at full command, rad)")
        element_number(doc.origin(hi_el), f"{what}/max", hi_el, lo=0.0, hi=SURFACE_MAX_RAD, lo_open=True, unit="rad")
        element_number(doc.origin(lo_el), f"{what}/min", lo_el, lo=-SURFACE_MAX_RAD, hi=0.0, hi_open=True, unit="rad")
    for tag in ("range", "clipto"):
        for i, el in enumerate(fcs.iter(tag)):
            lo_el, hi_el = el.find("min"), el.find("max")
            try:
                lo, hi = float((lo_el.text or "").strip()), float((hi_el.text or "").strip())  # type: ignore[union-attr]
            except (AttributeError, ValueError):
                continue  # property bounds (checked by name) or missing: JSBSim's defaults
            if not lo < hi:
                raise DefinitionError(doc.origin(el), f"flight_control/{tag}[{i}]", f"min {lo:g} >= max {hi:g} (allowed min < max)")
    for i, el in enumerate(fcs.iter("rate_limit")):
        try:
            v = float((el.text or "").strip())
        except ValueError:
            continue  # a property name
        if not v > 0.0:
            raise DefinitionError(doc.origin(el), f"flight_control/rate_limit[{i}]", f"value {v:g} out of range (allowed > 0 per s)")


def _contacts(doc: XmlDoc) -> None:
    """Ground contacts: a location, spring > 0, damping and friction coefficients >= 0 (as
    written: JSBSim converts their units)."""
    gr = doc.find("ground_reactions")
    assert gr is not None
    contacts = gr.findall("contact")
    if not contacts:
        raise DefinitionError(doc.path, "ground_reactions/contact", "missing element (the glider needs contacts to land)")
    for el in contacts:
        what = f"ground_reactions/contact[{el.attrib.get('name', '?')}]"
        loc = el.find("location")
        if loc is None:
            raise DefinitionError(doc.origin(el), f"{what}/location", "missing element")
        location(doc.origin(loc), loc, f"{what}/location")
        for tag, lo, lo_open in (("spring_coeff", 0.0, True), ("damping_coeff", 0.0, False), ("static_friction", 0.0, False),
                                 ("dynamic_friction", 0.0, False), ("rolling_friction", 0.0, False)):
            sub = el.find(tag)
            if sub is None:
                if tag == "spring_coeff":
                    raise DefinitionError(doc.origin(el), f"{what}/{tag}", "missing element")
                continue
            element_number(doc.origin(sub), f"{what}/{tag}", sub, lo=lo, lo_open=lo_open, convert=False)
    _ground_contact_flag(doc, contacts)


def _ground_contact_flag(doc: XmlDoc, contacts: list[ET.Element]) -> None:
    """The :data:`GROUND_CONTACT` post function of ``<ground_reactions>`` reads the WOW flag of
    every contact (JSBSim numbers the contacts in document order, a section's own before those
    of its section file; ``gear/unit[i]`` for BOGEY, ``contact/unit[i]`` for other types)."""
    what = f"ground_reactions/function[{GROUND_CONTACT}]"
    fn = doc.find(f"ground_reactions/function[@name='{GROUND_CONTACT}']", required=False)
    if fn is None:
        raise DefinitionError(doc.path, what, "missing element (the 6-DOF model's ground-contact flag)")
    if fn.attrib.get("type", "").strip() != "post":
        raise DefinitionError(doc.origin(fn), what, 'needs type="post" (evaluated after the contacts of the step)')
    read = {(el.text or "").strip().replace("[0]", "") for el in fn.iter("property")}
    for i, el in enumerate(contacts):
        flag = f"{'gear' if el.attrib.get('type') == 'BOGEY' else 'contact'}/unit[{i}]/WOW".replace("[0]", "")
        if flag not in read:
            raise DefinitionError(doc.origin(fn), what, f"does not read {flag} (contact {el.attrib.get('name', i)}): "
                                                        "it must read the WOW of every contact")


def _external_forces(doc: XmlDoc) -> None:
    """The tether hook the adapter drives (``external_reactions/force[tether]``, LOCAL frame)."""
    hook = doc.find("external_reactions/force[@name='tether']", required=False)
    if hook is None:
        raise DefinitionError(doc.path, "external_reactions/force[tether]", "missing element (the tether hook the ground station pulls)")
    if hook.attrib.get("frame", "").upper() != "LOCAL":
        raise DefinitionError(doc.origin(hook), "external_reactions/force[tether]", f"frame {hook.attrib.get('frame')!r} not allowed (allowed LOCAL: NED force components)")
    loc = hook.find("location")
    if loc is None:
        raise DefinitionError(doc.origin(hook), "external_reactions/force[tether]/location", "missing element")
    location(doc.origin(loc), loc, "external_reactions/force[tether]/location")


def _feeds(doc: XmlDoc) -> None:
    """Every engine ``<feed>`` names a tank of ``<propulsion>`` (JSBSim numbers them from 0)."""
    tanks = len(doc.root.findall("propulsion/tank"))
    for el in doc.root.iterfind("propulsion/engine/feed"):
        v = element_number(doc.origin(el), "propulsion/engine/feed", el)
        if not (0 <= v < tanks and v == int(v)):
            raise DefinitionError(doc.origin(el), "propulsion/engine/feed",
                                  f"tank {v:g} does not exist (the aircraft has {tanks} tank(s); an electric drive needs no <feed>)")


def airframe_checks(doc: XmlDoc) -> None:
    """The checks every aircraft file gets besides its geometry, mass, propulsion values and
    aerodynamics: controls, contacts, tether hook, engine feeds."""
    _controls(doc)
    _contacts(doc)
    _external_forces(doc)
    _feeds(doc)
