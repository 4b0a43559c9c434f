"""Turbulence of a flight (``fly --turbulence``): the forms, the JSBSim parameters each one sets,
its target intensity, and the intensity the glider met.

Every form is realised by JSBSim's MIL-F-8785C turbulence in its Tustin form (``turb-type`` 4,
``FGWinds::Turbulence``), which takes two parameters: the wind at 20 ft ``W20``
(``atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps``) and a severity index
(``.../milspec/severity``, the row of the standard's probability-of-exceedance table, Fig. 7).
Below 1000 ft (305 m) JSBSim follows the standard's low-altitude model, with ``h`` the height in
ft, held at 10 ft below 10 ft:

- ``sigma_w = 0.1 W20`` (vertical), ``sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4``
  (longitudinal, along the mean wind, and lateral);
- scale lengths ``L_w = h``, ``L_u = L_v = h / (0.177 + 0.000823 h)^1.2`` (ft), time constants
  ``L / V`` with ``V`` the airspeed (the glider flies through frozen turbulence).

The severity index only acts above 1000 ft (the high-altitude table, blended in linearly up to
2000 ft) and must be non-zero (zero switches the turbulence off). The forms:

- ``LEVEL[:SEED]`` with LEVEL ``light``, ``moderate``, ``severe``: a fixed ``W20`` of 15, 30,
  45 kt (the standard's low-altitude severities) and the index 3, 4, 6, whatever the flight's
  wind (the original forms, kept for old results);
- ``milspec:SEVERITY[:SEED]``: ``W20`` the flight's own wind at 20 ft (6.096 m; its profile's
  value there), so the intensity follows the wind; SEVERITY (light, moderate, severe) sets the
  index for flight above 1000 ft only: below it the standard's sigma is ``0.1 W20`` whatever the
  severity;
- ``iec:CLASS[:SEED]`` with CLASS ``A``, ``B``, ``C``: IEC 61400-1 (edition 3) normal turbulence
  model, ``sigma_1 = I_ref (0.75 V_hub + 5.6 m/s)`` with ``I_ref`` 0.16, 0.14, 0.12. The hub
  height is the reference cycle's time-mean height, ``V_hub`` the wind there (its profile's).
  ``W20`` is chosen so that JSBSim's longitudinal sigma at the hub height is ``sigma_1``:
  ``W20 = 10 sigma_1 (0.177 + 0.000823 h_hub)^0.4`` (h_hub in ft). Only the longitudinal sigma
  at the hub height matches IEC: JSBSim's lateral sigma equals it (IEC: 0.7 sigma_1), its
  vertical sigma is ``(0.177 + 0.000823 h)^0.4`` of it (0.72 at 100 m; IEC: 0.5), and its
  longitudinal sigma grows below the hub height and falls above it (x1.15 at 50 m, x0.87 at
  170 m for a hub at 100 m), where IEC's is the same at every height of the rotor.

SEED (1..2**31-1, default 1) seeds JSBSim's random generator; a flight repeats for a seed.

The target (:meth:`TurbulenceSetting.targets`) is the longitudinal sigma at the hub height and
the intensity ``sigma_u / V_hub``. The measurement (:func:`measure`) takes the wind the glider
met (logged total wind at its CG) minus the steady wind JSBSim was given at each step, splits it
into longitudinal (along the mean wind), lateral and vertical parts and takes their RMS about
zero (the turbulence's known mean; a record's own mean would bias a short record's sigma low),
over the whole flight; the intensity is that longitudinal sigma over the time-mean steady wind
speed at the glider.

Only the standard library is imported here: the command line parses the forms at start-up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

from .errors import InputError
from .units import FT

#: seeds of JSBSim's random generator (a positive 32-bit signed integer)
SEED_MIN, SEED_MAX = 1, 2**31 - 1
#: the named levels: (JSBSim severity index, wind at 20 ft in kt)
TURBULENCE_LEVELS: dict[str, tuple[int, float]] = {"light": (3, 15.0), "moderate": (4, 30.0), "severe": (6, 45.0)}
#: IEC 61400-1 ed. 3 turbulence classes: the expected intensity at 15 m/s, I_ref
IEC_CLASSES: dict[str, float] = {"A": 0.16, "B": 0.14, "C": 0.12}
#: the normal turbulence model's offset b [m/s]: sigma_1 = I_ref (0.75 V_hub + b)
IEC_B_MPS = 5.6
#: the height of the standard's reference wind W20 [m] (20 ft)
W20_HEIGHT_M = 20.0 * FT
#: the low-altitude model's range [m]: JSBSim holds the height at 10 ft below and leaves the model above 1000 ft
LOW_ALTITUDE_M = (10.0 * FT, 1000.0 * FT)
#: the forms of ``--turbulence``, for messages
FORMS = "LEVEL[:SEED] (light, moderate, severe), milspec:SEVERITY[:SEED] (light, moderate, severe) or iec:CLASS[:SEED] (A, B, C)"


def sigma_ratio(h: float) -> float:
    """JSBSim's ``sigma_u / sigma_w`` below 1000 ft at height ``h`` [m]:
    ``1 / (0.177 + 0.000823 h_ft)^0.4`` (h held at 10 ft below 10 ft)."""
    h_ft = max(float(h), LOW_ALTITUDE_M[0]) / FT
    return 1.0 / (0.177 + 0.000823 * h_ft) ** 0.4


def iec_sigma(i_ref: float, v_hub: float) -> float:
    """IEC 61400-1 normal turbulence model: the longitudinal sigma [m/s] at hub wind ``v_hub`` [m/s]."""
    return i_ref * (0.75 * v_hub + IEC_B_MPS)


def _seed(text: str, seed: str, option: str) -> int:
    try:
        n = int(seed)
    except ValueError:
        raise InputError(f"{option} {text!r}: seed {seed!r} is not an integer (allowed {SEED_MIN}..{SEED_MAX}; "
                         f"forms {FORMS})") from None
    if not SEED_MIN <= n <= SEED_MAX:
        raise InputError(f"{option} {text!r}: seed {n} out of range (allowed {SEED_MIN}..{SEED_MAX})")
    return n


@dataclass(frozen=True)
class Turbulence:
    """A turbulence form (module docstring): ``form`` ``"level"``, ``"milspec"`` or ``"iec"``,
    ``name`` the level or severity (light, moderate, severe) or the IEC class (A, B, C), and the
    ``seed``."""

    form: str
    name: str
    seed: int = SEED_MIN

    @classmethod
    def parse(cls, text: str, option: str = "--turbulence") -> "Turbulence":
        """The form of ``text``; a one-line :class:`InputError` naming ``option`` and the forms."""
        parts = str(text).strip().split(":")
        head = parts[0].lower()
        if head in TURBULENCE_LEVELS:
            if len(parts) > 2:
                raise InputError(f"{option} {text!r}: too many fields (allowed forms {FORMS})")
            return cls("level", head, _seed(text, parts[1], option) if len(parts) == 2 else SEED_MIN)
        if head in ("milspec", "iec"):
            names = tuple(TURBULENCE_LEVELS) if head == "milspec" else tuple(IEC_CLASSES)
            what = "severity" if head == "milspec" else "class"
            if len(parts) < 2 or not parts[1]:
                raise InputError(f"{option} {text!r}: {head} needs a {what} ({', '.join(names)}; forms {FORMS})")
            name = parts[1].lower() if head == "milspec" else parts[1].upper()
            if name not in names:
                raise InputError(f"{option} {text!r}: {what} {parts[1]!r} unknown (allowed {', '.join(names)}; "
                                 f"forms {FORMS})")
            if len(parts) > 3:
                raise InputError(f"{option} {text!r}: too many fields (allowed forms {FORMS})")
            return cls(head, name, _seed(text, parts[2], option) if len(parts) == 3 else SEED_MIN)
        raise InputError(f"{option} {text!r}: form {parts[0]!r} unknown (allowed forms {FORMS})")

    @classmethod
    def of(cls, value: "Turbulence | tuple[str, int] | None") -> "Turbulence | None":
        """``value`` as a form: a :class:`Turbulence`, None, or a named level's ``(level, seed)``."""
        if value is None or isinstance(value, Turbulence):
            return value
        try:
            level, seed = value
        except (TypeError, ValueError):
            raise InputError(f"turbulence: expected (level, seed) or a Turbulence form, got {value!r}") from None
        if level not in TURBULENCE_LEVELS:
            raise InputError(f"turbulence level: {level!r} not one of {', '.join(TURBULENCE_LEVELS)}")
        return cls("level", level, int(seed))

    def text(self) -> str:
        """The command-line form, e.g. ``iec:A:3``."""
        return f"{self.name}:{self.seed}" if self.form == "level" else f"{self.form}:{self.name}:{self.seed}"

    def setting(self, wind_mps: float = 0.0, profile: Any = None, hub_height_m: float | None = None,
                field: str = "--turbulence") -> "TurbulenceSetting":
        """The JSBSim parameters of this form for a flight in the wind ``wind_mps`` [m/s] at the
        reference height of ``profile`` (a :class:`fdm_awe.wind.WindProfile`; None: uniform),
        with the hub height ``hub_height_m`` [m] (the reference cycle's mean height; needed by
        ``iec``, used by every form for its targets). One-line :class:`InputError` naming
        ``field`` when the form cannot be realised (an IEC hub above JSBSim's low-altitude model)."""
        factor = (lambda h: 1.0) if profile is None else (lambda h: float(profile.factor(h)))
        v_hub = None if hub_height_m is None else float(wind_mps) * factor(hub_height_m)
        if self.form == "level":
            severity, w20_kt = TURBULENCE_LEVELS[self.name]
            w20 = w20_kt * 1852.0 / 3600.0
        elif self.form == "milspec":
            severity = TURBULENCE_LEVELS[self.name][0]
            w20 = float(wind_mps) * factor(W20_HEIGHT_M)
        else:
            if hub_height_m is None:
                raise InputError(f"{field} {self.text()}: the IEC form needs the hub height (the reference's mean height)")
            if not hub_height_m <= LOW_ALTITUDE_M[1]:
                raise InputError(f"{field} {self.text()}: the reference's mean height {hub_height_m:.0f} m is above "
                                 f"{LOW_ALTITUDE_M[1]:.0f} m (1000 ft), where JSBSim's turbulence leaves the "
                                 f"low-altitude model (allowed: an IEC hub at most {LOW_ALTITUDE_M[1]:.0f} m)")
            severity = TURBULENCE_LEVELS["light"][0]  # acts above 1000 ft only
            w20 = 10.0 * iec_sigma(IEC_CLASSES[self.name], v_hub) / sigma_ratio(hub_height_m)  # type: ignore[arg-type]
        return TurbulenceSetting(self, int(severity), float(w20),
                                 None if hub_height_m is None else float(hub_height_m), v_hub)


