"""Small, strict helpers to read numbers out of definition XML files.

Every failure raises :class:`fdm_awe.errors.DefinitionError` whose one-line message names
the file and the element (and the allowed range where one applies).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ..errors import DefinitionError
from ..units import TO_SI


@dataclass(frozen=True)
class XmlDoc:
    """A parsed definition file: its path (for messages) and its root element."""

    path: Path
    root: ET.Element

    @classmethod
    def load(cls, path: str | Path) -> "XmlDoc":
        p = Path(path)
        if not p.is_file():
            raise DefinitionError(p, "file", "not found")
        try:
            root = ET.parse(p).getroot()
        except ET.ParseError as exc:
            raise DefinitionError(p, "xml", f"not well-formed XML ({exc})") from None
        return cls(p, root)

    # -- element access ----------------------------------------------------------
    def find(self, xpath: str, required: bool = True) -> ET.Element | None:
        el = self.root.find(xpath)
        if el is None and required:
            raise DefinitionError(self.path, xpath, "missing element")
        return el

    def number(
        self,
        xpath: str,
        *,
        unit: str | None = None,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        default: float | None = None,
    ) -> float:
        """Read the float text of ``xpath``, converted to SI from its ``unit`` attribute.

        ``unit`` names the SI unit the caller expects (for the message); ``lo``/``hi`` bound
        the converted value (``lo_open`` makes the lower bound strict, e.g. ``> 0``).
        """
        el = self.find(xpath, required=default is None)
        if el is None:
            return float(default)  # type: ignore[arg-type]
        return element_number(self.path, xpath, el, lo=lo, hi=hi, lo_open=lo_open)

    def property_value(
        self,
        name: str,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
    ) -> float:
        """Value of a JSBSim ``<property value="...">name</property>`` declaration."""
        for el in self.root.iter("property"):
            if (el.text or "").strip() == name and "value" in el.attrib:
                return _check(self.path, f"property {name}", _to_float(self.path, f"property {name}", el.attrib["value"]), lo, hi, lo_open)
        raise DefinitionError(self.path, f"property {name}", "missing declaration (<property value=...>)")


def _to_float(path: Path, what: str, text: str | None) -> float:
    try:
        v = float((text or "").strip())
    except ValueError:
        raise DefinitionError(path, what, f"not a number: {text!r}") from None
    if not math.isfinite(v):
        raise DefinitionError(path, what, f"not a finite number: {text!r}")
    return v


def _check(path: Path, what: str, v: float, lo: float | None, hi: float | None, lo_open: bool) -> float:
    if lo is not None and (v <= lo if lo_open else v < lo):
        rng = f"{'>' if lo_open else '>='} {lo:g}" + (f" and <= {hi:g}" if hi is not None else "")
        raise DefinitionError(path, what, f"value {v:g} out of range (allowed {rng})")
    if hi is not None and v > hi:
        rng = (f"{'>' if lo_open else '>='} {lo:g} and " if lo is not None else "") + f"<= {hi:g}"
        raise DefinitionError(path, what, f"value {v:g} out of range (allowed {rng})")
    return v


def element_number(
    path: Path,
    what: str,
    el: ET.Element,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
) -> float:
    """Float text of ``el`` converted to SI with its ``unit`` attribute, range-checked."""
    v = _to_float(path, what, el.text)
    unit = el.attrib.get("unit")
    if unit is not None:
        if unit.upper() not in TO_SI:
            raise DefinitionError(path, what, f"unknown unit {unit!r} (known: {', '.join(sorted(TO_SI))})")
        v *= TO_SI[unit.upper()]
    return _check(path, what, v, lo, hi, lo_open)


def location(path: Path, el: ET.Element, what: str) -> tuple[float, float, float]:
    """A JSBSim ``<location unit=..>`` with x, y, z children, in metres."""
    unit = el.attrib.get("unit", "IN").upper()
    if unit not in TO_SI:
        raise DefinitionError(path, what, f"unknown unit {unit!r}")
    out = []
    for axis in ("x", "y", "z"):
        c = el.find(axis)
        if c is None:
            raise DefinitionError(path, f"{what}/{axis}", "missing element")
        out.append(_to_float(path, f"{what}/{axis}", c.text) * TO_SI[unit])
    return (out[0], out[1], out[2])
