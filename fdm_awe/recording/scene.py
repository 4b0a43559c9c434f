"""Geometry and colours shared by the recordings and the plots (NumPy only, no rerun).

The glider is drawn as a wireframe in body axes (x forward, y right, z down, origin at the
CG): fuselage, wing, horizontal tail and fin. The wing span follows the fold state linearly
from the unfolded to the folded span (both read from the aircraft definition files), so a
folded glider is visibly short-winged. Drawing proportions other than the spans, the chord
and the tail arm are only for looks.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

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


@dataclass(frozen=True)
class GliderShape:
    """Dimensions [m] of the drawn glider (spans and chord from the aircraft files)."""

    span_unfolded: float
    span_folded: float
    chord: float
    tail_arm: float
    tail_span: float

    @property
    def nose(self) -> float:
        return 0.35 * self.tail_arm

    def wing(self, fold: float) -> np.ndarray:
        """Wing outline (5, 3) at fold state ``fold`` (0 unfolded .. 1 folded), body axes."""
        f = float(np.clip(np.nan_to_num(fold), 0.0, 1.0))
        b = self.span_unfolded + f * (self.span_folded - self.span_unfolded)
        c = self.chord
        h = 0.5 * b
        le, te = 0.25 * c, -0.75 * c
        return np.array([[le, -h, 0.0], [le, h, 0.0], [te, h, 0.0], [te, -h, 0.0], [le, -h, 0.0]])

    def fixed_parts(self) -> list[np.ndarray]:
        """Fuselage, horizontal tail, fin (line strips in body axes)."""
        xt = -self.tail_arm
        hs = 0.5 * self.tail_span
        ct = 0.6 * self.chord
        fus = np.array([[self.nose, 0.0, 0.0], [xt - 0.5 * ct, 0.0, 0.0]])
        htail = np.array([[xt, -hs, 0.0], [xt, hs, 0.0], [xt - ct, hs, 0.0], [xt - ct, -hs, 0.0], [xt, -hs, 0.0]])
        fin = np.array([[xt, 0.0, 0.0], [xt - ct, 0.0, -0.6 * hs], [xt - ct, 0.0, 0.0]])
        return [fus, htail, fin]


@lru_cache(maxsize=4)
def glider_shape() -> GliderShape:
    """Shape of the foldable glider from ``aircraft/`` (spans, chord, tail arm and area)."""
    from .. import ROOT
    from ..definitions.aircraft import load_glider
    from ..definitions.xmlutil import XmlDoc

    g = load_glider()
    doc = XmlDoc.load(ROOT / "aircraft" / "glider_unfolded" / "glider_unfolded.xml")
    arm = doc.number("metrics/htailarm", lo=0.0, lo_open=True)
    area = doc.number("metrics/htailarea", lo=0.0, lo_open=True)
    # tail drawn with aspect ratio 3.125 (the tail of the aircraft files) from its area
    return GliderShape(g.unfolded.aero.b, g.folded.aero.b, g.unfolded.aero.c, arm, float(np.sqrt(3.125 * area)))


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


__all__ = ["GliderShape", "PHASE_COLORS", "REFERENCE_COLOR", "TETHER_COLOR", "WIND_COLOR", "glider_shape",
           "ground_grid", "phase_color", "phase_color_float", "scene_extent"]
