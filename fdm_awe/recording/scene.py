"""Geometry and colours shared by the recordings and the plots (NumPy only, no rerun).

The glider is drawn as a triangle mesh in body axes (x forward, y right, z down, origin at the
CG): fuselage, wing, horizontal tail and fin. From the aircraft definition files: the wing
span (unfolded and folded; the drawn span follows the fold state linearly between them), the
chord, the tail arms and areas, and the nose (the propeller's location ahead of the CG). Only
for looks: the thicknesses, the fuselage's cross-section and the fin's aspect ratio.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

#: RGB (0-255) per phase label; anything else is drawn grey.
PHASE_COLORS: dict[str, tuple[int, int, int]] = {
    "generation": (31, 119, 180),  # blue
    "recovery": (255, 127, 14),  # orange
    "ground": (127, 127, 127),
    "none": (127, 127, 127),
}
OTHER_COLOR = (148, 103, 189)  # purple
REFERENCE_COLOR = (60, 60, 60)
TETHER_COLOR = (214, 39, 40)  # red
WIND_COLOR = (44, 160, 44)  # green


def phase_color(label: str) -> tuple[int, int, int]:
    return PHASE_COLORS.get(label, OTHER_COLOR)


def phase_color_float(label: str) -> tuple[float, float, float]:
    r, g, b = phase_color(label)
    return (r / 255.0, g / 255.0, b / 255.0)


#: fin aspect ratio (height / mean chord) of the drawing; the files give only its area
FIN_ASPECT = 1.2
#: tail-plane aspect ratio (span / chord) of the drawing, from the tail the aircraft files describe
TAIL_ASPECT = 3.125


@dataclass(frozen=True)
class GliderShape:
    """Dimensions [m] of the drawn glider (from the aircraft files, see the module text)."""

    span_unfolded: float
    span_folded: float
    chord: float
    nose: float  #: nose ahead of the CG
    htail_arm: float  #: CG to the tail plane's quarter chord
    htail_area: float  #: [m^2]
    vtail_arm: float  #: CG to the fin's quarter chord
    vtail_area: float  #: [m^2]

    def span(self, fold: float) -> float:
        """Wing span [m] at fold state ``fold`` (0 unfolded .. 1 folded; NaN counts as 0)."""
        f = float(np.clip(np.nan_to_num(fold), 0.0, 1.0))
        return self.span_unfolded + f * (self.span_folded - self.span_unfolded)

    def wing_mesh(self, fold: float) -> tuple[np.ndarray, np.ndarray]:
        """(vertices (8, 3), triangles (12, 3)) of the wing at fold state ``fold``, body axes:
        a plate of the span, the chord (quarter chord on the CG) and 8 % of the chord thick."""
        c, h = self.chord, 0.5 * self.span(fold)
        return _box((-0.75 * c, 0.25 * c), (-h, h), (-0.04 * c, 0.04 * c))

    def body_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """(vertices, triangles) of fuselage, tail plane and fin, body axes (fin upwards: -z)."""
        ct = float(np.sqrt(self.htail_area / TAIL_ASPECT))
        st = TAIL_ASPECT * ct
        cf = float(np.sqrt(self.vtail_area / FIN_ASPECT))
        hf = FIN_ASPECT * cf
        xt, xf = -self.htail_arm, -self.vtail_arm
        tail_end = min(xt - 0.75 * ct, xf - 0.75 * cf)
        w = 0.08 * self.chord  # fuselage half width and half height
        fus = _loft([(self.nose, 0.3 * w), (0.6 * self.nose, w), (-0.75 * self.chord, w), (tail_end, 0.4 * w)])
        htail = _box((xt - 0.75 * ct, xt + 0.25 * ct), (-0.5 * st, 0.5 * st), (-0.05 * ct, 0.05 * ct))
        fin = _box((xf - 0.75 * cf, xf + 0.25 * cf), (-0.04 * cf, 0.04 * cf), (-hf, 0.0))
        return _join([fus, htail, fin])


def _box(xs: tuple[float, float], ys: tuple[float, float], zs: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned box: 8 vertices, 12 outward-facing triangles."""
    v = np.array([[x, y, z] for x in xs for y in ys for z in zs], float)
    # vertex index = 4 i_x + 2 i_y + i_z
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))], np.uint32)


