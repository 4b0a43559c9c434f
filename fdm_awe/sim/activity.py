"""Control activity of a flight: how much the control surfaces move above a cut-off frequency.

A path-following glider moves its surfaces slowly, at the rate of the manoeuvres (a pumping cycle
of 20-60 s, loops of a few seconds). Motion above about 0.5 Hz is the loops' own work (gust
rejection) or a loop ringing: a sustained oscillation of the surfaces shows here as a large
value. The measure is the RMS of each surface command above ``f_cut``: the square root of its
power spectral density (Welch's method, Hann window, linear detrend per segment) integrated from
``f_cut`` to the Nyquist frequency. A sine of amplitude ``A`` well above the cut-off gives
``A / sqrt(2)``; a slow manoeuvre well below it gives about 0 (the Hann window's side lobes fall
by 18 dB per octave, so a large slow motion does not leak into the band).

Surface commands are normalised (-1 .. 1, the JSBSim flight-control inputs), so the RMS is in
units of full deflection.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import welch

from ..errors import InputError

#: Hz, the default cut-off: above the manoeuvres of a pumping cycle, below the attitude loops'
#: bandwidths (1-6 rad/s, 0.2-1 Hz, and their ringing)
F_CUT_HZ = 0.5
#: s, Welch segment length: a frequency resolution of 0.125 Hz, four bins below the cut-off
SEGMENT_S = 8.0
#: the surfaces measured (columns of :data:`fdm_awe.sim.result.COLUMNS`)
SURFACES = ("aileron", "elevator", "rudder")


@dataclass(frozen=True)
class ControlActivity:
    """RMS of each surface command above ``f_cut_hz`` (full deflections) and their root sum
    of squares ``total``."""

    f_cut_hz: float
    aileron: float
    elevator: float
    rudder: float

    @property
    def total(self) -> float:
        return math.sqrt(self.aileron ** 2 + self.elevator ** 2 + self.rudder ** 2)

    def as_dict(self) -> dict[str, float]:
        return {"f_cut_hz": self.f_cut_hz, "aileron_rms": self.aileron, "elevator_rms": self.elevator,
                "rudder_rms": self.rudder, "total_rms": self.total}


def band_rms(x: np.ndarray, dt: float, f_cut: float = F_CUT_HZ, segment_s: float = SEGMENT_S) -> float:
    """RMS of the signal ``x`` (sampled every ``dt`` s) above ``f_cut`` Hz; NaN samples (a flight
    that ended early) are dropped from the end. Too short a signal (under two segments of a
    quarter of ``segment_s``) gives NaN."""
    if not (math.isfinite(dt) and dt > 0.0):
        raise InputError(f"dt: {dt!r} out of range (allowed > 0 s)")
    fs = 1.0 / dt
    if not (math.isfinite(f_cut) and 0.0 < f_cut < 0.5 * fs):
        raise InputError(f"f_cut: {f_cut!r} Hz out of range (allowed 0 .. {0.5 * fs:g} Hz, the Nyquist frequency)")
    x = np.asarray(x, dtype=float)
    bad = ~np.isfinite(x)
    if bad.any():
        x = x[: int(np.argmax(bad))]  # up to the first NaN
    nper = int(round(segment_s * fs))
    if len(x) < max(nper // 2, 8):
        return math.nan
    nper = min(nper, len(x))
    f, pxx = welch(x, fs=fs, window="hann", nperseg=nper, detrend="linear", scaling="density")
    band = f >= f_cut
    if not band.any():
        return 0.0
    df = f[1] - f[0]
    return float(math.sqrt(max(float(np.sum(pxx[band])) * df, 0.0)))


def control_activity(aileron: np.ndarray, elevator: np.ndarray, rudder: np.ndarray, dt: float,
                     f_cut: float = F_CUT_HZ) -> ControlActivity:
    """:class:`ControlActivity` of the three surface-command series (normalised, every ``dt`` s)."""
    return ControlActivity(f_cut_hz=float(f_cut), aileron=band_rms(aileron, dt, f_cut),
                           elevator=band_rms(elevator, dt, f_cut), rudder=band_rms(rudder, dt, f_cut))
