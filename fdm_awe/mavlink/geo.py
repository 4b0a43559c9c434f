"""Local NED (origin at the winch) <-> WGS-84 latitude/longitude/altitude about a home.

Flat-earth (equirectangular) mapping with the WGS-84 radii of curvature at the home
latitude: north = dlat * M(lat0), east = dlon * N(lat0) * cos(lat0), down = alt0 - alt,
where M = a (1 - e^2) / (1 - e^2 sin^2 lat0)^1.5 is the meridian radius and
N = a / sqrt(1 - e^2 sin^2 lat0) the prime-vertical radius. Over a tethered flight
(a few hundred metres) the error against the ellipsoid is far below a centimetre,
smaller than MAVLink's 1e-7 degree quantisation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fdm_awe.errors import InputError

WGS84_A = 6378137.0                      # semi-major axis, m
WGS84_F = 1.0 / 298.257223563            # flattening
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)     # first eccentricity squared


@dataclass(frozen=True)
class Home:
    """Geodetic position of the winch (NED origin): degrees, degrees, m above mean sea level.

    The default is ArduPilot SITL's usual home (Canberra Model Aircraft Club), which
    ground-station users will recognise on their maps.
    """

    lat_deg: float = -35.363262
    lon_deg: float = 149.165237
    alt_m: float = 584.0

    def __post_init__(self) -> None:
        for name, lo, hi in (("lat_deg", -89.0, 89.0), ("lon_deg", -180.0, 180.0),
                             ("alt_m", -500.0, 10000.0)):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
                raise InputError(f"home {name}: {v!r} outside [{lo:g}, {hi:g}]")


class GeoFrame:
    """Converts between local NED (m) and lat/lon (deg)/alt (m AMSL) about a Home."""

    def __init__(self, home: Home | None = None) -> None:
        self.home = home or Home()
        phi = math.radians(self.home.lat_deg)
        s2 = math.sin(phi) ** 2
        w = 1.0 - WGS84_E2 * s2
        #: meridian radius of curvature at home, m
        self.r_north = WGS84_A * (1.0 - WGS84_E2) / w ** 1.5
        #: radius of the parallel at home (N cos(lat)), m
        self.r_east = WGS84_A / math.sqrt(w) * math.cos(phi)
        self._deg_per_m_n = math.degrees(1.0 / self.r_north)
        self._deg_per_m_e = math.degrees(1.0 / self.r_east)

    def to_geodetic(self, north: float, east: float, down: float) -> tuple[float, float, float]:
        """NED (m) -> (lat deg, lon deg, alt m AMSL)."""
        h = self.home
        lon = h.lon_deg + east * self._deg_per_m_e
        lon = (lon + 180.0) % 360.0 - 180.0
        return h.lat_deg + north * self._deg_per_m_n, lon, h.alt_m - down

    def to_ned(self, lat_deg: float, lon_deg: float, alt_m: float) -> tuple[float, float, float]:
        """(lat deg, lon deg, alt m AMSL) -> NED (m)."""
        h = self.home
        dlon = (lon_deg - h.lon_deg + 180.0) % 360.0 - 180.0
        return ((lat_deg - h.lat_deg) / self._deg_per_m_n, dlon / self._deg_per_m_e,
                h.alt_m - alt_m)
