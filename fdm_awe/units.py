"""Unit conversion constants: the one place SI meets JSBSim's English units."""

from __future__ import annotations

FT = 0.3048  #: metres per foot
IN = 0.0254  #: metres per inch
LBF = 4.4482216152605  #: newtons per pound-force
LB = 0.45359237  #: kilograms per pound-mass
SLUG = 14.593902937206364  #: kilograms per slug
SLUG_FT2 = SLUG * FT * FT  #: kg m^2 per slug ft^2
PSF = LBF / (FT * FT)  #: pascals per lbf/ft^2
KT = 1852.0 / 3600.0  #: m/s per knot
HP = 745.69987158227022  #: watts per horsepower

# Factors to SI for the unit attributes used in JSBSim XML files.
TO_SI: dict[str, float] = {
    "M": 1.0,
    "FT": FT,
    "IN": IN,
    "M2": 1.0,
    "FT2": FT * FT,
    "KG": 1.0,
    "LBS": LB,
    "SLUG": SLUG,
    "KG*M2": 1.0,
    "SLUG*FT2": SLUG_FT2,
    "N": 1.0,
    "LBS_FORCE": LBF,
    "RAD": 1.0,
    "DEG": 3.141592653589793 / 180.0,
    "W": 1.0,
    "WATTS": 1.0,
    "HP": HP,
    "S": 1.0,
    "SEC": 1.0,
    "M/S": 1.0,
    "FT/SEC": FT,
}
