"""Wind profile (shear): the horizontal wind's speed as a function of height above ground.

The wind keeps one direction at all heights; its speed at height ``h`` [m] is the speed at the
reference height ``ref_height`` [m] times a factor ``f(h)`` (``f(ref_height) = 1``):

- ``uniform``: ``f = 1`` (the paper's wind, the default: the wind speed of a run is the speed
  the glider meets at any height);
- ``log`` with roughness length ``z0`` [m]: ``f = ln(h / z0) / ln(h_ref / z0)`` (the neutral
  atmospheric surface layer; z0 ~ 0.0002 m open sea, 0.03 m short grass, 0.1 m open country
  with a few obstacles, 0.5-1 m suburbs and forest);
- ``power`` with exponent ``alpha``: ``f = (h / h_ref)^alpha`` (Hellmann's law; alpha ~ 0.1
  over water, 1/7 = 0.143 open land, 0.2-0.3 rough terrain).

Below :meth:`WindProfile.floor` (1 m, and at least twice ``z0`` for the log profile) the factor
holds its value at the floor: the logarithm changes sign at ``z0`` and the power law has an
infinite slope at the ground, and neither describes the air among the roughness elements. The
glider keeps at least the ground clearance ``h_min`` (10 m by default), far above the floor.

:meth:`WindProfile.factor` is written with :mod:`fdm_awe.pointmass.mathops`, so the same expression
evaluates on floats, NumPy arrays and CasADi symbols (the optimiser's).

The text form (command line ``--wind-profile`` and sweep points) is ``uniform``,
``log:Z0`` (``Z0`` in metres) or ``power:ALPHA``; the reference height is given apart
(``--wind-ref-height``, default :data:`REF_HEIGHT_DEFAULT_M`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

from .pointmass import mathops as mo
from .errors import InputError

#: profile kinds
WIND_PROFILES = ("uniform", "log", "power")
#: default reference height [m]: the meteorological standard (anemometers of weather stations
#: measure at 10 m, and wind atlases and turbine power curves quote speeds there)
REF_HEIGHT_DEFAULT_M = 10.0
#: allowed reference heights [m]
REF_HEIGHT_RANGE_M = (1.0, 1000.0)
#: allowed roughness lengths [m] (open sea .. city centre)
Z0_RANGE_M = (1e-5, 2.0)
#: allowed power-law exponents (0 is the uniform wind)
EXPONENT_RANGE = (0.0, 1.0)
#: lowest height [m] at which the profile is evaluated (below it the factor holds)
FLOOR_M = 1.0
#: The wind the line sees: a straight line from the winch to the glider moves, at the fraction
#: ``s`` of its length, with ``s`` times the glider's velocity, so its drag per length grows
#: with ``s^2`` and the share the glider carries (the moment about the winch) with another
#: ``s``: the glider's share is weighted with ``s^3`` along the line, whose centroid is at
#: ``s = 4/5``. The line drag takes the wind at this fraction of the glider's height.
LINE_HEIGHT_FRACTION = 0.8
#: numeric codes of the profile kinds for compiled code (:func:`shear_factor`)
KIND_CODES = {"uniform": 0.0, "log": 1.0, "power": 2.0}


def shear_factor(code: float, param: float, ref_height: float, floor: float, h: float) -> float:
    """:meth:`WindProfile.factor` on floats, with the profile as numbers (``code`` from
    :data:`KIND_CODES`, ``param`` z0 [m] or the exponent, ``ref_height`` and ``floor`` [m]):
    plain arithmetic that numba compiles (the lumped line's nodes evaluate it in the ground
    station's compiled step) and Python runs as it is."""
    if code == 0.0:
        return 1.0
    hc = h if h > floor else floor
    if code == 1.0:
        return math.log(hc / param) / math.log(ref_height / param)
    return (hc / ref_height) ** param


def _num(v: Any) -> str:
    """Shortest text that reads back as the same float (``10`` for 10.0)."""
    t = repr(float(v))
    return t[:-2] if t.endswith(".0") else t


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


@dataclass(frozen=True)
class WindProfile:
    """Wind speed over height (module docstring). ``z0`` [m] only for ``log``, ``exponent`` only
    for ``power``; ``ref_height`` [m] the height at which a run's wind speed is given (None for
    ``uniform``, which has none)."""

    kind: str = "uniform"
    z0: float | None = None
    exponent: float | None = None
    ref_height: float | None = None

    def __post_init__(self) -> None:
        if self.kind == "uniform":  # one canonical form: a uniform wind has no parameters
            object.__setattr__(self, "z0", None)
            object.__setattr__(self, "exponent", None)
            object.__setattr__(self, "ref_height", None)
        elif self.ref_height is None:
            object.__setattr__(self, "ref_height", REF_HEIGHT_DEFAULT_M)

    @property
    def uniform(self) -> bool:
        return self.kind == "uniform"

    def validate(self, field: str = "wind_profile") -> "WindProfile":
        """Range checks; one-line :class:`InputError` naming ``field`` and the allowed range."""
        if self.kind not in WIND_PROFILES:
            raise InputError(f"{field}: kind {self.kind!r} unknown (allowed: {', '.join(WIND_PROFILES)})")
        if self.uniform:
            return self
        lo, hi = REF_HEIGHT_RANGE_M
        if not (_finite(self.ref_height) and lo <= self.ref_height <= hi):  # type: ignore[operator]
            raise InputError(f"{field}: reference height {self.ref_height!r} m out of range (allowed {lo:g}..{hi:g} m)")
        if self.kind == "log":
            lo, hi = Z0_RANGE_M
            if not (_finite(self.z0) and lo <= self.z0 <= hi):  # type: ignore[operator]
                raise InputError(f"{field}: roughness length z0 {self.z0!r} m out of range (allowed {lo:g}..{hi:g} m)")
            if self.exponent is not None:
                raise InputError(f"{field}: the log profile takes no exponent (allowed: z0 only)")
            if self.ref_height <= self.floor():  # type: ignore[operator]
                raise InputError(f"{field}: reference height {self.ref_height:g} m must exceed {self.floor():g} m "
                                 f"(twice the roughness length z0 = {self.z0:g} m, at least {FLOOR_M:g} m)")
        else:
            lo, hi = EXPONENT_RANGE
            if not (_finite(self.exponent) and lo <= self.exponent <= hi):  # type: ignore[operator]
                raise InputError(f"{field}: power-law exponent {self.exponent!r} out of range (allowed {lo:g}..{hi:g})")
            if self.z0 is not None:
                raise InputError(f"{field}: the power profile takes no roughness length (allowed: exponent only)")
        return self

    def floor(self) -> float:
        """Height [m] below which the factor holds its value (module docstring)."""
        if self.kind == "log":
            return max(FLOOR_M, 2.0 * float(self.z0))  # type: ignore[arg-type]
        return FLOOR_M

    def factor(self, h: Any) -> Any:
        """Wind speed at height ``h`` [m] over the speed at the reference height (float, NumPy
        or CasADi); exactly 1.0 for the uniform profile."""
        if self.uniform:
            return 1.0
        if isinstance(h, (int, float)):  # plain numbers: the compiled line's own function
            return shear_factor(*self.numbers(), float(h))
        hc = mo.fmax(h, self.floor())
        href = float(self.ref_height)  # type: ignore[arg-type]
        if self.kind == "log":
            z0 = float(self.z0)  # type: ignore[arg-type]
            return mo.log(hc / z0) / math.log(href / z0)
        return (hc / href) ** float(self.exponent)  # type: ignore[arg-type]

    def numbers(self) -> tuple[float, float, float, float]:
        """``(code, param, ref_height, floor)`` of :func:`shear_factor` (zeros for uniform)."""
        if self.uniform:
            return (0.0, 0.0, 0.0, 0.0)
        param = float(self.z0 if self.kind == "log" else self.exponent)  # type: ignore[arg-type]
        return (KIND_CODES[self.kind], param, float(self.ref_height), float(self.floor()))  # type: ignore[arg-type]

    def wind_at(self, wind: Sequence[Any], h: Any) -> tuple[Any, ...]:
        """The horizontal wind components ``wind`` (at the reference height) scaled to height
        ``h`` [m]; ``wind`` itself (same objects) for the uniform profile."""
        if self.uniform:
            return tuple(wind)
        f = self.factor(h)
        return tuple(w * f for w in wind)

    def label(self) -> str:
        """Text form: ``uniform``, ``log:Z0@H`` or ``power:ALPHA@H`` (H the reference height [m])."""
        if self.uniform:
            return "uniform"
        par = self.z0 if self.kind == "log" else self.exponent
        return f"{self.kind}:{_num(par)}@{_num(self.ref_height)}"

    def describe(self) -> str:
        """One phrase for reports, e.g. ``log profile (z0 0.1 m), wind at 10 m``."""
        if self.uniform:
            return "uniform wind (the same speed at every height)"
        par = f"z0 {self.z0:g} m" if self.kind == "log" else f"exponent {self.exponent:g}"
        return f"{self.kind} profile ({par}), wind speed given at {self.ref_height:g} m"

    def as_dict(self) -> dict[str, Any]:
        """JSON form (reference metadata, sweep records): ``kind`` and, for a shear profile,
        ``ref_height_m`` and ``z0_m`` or ``exponent``."""
        if self.uniform:
            return {"kind": "uniform"}
        d: dict[str, Any] = {"kind": self.kind, "ref_height_m": float(self.ref_height)}  # type: ignore[arg-type]
        if self.kind == "log":
            d["z0_m"] = float(self.z0)  # type: ignore[arg-type]
        else:
            d["exponent"] = float(self.exponent)  # type: ignore[arg-type]
        return d

    @classmethod
    def from_dict(cls, d: Any, field: str = "wind_profile") -> "WindProfile":
        """The profile of :meth:`as_dict`'s form, checked (one-line :class:`InputError` naming
        ``field``); None is the uniform wind (files written before profiles existed)."""
        if d is None:
            return cls()
        if not isinstance(d, dict):
            raise InputError(f"{field}: {type(d).__name__}, expected an object with kind "
                             f"({', '.join(WIND_PROFILES)}), ref_height_m and z0_m or exponent")
        known = {"kind", "ref_height_m", "z0_m", "exponent"}
        extra = sorted(set(d) - known)
        if extra:
            raise InputError(f"{field}: unknown field {extra[0]!r} (allowed: {', '.join(sorted(known))})")
        kind = d.get("kind")
        if kind not in WIND_PROFILES:
            raise InputError(f"{field}.kind: {kind!r} unknown (allowed: {', '.join(WIND_PROFILES)})")
        if kind == "uniform":
            if len(d) > 1:
                raise InputError(f"{field}: a uniform wind has no parameters (allowed: kind only)")
            return cls()
        if "ref_height_m" not in d:
            raise InputError(f"{field}.ref_height_m: missing (allowed {REF_HEIGHT_RANGE_M[0]:g}..{REF_HEIGHT_RANGE_M[1]:g} m)")
        p = cls(kind, d.get("z0_m"), d.get("exponent"), d.get("ref_height_m"))
        return p.validate(field)

    @classmethod
    def parse(cls, text: str, ref_height: float | None = None, option: str = "--wind-profile") -> "WindProfile":
        """The profile of the text form ``uniform``, ``log:Z0`` or ``power:ALPHA`` (an optional
        ``@H`` gives the reference height [m]; else ``ref_height``, else
        :data:`REF_HEIGHT_DEFAULT_M`); one-line :class:`InputError` naming ``option``."""
        allowed = "allowed uniform, log:Z0 (roughness length, m) or power:ALPHA (exponent)"
        s = str(text).strip().lower()
        if "@" in s:
            s, _, h = s.partition("@")
            try:
                ref_height = float(h)
            except ValueError:
                raise InputError(f"{option} {text!r}: reference height {h!r} is not a number ({allowed}, optionally @H metres)") from None
        kind, _, par = s.partition(":")
        if kind == "uniform" and not par:
            return cls()
        if kind not in ("log", "power") or not par:
            raise InputError(f"{option} {text!r} invalid ({allowed})")
        try:
            value = float(par)
        except ValueError:
            raise InputError(f"{option} {text!r}: {par!r} is not a number ({allowed})") from None
        h = REF_HEIGHT_DEFAULT_M if ref_height is None else float(ref_height)
        p = cls(kind, value if kind == "log" else None, value if kind == "power" else None, h)
        return p.validate(option)


def line_height(h: Any) -> Any:
    """Height [m] whose wind the line drag uses for a glider at height ``h`` [m]
    (:data:`LINE_HEIGHT_FRACTION`)."""
    return LINE_HEIGHT_FRACTION * h
