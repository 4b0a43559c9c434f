"""Stability margins of a feedback loop measured by breaking it and injecting a known signal.

The loop is broken at one point, the actuator input of a control loop: the controller's output
``u_out`` no longer goes straight to the plant, the plant gets ``u_in = u_out + d``, ``d`` the
injected signal. Going once round the loop from ``u_in`` back to ``u_out`` is the loop transfer
function ``L``: ``u_out = -L u_in`` (negative feedback), so at each injected frequency

    L(jw) = -U_out(jw) / U_in(jw)

from the Fourier coefficients of both signals. The other loops stay closed (loop-at-a-time
margins). The signal is a multisine (:class:`Multisine`): sines at chosen harmonics of one
period ``period_s``, with Schroeder phases (a low peak for its power), so that one run gives
every frequency and, over a whole number of periods, each coefficient is exact (no leakage
between the harmonics of a periodic steady state).

On a nonlinear plant (the 6-DOF glider, a manoeuvring point) the caller subtracts a run without
injection, started from the same state, from both signals (:func:`loop_gain` takes those
deviations): what is left is the plant's response to ``d`` alone, the co-simulation's own
finite difference about its trajectory, and its drift (a slow descent, a line paying out)
drops out.

Margins (:func:`margins`) are read off ``L`` on the measured frequencies:

- gain crossover: ``|L| = 1``; the phase margin there is the smallest phase change that brings
  ``L`` to -1, ``180 deg - |angle(L)|`` with the angle wrapped to (-180, 180];
- phase crossover: ``angle(L) = 180 deg`` (mod 360); the gain margin there is the gain change
  that brings ``|L|`` to 1, ``|20 log10 |L||`` dB (a loop whose gain is above 1 there has a
  lower gain margin: it goes unstable when its gain drops by that much);
- each margin is the smallest over its crossovers; none in the measured range gives infinity.

Crossovers between two measured frequencies are interpolated linearly in log frequency (gain in
dB, phase unwrapped between the pair).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class Multisine:
    """Sum of sines ``amplitude sin(w_k t + phi_k)``, ``w_k = 2 pi k / period_s`` for the
    harmonics ``k`` in ``harmonics``, Schroeder phases ``phi_k = -pi i (i + 1) / n`` (i the
    component's index, n their number). ``amplitude`` in the injected signal's unit."""

    period_s: float
    harmonics: tuple[int, ...]
    amplitude: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.period_s) and self.period_s > 0.0):
            raise InputError(f"Multisine.period_s: {self.period_s!r} out of range (allowed > 0 s)")
        if not self.harmonics or any(int(k) != k or k < 1 for k in self.harmonics) or \
                len(set(self.harmonics)) != len(self.harmonics):
            raise InputError(f"Multisine.harmonics: {self.harmonics!r} (allowed distinct integers >= 1)")
        if not (math.isfinite(self.amplitude) and self.amplitude > 0.0):
            raise InputError(f"Multisine.amplitude: {self.amplitude!r} out of range (allowed > 0)")

    @property
    def frequencies(self) -> np.ndarray:
        """Angular frequencies of the components [rad/s]."""
        return 2.0 * math.pi * np.asarray(self.harmonics, float) / self.period_s

    @property
    def phases(self) -> np.ndarray:
        """Schroeder phases of the components [rad]."""
        i = np.arange(len(self.harmonics), dtype=float)
        return -math.pi * i * (i + 1.0) / len(self.harmonics)

    def __call__(self, t: float | np.ndarray) -> float | np.ndarray:
        """The signal at time(s) ``t`` [s] from its start."""
        t = np.asarray(t, float)
        v = self.amplitude * np.sin(np.multiply.outer(t, self.frequencies) + self.phases).sum(axis=-1)
        return float(v) if v.ndim == 0 else v


def log_multisine(period_s: float, w_min: float, w_max: float, n: int, amplitude: float) -> Multisine:
    """A :class:`Multisine` of about ``n`` harmonics of ``period_s`` spread evenly in log
    frequency from ``w_min`` to ``w_max`` [rad/s] (repeats merged; the lowest is the first
    harmonic at least)."""
    w0 = 2.0 * math.pi / period_s
    if not (0.0 < w_min < w_max) or n < 2:
        raise InputError(f"log_multisine: need 0 < w_min < w_max and n >= 2, got {w_min!r}, {w_max!r}, {n!r}")
    k = np.unique(np.maximum(np.round(np.geomspace(w_min / w0, w_max / w0, n)), 1.0).astype(int))
    return Multisine(float(period_s), tuple(int(v) for v in k), float(amplitude))


def fourier(x: np.ndarray, t: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Fourier coefficients ``2/N sum x exp(-j w t)`` of samples ``x`` at times ``t`` [s] for the
    angular frequencies ``w`` [rad/s] (the complex amplitude of each component when the samples
    span whole periods of it)."""
    x = np.asarray(x, float)
    return 2.0 / len(x) * (np.exp(-1j * np.multiply.outer(np.asarray(w, float), np.asarray(t, float))) @ x)


def loop_gain(t: np.ndarray, u_in: np.ndarray, u_out: np.ndarray, signal: Multisine, t_on: float,
              settle_periods: int = 1, periods: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``(w, L)``: the loop transfer function ``L = -U_out/U_in`` at the signal's frequencies
    [rad/s], from the plant input ``u_in`` and the controller output ``u_out`` sampled at times
    ``t`` [s] (deviations from a run without injection on a nonlinear plant). The signal was
    switched on at ``t_on`` [s]; the first ``settle_periods`` of its periods are left for the
    transient, the next ``periods`` are analysed (they must lie within ``t``)."""
    t = np.asarray(t, float)
    a = t_on + settle_periods * signal.period_s
    b = a + periods * signal.period_s
    dt = float(np.median(np.diff(t)))
    sel = (t >= a - 0.5 * dt) & (t < b - 0.5 * dt)
    if t[-1] < b - 1.5 * dt or not sel.any():
        raise InputError(f"loop_gain: the samples end at {t[-1]:g} s, the analysis needs them to {b:g} s")
    w = signal.frequencies
    U_in = fourier(np.asarray(u_in, float)[sel], t[sel], w)
    U_out = fourier(np.asarray(u_out, float)[sel], t[sel], w)
    return w, -U_out / U_in


@dataclass(frozen=True)
class Margins:
    """Margins of one loop: gain margin [dB] at the phase crossover ``w_phase`` [rad/s], phase
    margin [deg] at the gain crossover ``w_gain`` [rad/s] (infinite / None where the measured
    range has no crossover)."""

    gain_margin_db: float
    phase_margin_deg: float
    w_gain: float | None
    w_phase: float | None

    def meets(self, gain_db: float = 6.0, phase_deg: float = 45.0) -> bool:
        """Both margins at least ``gain_db`` dB and ``phase_deg`` deg."""
        return self.gain_margin_db >= gain_db and self.phase_margin_deg >= phase_deg

    def as_dict(self) -> dict[str, float | None]:
        def fin(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else round(float(v), 4)

        return {"gain_margin_db": fin(self.gain_margin_db), "phase_margin_deg": fin(self.phase_margin_deg),
                "w_gain_rad_s": fin(self.w_gain), "w_phase_rad_s": fin(self.w_phase)}


def margins(w: np.ndarray, L: np.ndarray) -> Margins:
    """:class:`Margins` of the loop transfer function ``L`` sampled at increasing angular
    frequencies ``w`` [rad/s] (see the module doc)."""
    w = np.asarray(w, float)
    L = np.asarray(L, complex)
    if w.ndim != 1 or w.shape != L.shape or len(w) < 2 or np.any(np.diff(w) <= 0.0):
        raise InputError("margins: need increasing frequencies and one L value each (at least two)")
    lw = np.log(w)
    db = 20.0 * np.log10(np.abs(L))
    ph = np.degrees(np.unwrap(np.angle(L)))
    gm, w180 = math.inf, None
    pm, wc = math.inf, None
    for i in range(len(w) - 1):
        # gain crossover between samples i and i+1 (or on sample i)
        if db[i] == 0.0 or db[i] * db[i + 1] < 0.0:
            f = db[i] / (db[i] - db[i + 1])
            p = ph[i] + f * (ph[i + 1] - ph[i])
            m = 180.0 - abs((p + 180.0) % 360.0 - 180.0)
            if m < pm:
                pm, wc = m, float(math.exp(lw[i] + f * (lw[i + 1] - lw[i])))
        # phase crossover: the unwrapped phase passes an odd multiple of 180 deg
        k0, k1 = math.floor((ph[i] - 180.0) / 360.0), math.floor((ph[i + 1] - 180.0) / 360.0)
        if k0 != k1:
            target = 180.0 + 360.0 * max(k0, k1)
            f = (target - ph[i]) / (ph[i + 1] - ph[i])
            g = abs(db[i] + f * (db[i + 1] - db[i]))
            if g < gm:
                gm, w180 = g, float(math.exp(lw[i] + f * (lw[i + 1] - lw[i])))
    return Margins(gm, pm, wc, w180)