@dataclass(frozen=True)
class TurbulenceSetting:
    """A form realised for one flight: JSBSim's severity index and wind at 20 ft ``w20_mps``
    [m/s], the hub height [m] and the steady wind there [m/s] (None when not known)."""

    turbulence: Turbulence
    severity: int
    w20_mps: float
    hub_height_m: float | None = None
    wind_hub_mps: float | None = None

    @property
    def seed(self) -> int:
        return self.turbulence.seed

    def sigma_u(self, h: float) -> float:
        """JSBSim's longitudinal (and lateral) sigma [m/s] at height ``h`` [m] below 1000 ft."""
        return 0.1 * self.w20_mps * sigma_ratio(h)

    @property
    def sigma_w(self) -> float:
        """JSBSim's vertical sigma [m/s] below 1000 ft."""
        return 0.1 * self.w20_mps

    def targets(self) -> dict[str, float | None]:
        """``sigma_u_mps`` at the hub height, ``sigma_w_mps``, and the ``intensity`` sigma_u / V_hub
        (None where the hub height or a non-zero hub wind is not known)."""
        h = self.hub_height_m
        su = None if h is None else self.sigma_u(h)
        v = self.wind_hub_mps
        return {"sigma_u_mps": su, "sigma_w_mps": self.sigma_w,
                "intensity": None if su is None or not v else su / v}

    def as_dict(self) -> dict[str, Any]:
        """JSON form: ``form``, the level / severity / IEC class, ``seed``, the JSBSim parameters
        (``severity_index``, ``w20_mps``), ``hub_height_m``, ``wind_hub_mps`` and ``target``."""
        t = self.turbulence
        d: dict[str, Any] = {"form": t.form, "text": t.text()}
        if t.form == "level":
            d["level"] = t.name
        elif t.form == "milspec":
            d["severity"] = t.name
        else:
            d["iec_class"] = t.name
            d["i_ref"] = IEC_CLASSES[t.name]
        d.update({"seed": t.seed, "severity_index": self.severity, "w20_mps": self.w20_mps,
                  "hub_height_m": self.hub_height_m, "wind_hub_mps": self.wind_hub_mps, "target": self.targets()})
        return d