def _loft(sections: list[tuple[float, float]]) -> tuple[np.ndarray, np.ndarray]:
    """A body of square cross-sections ``(x, half width)`` along x, closed at both ends."""
    ring = np.array([[0.0, -1.0, -1.0], [0.0, 1.0, -1.0], [0.0, 1.0, 1.0], [0.0, -1.0, 1.0]])
    v = np.vstack([ring * [0.0, hw, hw] + [x, 0.0, 0.0] for x, hw in sections])
    tris = []
    for s in range(len(sections) - 1):
        a, b = 4 * s, 4 * (s + 1)
        for k in range(4):
            k1 = (k + 1) % 4
            tris += [(a + k, b + k, b + k1), (a + k, b + k1, a + k1)]
    last = 4 * (len(sections) - 1)
    tris += [(0, 1, 2), (0, 2, 3), (last, last + 2, last + 1), (last, last + 3, last + 2)]
    return v, np.array(tris, np.uint32)


def _join(parts: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """One mesh of several (vertices, triangles)."""
    verts, tris, n = [], [], 0
    for v, t in parts:
        verts.append(v)
        tris.append(t + n)
        n += len(v)
    return np.vstack(verts), np.vstack(tris).astype(np.uint32)


def recorded_aircraft(record: Any) -> Any:
    """The :class:`~fdm_awe.definitions.catalog.Aircraft` a flight report or reference records
    (``aircraft``: a table ``name`` or a ``directory``); None (the package's glider) when it
    records none or its folder is gone (a recording is drawn all the same)."""
    from ..definitions.catalog import resolve_aircraft
    from ..errors import FdmAweError

    if not isinstance(record, dict):
        return None
    spec = record.get("name") or record.get("directory")
    try:
        return resolve_aircraft(spec) if isinstance(spec, str) else None
    except FdmAweError:
        return None


@lru_cache(maxsize=4)
def glider_shape(aircraft: Any = None) -> GliderShape:
    """Shape of the foldable glider (spans, chord, nose, tail arms and areas) from the files of
    ``aircraft`` (a :class:`~fdm_awe.definitions.catalog.Aircraft`; None: the package's glider)."""
    from ..definitions.aircraft import load_glider
    from ..definitions.catalog import resolve_aircraft
    from ..definitions.xmlutil import XmlDoc, location

    a = resolve_aircraft(aircraft)
    g = load_glider(a)
    doc = XmlDoc.load(a.path("unfolded"))
    num = {k: doc.number(f"metrics/{k}", lo=0.0, lo_open=True) for k in ("htailarm", "htailarea", "vtailarm", "vtailarea")}
    prop = location(doc.path, doc.find("propulsion/engine/thruster/location"), "propulsion/engine/thruster/location")
    # structural x points aft: the propeller (on the nose) lies cg_x - prop_x ahead of the CG
    nose = max(g.unfolded.mass.cg_structural[0] - prop[0], 0.5 * g.unfolded.aero.c)
    return GliderShape(g.unfolded.aero.b, g.folded.aero.b, g.unfolded.aero.c, nose, num["htailarm"], num["htailarea"],
                       num["vtailarm"], num["vtailarea"])


def ground_grid(x_range: tuple[float, float], y_range: tuple[float, float], step: float = 50.0) -> list[np.ndarray]:
    """Lines of a square grid on the ground (z = 0) covering the ranges [m], ``step`` apart."""
    x0, x1 = np.floor(x_range[0] / step) * step, np.ceil(x_range[1] / step) * step
    y0, y1 = np.floor(y_range[0] / step) * step, np.ceil(y_range[1] / step) * step
    lines = [np.array([[x, y0, 0.0], [x, y1, 0.0]]) for x in np.arange(x0, x1 + 0.5 * step, step)]
    lines += [np.array([[x0, y, 0.0], [x1, y, 0.0]]) for y in np.arange(y0, y1 + 0.5 * step, step)]
    return lines


def scene_extent(*paths: np.ndarray, margin: float = 50.0) -> tuple[tuple[float, float], tuple[float, float]]:
    """Ground x/y ranges [m] covering the winch and every finite point of ``paths``."""
    pts = [np.zeros((1, 3))] + [np.asarray(p, float).reshape(-1, 3) for p in paths if p is not None and len(p)]
    a = np.vstack(pts)
    a = a[np.all(np.isfinite(a), axis=1)]
    return ((a[:, 0].min() - margin, a[:, 0].max() + margin), (a[:, 1].min() - margin, a[:, 1].max() + margin))


__all__ = ["FIN_ASPECT", "GliderShape", "TAIL_ASPECT", "PHASE_COLORS", "REFERENCE_COLOR", "TETHER_COLOR", "WIND_COLOR", "glider_shape",
           "ground_grid", "phase_color", "phase_color_float", "scene_extent"]
