"""Ground-station variants for design studies: the package's (or a user's) definition with
another supply voltage, written as a file of its own so that a run made with it records and
reproduces it (``--ground-station FILE``; its hash keys the optimiser's caches and the sweep's
points).

The supply voltage ``V_a`` is the one number the variant changes in the drive's physics: what
the drive allows follows from it through the ground station's own relations
(:func:`~.steady.motor_max_reel_in_speed`, :func:`~.steady.motor_steady`), read from the
variant file like from any other. The speed controller's gains are derived in the definition
for its supply (pole-zero cancellation, ``Kp = 20 J R / (K_t V_a)``, ``Ki = Kp x`` the
mechanical pole): the plant's gain ``K_t V_a / R`` scales with ``V_a``, so the variant scales
``kp`` and ``ki`` by ``V_old / V_new`` and keeps the loop's 20 rad/s crossover. Nothing else
changes.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..fileio import atomic_write_text
from .source import StationFile, resolve_ground_station

#: allowed supply voltages of a variant [V]: the optimiser's range (``--supply-voltage``)
SUPPLY_VOLTAGE_RANGE = (6.0, 200.0)

_FIELD = r'(<{tag} unit="[^"]*">)\s*([-+0-9.eE]+)\s*(</{tag}>)'


def check_supply_voltage(volts: float, option: str = "--supply-voltage") -> float:
    """``volts`` [V] if finite and within :data:`SUPPLY_VOLTAGE_RANGE`; else one-line
    :class:`~fdm_awe.errors.InputError` naming ``option`` and the range."""
    lo, hi = SUPPLY_VOLTAGE_RANGE
    v = float(volts)
    if not (math.isfinite(v) and lo <= v <= hi):
        raise InputError(f"{option} {volts!r} (winch supply) out of range (allowed {lo:g}..{hi:g} V)")
    return v


def _replace_one(text: str, tag: str, new: Any, source: Path) -> tuple[str, float]:
    """``text`` with the value of the one element ``tag`` replaced by ``new(old)``; the old value."""
    pat = re.compile(_FIELD.format(tag=tag))
    found = pat.findall(text)
    if len(found) != 1:
        raise InputError(f"{source}: <{tag}>: expected once with a unit attribute, found {len(found)} times")
    old = float(found[0][1])
    return pat.sub(lambda g: f"{g.group(1)} {new(old)!r} {g.group(3)}", text), old


def supply_variant_text(volts: float, source: "str | os.PathLike[str] | StationFile | None" = None,
                        option: str = "--supply-voltage") -> str:
    """The text of the ground-station definition ``source`` (None: the package's) with the
    supply voltage ``volts`` [V] and the speed controller's gains scaled for it (module
    docstring); checked range (:data:`SUPPLY_VOLTAGE_RANGE`, errors name ``option``)."""
    v = check_supply_voltage(volts, option)
    st = resolve_ground_station(source, "--ground-station")
    text = st.path.read_text(encoding="utf-8")
    text, v_old = _replace_one(text, "supply_voltage", lambda _old: v, st.path)
    scale = v_old / v
    for tag in ("kp", "ki"):
        text, _ = _replace_one(text, tag, lambda old: float(f"{old * scale:.6g}"), st.path)
    return text


def write_supply_variant(volts: float, dest: "str | os.PathLike[str]",
                         source: "str | os.PathLike[str] | StationFile | None" = None,
                         option: str = "--supply-voltage") -> StationFile:
    """Write the variant of :func:`supply_variant_text` to ``dest`` (atomically; unchanged
    bytes when the file already holds them, so a rerun keeps its hash) and return it resolved
    and checked like any ``--ground-station`` file."""
    text = supply_variant_text(volts, source, option)
    p = Path(dest)
    if not (p.is_file() and p.read_text(encoding="utf-8") == text):
        p.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(p, text)
    return resolve_ground_station(p, option)


def variant_name(volts: float) -> str:
    """The file name of the variant at ``volts`` [V], e.g. ``ground_station_36V.xml``."""
    return f"ground_station_{float(volts):g}V.xml"
