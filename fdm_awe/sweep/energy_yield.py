"""Energy yield of a power curve at a site: mean electrical power, AEP and capacity factor.

The site is a wind speed distribution at the height ``--yield-height`` (:class:`Distribution`):
Rayleigh of annual mean ``V`` [m/s] (Weibull with ``k = 2``, ``c = 2 V / sqrt(pi)``) or Weibull
``(k, c)`` [-, m/s]. The curve's wind speeds hold at the curve's height (the sweep's reference
height); the wind profile (``log:Z0`` or ``power:ALPHA``) carries the site's speeds there:
``v_curve = v_site * f(H_curve) / f(H_site)`` with the profile's factor ``f``, i.e. the
Weibull scale is multiplied by that ratio (the shape is unchanged). A uniform profile leaves
the speeds as they are.

The power between two curve points is interpolated linearly; outside the curve's wind range
the system is not operated (zero power), and the distribution's mass there is reported
(below the lowest and above the highest wind). ``clip`` (default True): the system is not
operated where the interpolated net power is at most zero (it would draw energy from the grid
to fly, so an operator would park it); off, negative power counts as negative. The mass where
the curve is at most zero inside its range is reported either way.

Mean power ``P = integral of P(v) pdf(v) dv`` [W] (Gauss-Legendre quadrature per curve segment,
split at the zero crossings, :data:`GAUSS_NODES` nodes: exact to rounding for these smooth
integrands); ``AEP = P x 8766 h / 1000`` [kWh/yr] (a year of 365.25 days); capacity factor
``P / P_rated`` with ``P_rated`` given, else the curve's largest power (None when that is not
positive). A curve whose range holds less than :data:`OUTSIDE_MASS` of the distribution is
flagged: its yield says little about the site.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import InputError

#: hours of a year (365.25 days)
HOURS_PER_YEAR = 8766.0
#: Gauss-Legendre nodes per curve segment
GAUSS_NODES = 48
#: a curve whose wind range holds less than this fraction of the distribution is "outside its mass"
OUTSIDE_MASS = 0.01
#: allowed Rayleigh annual means [m/s], Weibull shapes [-] and scales [m/s]
MEAN_RANGE = (0.5, 30.0)
SHAPE_RANGE = (0.5, 10.0)
SCALE_RANGE = (0.5, 40.0)
#: allowed heights of the site's distribution [m]
HEIGHT_RANGE = (1.0, 1000.0)


@dataclass(frozen=True)
class Distribution:
    """A Weibull distribution of wind speed: shape ``k`` [-], scale ``c`` [m/s]; ``label`` as given."""

    k: float
    c: float
    label: str

    @property
    def mean(self) -> float:
        """Mean wind speed [m/s]."""
        return self.c * math.gamma(1.0 + 1.0 / self.k)

    def scaled(self, ratio: float) -> "Distribution":
        """The distribution of ``ratio`` x the speed (the profile's height ratio)."""
        return Distribution(self.k, self.c * ratio, self.label)

    def pdf(self, v: Any) -> Any:
        v = np.asarray(v, float)
        x = np.maximum(v, 0.0) / self.c
        return np.where(v > 0, self.k / self.c * x ** (self.k - 1.0) * np.exp(-(x ** self.k)), 0.0)

    def cdf(self, v: Any) -> Any:
        v = np.asarray(v, float)
        return np.where(v > 0, 1.0 - np.exp(-((np.maximum(v, 0.0) / self.c) ** self.k)), 0.0)


def rayleigh(mean: float) -> Distribution:
    """Rayleigh distribution of annual mean ``mean`` [m/s]."""
    return Distribution(2.0, 2.0 * mean / math.sqrt(math.pi), f"Rayleigh {mean:g} m/s")


def parse_distributions(texts: Sequence[str], option: str = "--yield") -> list[Distribution]:
    """``rayleigh:V1,V2,...`` (annual means [m/s]) or ``weibull:K:C`` (shape, scale [m/s]); one
    or more such texts. One-line errors naming the option, the field and its range."""
    out: list[Distribution] = []
    forms = "allowed rayleigh:MEAN[,MEAN...] or weibull:K:C"
    for text in texts:
        kind, _, rest = str(text).strip().lower().partition(":")
        if kind == "rayleigh":
            items = [x.strip() for x in rest.split(",")]
            if not rest or any(not x for x in items):
                raise InputError(f"{option} {text!r}: no annual mean wind speeds ({forms})")
            for x in items:
                v = _number(x, option, text, "annual mean", "m/s", MEAN_RANGE)
                out.append(rayleigh(v))
        elif kind == "weibull":
            parts = rest.split(":")
            if len(parts) != 2:
                raise InputError(f"{option} {text!r}: expected weibull:K:C (shape K, scale C in m/s)")
            k = _number(parts[0], option, text, "shape K", "", SHAPE_RANGE)
            c = _number(parts[1], option, text, "scale C", "m/s", SCALE_RANGE)
            out.append(Distribution(k, c, f"Weibull k={k:g} c={c:g} m/s"))
        else:
            raise InputError(f"{option} {text!r}: unknown distribution ({forms})")
    return out


def _number(x: str, option: str, text: str, what: str, unit: str, rng: tuple[float, float]) -> float:
    try:
        v = float(x)
    except ValueError:
        raise InputError(f"{option} {text!r}: {what} {x!r} is not a number") from None
    lo, hi = rng
    if not (math.isfinite(v) and lo <= v <= hi):
        raise InputError(f"{option} {text!r}: {what} {v:g} out of range (allowed {lo:g}..{hi:g}{' ' + unit if unit else ''})")
    return v


@dataclass(frozen=True)
class YieldResult:
    """The yield of one curve at one site (powers [W], energies [kWh/yr], masses as fractions)."""

    distribution: str
    mean_power_W: float
    aep_kWh: float
    capacity_factor: float | None
    rated_power_W: float | None
    mass_below: float  #: fraction of the distribution below the curve's lowest wind
    mass_above: float  #: fraction above its highest wind
    mass_not_operated: float  #: fraction inside the range where the net power is at most zero
    outside_mass: bool  #: the curve's range holds less than :data:`OUTSIDE_MASS` of the distribution
    clip: bool

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def _segments(v: np.ndarray, P: np.ndarray) -> list[tuple[float, float, float, float]]:
    """The curve's linear pieces ``(v0, v1, P0, P1)``, split where the power crosses zero."""
    out = []
    for i in range(len(v) - 1):
        v0, v1, p0, p1 = float(v[i]), float(v[i + 1]), float(P[i]), float(P[i + 1])
        if p0 * p1 < 0:
            vz = v0 + (v1 - v0) * p0 / (p0 - p1)
            out += [(v0, vz, p0, 0.0), (vz, v1, 0.0, p1)]
        else:
            out.append((v0, v1, p0, p1))
    return out


def mean_power(winds: Sequence[float], power: Sequence[float], dist: Distribution, clip: bool = True) -> tuple[float, float]:
    """``(mean power [W], mass where the curve is at most zero)`` of the curve (``winds`` [m/s]
    ascending, ``power`` [W]) under ``dist`` (already at the curve's height); see the module
    docstring."""
    v, P = np.asarray(winds, float), np.asarray(power, float)
    x, wq = np.polynomial.legendre.leggauss(GAUSS_NODES)
    total, off = 0.0, 0.0
    for v0, v1, p0, p1 in _segments(v, P):
        if v1 <= v0:
            continue
        nonpositive = p0 <= 0 and p1 <= 0
        if nonpositive:
            off += float(dist.cdf(v1) - dist.cdf(v0))
            if clip:
                continue
        vv = 0.5 * (v1 - v0) * x + 0.5 * (v1 + v0)
        pp = p0 + (p1 - p0) * (vv - v0) / (v1 - v0)
        total += 0.5 * (v1 - v0) * float(np.sum(wq * pp * dist.pdf(vv)))
    return total, off


def energy_yield(winds: Sequence[float], power: Sequence[float], dist: Distribution, *, clip: bool = True,
                 rated_power_W: float | None = None, height_ratio: float = 1.0) -> YieldResult:
    """The yield of one curve at the site ``dist`` (see the module docstring). ``height_ratio``:
    ``f(H_curve) / f(H_site)`` of the wind profile (1: the same height or a uniform wind)."""
    order = np.argsort(np.asarray(winds, float))
    v = np.asarray(winds, float)[order]
    P = np.asarray(power, float)[order]
    if len(v) == 0 or not np.all(np.isfinite(P)):
        raise InputError("yield: the curve needs at least one wind speed with a finite power")
    d = dist.scaled(height_ratio)
    below, above = float(d.cdf(v[0])), float(1.0 - d.cdf(v[-1]))
    if len(v) == 1:  # a single point: no range to operate in
        pm, off = 0.0, 0.0
    else:
        pm, off = mean_power(v, P, d, clip)
    rated = rated_power_W if rated_power_W is not None else float(np.max(P))
    cf = pm / rated if rated is not None and rated > 0 else None
    inside = 1.0 - below - above
    return YieldResult(dist.label, pm, pm * HOURS_PER_YEAR / 1000.0, cf, rated if rated > 0 else None, below, above, off,
                       inside < OUTSIDE_MASS, clip)


def cut_in_wind(winds: Sequence[float], power: Sequence[float]) -> float | None:
    """The wind [m/s] from which the curve stays positive up to its end (its zero crossing
    interpolated linearly; the lowest wind when positive throughout); None: not positive at
    its highest wind."""
    v, P = np.asarray(winds, float), np.asarray(power, float)
    if len(v) == 0 or P[-1] <= 0:
        return None
    i = len(v) - 1
    while i > 0 and P[i - 1] > 0:
        i -= 1
    if i == 0:
        return float(v[0])
    return float(v[i - 1] + (v[i] - v[i - 1]) * (-P[i - 1]) / (P[i] - P[i - 1]))


def rated_wind(winds: Sequence[float], power: Sequence[float], rated_power_W: float | None = None) -> tuple[float | None, bool]:
    """The lowest wind [m/s] at which the curve reaches the rated power (given, else its largest
    power; interpolated linearly) and whether that is the curve's highest wind (then the curve
    still rises there: the rated wind is at or above it)."""
    v, P = np.asarray(winds, float), np.asarray(power, float)
    if len(v) == 0:
        return None, False
    Pr = float(np.max(P)) if rated_power_W is None else float(rated_power_W)
    if Pr <= 0:
        return None, False
    for i in range(len(v)):
        if P[i] >= Pr:
            if i == 0:
                return float(v[0]), len(v) == 1
            vr = float(v[i - 1] + (v[i] - v[i - 1]) * (Pr - P[i - 1]) / (P[i] - P[i - 1]))
            return vr, i == len(v) - 1 and rated_power_W is None
    return None, True