def mean_height(t: Sequence[float], height: Sequence[float]) -> float:
    """Time-mean [m] of ``height`` [m] sampled at times ``t`` [s] (trapezoidal rule)."""
    s = 0.0
    for i in range(1, len(t)):
        s += 0.5 * (height[i] + height[i - 1]) * (t[i] - t[i - 1])
    return s / (t[-1] - t[0])


def measure(t: Any, wind: Any, steady: Any, direction: Sequence[float]) -> dict[str, float | None]:
    """The turbulence the glider met (module docstring): ``t`` [s] (n,), the logged total wind
    ``wind`` and the steady wind it was given ``steady`` (n, 3) NED [m/s], ``direction`` the
    mean wind's horizontal direction (N, E; any length). Returns the longitudinal, lateral and
    vertical sigma [m/s], the time-mean steady wind speed ``mean_wind_mps`` [m/s], the
    ``intensity`` and the record's length ``duration_s`` [s] (None where no finite row is)."""
    import numpy as np

    t = np.asarray(t, float)
    g = np.asarray(wind, float) - np.asarray(steady, float)
    ok = np.isfinite(g).all(axis=1) & np.isfinite(t)
    t, g, st = t[ok], g[ok], np.asarray(steady, float)[ok]
    none = {"sigma_u_mps": None, "sigma_v_mps": None, "sigma_w_mps": None, "mean_wind_mps": None,
            "intensity": None, "duration_s": 0.0}
    if len(t) < 2:
        return none
    dn, de = float(direction[0]), float(direction[1])
    norm = math.hypot(dn, de)
    ex = (dn / norm, de / norm) if norm > 0 else (1.0, 0.0)
    u = g[:, 0] * ex[0] + g[:, 1] * ex[1]
    v = -g[:, 0] * ex[1] + g[:, 1] * ex[0]
    rms = lambda a: float(np.sqrt(np.mean(a * a)))  # noqa: E731
    su = rms(u)
    mean = float(np.mean(np.hypot(st[:, 0], st[:, 1])))
    return {"sigma_u_mps": su, "sigma_v_mps": rms(v), "sigma_w_mps": rms(g[:, 2]), "mean_wind_mps": mean,
            "intensity": su / mean if mean > 0 else None, "duration_s": float(t[-1] - t[0])}


__all__ = ["FORMS", "IEC_B_MPS", "IEC_CLASSES", "LOW_ALTITUDE_M", "SEED_MAX", "SEED_MIN", "TURBULENCE_LEVELS",
           "W20_HEIGHT_M", "Turbulence", "TurbulenceSetting", "iec_sigma", "mean_height", "measure", "sigma_ratio"]
